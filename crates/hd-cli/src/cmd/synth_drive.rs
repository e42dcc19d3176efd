//! `hdw synth drive`: the simulated drive under a voltage test, logged as a rig logs it:
//! the applied voltage, the current with noise, and both encoders, quantised.

use super::control_args::ControlArgs;
use super::model_args::ModelArgs;
use super::sim_progress::SimProgress;
use super::simulate::SimulateArgs;
use anyhow::{Context, Result, bail};
use clap::Args;
use hd_ident::synth::{Noise, add_noise};
use hd_model::error::num;
use hd_model::signals::Sample;
use hd_model::{Input, Profile, simulate_streaming};
use std::f64::consts::TAU;
use std::path::PathBuf;

/// Tones of the multisine, log-spaced over its band [–].
const MULTISINE_TONES: usize = 12;

/// Record the drive under a voltage test, as its rig would log it.
#[derive(Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "The drive is the simulator's (hdw simulate's model, parameters, variant and stiffness law), open\n\
loop, driven from rest by the test voltage. It is logged every --sample-period:\n\
  t [s], u [V]               time and applied voltage\n\
  i [A]                      armature current plus Gaussian noise (--current-noise × its RMS)\n\
  theta_m, theta_l [rad]     motor and load encoders: θj and θz rounded to 2π/--motor-counts and\n\
                             2π/--load-counts\n\
  theta_j_true, theta_z_true the same angles before quantisation, to judge a fit against\n\
Tests: chirp (--freq/10 to 10·--freq, linear over the record) or multisine (12 tones log-spaced\n\
over the same band, Schroeder phases, peak --voltage). The motor gets each logged voltage held until the\n\
next sample (--applied held, a digital amplifier; fit it with voltage_between = \"hold\"), or the test\n\
signal itself (--applied continuous).\n\n\
Closed loop (--loop-kp and --loop-kv): the drive follows a position reference (--loop-reference steps or\n\
chirp, --loop-amplitude rad on the fed-back side) through the discrete controller of hdw fit drive,\n\
u = kp·kv·(r − q) − kv·(q_k − q_k−1)/h, clamped to ±--loop-saturation, computed from the quantised\n\
--loop-feedback encoder and held over each sample after --loop-delay samples. Its output is the motor\n\
voltage or, with --loop-amplifier current, the current of an ideal current amplifier. Each sample is\n\
integrated by hd-model's solver under the held command. --input, --voltage and --applied are then unused.\n\
Columns: t, ref [rad], cmd [V or A], i [A] (+ noise), theta_m, theta_l, theta_j_true, theta_z_true.\n\n\
Limits: 50 to 10 M samples (--t-end / --sample-period + 1; 10 M take about 10 min and 1.5 GB); a band\n\
starting below the Nyquist frequency; |--voltage| <= 1e4 V. A long record shows its progress on stderr.\n\n\
Examples:\n  hdw synth drive --input multisine --freq 20 --t-end 1 --out out/drive.csv\n\
  hdw synth drive --loop-kp 30 --loop-kv 0.5 --loop-reference steps --freq 4 --t-end 1 --out out/loop.csv"
)]
pub struct DriveSynthArgs {
    /// Parameters, stiffness law, variant and solver (as `hdw simulate` takes them).
    #[command(flatten)]
    pub model: ModelArgs,
    /// Test voltage: chirp or multisine.
    #[arg(long, default_value = "chirp")]
    pub input: String,
    /// Amplitude of the chirp, or peak of the multisine [V] (not zero, at most 1e4 in
    /// magnitude).
    #[arg(long, default_value_t = 12.0)]
    pub voltage: f64,
    /// Centre of the test band [Hz]: it spans freq/10 to 10·freq; freq/10 must lie below the
    /// log's Nyquist frequency 1/(2·--sample-period).
    #[arg(long, default_value_t = 20.0)]
    pub freq: f64,
    /// Record length [s]: at most 10 M samples (--t-end / --sample-period + 1), at least
    /// 50.
    #[arg(long, default_value_t = 2.0)]
    pub t_end: f64,
    /// Logging interval [s].
    #[arg(long, default_value_t = 1e-3)]
    pub sample_period: f64,
    /// Motor encoder resolution [counts per revolution of the motor].
    #[arg(long, default_value_t = 4096)]
    pub motor_counts: u64,
    /// Load encoder resolution [counts per revolution of the load].
    #[arg(long, default_value_t = 1 << 20)]
    pub load_counts: u64,
    /// Current noise, standard deviation relative to the RMS current [–].
    #[arg(long, default_value_t = 0.01)]
    pub current_noise: f64,
    /// Seed of the noise generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// How the test voltage reaches the motor: `held` (default), each logged sample held
    /// until the next, as a rig's digital amplifier applies it; or `continuous`, the test
    /// signal itself between the samples.
    #[arg(long, default_value = "held")]
    pub applied: String,
    /// Output file (.csv or .parquet).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Closed loop (with --loop-kp and --loop-kv).
    #[command(flatten)]
    pub closed: super::synth_drive_loop::LoopArgs,
}

