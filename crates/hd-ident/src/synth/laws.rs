//! Synthetic torque–deflection records from any stiffness law under either schedule: the
//! seed's sum of sines, or a quasi-static test of amplitude steps at slow rates. The
//! memory law integrates its state with hd-model's Dopri5; the rate-independent laws step
//! their states through the deflection at 32 sub-samples per sample interval, so every
//! reversal between samples is followed.

use super::Synthetic;
use super::excitation::{QuasiStatic, SumOfSines};
use super::hysteresis::{HysteresisExcitation, synth_hysteresis};
use super::noise::{Noise, add_noise};
use crate::error::FitError;
use crate::path::{MemoryAlong, Signal, state_at_samples};
use hd_model::Params;
use hd_model::laws::bouc_wen::BoucWenStiffness;
use hd_model::laws::maxwell_slip::MaxwellSlip;
use hd_model::laws::stiffness::{CubicSpring, FadingMemory, Hysteretic, StiffnessLaw};
use hd_model::solver::{Method, SolverOptions};

/// The law that makes the data, with its true parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum StiffnessTruth {
    /// Cubic spring and fading memory, parameters a, b, c, mem_A, mem_B of `Params`.
    Memory(Box<Params>),
    /// Cubic spring and elastoplastic elements.
    MaxwellSlip(MaxwellSlip),
    /// Cubic spring and a Bouc–Wen element.
    BoucWen(BoucWenStiffness),
}

/// The imposed deflection and its sampling.
#[derive(Clone, Debug, PartialEq)]
pub enum Schedule {
    /// Sum of sines (see [`HysteresisExcitation`]).
    Sines(HysteresisExcitation),
    /// Amplitude steps at slow rates, sampled at `sample_rate` [Hz].
    QuasiStatic { test: QuasiStatic, sample_rate: f64 },
}

/// Sub-samples per sample interval for the rate-independent laws.
const SUB: usize = 32;

fn setting(field: &'static str, value: impl ToString, expected: &str) -> FitError {
    FitError::Setting { field, value: value.to_string(), expected: expected.to_string() }
}

fn check(q: &QuasiStatic, sample_rate: f64) -> Result<(), FitError> {
    if !(q.amplitude > 0.0 && q.amplitude.is_finite()) {
        return Err(setting("amplitude", q.amplitude, "a finite value > 0 [rad]"));
    }
    if q.levels.is_empty() || q.levels.iter().any(|l| !(*l > 0.0 && l.is_finite())) {
        return Err(setting("levels", format!("{:?}", q.levels), "one or more finite shares > 0"));
    }
    if q.frequencies.is_empty() || q.frequencies.iter().any(|f| !(*f > 0.0 && f.is_finite())) {
        return Err(setting(
            "frequencies",
            format!("{:?}", q.frequencies),
            "one or more finite values > 0 [Hz]",
        ));
    }
    if q.cycles == 0 {
        return Err(setting("cycles", 0, "at least 1 cycle per block"));
    }
    if !(sample_rate > 0.0 && sample_rate.is_finite()) {
        return Err(setting("sample_rate", sample_rate, "a finite value > 0 [Hz]"));
    }
    Ok(())
}

