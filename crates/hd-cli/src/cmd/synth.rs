//! `hdw synth hysteresis|friction|drive`: synthetic data from the model, to check what an
//! experiment can identify before running it.

use super::common::load_params;
use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use hd_ident::synth::{
    HysteresisExcitation, Noise, PlateauProfile, QuasiStatic, Schedule, SteadySweep,
    StiffnessTruth, Synthetic, TransientExcitation, bouc_wen_truth, is_law_name,
    maxwell_slip_truth, synth_plateaus, synth_steady, synth_stiffness, synth_transient,
};
use std::path::PathBuf;

/// Write synthetic data from the model (CSV or Parquet by the extension of --out).
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "True parameters are the registry defaults changed by --params/--set; noise is Gaussian with a\n\
standard deviation of --noise times the RMS of the clean torque. Fit the file back with hdw fit\n\
to see which parameters an experiment like it can determine.\n\n\
Example:\n  hdw synth hysteresis --set B=150 --out out/hyst.csv && hdw fit hysteresis out/hyst.csv --out out/fit"
)]
pub struct SynthArgs {
    #[command(subcommand)]
    pub what: SynthWhat,
}

/// Which data set to synthesise.
#[derive(Subcommand, Debug)]
pub enum SynthWhat {
    /// A torque–deflection record (columns t, theta, torque).
    Hysteresis(HysteresisSynthArgs),
    /// Friction data: a steady-state sweep (omega, torque) or, with --transient, a time
    /// series (t, omega, torque).
    Friction(FrictionSynthArgs),
    /// The drive under a voltage test, logged as a rig logs it (t, u, i, theta_m, theta_l).
    Drive(super::synth_drive::DriveSynthArgs),
    /// A fleet of friction logs (robots × joints × days) with temperature effects and wear.
    Fleet(super::synth_fleet::FleetSynthArgs),
}

/// Settings every synthetic data set shares.
#[derive(Args, Debug)]
pub struct Common {
    /// Parameter file (TOML, registry names as keys).
    #[arg(long, value_name = "FILE.toml")]
    pub params: Option<PathBuf>,
    /// Set a true parameter, e.g. `--set B=150` (repeatable; applied after --params).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Gaussian noise, standard deviation relative to the RMS of the clean torque.
    #[arg(long, value_name = "REL", default_value_t = 0.01)]
    pub noise: f64,
    /// Seed of the noise generator.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub seed: u64,
    /// Output file: .csv or .parquet.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

/// `hdw synth hysteresis`.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "Laws (--law): memory (f(θ) + z, ż = A·θ̇ − B·z; its state integrated by hd-model's Dopri5),\n\
maxwell-slip (f(θ) plus --elements elastoplastic elements; by default of equal stiffness mem_A/N with\n\
yield deflections log-spaced from 2 % to 60 % of --amplitude; set ms_k<i>, ms_f<i>), bouc-wen (f(θ) + α·w\n\
with α = mem_A, A = 1, n = 1 and saturation deflection 0.2 × --amplitude by default; set bw_alpha,\n\
bw_A, bw_beta, bw_gamma, bw_n). The rate-independent laws step their states through θ at 32 points\n\
per sample interval. The spring a, b, c always comes from --params/--set.\n\n\
Schedules (--schedule): sines (θ(t) a sum of equal sines at --freqs, all starting at zero, peak bounded\n\
by --amplitude, --samples over --duration); quasi-static (for each of --freqs, default 0.02,0.2 Hz, in\n\
turn, --cycles whole cycles of level·amplitude·sin(2πft) at each of --levels, sampled at --sample-rate).\n\n\
Output: --out FILE with columns t [s], theta [rad], torque [N·m].\n\n\
Example:\n  hdw synth hysteresis --set c=6.5e4 --set A=2.5e4 --set B=150 --noise 0.01 --out out/hyst.csv\n  hdw synth hysteresis --set a=1e8 --set b=2e6 --amplitude 0.02 --out out/wide.parquet\n  hdw synth hysteresis --law maxwell-slip --schedule quasi-static --noise 0.01 --out out/qs.csv\n  hdw synth hysteresis --law bouc-wen --set bw_n=2 --schedule quasi-static --out out/bw.parquet"
)]
pub struct HysteresisSynthArgs {
    #[command(flatten)]
    pub common: Common,
    /// Stiffness law that makes the data: memory, maxwell-slip or bouc-wen.
    #[arg(long, value_name = "LAW", default_value = "memory")]
    pub law: String,
    /// Maxwell-slip: number of elements of the true law.
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub elements: usize,
    /// Imposed deflection: sines or quasi-static.
    #[arg(long, value_name = "NAME", default_value = "sines")]
    pub schedule: String,
    /// Peak bound of the deflection (sines) or rated amplitude (quasi-static) [rad].
    #[arg(long, default_value_t = 1e-3)]
    pub amplitude: f64,
    /// Frequencies [Hz], comma-separated (default 4,15,55,200 for sines, 0.02,0.2 quasi-static).
    #[arg(long, value_name = "F1,F2,..")]
    pub freqs: Option<String>,
    /// Sines: record length [s].
    #[arg(long, default_value_t = 0.5)]
    pub duration: f64,
    /// Sines: samples, evenly spaced over the record.
    #[arg(long, default_value_t = 20_000)]
    pub samples: usize,
    /// Quasi-static: amplitude levels as shares of --amplitude, comma-separated, in order.
    #[arg(long, value_name = "L1,L2,..", default_value = "0.25,0.5,1")]
    pub levels: String,
    /// Quasi-static: whole cycles per level and frequency.
    #[arg(long, default_value_t = 1)]
    pub cycles: usize,
    /// Quasi-static: sampling rate [Hz].
    #[arg(long, default_value_t = 200.0)]
    pub sample_rate: f64,
}