/// The test voltage sampled every `h` [s] up to `t_end` and held from each sample to the
/// next: a staircase whose risers last a millionth of a sample (every profile point is a
/// breakpoint of the solver, so each tread is integrated as a constant voltage).
fn held(input: &Input, h: f64, t_end: f64) -> Result<Input> {
    let n = (t_end / h).round() as usize + 1;
    let rise = 1e-6 * h;
    let mut t = Vec::with_capacity(2 * n);
    let mut u = Vec::with_capacity(2 * n);
    for k in 0..n {
        let tk = k as f64 * h;
        let uk = input.value(tk);
        t.push(tk);
        u.push(uk);
        t.push(tk + h - rise);
        u.push(uk);
    }
    Ok(Input::Recorded(Profile::new(t, u, "held test voltage")?))
}

/// The test voltage.
fn test_input(a: &DriveSynthArgs) -> Result<Input> {
    let (f0, f1) = (a.freq / 10.0, a.freq * 10.0);
    match a.input.as_str() {
        "chirp" => Ok(Input::Chirp { amplitude: a.voltage, f0, f1, duration: a.t_end }),
        "multisine" => {
            // Sampled twenty times per period of the highest tone (the profile is linear
            // between samples), Schroeder phases for a low crest factor, scaled to the peak.
            let dt = 1.0 / (20.0 * f1);
            let n = (a.t_end / dt).ceil() as usize + 1;
            let tones: Vec<f64> = (0..MULTISINE_TONES)
                .map(|k| f0 * (f1 / f0).powf(k as f64 / (MULTISINE_TONES - 1) as f64))
                .collect();
            let m = tones.len() as f64;
            let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
            let mut u: Vec<f64> = t
                .iter()
                .map(|&t| {
                    tones
                        .iter()
                        .enumerate()
                        .map(|(k, f)| {
                            let phase = -std::f64::consts::PI * (k * (k + 1)) as f64 / m;
                            (TAU * f * t + phase).sin()
                        })
                        .sum::<f64>()
                })
                .collect();
            let peak = u.iter().fold(0.0f64, |p, v| p.max(v.abs())).max(f64::MIN_POSITIVE);
            u.iter_mut().for_each(|v| *v *= a.voltage / peak);
            Ok(Input::Recorded(Profile::new(t, u, "multisine")?))
        }
        other => bail!("--input {other}: expected chirp or multisine"),
    }
}

/// Fewest samples a drive record may have [–]: fewer cannot show the drive's response to a
/// test band (nor determine its parameters).
pub const MIN_DRIVE_SAMPLES: f64 = 50.0;

