//! Load-angle references θz_ref(t) for the closed loop (docs/model.md §6.1).

use crate::error::ConfigError;
use crate::laws::cycles::sin_cos_cycles;
use crate::laws::input::Profile;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// A reference for the load angle, with its first two time derivatives.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Reference {
    /// 0 before `t0`, `amplitude` from `t0` on.
    Step {
        /// Step height [rad].
        amplitude: f64,
        /// Step time [s].
        #[serde(default)]
        t0: f64,
    },
    /// `amplitude·sin(2π·freq·t)`.
    Sine {
        /// Amplitude [rad].
        amplitude: f64,
        /// Frequency [Hz].
        freq: f64,
    },
    /// Point-to-point move of `amplitude` in `duration` seconds from `t0`, trapezoidal
    /// speed: constant acceleration for the first quarter of the move, constant speed for
    /// the middle half, constant deceleration for the last quarter.
    Trapezoid {
        /// Distance [rad].
        amplitude: f64,
        /// Move time [s].
        duration: f64,
        /// Start time [s].
        #[serde(default)]
        t0: f64,
    },
    /// Point-to-point move with continuous acceleration (cycloidal S-curve):
    /// `D·(s − sin(2πs)/(2π))`, s = (t − t0)/duration.
    SCurve {
        /// Distance [rad].
        amplitude: f64,
        /// Move time [s].
        duration: f64,
        /// Start time [s].
        #[serde(default)]
        t0: f64,
    },
    /// A recorded angle profile (columns t [s] and the angle [rad]), linearly interpolated
    /// and held at its end values.
    Recorded(Profile),
}

impl Default for Reference {
    fn default() -> Self {
        Reference::Sine { amplitude: 1e-3, freq: 0.2 }
    }
}

impl Reference {
    /// θz_ref [rad], its speed [rad/s] and its acceleration [rad/s²] at time t [s].
    pub fn eval(&self, t: f64) -> [f64; 3] {
        match self {
            Reference::Step { amplitude, t0 } => {
                [if t >= *t0 { *amplitude } else { 0.0 }, 0.0, 0.0]
            }
            Reference::Sine { amplitude, freq } => {
                let w = TAU * freq;
                let (s, c) = sin_cos_cycles(freq * t);
                [amplitude * s, amplitude * w * c, -amplitude * w * w * s]
            }
            Reference::Trapezoid { amplitude: d, duration: big_t, t0 } => {
                let tau = t - t0;
                let ta = 0.25 * big_t;
                let a = d / (ta * (big_t - ta));
                if tau <= 0.0 {
                    [0.0; 3]
                } else if tau < ta {
                    [0.5 * a * tau * tau, a * tau, a]
                } else if tau < big_t - ta {
                    [0.5 * a * ta * ta + a * ta * (tau - ta), a * ta, 0.0]
                } else if tau < *big_t {
                    let rest = big_t - tau;
                    [d - 0.5 * a * rest * rest, a * rest, -a]
                } else {
                    [*d, 0.0, 0.0]
                }
            }
            Reference::SCurve { amplitude: d, duration: big_t, t0 } => {
                let s = ((t - t0) / big_t).clamp(0.0, 1.0);
                let (sn, cs) = sin_cos_cycles(s);
                if s <= 0.0 || s >= 1.0 {
                    return [d * s, 0.0, 0.0];
                }
                [d * (s - sn / TAU), d / big_t * (1.0 - cs), d * TAU / (big_t * big_t) * sn]
            }
            Reference::Recorded(p) => {
                let n = p.t.len();
                if t <= p.t[0] || t >= p.t[n - 1] {
                    return [if t <= p.t[0] { p.u[0] } else { p.u[n - 1] }, 0.0, 0.0];
                }
                let (v, rate) = crate::interp::linear_at(&p.t, &p.u, t);
                [v, rate, 0.0]
            }
        }
    }

    /// The period of a periodic reference [s].
    pub fn period(&self) -> Option<f64> {
        match self {
            Reference::Sine { freq, .. } => Some(1.0 / freq),
            _ => None,
        }
    }