/// `hdw synth friction`.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "Steady sweep (default): the steady LuGre torque sign(ω)·(Tc + (Ts − Tc)·exp(−(ω/ωs)²)) + σ2·ω at\n\
log-spaced speeds of both signs. Time series (--transient): ω(t) is a sine through zero whose\n\
amplitude grows geometrically (--decades) up to --peak-speed, so the record holds pure\n\
pre-sliding cycles, partial slip and full reversals; the bristle state follows the LuGre law\n\
(hd-model's Rodas4) from rest, and the torque is σ0·s + σ1·ṡ + σ2·ω.\n\n\
Output: --out FILE with columns omega [rad/s], torque [N·m] (steady) or t [s], omega [rad/s],\n\
torque [N·m] (time series).\n\n\
Example:\n  hdw synth friction --set Tc=0.2 --set Ts=0.35 --set ws=0.02 --out out/steady.csv\n  hdw synth friction --transient --set sigma0=8e4 --set sigma1=0.5 --out out/transient.parquet\n  hdw synth friction --transient --profile joint --set Tc_neg=0.12 --out out/joint.csv"
)]
pub struct FrictionSynthArgs {
    #[command(flatten)]
    pub common: Common,
    /// Write a time series instead of a steady-state sweep.
    #[arg(long)]
    pub transient: bool,
    /// Time series: speed profile. `growing-sine`: a sine through zero whose amplitude grows;
    /// `joint`: a joint friction test, plateaus at --levels log-spaced speeds from --omega-min
    /// to --omega-max, each held --dwell s forwards then backwards, smooth --transition s
    /// reversals, sampled at --sample-rate.
    #[arg(long, value_name = "NAME", default_value = "growing-sine")]
    pub profile: String,
    /// Joint profile: number of speed levels.
    #[arg(long, default_value_t = 8)]
    pub levels: usize,
    /// Joint profile: time held at each plateau [s].
    #[arg(long, default_value_t = 0.25)]
    pub dwell: f64,
    /// Joint profile: duration of each speed change [s].
    #[arg(long, default_value_t = 0.05)]
    pub transition: f64,
    /// Joint profile: sampling rate [Hz].
    #[arg(long, default_value_t = 5000.0)]
    pub sample_rate: f64,
    /// Steady sweep: slowest |ω| [rad/s].
    #[arg(long, default_value_t = 1e-4)]
    pub omega_min: f64,
    /// Steady sweep: fastest |ω| [rad/s].
    #[arg(long, default_value_t = 1.0)]
    pub omega_max: f64,
    /// Steady sweep: speeds per sign.
    #[arg(long, default_value_t = 50)]
    pub points: usize,
    /// Time series: final speed amplitude [rad/s].
    #[arg(long, default_value_t = 2.0)]
    pub peak_speed: f64,
    /// Time series: frequency of the speed sine [Hz].
    #[arg(long, default_value_t = 200.0)]
    pub freq: f64,
    /// Time series: whole cycles.
    #[arg(long, default_value_t = 6)]
    pub cycles: usize,
    /// Time series: decades of amplitude growth over the record.
    #[arg(long, default_value_t = 3.0)]
    pub decades: f64,
    /// Time series: samples per cycle.
    #[arg(long, default_value_t = 2500)]
    pub samples_per_cycle: usize,
}

