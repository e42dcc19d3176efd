//! `hdw design --check N`: the design's predicted standard errors against refits. Each of N
//! replicates synthesises the designed record and the fitted records' voltages with the
//! drive (hd-model's solver under the held voltage, encoders rounded to their counts,
//! Gaussian current noise: what `hdw synth drive` does) and fresh noise, and fits them
//! together with the compliant fit from starts 25 % off the truth (random signs). Each
//! replicate's encoders round at a fresh random phase: with one phase, the rounding error
//! would be the same in every replicate and the spread would miss it.

use super::design::DesignArgs;
use super::design_load::{Loaded, read_params};
use super::model_args::{MethodArg, ModelArgs, VariantArg};
use super::simulate::SimulateArgs;
use super::synth_drive::encoder;
use anyhow::{Context, Result};
use hd_ident::design::Outcome;
use hd_ident::drive::compliant::fit::CompliantSpec;
use hd_ident::drive::compliant::fit::cost_at;
use hd_ident::drive::compliant::model::P;
use hd_ident::drive::compliant::synth_loop::run_loop;
use hd_ident::drive::compliant::{ClosedLoop, Feedback, Signal, VoltageRecord, fit_compliant};
use hd_ident::synth::{Noise, add_noise};
use hd_model::signals::Sample;
use hd_model::{Input, Profile, simulate_streaming};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;
use std::time::Instant;

/// Relative offset of the refits' starts from the truth [–].
pub const START_OFFSET: f64 = 0.25;

/// How far above the truth's cost a refit may stop and still count as at its optimum [–]:
/// half a unit of the noise-weighted sum of squares, far below what moves an estimate by a
/// standard error (one unit) and far above the fits' own stopping tolerance.
pub const SHORT_OF_OPTIMUM: f64 = 0.5;

/// One refit: values, standard errors, determined flags ([`NAMES`](hd_ident::drive::compliant::NAMES) order).
pub type Refit = ([f64; P], [Option<f64>; P], [bool; P]);

/// The refits' results.
#[derive(Clone, Debug)]
pub struct Check {
    /// The truth ([`NAMES`](hd_ident::drive::compliant::NAMES) order).
    pub truth: [f64; P],
    /// Each refit's values, standard errors and determined flags.
    pub fits: Vec<Refit>,
    /// Each refit's verdict in words (the fit's sentences on what the records determine).
    pub sentences: Vec<Vec<String>>,
    /// Each refit's Σ (residual/noise)² less the truth's on the same records, at the same
    /// substeps [–] (None where either cannot be evaluated). The truth is a point the fit
    /// could have reached, so a refit above it by more than [`SHORT_OF_OPTIMUM`] stopped at a
    /// local optimum: its distance from the truth is the optimiser's, not the noise's.
    pub above_truth: Vec<Option<f64>>,
    /// Refits that failed, with why.
    pub failed: Vec<String>,
    /// Wall time [s].
    pub secs: f64,
}

