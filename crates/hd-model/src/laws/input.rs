//! Armature-voltage inputs u(t) (docs/model.md §2.8).

use super::cycles::{sin_cos_cycles, sin_cycles};
use crate::error::ConfigError;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// A recorded voltage profile, linearly interpolated and held constant outside its range.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    /// Sample times [s], strictly increasing.
    pub t: Vec<f64>,
    /// Voltages [V].
    pub u: Vec<f64>,
}

impl Profile {
    /// Build a profile, checking that it has at least two samples, equal lengths, finite
    /// values and strictly increasing time. `source` names the origin in errors.
    pub fn new(t: Vec<f64>, u: Vec<f64>, source: &str) -> Result<Self, ConfigError> {
        let bad = |value: String, expected: &str| ConfigError::Invalid {
            field: source.to_string(),
            value,
            expected: expected.to_string(),
        };
        if t.len() != u.len() {
            return Err(bad(format!("{} times, {} voltages", t.len(), u.len()), "equal lengths"));
        }
        if t.len() < 2 {
            return Err(bad(format!("{} samples", t.len()), "at least 2 samples"));
        }
        for (k, (&tk, &uk)) in t.iter().zip(&u).enumerate() {
            if !tk.is_finite() || !uk.is_finite() {
                return Err(bad(format!("row {}: t = {tk}, u = {uk}", k + 1), "finite t and u"));
            }
            if k > 0 && tk <= t[k - 1] {
                return Err(bad(
                    format!("row {}: t = {tk} after t = {}", k + 1, t[k - 1]),
                    "strictly increasing time",
                ));
            }
        }
        Ok(Self { t, u })
    }

    fn value_and_rate(&self, t: f64) -> (f64, f64) {
        let n = self.t.len();
        // Held constant outside the recording (no rate at its ends either).
        if t <= self.t[0] || t >= self.t[n - 1] {
            return (if t <= self.t[0] { self.u[0] } else { self.u[n - 1] }, 0.0);
        }
        crate::interp::linear_at(&self.t, &self.u, t)
    }
}

/// The armature-voltage input.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Input {
    /// `U·sin(2π·f·t)`.
    Sine {
        /// Amplitude U [V].
        amplitude: f64,
        /// Frequency f [Hz].
        freq: f64,
    },
    /// 0 before `t0`, `U` from `t0` on.
    Step {
        /// Level U [V].
        amplitude: f64,
        /// Switching time t0 [s].
        t0: f64,
    },
    /// Constant `U`.
    Constant {
        /// Level U [V].
        amplitude: f64,
    },
    /// Linear chirp `U·sin(2π(f0·t + (f1−f0)·t²/(2T)))` for t ≤ T, then f1.
    Chirp {
        /// Amplitude U [V].
        amplitude: f64,
        /// Start frequency f0 [Hz].
        f0: f64,
        /// End frequency f1 [Hz].
        f1: f64,
        /// Sweep duration T [s].
        duration: f64,
    },
    /// Stepped sine: each frequency held for `dwell` seconds, phase-continuous.
    SteppedSine {
        /// Amplitude U [V].
        amplitude: f64,
        /// Frequencies [Hz], in order.
        freqs: Vec<f64>,
        /// Time at each frequency [s].
        dwell: f64,
    },
    /// A recorded profile.
    Recorded(Profile),
}

impl Default for Input {
    fn default() -> Self {
        Input::Sine { amplitude: 24.0, freq: 50.0 }
    }
}

