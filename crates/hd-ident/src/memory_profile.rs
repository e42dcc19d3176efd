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
        let (mut z, mut h_last, mut factors) = (0.0f64, f64::NAN, (1.0, 1.0));
        for i in 0..t.len() {
            if i > 0 {
                let h = t[i] - t[i - 1];
                if h != h_last {
                    factors = m.step_factors(h);
                    h_last = h;
                }
                z = m.step_with(z, theta[i] - theta[i - 1], factors.0, factors.1);
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
}
