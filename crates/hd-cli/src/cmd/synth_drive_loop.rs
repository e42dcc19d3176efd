//! `hdw synth drive` in closed loop: the simulator's drive (hd-model's adaptive solver)
//! under a position reference, through the discrete controller of `hdw fit drive`
//! (cascade P position / P speed loop, delay in whole samples, saturation) reading the
//! quantised encoder. Each sample is integrated by hd-model's solver from the state the
//! previous one ended in, with the command held: the zero-order-hold loop exactly
//! ([`hd_ident::drive::compliant::synth_loop`]).

use super::synth_drive::DriveSynthArgs;
use anyhow::{Context, Result, bail};
use clap::Args;
use hd_ident::drive::compliant::synth_loop::LoopRun;
use hd_ident::drive::compliant::{Amplifier, Feedback};
use hd_ident::drive::controller::Controller;
use hd_ident::synth::{Noise, add_noise};
use hd_model::SimConfig;
use hd_model::error::num;
use indicatif::{ProgressBar, ProgressStyle};
use std::f64::consts::{PI, TAU};
use std::time::Duration;

/// The closed-loop options of `hdw synth drive` (closed loop when `--loop-kp` is given).
#[derive(Args, Debug, Default, Clone)]
pub struct LoopArgs {
    /// Closed loop: position-loop gain kp [1/s] of the cascade P–P controller (with
    /// --loop-kv; the command is kp·kv·(r − q) − kv·v̂).
    #[arg(long)]
    pub loop_kp: Option<f64>,
    /// Closed loop: speed-loop gain kv [V or A per rad/s].
    #[arg(long)]
    pub loop_kv: Option<f64>,
    /// Closed loop: computation delay [samples]; shorter than half the record.
    #[arg(long, default_value_t = 0)]
    pub loop_delay: usize,
    /// Closed loop: output limit [V or A]; none by default.
    #[arg(long)]
    pub loop_saturation: Option<f64>,
    /// Closed loop: the encoder the controller reads, motor or load.
    #[arg(long, default_value = "motor")]
    pub loop_feedback: String,
    /// Closed loop: the amplifier, voltage (the output is the motor voltage) or current
    /// (an ideal current amplifier: the current is the command).
    #[arg(long, default_value = "voltage")]
    pub loop_amplifier: String,
    /// Closed loop: the position reference, steps (smoothed steps to seeded levels, one
    /// every 1/--freq s) or chirp (--freq/10 to 10·--freq, linear over the record).
    #[arg(long, default_value = "steps")]
    pub loop_reference: String,
    /// Closed loop: the reference's largest level (steps) or amplitude (chirp) [rad, on
    /// the fed-back encoder's side]; at most 1e4 in magnitude, and the reference's speed
    /// at most 1e4 rad/s.
    #[arg(long, default_value_t = 2.0)]
    pub loop_amplitude: f64,
}

impl LoopArgs {
    /// Whether a closed-loop record is asked for.
    pub fn active(&self) -> bool {
        self.loop_kp.is_some() || self.loop_kv.is_some()
    }
}

