//! Analytic excitation signals for synthetic experiments.

use crate::path::Signal;
use std::f64::consts::TAU;

/// `x(t) = Σ_k (amplitude/K)·sin(2π·f_k·t)`: K sines of equal amplitude, all starting at
/// zero; their beats sweep the peak through many levels up to `amplitude`.
#[derive(Clone, Debug, PartialEq)]
pub struct SumOfSines {
    /// Peak bound [signal unit].
    pub amplitude: f64,
    /// Frequencies [Hz].
    pub frequencies: Vec<f64>,
}

impl Signal for SumOfSines {
    fn at(&self, t: f64) -> [f64; 3] {
        let a = self.amplitude / self.frequencies.len().max(1) as f64;
        let mut out = [0.0; 3];
        for &f in &self.frequencies {
            let w = TAU * f;
            let (s, c) = (w * t).sin_cos();
            out[0] += a * s;
            out[1] += a * w * c;
            out[2] -= a * w * w * s;
        }
        out
    }
}

/// A quasi-static stiffness test: for each frequency in turn, `cycles` whole cycles of
/// `x(t) = level·amplitude·sin(2π·f·t)` at each level, starting and ending every block at 0
/// (the amplitude steps between blocks; the slope jumps, the deflection does not).
#[derive(Clone, Debug, PartialEq)]
pub struct QuasiStatic {
    /// Rated (largest) amplitude [signal unit].
    pub amplitude: f64,
    /// Levels as shares of the amplitude, in order [–]; default 0.25, 0.5, 1.
    pub levels: Vec<f64>,
    /// Frequencies [Hz], in order; default 0.02 and 0.2.
    pub frequencies: Vec<f64>,
    /// Whole cycles per block; default 1.
    pub cycles: usize,
}

impl Default for QuasiStatic {
    fn default() -> Self {
        Self {
            amplitude: 1e-3,
            levels: vec![0.25, 0.5, 1.0],
            frequencies: vec![0.02, 0.2],
            cycles: 1,
        }
    }
}

impl QuasiStatic {
    /// The blocks in order: (start time [s], amplitude, frequency [Hz]).
    fn blocks(&self) -> Vec<(f64, f64, f64)> {
        let mut t = 0.0;
        let mut out = Vec::new();
        for &f in &self.frequencies {
            for &l in &self.levels {
                out.push((t, l * self.amplitude, f));
                t += self.cycles as f64 / f;
            }
        }
        out
    }

    /// Total duration [s].
    pub fn duration(&self) -> f64 {
        self.frequencies.iter().map(|f| self.cycles as f64 * self.levels.len() as f64 / f).sum()
    }
}

impl Signal for QuasiStatic {
    fn at(&self, t: f64) -> [f64; 3] {
        let blocks = self.blocks();
        let Some(&(t0, a, f)) = blocks.iter().rev().find(|b| b.0 <= t) else {
            return [0.0; 3];
        };
        if t >= self.duration() {
            return [0.0; 3];
        }
        let w = TAU * f;
        let (s, c) = (w * (t - t0)).sin_cos();
        [a * s, a * w * c, -a * w * w * s]
    }
}

/// `x(t) = e(t)·sin(2π·f·t)` with a geometric envelope `e(t) = peak·10^{−decades·(1 − t/T)}`
/// that grows from `peak·10^{−decades}` at t = 0 to `peak` at t = T.
#[derive(Clone, Debug, PartialEq)]
pub struct GrowingSine {
    /// Final amplitude [signal unit].
    pub peak: f64,
    /// Frequency [Hz].
    pub frequency: f64,
    /// Decades of growth over the record [–].
    pub decades: f64,
    /// Record length T [s].
    pub duration: f64,
}

impl Signal for GrowingSine {
    fn at(&self, t: f64) -> [f64; 3] {
        let k = self.decades * std::f64::consts::LN_10 / self.duration;
        let e = self.peak * (-k * (self.duration - t)).exp();
        let (de, dde) = (k * e, k * k * e);
        let w = TAU * self.frequency;
        let (s, c) = (w * t).sin_cos();
        [e * s, de * s + e * w * c, dde * s + 2.0 * de * w * c - e * w * w * s]
    }
}

/// A joint friction test as rigs run it: the speed steps through plateaus at log-spaced
/// levels from `omega_min` to `omega_max`, each level held first forwards and then
/// backwards, joined by smooth raised-cosine transitions (so every reversal passes
/// slowly through zero, where the bristles' pre-sliding shows). Starts and ends at rest.
#[derive(Clone, Debug, PartialEq)]
pub struct PlateauProfile {
    /// Slowest plateau speed [rad/s].
    pub omega_min: f64,
    /// Fastest plateau speed [rad/s].
    pub omega_max: f64,
    /// Number of levels.
    pub levels: usize,
    /// Time held at each plateau [s].
    pub dwell: f64,
    /// Duration of each transition [s].
    pub transition: f64,
}