fn noise(c: &Common) -> Result<Noise> {
    if !(c.noise >= 0.0 && c.noise.is_finite()) {
        bail!("--noise {}: expected a finite value >= 0 (relative to the RMS torque)", c.noise);
    }
    Ok(Noise { relative: c.noise, seed: c.seed })
}

fn write(c: &Common, data: &Synthetic) -> Result<()> {
    hd_io::write_columns(&c.out, &data.names, &data.columns)?;
    eprintln!("{}\nwrote {} rows to {}", data.description, data.columns[0].len(), c.out.display());
    Ok(())
}

/// Run `hdw synth ...`.
pub fn run(args: SynthArgs) -> Result<()> {
    match args.what {
        SynthWhat::Drive(a) => super::synth_drive::run(a),
        SynthWhat::Fleet(a) => super::synth_fleet::run(a),
        SynthWhat::Hysteresis(a) => synth_hysteresis_cmd(a),
        SynthWhat::Friction(a) => {
            let p = load_params(a.common.params.as_deref(), &a.common.set)?;
            let n = noise(&a.common)?;
            let data = if a.transient && a.profile == "joint" {
                // The steady sweep's defaults (1e-4..1) suit a sweep; a joint test starts at 1e-3.
                let omega_min = if a.omega_min == 1e-4 { 1e-3 } else { a.omega_min };
                let profile = PlateauProfile {
                    omega_min,
                    omega_max: a.omega_max,
                    levels: a.levels,
                    dwell: a.dwell,
                    transition: a.transition,
                };
                if !(a.sample_rate > 0.0 && a.sample_rate.is_finite()) {
                    bail!("--sample-rate {}: expected a finite value > 0 [Hz]", a.sample_rate);
                }
                let length = a.levels as f64 * 2.0 * (a.dwell + a.transition);
                check_rows(
                    length * a.sample_rate,
                    "--levels × (--dwell + --transition) × --sample-rate",
                )?;
                synth_plateaus(&p, &profile, 1.0 / a.sample_rate, &n)?
            } else if a.transient {
                if a.profile != "growing-sine" {
                    bail!("--profile {}: expected growing-sine or joint", a.profile);
                }
                let exc = TransientExcitation {
                    peak_speed: a.peak_speed,
                    frequency: a.freq,
                    cycles: a.cycles,
                    decades: a.decades,
                    samples_per_cycle: a.samples_per_cycle,
                };
                check_rows(
                    a.cycles as f64 * a.samples_per_cycle as f64,
                    "--cycles × --samples-per-cycle",
                )?;
                synth_transient(&p, &exc, &n)?
            } else {
                let sweep = SteadySweep {
                    omega_min: a.omega_min,
                    omega_max: a.omega_max,
                    points_per_sign: a.points,
                };
                check_rows(2.0 * a.points as f64, "2 × --points")?;
                synth_steady(&p, &sweep, &n)?
            };
            write(&a.common, &data)
        }
    }
}