impl Input {
    /// The input's kind as a study file and the CLI name it (`sine`, `step`, `recorded`, …).
    pub fn kind_name(&self) -> &'static str {
        match self {
            Input::Sine { .. } => "sine",
            Input::Step { .. } => "step",
            Input::Constant { .. } => "constant",
            Input::Chirp { .. } => "chirp",
            Input::SteppedSine { .. } => "stepped sine",
            Input::Recorded(_) => "recorded",
        }
    }

    /// Voltage u(t) [V] and its time derivative du/dt [V/s].
    pub fn value_and_rate(&self, t: f64) -> (f64, f64) {
        match self {
            Input::Sine { amplitude, freq } => {
                let (s, c) = sin_cos_cycles(freq * t);
                (amplitude * s, amplitude * TAU * freq * c)
            }
            Input::Step { amplitude, t0 } => (if t >= *t0 { *amplitude } else { 0.0 }, 0.0),
            Input::Constant { amplitude } => (*amplitude, 0.0),
            Input::Chirp { amplitude, f0, f1, duration } => {
                let (phase, f) = if t <= *duration {
                    let k = (f1 - f0) / duration;
                    (f0 * t + 0.5 * k * t * t, f0 + k * t)
                } else {
                    (f0 * duration + 0.5 * (f1 - f0) * duration + f1 * (t - duration), *f1)
                };
                let (s, c) = sin_cos_cycles(phase);
                (amplitude * s, amplitude * TAU * f * c)
            }
            Input::SteppedSine { amplitude, freqs, dwell } => {
                let (phase, f) = stepped_phase(freqs, *dwell, t);
                let (s, c) = sin_cos_cycles(phase);
                (amplitude * s, amplitude * TAU * f * c)
            }
            Input::Recorded(p) => p.value_and_rate(t),
        }
    }

    /// Voltage u(t) [V].
    pub fn value(&self, t: f64) -> f64 {
        // The sine is the hot case: skip the derivative's cosine.
        match self {
            Input::Sine { amplitude, freq } => amplitude * sin_cycles(freq * t),
            _ => self.value_and_rate(t).0,
        }
    }

    /// Cycles the input runs through from 0 to `t` [–] (its phase), for the oscillating
    /// inputs; 0 for steps, constants and recorded profiles (their samples bound the work).
    pub fn cycles_until(&self, t: f64) -> f64 {
        match self {
            Input::Sine { freq, .. } => freq * t,
            Input::Chirp { f0, f1, duration, .. } => {
                let d = t.min(*duration);
                f0 * d + 0.5 * (f1 - f0) / duration * d * d + f1 * (t - d).max(0.0)
            }
            Input::SteppedSine { freqs, dwell, .. } => stepped_phase(freqs, *dwell, t).0,
            _ => 0.0,
        }
    }

    /// The drive frequency of a periodic input [Hz], if it has one: the sine's, or that of a
    /// recorded profile that repeats ([`super::periodicity::period_of`]).
    pub fn drive_frequency(&self) -> Option<f64> {
        match self {
            Input::Sine { freq, .. } => Some(*freq),
            Input::Recorded(p) => super::periodicity::period_of(&p.t, &p.u).map(|p| 1.0 / p),
            _ => None,
        }
    }

    /// Times where u or du/dt jumps; the integrator restarts there.
    pub fn breakpoints(&self) -> Vec<f64> {
        match self {
            Input::Step { t0, .. } if *t0 > 0.0 => vec![*t0],
            Input::Chirp { duration, .. } => vec![*duration],
            Input::SteppedSine { freqs, dwell, .. } => {
                (1..freqs.len()).map(|k| k as f64 * dwell).collect()
            }
            Input::Recorded(p) => p.t.clone(),
            _ => Vec::new(),
        }
    }

    /// Check the input's settings.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.validate_as("input")
    }

    /// Check the settings of this signal used under the name `prefix` (errors name
    /// `prefix.field`), e.g. `load_torque` when it describes a load torque.
    pub fn validate_as(&self, prefix: &str) -> Result<(), ConfigError> {
        let bad = |field: &str, value: f64, expected: &str| {
            Err(ConfigError::Invalid {
                field: format!("{prefix}.{field}"),
                value: crate::error::num(value),
                expected: expected.to_string(),
            })
        };
        let finite = |field: &str, v: f64| {
            if v.is_finite() { Ok(()) } else { bad(field, v, "a finite number") }
        };
        let positive = |field: &str, v: f64| {
            if v.is_finite() && v > 0.0 { Ok(()) } else { bad(field, v, "a finite number > 0") }
        };
        match self {
            Input::Sine { amplitude, freq } => {
                finite("amplitude", *amplitude)?;
                positive("freq", *freq)
            }
            Input::Step { amplitude, t0 } => {
                finite("amplitude", *amplitude)?;
                if !(t0.is_finite() && *t0 >= 0.0) {
                    return bad("t0", *t0, "a finite time >= 0 [s]");
                }
                Ok(())
            }
            Input::Constant { amplitude } => finite("amplitude", *amplitude),
            Input::Chirp { amplitude, f0, f1, duration } => {
                finite("amplitude", *amplitude)?;
                positive("f0", *f0)?;
                positive("f1", *f1)?;
                positive("duration", *duration)
            }
            Input::SteppedSine { amplitude, freqs, dwell } => {
                finite("amplitude", *amplitude)?;
                positive("dwell", *dwell)?;
                if freqs.is_empty() {
                    return bad("freqs", f64::NAN, "at least one frequency [Hz]");
                }
                freqs.iter().try_for_each(|f| positive("freqs", *f))
            }
            Input::Recorded(p) => Profile::new(p.t.clone(), p.u.clone(), prefix).map(|_| ()),
        }
    }
}