    /// Time from which the tracking metrics are taken [s]: one period for a periodic
    /// reference, the end of the move for a point-to-point one, the step time for a step.
    pub fn settled_from(&self) -> f64 {
        match self {
            Reference::Sine { freq, .. } => 1.0 / freq,
            Reference::Step { t0, .. } => *t0,
            Reference::Trapezoid { duration, t0, .. } | Reference::SCurve { duration, t0, .. } => {
                t0 + duration
            }
            Reference::Recorded(_) => 0.0,
        }
    }

    /// Whether the reference ends at rest (a regulation task: steady error and hunting
    /// are measured).
    pub fn is_regulation(&self) -> bool {
        !matches!(self, Reference::Sine { .. } | Reference::Recorded(_))
    }

    /// Times where the reference or its derivatives jump.
    pub fn breakpoints(&self) -> Vec<f64> {
        match self {
            Reference::Step { t0, .. } if *t0 > 0.0 => vec![*t0],
            Reference::Trapezoid { duration, t0, .. } => {
                vec![*t0, t0 + 0.25 * duration, t0 + 0.75 * duration, t0 + duration]
            }
            Reference::SCurve { duration, t0, .. } => vec![*t0, t0 + duration],
            Reference::Recorded(p) => p.t.clone(),
            _ => Vec::new(),
        }
    }

    /// Check the settings; errors name `controller.reference.<field>`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let bad = |field: &str, value: f64, expected: &str| {
            Err(ConfigError::Invalid {
                field: format!("controller.reference.{field}"),
                value: crate::error::num(value),
                expected: expected.to_string(),
            })
        };
        let finite = |field: &str, v: f64| {
            if v.is_finite() { Ok(()) } else { bad(field, v, "a finite number [rad]") }
        };
        let positive = |field: &str, v: f64| {
            if v.is_finite() && v > 0.0 { Ok(()) } else { bad(field, v, "a finite number > 0") }
        };
        let start = |v: f64| {
            if v.is_finite() && v >= 0.0 { Ok(()) } else { bad("t0", v, "a finite time >= 0 [s]") }
        };
        match self {
            Reference::Step { amplitude, t0 } => {
                finite("amplitude", *amplitude)?;
                start(*t0)
            }
            Reference::Sine { amplitude, freq } => {
                finite("amplitude", *amplitude)?;
                positive("freq", *freq)
            }
            Reference::Trapezoid { amplitude, duration, t0 }
            | Reference::SCurve { amplitude, duration, t0 } => {
                finite("amplitude", *amplitude)?;
                positive("duration", *duration)?;
                start(*t0)
            }
            Reference::Recorded(p) => {
                Profile::new(p.t.clone(), p.u.clone(), "controller.reference").map(|_| ())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Speed and acceleration are the derivatives of the angle (central differences away
    /// from the breakpoints), and the moves end at their distance.
    #[test]
    fn derivatives_are_consistent_and_moves_arrive() {
        let refs = [
            Reference::Sine { amplitude: 2e-3, freq: 0.7 },
            Reference::Trapezoid { amplitude: 0.5, duration: 2.0, t0: 0.1 },
            Reference::SCurve { amplitude: 0.5, duration: 2.0, t0: 0.1 },
        ];
        let h = 1e-6;
        for r in &refs {
            for k in 1..200 {
                let t = k as f64 * 0.0123;
                if r.breakpoints().iter().any(|b| (b - t).abs() < 1e-3) {
                    continue;
                }
                let [_, v, a] = r.eval(t);
                let v_fd = (r.eval(t + h)[0] - r.eval(t - h)[0]) / (2.0 * h);
                let a_fd = (r.eval(t + h)[1] - r.eval(t - h)[1]) / (2.0 * h);
                assert!((v - v_fd).abs() < 1e-6 * v.abs().max(1e-3), "{r:?} v at {t}");
                assert!((a - a_fd).abs() < 1e-5 * a.abs().max(1e-2), "{r:?} a at {t}");
            }
        }
        for r in &refs[1..] {
            assert_eq!(r.eval(5.0), [0.5, 0.0, 0.0]);
            assert!(r.eval(2.09)[0] < 0.5 && r.eval(0.05)[0] == 0.0);
        }
    }
}