/// A uniform number in [−1, 1) from a seeded xorshift state.
fn next_level(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// The reference at the sample times `t` [s].
fn reference(a: &DriveSynthArgs, t: &[f64]) -> Result<Vec<f64>> {
    let l = &a.closed;
    let amp = l.loop_amplitude;
    match l.loop_reference.as_str() {
        "steps" => {
            // One level per 1/freq s from rest, each reached by a raised-cosine ramp over
            // the first 30 % of its interval.
            let period = 1.0 / a.freq;
            let count = (a.t_end / period).ceil() as usize + 1;
            let mut state = 0x9E37_79B9_7F4A_7C15u64 ^ a.seed.wrapping_mul(0xBF58_476D_1CE4_E5B9);
            let mut levels = vec![0.0];
            for _ in 0..count {
                levels.push(amp * next_level(&mut state));
            }
            Ok(t.iter()
                .map(|&tk| {
                    let j = (tk / period).floor() as usize;
                    let s = ((tk - j as f64 * period) / (0.3 * period)).min(1.0);
                    let blend = 0.5 - 0.5 * (PI * s).cos();
                    levels[j] + (levels[j + 1] - levels[j]) * blend
                })
                .collect())
        }
        "chirp" => {
            let (f0, f1, dur) = (a.freq / 10.0, a.freq * 10.0, a.t_end);
            Ok(t.iter()
                .map(|&tk| amp * (TAU * (f0 * tk + (f1 - f0) * tk * tk / (2.0 * dur))).sin())
                .collect())
        }
        other => bail!("--loop-reference {other}: expected steps or chirp"),
    }
}

/// Largest reference amplitude [rad on the fed-back side]: some 1600 revolutions.
pub const MAX_LOOP_AMPLITUDE: f64 = 1e4;

/// Largest speed the reference may ask for [rad/s on the fed-back side]: about 95 000 rpm,
/// beyond any servo motor.
pub const MAX_REFERENCE_SPEED: f64 = 1e4;

/// The reference's peak speed [rad/s]: a chirp's amplitude times its top angular
/// frequency; a step of up to twice the amplitude over its raised-cosine ramp (π/2 times
/// the mean speed over 30 % of the interval).
fn reference_speed(a: &DriveSynthArgs) -> f64 {
    let amp = a.closed.loop_amplitude.abs();
    match a.closed.loop_reference.as_str() {
        "chirp" => amp * TAU * 10.0 * a.freq,
        _ => PI / 2.0 * 2.0 * amp / (0.3 / a.freq),
    }
}

/// `x` rounded to seven significant digits, to show a product of inputs (1001 × 0.001 is
/// 1.001, not 1.0010000000000001).
fn seven_digits(x: f64) -> f64 {
    format!("{x:.6e}").parse().unwrap_or(x)
}

/// Check the closed-loop options of `a` (after its record length and band), naming the
/// one at fault.
pub fn check(a: &DriveSynthArgs) -> Result<()> {
    let l = &a.closed;
    let (Some(kp), Some(kv)) = (l.loop_kp, l.loop_kv) else {
        bail!("--loop-kp and --loop-kv: a closed-loop record needs both gains");
    };
    for (flag, g) in [("--loop-kp", kp), ("--loop-kv", kv)] {
        if !(g.is_finite() && g > 0.0) {
            bail!(
                "{flag} {}: expected a finite gain > 0 (a negative gain feeds back positively)",
                num(g)
            );
        }
    }
    let saturation = l.loop_saturation.unwrap_or(f64::INFINITY);
    if saturation.is_nan() || saturation <= 0.0 {
        bail!("--loop-saturation {}: expected a limit > 0", num(saturation));
    }
    if Feedback::parse(&l.loop_feedback).is_none() {
        bail!("--loop-feedback {}: expected motor or load", l.loop_feedback);
    }
    if Amplifier::parse(&l.loop_amplifier).is_none() {
        bail!("--loop-amplifier {}: expected voltage or current", l.loop_amplifier);
    }
    if !matches!(l.loop_reference.as_str(), "steps" | "chirp") {
        bail!("--loop-reference {}: expected steps or chirp", l.loop_reference);
    }
    let amp = l.loop_amplitude;
    if !(amp.is_finite() && amp != 0.0 && amp.abs() <= MAX_LOOP_AMPLITUDE) {
        bail!(
            "--loop-amplitude {} rad: expected a finite amplitude, not zero, of at most {MAX_LOOP_AMPLITUDE:.0e} rad in magnitude",
            num(amp)
        );
    }
    let speed = reference_speed(a);
    if speed > MAX_REFERENCE_SPEED {
        bail!(
            "--loop-amplitude {} rad with --freq {} Hz: the {} reference moves at up to {speed:.3e} rad/s, more than the {MAX_REFERENCE_SPEED:.0e} rad/s a drive can follow: lower --loop-amplitude or --freq",
            num(amp),
            num(a.freq),
            l.loop_reference
        );
    }
    let samples = (a.t_end / a.sample_period).round() + 1.0;
    if l.loop_delay as f64 >= 0.5 * samples {
        bail!(
            "--loop-delay {} samples ({} s): expected a delay shorter than half the record ({samples} samples over --t-end {} s), or the loop barely acts",
            l.loop_delay,
            num(seven_digits(l.loop_delay as f64 * a.sample_period)),
            num(a.t_end)
        );
    }
    Ok(())
}

/// Run the closed loop of `a` (checked by [`check`]) on the drive of `cfg` (checked, open
/// loop, at rest).
fn run_loop(a: &DriveSynthArgs, cfg: &SimConfig) -> Result<(Vec<f64>, LoopRun)> {
    let l = &a.closed;
    let (Some(kp), Some(kv)) = (l.loop_kp, l.loop_kv) else {
        bail!("--loop-kp and --loop-kv: a closed-loop record needs both gains");
    };
    let saturation = l.loop_saturation.unwrap_or(f64::INFINITY);
    let (Some(feedback), Some(amplifier)) =
        (Feedback::parse(&l.loop_feedback), Amplifier::parse(&l.loop_amplifier))
    else {
        bail!("--loop-feedback or --loop-amplifier: not known");
    };
    let h = a.sample_period;
    let c = Controller {
        kp,
        kv,
        saturation,
        delay: l.loop_delay,
        speed_filter: vec![1.0],
        h,
        open_loop: None,
    };
    let n = (a.t_end / h).round() as usize + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
    let r = reference(a, &t)?;
    let counts = match feedback {
        Feedback::Motor => a.motor_counts,
        Feedback::Load => a.load_counts,
    };
    // The loop reports no progress of its own: a spinner with the elapsed time shows a
    // long one is alive (drawn only on a terminal).
    let spinner = (n > 100_000).then(|| {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} {elapsed_precise} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.set_message(format!("closed loop over {n} samples ({} s)", a.t_end));
        bar.enable_steady_tick(Duration::from_millis(250));
        bar
    });
    let run =
        hd_ident::drive::compliant::synth_loop::run_loop(cfg, &c, feedback, amplifier, &r, counts)
            .with_context(|| {
                format!(
                    "the closed loop (--loop-kp {}, --loop-kv {}, --loop-amplitude {} rad, --loop-saturation {}) cannot be simulated",
                    num(kp),
                    num(kv),
                    num(l.loop_amplitude),
                    num(saturation)
                )
            });
    if let Some(bar) = spinner {
        bar.finish_and_clear();
    }
    Ok((r, run?))
}

/// Write the closed-loop record of `a`: t, ref, cmd, i (+ noise), the quantised encoders
/// and the true angles.
pub fn write(a: &DriveSynthArgs, cfg: &SimConfig) -> Result<()> {
    let (r, LoopRun { t, command: cmd, current: mut i, theta_j, theta_z }) = run_loop(a, cfg)?;
    add_noise(&mut i, &Noise { relative: a.current_noise, seed: a.seed });
    let theta_m = super::synth_drive::encoder(&theta_j, a.motor_counts);
    let theta_l = super::synth_drive::encoder(&theta_z, a.load_counts);
    let names = ["t", "ref", "cmd", "i", "theta_m", "theta_l", "theta_j_true", "theta_z_true"];
    let rows = t.len();
    hd_io::write_columns(&a.out, &names, &[t, r, cmd, i, theta_m, theta_l, theta_j, theta_z])?;
    eprintln!(
        "closed loop ({} reference, {} feedback, {} amplifier) of the {} drive, {} s logged every {} s; wrote {rows} rows to {}",
        a.closed.loop_reference,
        a.closed.loop_feedback,
        a.closed.loop_amplifier,
        cfg.variant,
        a.t_end,
        a.sample_period,
        a.out.display()
    );
    Ok(())
}