/// Accumulated phase [cycles] and current frequency [Hz] of a stepped sine at time t.
fn stepped_phase(freqs: &[f64], dwell: f64, t: f64) -> (f64, f64) {
    let k = ((t / dwell).floor().max(0.0) as usize).min(freqs.len() - 1);
    let done: f64 = freqs[..k].iter().map(|f| f * dwell).sum();
    (done + freqs[k] * (t - k as f64 * dwell), freqs[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central difference of u(t).
    fn fd(input: &Input, t: f64) -> f64 {
        let h = 1e-7;
        (input.value(t + h) - input.value(t - h)) / (2.0 * h)
    }

    #[test]
    fn every_input_reports_the_derivative_of_its_value() {
        let inputs = [
            Input::Sine { amplitude: 24.0, freq: 50.0 },
            Input::Chirp { amplitude: 5.0, f0: 10.0, f1: 100.0, duration: 0.3 },
            Input::SteppedSine { amplitude: 3.0, freqs: vec![10.0, 40.0, 90.0], dwell: 0.1 },
            Input::Recorded(
                Profile::new(vec![0.0, 0.1, 0.3], vec![0.0, 2.0, -1.0], "test").unwrap(),
            ),
        ];
        for input in &inputs {
            for k in 1..50 {
                let t = k as f64 * 0.0071;
                if input.breakpoints().iter().any(|b| (b - t).abs() < 1e-6) {
                    continue;
                }
                let (_, rate) = input.value_and_rate(t);
                assert!(
                    (rate - fd(input, t)).abs() < 1e-4 * rate.abs().max(1.0),
                    "{input:?} at {t}"
                );
            }
        }
    }

    #[test]
    fn chirp_sweeps_linearly_and_stepped_sine_is_phase_continuous() {
        // Instantaneous frequency = (du/dt) / (2π·U·cos φ); check it via the phase rate at
        // zero crossings of the derivative-free form: count cycles instead.
        let chirp = Input::Chirp { amplitude: 1.0, f0: 10.0, f1: 30.0, duration: 1.0 };
        let crossings = (1..100_000)
            .filter(|&k| {
                let (a, b) = (chirp.value((k - 1) as f64 * 1e-5), chirp.value(k as f64 * 1e-5));
                a < 0.0 && b >= 0.0
            })
            .count();
        // Cycles in 1 s of a 10→30 Hz linear chirp: the mean frequency, 20.
        assert!((crossings as i64 - 20).abs() <= 1, "{crossings}");
        let stepped = Input::SteppedSine { amplitude: 1.0, freqs: vec![10.0, 25.0], dwell: 0.13 };
        let (before, after) = (stepped.value(0.13 - 1e-9), stepped.value(0.13 + 1e-9));
        assert!((before - after).abs() < 1e-6, "no jump at the frequency change");
        assert_eq!(stepped.breakpoints(), vec![0.13]);
    }

    #[test]
    fn recorded_profiles_are_checked() {
        assert!(Profile::new(vec![0.0, 0.1, 0.1], vec![0.0; 3], "f").is_err());
        assert!(Profile::new(vec![0.0, f64::NAN], vec![0.0; 2], "f").is_err());
        assert!(Profile::new(vec![0.0], vec![0.0], "f").is_err());
        assert!(Profile::new(vec![0.0, 1.0], vec![0.0], "f").is_err());
    }
}
