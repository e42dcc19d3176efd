//! Periodic-run metrics: the least-squares fundamental fit behind `thz_ripple`.

use crate::laws::cycles::sin_cos_cycles;
use nalgebra::{Const, Matrix3, Vector3, linalg::LU};

/// Least-squares fit of `m + a·sin(2πft) + b·cos(2πft)` to samples `(t, x)`; returns
/// `(m, a, b, rms_residual)`. NaN if there are fewer than 4 samples or the fit is singular.
pub fn fit_fundamental(t: &[f64], x: &[f64], freq: f64) -> (f64, f64, f64, f64) {
    Fundamental::new(t, freq).fit(x)
}

/// The sine and cosine of the fundamental at a set of sample times, and the normal matrix
/// of the fit (it depends on the times only), computed once for fitting several signals
/// sampled at those times.
pub struct Fundamental {
    sc: Vec<(f64, f64)>,
    /// LU factors of Σ φ·φᵀ over the samples, φ = (1, sin, cos).
    normal: LU<f64, Const<3>, Const<3>>,
}

impl Fundamental {
    /// The basis at times `t` [s] for frequency `freq` [Hz].
    pub fn new(t: &[f64], freq: f64) -> Self {
        Self::from_basis(t.iter().map(|&tk| sin_cos_cycles(freq * tk)).collect())
    }

    /// The basis at `n` samples `t_k = t0 + k/(freq·per_cycle)` [s], `per_cycle` to a cycle
    /// of `freq` [Hz]: the values repeat every cycle, so one cycle's are computed.
    pub fn uniform(t0: f64, freq: f64, per_cycle: usize, n: usize) -> Self {
        let p0 = freq * t0;
        let cycle: Vec<(f64, f64)> = (0..per_cycle.max(1))
            .map(|j| sin_cos_cycles(p0 + j as f64 / per_cycle.max(1) as f64))
            .collect();
        Self::from_basis(cycle.iter().copied().cycle().take(n).collect())
    }

    fn from_basis(sc: Vec<(f64, f64)>) -> Self {
        let mut g = Matrix3::<f64>::zeros();
        for &(s, c) in &sc {
            let phi = Vector3::new(1.0, s, c);
            g += phi * phi.transpose();
        }
        Self { sc, normal: g.lu() }
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
        let mut r = Vector3::<f64>::zeros();
        for (&(s, c), &xk) in self.sc.iter().zip(x) {
            r += Vector3::new(1.0, s, c) * (xk - xm);
        }
        let Some(sol) = self.normal.solve(&r) else {
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

    /// The uniform-grid basis (one cycle computed, then repeated) fits as the basis built
    /// from every sample time does, over whole and part cycles, from a start that is not
    /// on a cycle boundary (measured: 6.7e-16 of the amplitude).
    #[test]
    fn the_uniform_grid_basis_fits_as_the_general_one() {
        let (f, spc, t0) = (50.0, 128, 0.013_7);
        let mut worst: f64 = 0.0;
        for n in [spc * 5, spc * 3 + 17] {
            let t: Vec<f64> = (0..n).map(|k| t0 + k as f64 / (f * spc as f64)).collect();
            let x: Vec<f64> = t
                .iter()
                .map(|&t| 0.4 + 2.0 * (TAU * f * t + 0.3).sin() + 0.2 * (2.0 * TAU * f * t).cos())
                .collect();
            let (a, b) =
                (Fundamental::new(&t, f).fit(&x), Fundamental::uniform(t0, f, spc, n).fit(&x));
            for (p, q) in [(a.0, b.0), (a.1, b.1), (a.2, b.2), (a.3, b.3)] {
                worst = worst.max((p - q).abs() / 2.0);
            }
        }
        assert!(worst < 7e-15, "largest difference ÷ amplitude {worst:e}");
    }
}
