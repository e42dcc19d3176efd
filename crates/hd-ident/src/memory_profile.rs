//! The hysteresis fit's profile cost RSS(B) in one streaming pass per trial, with no
//! column held in memory.
//!
//! Of the model's columns only the memory ζ (unit intensity) depends on B; the spring's
//! θ³, θ², θ (and the offset's 1) do not. So the QR factor of `[θ³ θ² θ (1) | y]` is
//! computed once ([`StreamingQr`]): `R₀`, `c_f = Q₀ᵀy` and the residual `rss_f` of the
//! spring alone. For a trial B one pass runs ζ along the record and accumulates
//! `u = Xᵀζ`, `ζᵀζ` and `ζᵀy`; bordering R₀ with ζ's column then gives
//! `r = R₀⁻ᵀu`, `ρ = √(ζᵀζ − rᵀr)`, `c_ζ = (ζᵀy − rᵀc_f)/ρ` and
//! `RSS = rss_f − c_ζ²` without bounds; with them, the bounded solve runs on the bordered
//! (k+1)-row triangular system, whose residual differs from the full one by that
//! constant. Where this is not safe (the spring's columns or ζ nearly dependent) the
//! caller falls back to the full bounded solve.

use crate::linear::bounded_least_squares;
use crate::qr_stream::StreamingQr;
use hd_model::laws::stiffness::FadingMemory;
use nalgebra::{DMatrix, DVector};

/// Smallest accepted ratio of singular values of the column-scaled spring factor, and
/// of ρ² to ζᵀζ: below it the bordered solve would lose more digits than the full one.
const MIN_INDEPENDENCE: f64 = 1e-8;

/// Whether the sample interval `h` [s] ending at time `t` [s] equals `h_last` to within the
/// rounding of the time stamps (4 ulps of t, 8 of h): a uniformly sampled record's
/// differences vary by that much, and then share one set of step factors. The factors'
/// change over such a difference is no larger than their uncertainty from the stamps.
#[inline]
pub(crate) fn same_interval(h: f64, h_last: f64, t: f64) -> bool {
    (h - h_last).abs() <= 4.0 * f64::EPSILON * t.abs() + 8.0 * f64::EPSILON * h
}

/// A fading-memory law's step factors for the latest sample interval, recomputed only when
/// the interval differs from the previous one beyond the stamps' rounding
/// ([`same_interval`]): a uniformly sampled record pays for them once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SharedFactors<F: Copy> {
    h: f64,
    factors: F,
}

impl<F: Copy> SharedFactors<F> {
    /// No interval seen yet; `placeholder` is never returned.
    pub(crate) fn new(placeholder: F) -> Self {
        Self { h: f64::NAN, factors: placeholder }
    }

    /// The factors for interval `h` [s] ending at time `t` [s], from `compute` when `h` is
    /// a new interval.
    #[inline]
    pub(crate) fn at(&mut self, h: f64, t: f64, compute: impl FnOnce(f64) -> F) -> F {
        if !same_interval(h, self.h, t) {
            self.factors = compute(h);
            self.h = h;
        }
        self.factors
    }

    /// The interval the factors belong to [s].
    pub(crate) fn interval(&self) -> f64 {
        self.h
    }
}

/// The spring part of the hysteresis design, factorised once.
pub struct MemoryProfile {
    offset: bool,
    r0: DMatrix<f64>,
    c_f: DVector<f64>,
    rss_f: f64,
    usable: bool,
}

/// The spring's columns at deflection θ [rad] (θ³, θ², θ and, with an offset, 1).
#[inline]
fn spring_row(th: f64, offset: bool, row: &mut [f64]) {
    row[0] = th * th * th;
    row[1] = th * th;
    row[2] = th;
    if offset {
        row[3] = 1.0;
    }
}

