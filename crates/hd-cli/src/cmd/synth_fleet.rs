//! `hdw synth fleet`: a synthetic fleet (robots × joints × days of friction joint tests)
//! with known temperature effects and wear, its manifest and its truth.

use anyhow::{Context, Result, bail};
use clap::Args;
use hd_ident::fleet::synth::{FleetSpec, Wear};
use hd_ident::synth::{Noise, PlateauProfile, synth_plateaus};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::path::PathBuf;

/// Write a synthetic fleet: logs, manifest.csv, truth.csv and truth.json.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "Each unit (robot rR, joint jJ) draws its own Tc, Ts, ws, sigma2 around the registry defaults\n\
(sigma2 = 0.05 N·m·s/rad; log-normal spread --unit-spread). Each robot's ambient temperature cycles\n\
T = 25 °C + A·sin(2π·day/P + φ) + weather; each parameter is multiplied by exp(c·(T − 25)) (c = --coef-levels\n\
for Tc and Ts, --coef-viscous for sigma2), by a day-to-day scatter (1 + --day-scatter·N(0,1)) and, in the\n\
units named by --wear rR/jJ@DAY (1-based), by a wear factor rising linearly by --wear-rise over\n\
--wear-days from that day and held there. Each log is a joint test (hdw synth friction --profile joint):\n\
--levels speeds from --omega-min to --omega-max, forwards and backwards, in --duration s at --sample-rate,\n\
the LuGre torque along it plus Gaussian noise (--noise × RMS).\n\n\
Outputs (in --out DIR): logs/rR/jJ/DATE.csv (t [s], omega [rad/s], torque [N·m]); manifest.csv (file,\n\
robot, joint, date, temperature); truth.csv (the true parameters of every log); truth.json (the spec).\n\n\
Example:\n  hdw synth fleet --robots 2 --joints 2 --days 24 --duration 4 --wear r2/j1@14 --out out/fleet-data"
)]
pub struct FleetSynthArgs {
    /// Robots.
    #[arg(long, default_value_t = 4)]
    pub robots: usize,
    /// Joints per robot.
    #[arg(long, default_value_t = 3)]
    pub joints: usize,
    /// Days (one log per unit and day).
    #[arg(long, default_value_t = 60)]
    pub days: usize,
    /// Date of the first day.
    #[arg(long, value_name = "YYYY-MM-DD", default_value = "2026-01-05")]
    pub start: String,
    /// Amplitude of the temperature cycle [K].
    #[arg(long, default_value_t = 10.0)]
    pub temp_amplitude: f64,
    /// Period of the temperature cycle [days].
    #[arg(long, default_value_t = 15.0)]
    pub temp_period: f64,
    /// Day-to-day weather on top of the cycle [K].
    #[arg(long, default_value_t = 1.0)]
    pub temp_noise: f64,
    /// Temperature effect on Tc and Ts [1/K] (−0.006: about −0.6 %/K).
    #[arg(long, default_value_t = -0.006)]
    pub coef_levels: f64,
    /// Temperature effect on sigma2 [1/K].
    #[arg(long, default_value_t = -0.02)]
    pub coef_viscous: f64,
    /// Relative spread of the units' own parameters.
    #[arg(long, default_value_t = 0.1)]
    pub unit_spread: f64,
    /// Relative day-to-day scatter of the parameters.
    #[arg(long, default_value_t = 0.003)]
    pub day_scatter: f64,
    /// A wearing unit and its first day (0-based day), e.g. r2/j1@30 (repeatable).
    #[arg(long, value_name = "rR/jJ@DAY")]
    pub wear: Vec<String>,
    /// Rise of Tc, Ts, sigma2 at the end of the wear ramp.
    #[arg(long, default_value_t = 0.15)]
    pub wear_rise: f64,
    /// Length of the wear ramp [days].
    #[arg(long, default_value_t = 20.0)]
    pub wear_days: f64,
    /// Measurement noise relative to the RMS torque.
    #[arg(long, default_value_t = 0.01)]
    pub noise: f64,
    /// Speed levels of the joint test.
    #[arg(long, default_value_t = 8)]
    pub levels: usize,
    /// Length of each log [s].
    #[arg(long, default_value_t = 10.0)]
    pub duration: f64,
    /// Sampling rate [Hz].
    #[arg(long, default_value_t = 1000.0)]
    pub sample_rate: f64,
    /// Speed changes [s].
    #[arg(long, default_value_t = 0.05)]
    pub transition: f64,
    /// Slowest plateau [rad/s].
    #[arg(long, default_value_t = 1e-3)]
    pub omega_min: f64,
    /// Fastest plateau [rad/s].
    #[arg(long, default_value_t = 1.0)]
    pub omega_max: f64,
    /// Log format: csv or parquet.
    #[arg(long, default_value = "csv", value_parser = ["csv", "parquet"])]
    pub format: String,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output folder.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

fn parse_wear(s: &str, robots: usize, joints: usize) -> Result<Wear> {
    let bad = || {
        anyhow::anyhow!(
            "--wear {s}: expected rR/jJ@DAY, e.g. r2/j1@30 (robot 1..{robots}, joint 1..{joints}, day ≥ 0)"
        )
    };
    let (unit, day) = s.split_once('@').ok_or_else(bad)?;
    let (r, j) = unit.split_once('/').ok_or_else(bad)?;
    let r: usize = r.trim_start_matches('r').parse().map_err(|_| bad())?;
    let j: usize = j.trim_start_matches('j').parse().map_err(|_| bad())?;
    let onset: f64 = day.parse().map_err(|_| bad())?;
    if !(1..=robots).contains(&r) || !(1..=joints).contains(&j) || onset.is_nan() || onset < 0.0 {
        return Err(bad());
    }
    Ok(Wear { robot: r - 1, joint: j - 1, onset })
}

/// Most logs a synthetic fleet may have (a hundred times the 7 200 of the benchmark's large
/// fleet).
const MAX_LOGS: usize = 1_000_000;

/// Most samples one synthetic log may have (as `hdw synth drive`'s record) [–].
const MAX_LOG_SAMPLES: f64 = 1e7;

/// Run `hdw synth fleet`.
pub fn run(a: FleetSynthArgs) -> Result<()> {
    if a.robots == 0 || a.joints == 0 || a.days == 0 {
        bail!("--robots, --joints, --days: expected at least 1 each");
    }
    let logs = a.robots.saturating_mul(a.joints).saturating_mul(a.days);
    if logs > MAX_LOGS {
        bail!(
            "--robots {} × --joints {} × --days {} give {logs} logs, more than the {MAX_LOGS} a synthetic fleet may have: ask for fewer",
            a.robots,
            a.joints,
            a.days
        );
    }
    for (flag, v) in [("--duration", a.duration), ("--sample-rate", a.sample_rate)] {
        if !(v.is_finite() && v > 0.0) {
            bail!("{flag} {v}: expected a finite value > 0");
        }
    }
    let per_log = a.duration * a.sample_rate;
    if per_log > MAX_LOG_SAMPLES {
        bail!(
            "--duration {} s at --sample-rate {} Hz gives {per_log:.3e} samples a log, more than the {MAX_LOG_SAMPLES:e} a log may have: shorten --duration or lower --sample-rate",
            a.duration,
            a.sample_rate
        );
    }
    let start = hd_io::fleet::parse_day(&a.start).map_err(|e| anyhow::anyhow!("--start: {e}"))?;
    let wear =
        a.wear.iter().map(|w| parse_wear(w, a.robots, a.joints)).collect::<Result<Vec<_>>>()?;
    let spec = FleetSpec {
        robots: a.robots,
        joints: a.joints,
        days: a.days,
        temp_amplitude: a.temp_amplitude,
        temp_period: a.temp_period,
        temp_noise: a.temp_noise,
        coef_levels: a.coef_levels,
        coef_viscous: a.coef_viscous,
        unit_spread: a.unit_spread,
        day_scatter: a.day_scatter,
        wear_rise: a.wear_rise,
        wear_days: a.wear_days,
        wear,
        seed: a.seed,
        ..Default::default()
    };
    let plateaus = 2 * a.levels.max(1);
    let dwell = (a.duration - a.transition) / plateaus as f64 - a.transition;
    if dwell.is_nan() || dwell <= 2.0 * a.transition {
        bail!(
            "--duration {} s is too short for {} plateaus with --transition {} s",
            a.duration,
            plateaus,
            a.transition
        );
    }
    let profile = PlateauProfile {
        omega_min: a.omega_min,
        omega_max: a.omega_max,
        levels: a.levels,
        dwell,
        transition: a.transition,
    };
    let dt = 1.0 / a.sample_rate;
    let truth = spec.truth();
    let dir = super::common::ensure_dir(&a.out)?;
    let bar = ProgressBar::new(truth.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} logs · ETA {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    // A pool of its own with large stacks, fed a chunk at a time: the model code runs
    // rayon inside, and a worker blocked there steals further logs onto its stack.
    let pool =
        rayon::ThreadPoolBuilder::new().stack_size(64 << 20).build().context("thread pool")?;
    let mut files: Vec<String> = Vec::with_capacity(truth.len());
    for chunk in truth.chunks(64) {
        let part: Vec<String> = pool.install(|| {
            chunk
                .par_iter()
                .map(|l| -> Result<String> {
                    let date = hd_io::fleet::format_day(start + l.day as f64);
                    let rel = format!("logs/r{}/j{}/{date}.{}", l.robot + 1, l.joint + 1, a.format);
                    let s = synth_plateaus(
                        &l.params,
                        &profile,
                        dt,
                        &Noise { relative: a.noise, seed: l.noise_seed },
                    )
                    .with_context(|| format!("log {rel}"))?;
                    hd_io::write_columns(&dir.join(&rel), &s.names, &s.columns)?;
                    bar.inc(1);
                    Ok(rel)
                })
                .collect::<Result<_>>()
        })?;
        files.extend(part);
    }
    bar.finish();
    let mut manifest = String::from("file,robot,joint,date,temperature\n");
    let mut truth_csv =
        String::from("file,robot,joint,date,day,temperature,wear,Tc,Ts,ws,sigma2,sigma0,sigma1\n");
    for (l, f) in truth.iter().zip(&files) {
        let date = hd_io::fleet::format_day(start + l.day as f64);
        manifest.push_str(&format!(
            "{f},r{},j{},{date},{:.3}\n",
            l.robot + 1,
            l.joint + 1,
            l.temperature
        ));
        let p = &l.params;
        truth_csv.push_str(&format!(
            "{f},r{},j{},{date},{},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}\n",
            l.robot + 1,
            l.joint + 1,
            l.day,
            l.temperature,
            l.wear,
            p.tc,
            p.ts,
            p.ws,
            p.sigma2,
            p.sigma0,
            p.sigma1
        ));
    }
    let write = |name: &str, text: &str| -> Result<()> {
        let p = dir.join(name);
        hd_io::atomic::write_atomically(&p, |f| {
            use std::io::Write;
            f.write_all(text.as_bytes()).map_err(|e| hd_io::IoError::fs(&p, e))
        })?;
        Ok(())
    };
    write("truth.csv", &truth_csv)?;
    let doc = serde_json::json!({
        "robots": a.robots, "joints": a.joints, "days": a.days, "start": a.start,
        "temperature": {"mean_C": spec.temp_mean, "amplitude_K": a.temp_amplitude, "period_days": a.temp_period, "weather_sd_K": a.temp_noise},
        "effects_per_K_log_scale": {"Tc": a.coef_levels, "Ts": a.coef_levels, "sigma2": a.coef_viscous},
        "unit_spread": a.unit_spread, "day_scatter": a.day_scatter,
        "wear": spec.wear.iter().map(|w| serde_json::json!({"unit_id": format!("r{}/j{}", w.robot + 1, w.joint + 1), "onset_day": w.onset, "onset": hd_io::fleet::format_day(start + w.onset)})).collect::<Vec<_>>(),
        "wear_rise": a.wear_rise, "wear_days": a.wear_days, "wear_parameters": ["Tc", "Ts", "sigma2"],
        "log": {"levels": a.levels, "omega_min": a.omega_min, "omega_max": a.omega_max, "duration_s": a.duration, "dwell_s": dwell, "transition_s": a.transition, "sample_rate_hz": a.sample_rate, "noise_rel_rms": a.noise},
        "seed": a.seed,
    });
    write("truth.json", &serde_json::to_string_pretty(&doc).unwrap_or_default())?;
    write("manifest.csv", &manifest)?;
    eprintln!(
        "wrote {} logs, manifest.csv, truth.csv, truth.json in {}",
        files.len(),
        dir.display()
    );
    Ok(())
}
