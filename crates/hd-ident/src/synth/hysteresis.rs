//! Synthetic hysteresis records: an imposed deflection drives the hysteretic law, whose
//! memory state is integrated by hd-model's solver (Dopri5, tight tolerances) and whose
//! torque `f(θ) + z` is read at every sample.

use super::Synthetic;
use super::excitation::SumOfSines;
use super::noise::{Noise, add_noise};
use crate::error::FitError;
use crate::path::{MemoryAlong, Signal, state_at_samples};
use hd_model::Params;
use hd_model::laws::stiffness::{CubicSpring, FadingMemory, Hysteretic, StiffnessLaw};
use hd_model::solver::{Method, SolverOptions};

/// The imposed deflection of a synthetic hysteresis experiment: `θ(t)` a sum of equal
/// sines (see [`SumOfSines`]), sampled uniformly.
#[derive(Clone, Debug, PartialEq)]
pub struct HysteresisExcitation {
    /// Peak bound of θ [rad]; default 1e-3 (the seed's deflection range).
    pub amplitude: f64,
    /// Sine frequencies [Hz]; default 3, 13, 47 and 190 Hz, spread around the default
    /// memory corner frequency B/2π ≈ 48 Hz so that B and A are both visible.
    pub frequencies: Vec<f64>,
    /// Record length [s]; default 1.
    pub duration: f64,
    /// Samples, evenly spaced from t = 0 to t = duration; default 20 000.
    pub samples: usize,
}

impl Default for HysteresisExcitation {
    fn default() -> Self {
        Self {
            amplitude: 1e-3,
            frequencies: vec![4.0, 15.0, 55.0, 200.0],
            duration: 0.5,
            samples: 20_000,
        }
    }
}

fn setting(field: &'static str, value: impl ToString, expected: &str) -> FitError {
    FitError::Setting { field, value: value.to_string(), expected: expected.to_string() }
}

impl HysteresisExcitation {
    /// Check the settings.
    pub fn validate(&self) -> Result<(), FitError> {
        if !(self.amplitude > 0.0 && self.amplitude.is_finite()) {
            return Err(setting("amplitude", self.amplitude, "a finite value > 0 [rad]"));
        }
        if self.frequencies.is_empty()
            || self.frequencies.iter().any(|f| !(*f > 0.0 && f.is_finite()))
        {
            return Err(setting(
                "frequencies",
                format!("{:?}", self.frequencies),
                "one or more finite values > 0 [Hz]",
            ));
        }
        if !(self.duration > 0.0 && self.duration.is_finite()) {
            return Err(setting("duration", self.duration, "a finite value > 0 [s]"));
        }
        if self.samples < 2 {
            return Err(setting("samples", self.samples, "at least 2"));
        }
        Ok(())
    }
}

/// Columns `t, theta, torque` from the hysteretic law with parameters `p` (a, b, c, A,
/// B) under `exc`, plus noise.
pub fn synth_hysteresis(
    p: &Params,
    exc: &HysteresisExcitation,
    noise: &Noise,
) -> Result<Synthetic, FitError> {
    exc.validate()?;
    p.validate()?;
    let law = Hysteretic {
        spring: CubicSpring { a: p.a, b: p.b, c: p.c },
        memory: FadingMemory { a: p.mem_a, b: p.mem_b },
    };
    let signal = SumOfSines { amplitude: exc.amplitude, frequencies: exc.frequencies.clone() };
    let dt = exc.duration / (exc.samples - 1) as f64;
    let t: Vec<f64> = (0..exc.samples).map(|k| k as f64 * dt).collect();
    let scale = (p.mem_a * exc.amplitude).max(f64::MIN_POSITIVE);
    let sys = MemoryAlong { law, deflection: &signal, scale };
    let opts =
        SolverOptions { method: Method::Dopri5, rtol: 1e-10, atol: 1e-12, ..Default::default() };
    let z = state_at_samples(&sys, &t, 0.0, &opts).map_err(|source| FitError::Solver {
        what: "the memory state along the imposed deflection".into(),
        source,
    })?;
    let (theta, mut torque): (Vec<f64>, Vec<f64>) = t
        .iter()
        .zip(&z)
        .map(|(&ti, &zi)| {
            let [th, dth, _] = signal.at(ti);
            (th, law.eval(th, dth, zi).torque)
        })
        .unzip();
    let sd = add_noise(&mut torque, noise);
    let freqs: Vec<String> = exc.frequencies.iter().map(|f| format!("{f}")).collect();
    let description = format!(
        "hysteresis: theta(t) = sum of {} equal sines at {} Hz, peak bound {:e} rad, {} samples over {} s; \
         a={:e}, b={:e}, c={:e}, mem_A={:e}, mem_B={:e}; Gaussian noise {} x RMS torque = {:.4e} N·m (seed {})",
        exc.frequencies.len(),
        freqs.join(", "),
        exc.amplitude,
        exc.samples,
        exc.duration,
        p.a,
        p.b,
        p.c,
        p.mem_a,
        p.mem_b,
        noise.relative,
        sd,
        noise.seed
    );
    Ok(Synthetic {
        names: vec!["t", "theta", "torque"],
        columns: vec![t, theta, torque],
        noise_std: sd,
        description,
    })
}