impl PlateauProfile {
    /// The plateau speeds in order: +v1, −v1, +v2, −v2, …
    fn targets(&self) -> Vec<f64> {
        let m = self.levels.max(1);
        let ratio =
            if m > 1 { (self.omega_max / self.omega_min).ln() / (m - 1) as f64 } else { 0.0 };
        (0..m)
            .flat_map(|k| {
                let v = self.omega_min * (ratio * k as f64).exp();
                [v, -v]
            })
            .collect()
    }

    /// Total duration [s]: every plateau with its incoming transition, and a final
    /// transition back to rest.
    pub fn duration(&self) -> f64 {
        self.targets().len() as f64 * (self.dwell + self.transition) + self.transition
    }
}

impl Signal for PlateauProfile {
    fn at(&self, t: f64) -> [f64; 3] {
        let targets = self.targets();
        let period = self.dwell + self.transition;
        let k = (t.max(0.0) / period).floor() as usize;
        let (from, to) = match k {
            0 => (0.0, targets[0]),
            k if k < targets.len() => (targets[k - 1], targets[k]),
            _ => (targets[targets.len() - 1], 0.0),
        };
        let tau = t - k as f64 * period;
        if k > targets.len() || tau >= self.transition {
            let held = if k >= targets.len() && tau >= self.transition { 0.0 } else { to };
            return [held, 0.0, 0.0];
        }
        let w = std::f64::consts::PI / self.transition;
        let (s, c) = (w * tau).sin_cos();
        let d = to - from;
        [from + d * (1.0 - c) / 2.0, d * w * s / 2.0, d * w * w * c / 2.0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_derivatives(sig: &dyn Signal, t: f64, scale: f64) {
        let h = 1e-7;
        let [_, d, dd] = sig.at(t);
        let num_d = (sig.at(t + h)[0] - sig.at(t - h)[0]) / (2.0 * h);
        let num_dd = (sig.at(t + h)[1] - sig.at(t - h)[1]) / (2.0 * h);
        assert!((d - num_d).abs() < 1e-6 * scale, "{d} vs {num_d}");
        assert!((dd - num_dd).abs() < 1e-4 * scale * 1e3, "{dd} vs {num_dd}");
    }

    #[test]
    fn derivatives_are_consistent() {
        let s = SumOfSines { amplitude: 1.0, frequencies: vec![3.0, 47.0] };
        check_derivatives(&s, 0.0123, 300.0);
        let g = GrowingSine { peak: 1.0, frequency: 50.0, decades: 2.0, duration: 0.1 };
        check_derivatives(&g, 0.0377, 300.0);
        let p = PlateauProfile {
            omega_min: 0.01,
            omega_max: 1.0,
            levels: 3,
            dwell: 0.2,
            transition: 0.05,
        };
        check_derivatives(&p, 0.27, 100.0);
        check_derivatives(&p, 0.51, 100.0);
    }

    #[test]
    fn quasi_static_blocks_step_the_amplitude() {
        let q = QuasiStatic::default();
        assert!((q.duration() - 165.0).abs() < 1e-12);
        check_derivatives(&q, 12.3, 1e-3);
        // Peak of the first block (0.25·1e-3 at t = 12.5 s) and of the last (1e-3).
        assert!((q.at(12.5)[0] - 2.5e-4).abs() < 1e-15);
        assert!((q.at(160.0 + 1.25)[0] - 1e-3).abs() < 1e-15);
    }

    #[test]
    fn plateaus_hold_their_levels_and_end_at_rest() {
        let p = PlateauProfile {
            omega_min: 0.01,
            omega_max: 1.0,
            levels: 3,
            dwell: 0.2,
            transition: 0.05,
        };
        assert_eq!(p.at(0.0)[0], 0.0);
        assert!((p.at(0.1)[0] - 0.01).abs() < 1e-15);
        assert!((p.at(0.35)[0] + 0.01).abs() < 1e-15);
        assert!((p.at(1.4)[0] + 1.0).abs() < 1e-15);
        assert!((p.duration() - 1.55).abs() < 1e-12);
        assert!(p.at(p.duration() - 1e-9)[0].abs() < 1e-6);
        // Continuous at every segment boundary.
        for k in 1..7 {
            let tb = k as f64 * 0.25;
            assert!((p.at(tb - 1e-12)[0] - p.at(tb + 1e-12)[0]).abs() < 1e-9, "at {tb}");
        }
    }
}
