//! Periodic-run metrics: the least-squares fundamental fit behind `thz_ripple`.

use crate::laws::cycles::sin_cos_cycles;
use nalgebra::{Matrix3, Vector3};

/// Least-squares fit of `m + a·sin(2πft) + b·cos(2πft)` to samples `(t, x)`; returns
/// `(m, a, b, rms_residual)`. NaN if there are fewer than 4 samples or the fit is singular.
pub fn fit_fundamental(t: &[f64], x: &[f64], freq: f64) -> (f64, f64, f64, f64) {
    Fundamental::new(t, freq).fit(x)
}

/// The sine and cosine of the fundamental at a set of sample times, computed once for
/// fitting several signals sampled at those times.
pub struct Fundamental {
    sc: Vec<(f64, f64)>,
}

impl Fundamental {
    /// The basis at times `t` [s] for frequency `freq` [Hz].
    pub fn new(t: &[f64], freq: f64) -> Self {
        Self { sc: t.iter().map(|&tk| sin_cos_cycles(freq * tk)).collect() }
    }

    /// [`fit_fundamental`] of `x`, sampled at this basis' times.
    pub fn fit(&self, x: &[f64]) -> (f64, f64, f64, f64) {
        let n = self.sc.len();
        let nan = (f64::NAN, f64::NAN, f64::NAN, f64::NAN);
        if n < 4 || x.len() != n {
            return nan;
        }
        // Normal equations in a 3×3 system, centred on the mean of x for conditioning.
        let xm = x.iter().sum::<f64>() / n as f64;
        let mut g = Matrix3::<f64>::zeros();
        let mut r = Vector3::<f64>::zeros();
        for (&(s, c), &xk) in self.sc.iter().zip(x) {
            let phi = Vector3::new(1.0, s, c);
            g += phi * phi.transpose();
            r += phi * (xk - xm);
        }
        let Some(sol) = g.lu().solve(&r) else {
            return nan;
        };
        let (m, a, b) = (sol[0] + xm, sol[1], sol[2]);
        let mut ss = 0.0;
        for (&(s, c), &xk) in self.sc.iter().zip(x) {
            let e = xk - m - a * s - b * c;
            ss += e * e;
        }
        (m, a, b, (ss / n as f64).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn recovers_mean_fundamental_and_a_known_harmonic_ripple() {
        let f = 50.0;
        let t: Vec<f64> = (0..2560).map(|k| k as f64 * 5.0 / f / 2560.0).collect();
        // Ripple: third harmonic of amplitude 0.1 → RMS 0.1/√2.
        let x: Vec<f64> = t
            .iter()
            .map(|&t| {
                2.0 + 3.0 * (TAU * f * t).sin() - 1.5 * (TAU * f * t).cos()
                    + 0.1 * (3.0 * TAU * f * t).sin()
            })
            .collect();
        let (m, a, b, rms) = fit_fundamental(&t, &x, f);
        assert!((m - 2.0).abs() < 1e-12 && (a - 3.0).abs() < 1e-12 && (b + 1.5).abs() < 1e-12);
        assert!((rms - 0.1 / 2f64.sqrt()).abs() < 1e-12, "{rms}");
    }
}