/// Most samples a drive record may have [–]: each costs the simulated drive 50–75 µs and
/// 140–170 B while the record is made (measured on the seed drive's chirp, release build),
/// so 10 million take 8–12 minutes and 1.4–1.7 GB.
pub const MAX_DRIVE_SAMPLES: f64 = 1e7;

/// Largest test voltage [V]: far above any servo drive's supply, and small enough that the
/// drive's equations stay finite.
pub const MAX_TEST_VOLTAGE: f64 = 1e4;

/// Points of the multisine profile: twenty per period of its highest tone [–].
fn multisine_points(a: &DriveSynthArgs) -> f64 {
    (a.t_end * 20.0 * 10.0 * a.freq).ceil() + 1.0
}

/// `x` > 0 rounded down to two significant digits (a value to suggest; divided by an exact
/// power of ten so that it prints short: 0.00081, not 0.0008100000000000001).
fn two_digits_down(x: f64) -> f64 {
    let e = x.log10().floor() as i32 - 1;
    if e < 0 {
        let scale = 10f64.powi(-e);
        (x * scale).floor() / scale
    } else {
        let unit = 10f64.powi(e);
        (x / unit).floor() * unit
    }
}

/// Check the options of `a` that do not need the drive, naming the one at fault.
fn check(a: &DriveSynthArgs) -> Result<()> {
    for (flag, v) in
        [("--sample-period", a.sample_period), ("--t-end", a.t_end), ("--freq", a.freq)]
    {
        if !(v.is_finite() && v > 0.0) {
            bail!("{flag} {}: expected a finite value > 0", num(v));
        }
    }
    if !(a.current_noise.is_finite() && a.current_noise >= 0.0) {
        bail!("--current-noise {}: expected a finite value >= 0", num(a.current_noise));
    }
    if a.motor_counts == 0 || a.load_counts == 0 {
        bail!("--motor-counts and --load-counts: expected at least 1 count per revolution");
    }
    let intervals = a.t_end / a.sample_period;
    if intervals + 1.0 > MAX_DRIVE_SAMPLES {
        bail!(
            "--t-end {} s logged every --sample-period {} s gives {:.3e} samples, more than the {MAX_DRIVE_SAMPLES:.0e} a drive record may have: shorten --t-end or lengthen --sample-period",
            num(a.t_end),
            num(a.sample_period),
            intervals + 1.0
        );
    }
    if intervals + 1.0 < MIN_DRIVE_SAMPLES {
        bail!(
            "--sample-period {} s over --t-end {} s gives {} sample intervals, fewer than the {} ({MIN_DRIVE_SAMPLES} samples) a drive record needs: use --sample-period {} s or less",
            num(a.sample_period),
            num(a.t_end),
            hd_model::error::num(intervals),
            MIN_DRIVE_SAMPLES - 1.0,
            num(two_digits_down(a.t_end / (MIN_DRIVE_SAMPLES - 1.0)))
        );
    }
    // The test band (and a closed loop's reference band) against the log's Nyquist
    // frequency: a band wholly above it is logged as aliases only.
    let nyquist = 0.5 / a.sample_period;
    let (f0, f1) = (a.freq / 10.0, a.freq * 10.0);
    if f0 >= nyquist {
        bail!(
            "--freq {} Hz: the band {}-{} Hz lies wholly above the Nyquist frequency {} Hz of --sample-period {} s: use --freq below {} Hz or a shorter --sample-period",
            num(a.freq),
            num(f0),
            num(f1),
            num(nyquist),
            num(a.sample_period),
            num(10.0 * nyquist)
        );
    }
    if a.closed.active() {
        return super::synth_drive_loop::check(a);
    }
    if !(a.voltage.is_finite() && a.voltage != 0.0 && a.voltage.abs() <= MAX_TEST_VOLTAGE) {
        bail!(
            "--voltage {} V: expected a finite test voltage, not zero, of at most {MAX_TEST_VOLTAGE:.0e} V in magnitude",
            num(a.voltage)
        );
    }
    if a.input == "multisine" && multisine_points(a) > MAX_DRIVE_SAMPLES {
        bail!(
            "--input multisine with --freq {} Hz over --t-end {} s needs {:.3e} profile points (20 per period of the top tone), more than {MAX_DRIVE_SAMPLES:.0e}: lower --freq or shorten --t-end",
            num(a.freq),
            num(a.t_end),
            multisine_points(a)
        );
    }
    Ok(())
}