/// Columns `t, theta, torque` from `truth` under `schedule`, plus noise.
pub fn synth_stiffness(
    truth: &StiffnessTruth,
    schedule: &Schedule,
    noise: &Noise,
) -> Result<Synthetic, FitError> {
    let (signal, t, what): (Box<dyn Signal>, Vec<f64>, String) = match schedule {
        Schedule::Sines(exc) => {
            if let StiffnessTruth::Memory(p) = truth {
                return synth_hysteresis(p, exc, noise);
            }
            exc.validate()?;
            let dt = exc.duration / (exc.samples - 1) as f64;
            let t = (0..exc.samples).map(|k| k as f64 * dt).collect();
            let s = SumOfSines { amplitude: exc.amplitude, frequencies: exc.frequencies.clone() };
            (
                Box::new(s),
                t,
                format!(
                    "sum of sines at {:?} Hz, peak bound {:e} rad",
                    exc.frequencies, exc.amplitude
                ),
            )
        }
        Schedule::QuasiStatic { test, sample_rate } => {
            check(test, *sample_rate)?;
            let n = (test.duration() * sample_rate).round() as usize + 1;
            let t = (0..n).map(|k| k as f64 / sample_rate).collect();
            let what = format!(
                "quasi-static test: {} cycle(s) at each of {:?} × {:e} rad, at {:?} Hz, sampled at {sample_rate} Hz",
                test.cycles, test.levels, test.amplitude, test.frequencies
            );
            (Box::new(test.clone()), t, what)
        }
    };
    let theta: Vec<f64> = t.iter().map(|&ti| signal.at(ti)[0]).collect();
    let (mut torque, law_text) = match truth {
        StiffnessTruth::Memory(p) => (
            memory_along(p, signal.as_ref(), &t)?,
            format!(
                "memory law a={:e}, b={:e}, c={:e}, mem_A={:e}, mem_B={:e}",
                p.a, p.b, p.c, p.mem_a, p.mem_b
            ),
        ),
        StiffnessTruth::MaxwellSlip(law) => {
            let fine = sub_sampled(signal.as_ref(), &t);
            let tb = law.torque_along(&fine);
            let els: Vec<String> =
                law.elements.iter().map(|e| format!("(k={:e}, F={:e})", e.k, e.f)).collect();
            (
                tb.into_iter().step_by(SUB).collect(),
                format!(
                    "Maxwell-slip law a={:e}, b={:e}, c={:e}, elements {}",
                    law.spring.a,
                    law.spring.b,
                    law.spring.c,
                    els.join(" ")
                ),
            )
        }
        StiffnessTruth::BoucWen(law) => {
            let fine = sub_sampled(signal.as_ref(), &t);
            let tb = law.torque_along(&fine);
            let e = law.element;
            (
                tb.into_iter().step_by(SUB).collect(),
                format!(
                    "Bouc–Wen law a={:e}, b={:e}, c={:e}, bw_alpha={:e}, bw_A={:e}, bw_beta={:e}, bw_gamma={:e}, bw_n={:e}",
                    law.spring.a, law.spring.b, law.spring.c, e.alpha, e.a, e.beta, e.gamma, e.n
                ),
            )
        }
    };
    let sd = add_noise(&mut torque, noise);
    let description = format!(
        "hysteresis: theta(t) = {what}, {} samples; {law_text}; Gaussian noise {} x RMS torque = {sd:.4e} N·m (seed {})",
        t.len(),
        noise.relative,
        noise.seed
    );
    Ok(Synthetic {
        names: vec!["t", "theta", "torque"],
        columns: vec![t, theta, torque],
        noise_std: sd,
        description,
    })
}

/// θ at [`SUB`] points per sample interval (the samples themselves every SUB-th).
fn sub_sampled(signal: &dyn Signal, t: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(t.len() * SUB);
    out.push(signal.at(t[0])[0]);
    for w in t.windows(2) {
        for j in 1..=SUB {
            out.push(signal.at(w[0] + (w[1] - w[0]) * j as f64 / SUB as f64)[0]);
        }
    }
    out
}

struct Dyn<'a>(&'a dyn Signal);
impl Signal for Dyn<'_> {
    fn at(&self, t: f64) -> [f64; 3] {
        self.0.at(t)
    }
}

fn memory_along(p: &Params, signal: &dyn Signal, t: &[f64]) -> Result<Vec<f64>, FitError> {
    p.validate()?;
    let law = Hysteretic {
        spring: CubicSpring { a: p.a, b: p.b, c: p.c },
        memory: FadingMemory { a: p.mem_a, b: p.mem_b },
    };
    let peak = t.iter().map(|&ti| signal.at(ti)[0].abs()).fold(0.0, f64::max);
    let sys = MemoryAlong {
        law,
        deflection: &Dyn(signal),
        scale: (p.mem_a * peak).max(f64::MIN_POSITIVE),
    };
    let opts =
        SolverOptions { method: Method::Dopri5, rtol: 1e-10, atol: 1e-12, ..Default::default() };
    let z = state_at_samples(&sys, t, 0.0, &opts).map_err(|source| FitError::Solver {
        what: "the memory state along the imposed deflection".into(),
        source,
    })?;
    Ok(t.iter()
        .zip(&z)
        .map(|(&ti, &zi)| {
            let [th, dth, _] = signal.at(ti);
            law.eval(th, dth, zi).torque
        })
        .collect())
}