impl MemoryProfile {
    /// Factorise the spring's columns and the measured torque `y` [N·m].
    pub fn new(theta: &[f64], y: &[f64], offset: bool) -> Self {
        let k = 3 + usize::from(offset);
        let mut qr = StreamingQr::new(k + 1);
        let mut row = vec![0.0; k + 1];
        for (&th, &yi) in theta.iter().zip(y) {
            spring_row(th, offset, &mut row);
            row[k] = yi;
            qr.push(&row);
        }
        let r = qr.finish();
        let r0 = r.view((0, 0), (k, k)).into_owned();
        let c_f = r.view((0, k), (k, 1)).column(0).into_owned();
        let rss_f = r[(k, k)] * r[(k, k)];
        // Independence of the spring's columns, scaled to unit norm.
        let norms: Vec<f64> = (0..k).map(|j| r0.column(j).norm()).collect();
        let usable = norms.iter().all(|n| *n > 0.0 && n.is_finite()) && {
            let scaled = DMatrix::from_fn(k, k, |i, j| r0[(i, j)] / norms[j]);
            let s = scaled.singular_values();
            s.min() > MIN_INDEPENDENCE * s.max()
        };
        Self { offset, r0, c_f, rss_f, usable }
    }

    /// RSS [N·m²], the coefficients (a, b, c, A and the offset, in the hysteresis fit's
    /// order, each within `[lo, hi]`) and which of them sit at a bound, at decay rate `b`
    /// [1/s]; `None` where the caller should solve in full (the design is nearly
    /// singular).
    pub fn at(
        &self,
        t: &[f64],
        theta: &[f64],
        y: &[f64],
        b: f64,
        lo: &[f64],
        hi: &[f64],
    ) -> Option<(f64, Vec<f64>, Vec<bool>)> {
        if !self.usable {
            return None;
        }
        let k = 3 + usize::from(self.offset);
        let m = FadingMemory { a: 1.0, b };
        let (mut u, mut zz, mut zy) = ([0.0f64; 4], 0.0, 0.0);
        let mut row = [0.0f64; 4];
        let (mut z, mut shared) = (0.0f64, SharedFactors::new((1.0, 1.0)));
        for i in 0..t.len() {
            if i > 0 {
                let (decay, gain) = shared.at(t[i] - t[i - 1], t[i], |h| m.step_factors(h));
                z = m.step_with(z, theta[i] - theta[i - 1], decay, gain);
            }
            spring_row(theta[i], self.offset, &mut row);
            for j in 0..k {
                u[j] += row[j] * z;
            }
            zz += z * z;
            zy += z * y[i];
        }
        let u = DVector::from_column_slice(&u[..k]);
        let r = self.r0.transpose().solve_lower_triangular(&u)?;
        let rho2 = zz - r.norm_squared();
        if rho2.is_nan() || rho2 <= MIN_INDEPENDENCE * zz {
            return None;
        }
        let rho = rho2.sqrt();
        let c_z = (zy - r.dot(&self.c_f)) / rho;
        // Beyond the bordered factor, the residual of y is rss_f − c_ζ²; within it the
        // coefficients solve R̃β ≈ c̃ under their bounds (a (k+1)-row problem, solved by
        // the same bounded solver as the full one).
        let beyond = (self.rss_f - c_z * c_z).max(0.0);
        let m = k + 1;
        let mut rt = DMatrix::<f64>::zeros(m, m);
        rt.view_mut((0, 0), (k, k)).copy_from(&self.r0);
        rt.view_mut((0, k), (k, 1)).copy_from(&r);
        rt[(k, k)] = rho;
        let mut ct: Vec<f64> = self.c_f.iter().copied().collect();
        ct.push(c_z);
        // The fit's order: a, b, c (θ³, θ², θ), A (ζ, last in R̃), then the offset.
        let order: Vec<usize> = if self.offset { vec![0, 1, 2, k, 3] } else { vec![0, 1, 2, k] };
        let cols: Vec<Vec<f64>> =
            order.iter().map(|&j| rt.column(j).iter().copied().collect()).collect();
        let refs: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
        let sol = bounded_least_squares(&refs, &ct, lo, hi);
        let rss = sol.rss + beyond;
        rss.is_finite().then_some((rss, sol.coef, sol.at_bound))
    }