/// SplitMix64: the next of a seeded sequence.
fn splitmix(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Encoder counts per revolution whose count/√12 is `sigma` [rad].
fn counts_of(sigma: f64) -> u64 {
    (std::f64::consts::TAU / (sigma * 12f64.sqrt())).round().max(1.0) as u64
}

/// Angles `x` [rad] read by an encoder of `counts` whose zero lies at a random phase
/// within a count (seeded by `seed`): the rounding is redrawn with each replicate, as a
/// rig's encoder zero falls anywhere; the fit's encoder zero absorbs the phase.
fn rounded(x: &[f64], counts: u64, seed: u64) -> Vec<f64> {
    let mut state = seed;
    let q = std::f64::consts::TAU / counts as f64;
    let phase = (splitmix(&mut state) >> 11) as f64 / (1u64 << 53) as f64 * q;
    let shifted: Vec<f64> = x.iter().map(|v| v + phase).collect();
    encoder(&shifted, counts)
}

/// The simulation of the drive of `params` over `t_end` [s], logged every `h` [s], at rest
/// under zero voltage (the caller sets the input).
fn drive_config(params: &Path, t_end: f64, h: f64) -> Result<hd_model::SimConfig> {
    let sim = SimulateArgs {
        model: ModelArgs {
            params: Some(params.to_path_buf()),
            set: Vec::new(),
            variant: VariantArg::Full,
            stiffness: None,
            friction_velocity: None,
            rtol: 1e-6,
            atol: 1e-9,
            method: MethodArg::Auto,
        },
        input: "constant".into(),
        voltage: 0.0,
        freq: 1.0,
        t_end,
        dt_out: h,
        cycles: 5,
        no_trace: true,
        max_output_values: 0,
        control: Default::default(),
        out: Default::default(),
    };
    super::simulate::config(&sim)
}

/// `i` [A] with Gaussian noise of standard deviation `sd` [A] (None: not logged).
fn noisy_current(mut i: Vec<f64>, sd: Option<f64>, seed: u64) -> Option<Vec<f64>> {
    let sd = sd?;
    let rms = (i.iter().map(|v| v * v).sum::<f64>() / i.len().max(1) as f64).sqrt();
    add_noise(&mut i, &Noise { relative: sd / rms.max(f64::MIN_POSITIVE), seed });
    Some(i)
}

/// Synthesise one record of voltage `u` sampled every `h` [s] by the drive of `params`.
fn synth(
    params: &Path,
    u: &[f64],
    h: f64,
    noise: (f64, f64, Option<f64>),
    seed: u64,
    name: &str,
) -> Result<VoltageRecord> {
    let mut cfg = drive_config(params, (u.len() - 1) as f64 * h, h)?;
    // Held voltage: each sample's value until just before the next (as synth drive holds it).
    let rise = 1e-6 * h;
    let mut pt = Vec::with_capacity(2 * u.len());
    let mut pu = Vec::with_capacity(2 * u.len());
    for (k, &v) in u.iter().enumerate() {
        pt.push(k as f64 * h);
        pu.push(v);
        pt.push(k as f64 * h + h - rise);
        pu.push(v);
    }
    cfg.input = Input::Recorded(Profile::new(pt, pu, "designed voltage")?);
    cfg.validate()?;
    let mut cols: [Vec<f64>; 5] = std::array::from_fn(|_| Vec::with_capacity(u.len()));
    simulate_streaming(
        &cfg,
        Some(&mut |s: &Sample| {
            for (c, v) in cols.iter_mut().zip([s.t, s.u, s.i, s.theta_j, s.theta_z]) {
                c.push(v);
            }
        }),
    )
    .context("the check's record cannot be simulated")?;
    let [t, uu, i, tj, tz] = cols;
    Ok(VoltageRecord::new(
        name,
        "check",
        t,
        uu,
        rounded(&tj, counts_of(noise.0), seed ^ 0x5151),
        rounded(&tz, counts_of(noise.1), seed ^ 0xA3A3),
        noisy_current(i, noise.2, seed),
    )?)
}

/// Synthesise one closed-loop record of reference `cl.reference` by the drive of `params`
/// in `cl`'s loop (hd-model's solver under each sample's held command, the controller
/// reading the fed-back encoder rounded to its counts, as `hdw synth drive --loop-kp`
/// does); the other encoder rounds at a random phase.
fn synth_in_loop(
    params: &Path,
    cl: &ClosedLoop,
    noise: (f64, f64, Option<f64>),
    seed: u64,
    name: &str,
) -> Result<VoltageRecord> {
    let c = &cl.controller;
    let cfg = drive_config(params, (cl.reference.len() - 1) as f64 * c.h, c.h)?;
    let (motor, load) = (counts_of(noise.0), counts_of(noise.1));
    let fed = if cl.feedback == Feedback::Load { load } else { motor };
    let run = run_loop(&cfg, c, cl.feedback, cl.amplifier, &cl.reference, fed)
        .context("the check's closed-loop record cannot be simulated")?;
    // The fed-back encoder as the controller read it; the other at a random phase.
    let (theta_m, theta_l) = match cl.feedback {
        Feedback::Motor => {
            (encoder(&run.theta_j, motor), rounded(&run.theta_z, load, seed ^ 0xA3A3))
        }
        Feedback::Load => {
            (rounded(&run.theta_j, motor, seed ^ 0x5151), encoder(&run.theta_z, load))
        }
    };
    let current = noisy_current(run.current, noise.2, seed);
    let rec = VoltageRecord::new(name, "check", run.t, run.command, theta_m, theta_l, current)?;
    Ok(rec.in_loop(cl.clone())?)
}

/// Run the check of `a.check` refits.
pub fn check(a: &DesignArgs, loaded: &Loaded, outcome: &Outcome) -> Result<Check> {
    let t0 = Instant::now();
    let p = &loaded.problem;
    let truth_file = a.truth.clone().unwrap_or_else(|| loaded.params_file.clone());
    let (truth, _, _) = read_params(&truth_file)?;
    let truth = p.spec.tied(truth);
    let h = 1.0 / p.limits.rate;
    let design_u = &outcome.best().scaled.u;
    let level = |o: Signal, k: usize| p.spec.outputs.iter().find(|x| x.0 == o).map(|x| x.1[k]);
    let bar = ProgressBar::new(a.check as u64);
    bar.set_style(
        ProgressStyle::with_template("{spinner} check: refit {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut fits = Vec::new();
    let mut sentences = Vec::new();
    let mut failed = Vec::new();
    let mut above_truth = Vec::new();
    for r in 0..a.check {
        let seed = a.seed.wrapping_mul(1000).wrapping_add(r as u64);
        let mut records = Vec::new();
        let mut outputs: Vec<(Signal, Vec<f64>)> = Vec::new();
        let mut push_noise = |o: Signal, v: Option<f64>| {
            if let Some(v) = v {
                match outputs.iter_mut().find(|x| x.0 == o) {
                    Some(x) => x.1.push(v),
                    None => outputs.push((o, vec![v])),
                }
            }
        };
        for (k, rec) in loaded.records.iter().enumerate() {
            let nz = (
                level(Signal::Motor, k).unwrap_or(p.noise.motor),
                level(Signal::Load, k).unwrap_or(p.noise.load),
                level(Signal::Current, k),
            );
            let s = seed * 7 + k as u64;
            records.push(match &rec.closed {
                Some(cl) => synth_in_loop(&truth_file, cl, nz, s, &rec.name)?,
                None => synth(&truth_file, &rec.u, rec.h, nz, s, &rec.name)?,
            });
            push_noise(Signal::Motor, Some(nz.0));
            push_noise(Signal::Load, Some(nz.1));
            push_noise(Signal::Current, nz.2);
            if rec.closed.is_some() {
                push_noise(Signal::Command, level(Signal::Command, k));
            }
        }
        let nz = (p.noise.motor, p.noise.load, p.noise.current);
        records.push(match &p.closed {
            Some(l) => synth_in_loop(&truth_file, &l.closed(design_u), nz, seed * 7 + 5, "design")?,
            None => synth(&truth_file, design_u, h, nz, seed * 7 + 5, "design")?,
        });
        push_noise(Signal::Motor, Some(p.noise.motor));
        push_noise(Signal::Load, Some(p.noise.load));
        push_noise(Signal::Current, p.noise.current);
        if let Some(l) = &p.closed {
            push_noise(Signal::Command, Some(l.command_noise));
        }
        let mut state = seed ^ 0x9E37_79B9_7F4A_7C15;
        let mut start = truth;
        for &k in &p.free {
            let s = if splitmix(&mut state) >> 63 == 1 {
                1.0 + START_OFFSET
            } else {
                1.0 - START_OFFSET
            };
            start[k] = truth[k] * s;
        }
        let start = p.spec.tied(start);
        let spec = CompliantSpec {
            start,
            lower: start.map(|v| if v > 0.0 { v / 1e3 } else { v * 1e3 }),
            upper: start.map(|v| if v > 0.0 { v * 1e3 } else { v / 1e3 }),
            noise_estimated: vec![false; outputs.len()],
            outputs,
            ..p.spec.clone()
        };
        bar.set_message(format!("({} failed)", failed.len()));
        match fit_compliant(&spec, &records, &|_, _, _| {}) {
            Ok(f) => {
                let at = |v: &[f64; P]| cost_at(&spec, v, &records);
                above_truth.push(at(&f.values).zip(at(&truth)).map(|(a, b)| a - b));
                fits.push((f.values, f.std_errors, f.determined));
                sentences.push(f.determination.sentences);
            }
            Err(e) => failed.push(e),
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(Check { truth, fits, sentences, above_truth, failed, secs: t0.elapsed().as_secs_f64() })
}