/// Most rows a synthetic data set may have [–]: 20 million rows of a few columns are
/// about a gigabyte of CSV and of memory while it is generated.
pub const MAX_SYNTH_ROWS: f64 = 2e7;

/// Refuse a data set of `rows` rows (what the `flags` multiply to) above [`MAX_SYNTH_ROWS`].
pub(crate) fn check_rows(rows: f64, flags: &str) -> Result<()> {
    if rows.is_nan() || rows > MAX_SYNTH_ROWS {
        bail!(
            "{flags} give {rows:.3e} rows, more than the {MAX_SYNTH_ROWS:e} a synthetic data set may have: ask for fewer samples"
        );
    }
    Ok(())
}

fn numbers(text: &str, flag: &str, unit: &str) -> Result<Vec<f64>> {
    text.split(',')
        .map(|f| f.trim().parse::<f64>())
        .collect::<Result<Vec<f64>, _>>()
        .with_context(|| format!("{flag} {text}: expected comma-separated numbers [{unit}]"))
}

fn synth_hysteresis_cmd(a: HysteresisSynthArgs) -> Result<()> {
    // Names of the rate-independent laws go to the law; the rest to the registry.
    let (law_sets, reg_sets): (Vec<String>, Vec<String>) = a
        .common
        .set
        .iter()
        .cloned()
        .partition(|s| is_law_name(s.split('=').next().unwrap_or("").trim()));
    let p = load_params(a.common.params.as_deref(), &reg_sets)?;
    let law_values = law_sets
        .iter()
        .map(|s| {
            let (name, value) = s.split_once('=').unwrap_or((s, ""));
            let v = value.trim().parse::<f64>().with_context(|| {
                format!("--set {s}: expected NAME=VALUE with a number after '='")
            })?;
            Ok((name.trim().to_string(), v))
        })
        .collect::<Result<Vec<(String, f64)>>>()?;
    let truth = match a.law.as_str() {
        "memory" => {
            if let Some((name, _)) = law_values.first() {
                bail!(
                    "--set {name}: a parameter of another law; --law memory takes registry names (a, b, c, A, B)"
                );
            }
            StiffnessTruth::Memory(Box::new(p))
        }
        "maxwell-slip" => StiffnessTruth::MaxwellSlip(maxwell_slip_truth(
            &p,
            a.amplitude,
            a.elements,
            &law_values,
        )?),
        "bouc-wen" => StiffnessTruth::BoucWen(bouc_wen_truth(&p, a.amplitude, &law_values)?),
        other => bail!("--law {other}: expected memory, maxwell-slip or bouc-wen"),
    };
    let schedule = match a.schedule.as_str() {
        "sines" => Schedule::Sines({
            let freqs = numbers(a.freqs.as_deref().unwrap_or("4,15,55,200"), "--freqs", "Hz")?;
            check_rows(a.samples as f64, "--samples")?;
            HysteresisExcitation {
                amplitude: a.amplitude,
                frequencies: freqs,
                duration: a.duration,
                samples: a.samples,
            }
        }),
        "quasi-static" => {
            let levels = numbers(&a.levels, "--levels", "-")?;
            let freqs = numbers(a.freqs.as_deref().unwrap_or("0.02,0.2"), "--freqs", "Hz")?;
            let seconds: f64 =
                freqs.iter().map(|f| 1.0 / f.abs()).sum::<f64>() * (levels.len() * a.cycles) as f64;
            check_rows(seconds * a.sample_rate, "--levels × --cycles × --sample-rate / --freqs")?;
            Schedule::QuasiStatic {
                test: QuasiStatic {
                    amplitude: a.amplitude,
                    levels,
                    frequencies: freqs,
                    cycles: a.cycles,
                },
                sample_rate: a.sample_rate,
            }
        }
        other => bail!("--schedule {other}: expected sines or quasi-static"),
    };
    let data = synth_stiffness(&truth, &schedule, &noise(&a.common)?)?;
    write(&a.common, &data)
}