    /// [`MemoryProfile::at`] without the bordered shortcut, for the trials where it is
    /// unsafe: the QR factor of the whole design `[θ³ θ² θ ζ (1) | y]` accumulated in
    /// blocks (as stable as one QR of the whole matrix, and still holding no column),
    /// then the bounded solve on its triangle. `None` only where the RSS is not finite.
    pub fn at_full(
        &self,
        t: &[f64],
        theta: &[f64],
        y: &[f64],
        b: f64,
        lo: &[f64],
        hi: &[f64],
    ) -> Option<(f64, Vec<f64>, Vec<bool>)> {
        let k = 3 + usize::from(self.offset);
        let m = FadingMemory { a: 1.0, b };
        // Row: the fit's order a, b, c (θ³, θ², θ), A (ζ), then the offset; y last.
        let mut qr = StreamingQr::new(k + 2);
        let mut row = [0.0f64; 6];
        let (mut z, mut shared) = (0.0f64, SharedFactors::new((1.0, 1.0)));
        for i in 0..t.len() {
            if i > 0 {
                let (decay, gain) = shared.at(t[i] - t[i - 1], t[i], |h| m.step_factors(h));
                z = m.step_with(z, theta[i] - theta[i - 1], decay, gain);
            }
            let th = theta[i];
            row[..4].copy_from_slice(&[th * th * th, th * th, th, z]);
            if self.offset {
                row[4] = 1.0;
            }
            row[k + 1] = y[i];
            qr.push(&row[..k + 2]);
        }
        let r = qr.finish();
        let cols: Vec<Vec<f64>> = (0..=k).map(|j| r.column(j).iter().copied().collect()).collect();
        let refs: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
        let rhs: Vec<f64> = r.column(k + 1).iter().copied().collect();
        let sol = bounded_least_squares(&refs, &rhs, lo, hi);
        // The triangle's last row (y's part beyond the design) is in the solve's RSS.
        let rss = sol.rss;
        rss.is_finite().then_some((rss, sol.coef, sol.at_bound))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bordered shortcut and the streamed full factor give the bounded solve of the
    /// explicit columns.
    #[test]
    fn shortcut_and_full_factor_match_the_explicit_solve() {
        let n = 3000;
        let t: Vec<f64> = (0..n).map(|k| 1e-3 * k as f64).collect();
        let th: Vec<f64> =
            t.iter().map(|&t| 1e-3 * (7.0 * t).sin() + 4e-4 * (41.0 * t).sin()).collect();
        let b = 60.0;
        let m = FadingMemory { a: 1.0, b };
        let mut zeta = vec![0.0; n];
        for k in 1..n {
            zeta[k] = m.step_linear(zeta[k - 1], th[k] - th[k - 1], t[k] - t[k - 1]);
        }
        let y: Vec<f64> = (0..n)
            .map(|k| 5e4 * th[k] + 3e4 * zeta[k] + 0.3 + 0.05 * (1.9 * k as f64).sin())
            .collect();
        let cols: Vec<Vec<f64>> = vec![
            th.iter().map(|v| v * v * v).collect(),
            th.iter().map(|v| v * v).collect(),
            th.clone(),
            zeta,
            vec![1.0; n],
        ];
        let refs: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
        let (lo, hi) = ([f64::NEG_INFINITY; 5], [f64::INFINITY; 5]);
        let want = bounded_least_squares(&refs, &y, &lo, &hi);
        let p = MemoryProfile::new(&th, &y, true);
        for (rss, coef, _) in
            [p.at(&t, &th, &y, b, &lo, &hi).unwrap(), p.at_full(&t, &th, &y, b, &lo, &hi).unwrap()]
        {
            assert!((rss - want.rss).abs() <= 1e-9 * want.rss, "{rss} vs {}", want.rss);
            for (a, w) in coef.iter().zip(&want.coef).skip(2) {
                assert!((a - w).abs() <= 1e-7 * w.abs(), "{coef:?} vs {:?}", want.coef);
            }
        }
    }
}
