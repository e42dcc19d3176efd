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
    }
}