/// Run `hdw synth drive`.
pub fn run(a: DriveSynthArgs) -> Result<()> {
    check(&a)?;
    let (nyquist, f1) = (0.5 / a.sample_period, 10.0 * a.freq);
    if f1 > nyquist {
        eprintln!(
            "warning: --freq {} Hz: the band reaches {} Hz, above the Nyquist frequency {} Hz of --sample-period {} s; the log aliases the top of the band",
            num(a.freq),
            num(f1),
            num(nyquist),
            num(a.sample_period)
        );
    }
    // The run exactly as `hdw simulate` checks it, with the test voltage and the log's grid.
    let sim = SimulateArgs {
        model: a.model.clone(),
        input: "constant".to_string(),
        voltage: 0.0,
        freq: a.freq,
        t_end: a.t_end,
        dt_out: a.sample_period,
        cycles: 5,
        no_trace: true,
        max_output_values: 0,
        control: ControlArgs::default(),
        out: PathBuf::new(),
    };
    let mut cfg = super::simulate::config(&sim)?;
    if a.closed.active() {
        cfg.validate()?;
        return super::synth_drive_loop::write(&a, &cfg);
    }
    cfg.input = match a.applied.as_str() {
        "held" => held(&test_input(&a)?, a.sample_period, a.t_end)?,
        "continuous" => test_input(&a)?,
        other => bail!("--applied {other}: expected held or continuous"),
    };
    cfg.validate().with_context(|| test_options(&a))?;
    let rows = (a.t_end / a.sample_period).round() as usize + 1;
    let mut cols: [Vec<f64>; 5] = std::array::from_fn(|_| Vec::with_capacity(rows));
    let mut progress = SimProgress::new(a.t_end);
    simulate_streaming(
        &cfg,
        Some(&mut |s: &Sample| {
            progress.at(s.t);
            for (c, v) in cols.iter_mut().zip([s.t, s.u, s.i, s.theta_j, s.theta_z]) {
                c.push(v);
            }
        }),
    )
    .with_context(|| test_options(&a))?;
    progress.finish();
    let [t, u, mut i, theta_j, theta_z] = cols;
    add_noise(&mut i, &Noise { relative: a.current_noise, seed: a.seed });
    let theta_m = encoder(&theta_j, a.motor_counts);
    let theta_l = encoder(&theta_z, a.load_counts);
    let names = ["t", "u", "i", "theta_m", "theta_l", "theta_j_true", "theta_z_true"];
    let rows = t.len();
    hd_io::write_columns(&a.out, &names, &[t, u, i, theta_m, theta_l, theta_j, theta_z])?;
    eprintln!(
        "{} test of the {} drive, {} s logged every {} s; wrote {rows} rows to {}",
        a.input,
        cfg.variant,
        num(a.t_end),
        num(a.sample_period),
        a.out.display()
    );
    Ok(())
}

/// The options that shape the open-loop test, for an error of the simulation.
fn test_options(a: &DriveSynthArgs) -> String {
    format!(
        "the {} test (--voltage {} V, --freq {} Hz, --t-end {} s) cannot be simulated",
        a.input,
        num(a.voltage),
        num(a.freq),
        num(a.t_end)
    )
}

/// The readings of an encoder of `counts` per revolution following the angles `x` [rad]
/// (hd-model's rounding to its count, 2π/counts).
pub fn encoder(x: &[f64], counts: u64) -> Vec<f64> {
    let q = TAU / counts as f64;
    x.iter().map(|&v| hd_model::control::quantise(v, q)).collect()
}
