//! Uncertainty from the Jacobian at the optimum: the covariance `σ²·(JᵀJ)⁻¹` with
//! `σ² = RSS/(n − p)`, standard errors, 95 % intervals and the correlation matrix.
//!
//! The Jacobian's columns are scaled to unit norm first, so the conditioning measured is
//! that of the parameters' *effects*, not of their units. Directions whose scaled singular
//! value falls below [`SINGULAR_TOLERANCE`] of the largest carry no usable information:
//! the parameters that load on them get no standard error and are reported as undetermined.

use crate::student_t::t975;
use nalgebra::DMatrix;

/// Relative singular value (of the column-scaled Jacobian) below which a direction counts
/// as unidentifiable: the information matrix then has a condition number above 1e16.
pub const SINGULAR_TOLERANCE: f64 = 1e-8;

/// Share of a parameter's (scaled) variance direction lying in the unidentifiable
/// subspace above which the parameter is called undetermined by near-singularity.
const NULL_SHARE: f64 = 0.01;

/// Covariance summary of a fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Covariance {
    /// Standard error per parameter (`None` where the information is singular).
    pub std_error: Vec<Option<f64>>,
    /// Correlation matrix (`None` entries where undefined).
    pub correlation: Vec<Vec<Option<f64>>>,
    /// Whether each parameter loads on a near-singular direction.
    pub singular: Vec<bool>,
    /// Residual standard deviation σ = √(RSS/(n − p)).
    pub sigma: f64,
    /// Degrees of freedom n − p.
    pub dof: usize,
    /// Half-width factor of a 95 % interval (Student's t, 97.5 % quantile).
    pub t95: f64,
    /// Euclidean norm of each Jacobian column [N·m per unit of the parameter].
    pub column_norms: Vec<f64>,
}

impl Covariance {
    /// Covariance entry (i, j) = correlation·se_i·se_j, where defined.
    pub fn entry(&self, i: usize, j: usize) -> Option<f64> {
        Some(self.correlation[i][j]? * self.std_error[i]? * self.std_error[j]?)
    }
}

/// Covariance of the parameters whose model sensitivities are the columns `jac` (each of
/// length n, ∂prediction/∂parameter), given the residual sum of squares `rss`.
pub fn covariance(jac: &[Vec<f64>], rss: f64) -> Covariance {
    let n = jac.first().map_or(0, Vec::len);
    let mut row = vec![0.0; jac.len()];
    covariance_rows(jac.len(), n, rss, &mut |f: &mut dyn FnMut(&[f64])| {
        for i in 0..n {
            for (x, col) in row.iter_mut().zip(jac) {
                *x = col[i];
            }
            f(&row);
        }
        Ok(())
    })
    .expect("rows from columns never fail")
}

/// Hands each row of the Jacobian (p values) to the callback, in order; may be called
/// more than once.
pub type RowSource<'a> =
    dyn FnMut(&mut dyn FnMut(&[f64])) -> Result<(), crate::error::FitError> + 'a;

/// [`covariance`] from a Jacobian of `p` columns and `n` rows that is streamed row by row
/// (twice: once for the column norms, once into the QR factor), so that no column is
/// held: for records of millions of samples.
pub fn covariance_rows(
    p: usize,
    n: usize,
    rss: f64,
    rows: &mut RowSource,
) -> Result<Covariance, crate::error::FitError> {
    let dof = n.saturating_sub(p);
    let sigma = if dof > 0 { (rss / dof as f64).sqrt() } else { f64::NAN };
    let mut sq = vec![0.0; p];
    rows(&mut |r: &[f64]| sq.iter_mut().zip(r).for_each(|(s, v)| *s += v * v))?;
    let norms: Vec<f64> = sq.iter().map(|s| s.sqrt()).collect();
    let mut out = Covariance {
        std_error: vec![None; p],
        correlation: vec![vec![None; p]; p],
        singular: vec![true; p],
        sigma,
        dof,
        t95: t975(dof),
        column_norms: norms.clone(),
    };
    if p == 0 || n < p {
        return Ok(out);
    }
    // R of the column-scaled Jacobian, accumulated in blocks (no n×p copy).
    let mut qr = crate::qr_stream::StreamingQr::new(p);
    let mut scaled = vec![0.0; p];
    rows(&mut |r: &[f64]| {
        for ((x, v), norm) in scaled.iter_mut().zip(r).zip(&norms) {
            *x = if *norm > 0.0 { v / norm } else { 0.0 };
        }
        qr.push(&scaled);
    })?;
    let r = qr.finish();
    // A non-finite Jacobian (a simulation that broke down near the result) determines
    // nothing: every parameter is left without a standard error.
    let Some(svd) = crate::linear::bounded_svd(r, false, true) else { return Ok(out) };
    let Some(vt) = svd.v_t else { return Ok(out) };
    let s = &svd.singular_values;
    let smax = s.max();
    // Scaled covariance over the informative directions.
    let mut cov_s = DMatrix::<f64>::zeros(p, p);
    let mut null_share = vec![0.0; p];
    for k in 0..p {
        let v = vt.row(k);
        if s[k] > SINGULAR_TOLERANCE * smax && s[k] > 0.0 {
            let w = 1.0 / (s[k] * s[k]);
            for a in 0..p {
                for b in 0..p {
                    cov_s[(a, b)] += w * v[a] * v[b];
                }
            }
        } else {
            for a in 0..p {
                null_share[a] += v[a] * v[a];
            }
        }
    }
    for a in 0..p {
        out.singular[a] = norms[a] == 0.0 || null_share[a] > NULL_SHARE;
        if !out.singular[a] {
            out.std_error[a] = Some(sigma * cov_s[(a, a)].sqrt() / norms[a]);
        }
    }
    for a in 0..p {
        for b in 0..p {
            if !out.singular[a] && !out.singular[b] {
                let c = cov_s[(a, b)] / (cov_s[(a, a)] * cov_s[(b, b)]).sqrt();
                out.correlation[a][b] = Some(c.clamp(-1.0, 1.0));
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_line_standard_errors() {
        // y = b0 + b1·x with known residual: compare with the textbook formulas.
        let x: Vec<f64> = (0..20).map(|i| i as f64).collect();
        let ones = vec![1.0; 20];
        let rss = 18.0; // σ² = 1
        let c = covariance(&[ones, x.clone()], rss);
        let n = 20.0;
        let mean = x.iter().sum::<f64>() / n;
        let sxx: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
        let se_slope = (1.0 / sxx).sqrt();
        let se_icpt = (1.0 / n + mean * mean / sxx).sqrt();
        assert!((c.std_error[1].unwrap() - se_slope).abs() < 1e-12);
        assert!((c.std_error[0].unwrap() - se_icpt).abs() < 1e-12);
        let r = c.correlation[0][1].unwrap();
        assert!((r + mean / (sxx / n + mean * mean).sqrt()).abs() < 1e-12);
    }

    /// A NaN or an infinite sensitivity gives no standard error, at once (the SVD it
    /// would have run loops for minutes on such a matrix).
    #[test]
    fn non_finite_jacobian_determines_nothing() {
        let x: Vec<f64> = (0..20).map(|i| i as f64).collect();
        for bad in [f64::NAN, f64::INFINITY] {
            let mut y = vec![1.0; 20];
            y[3] = bad;
            let c = covariance(&[x.clone(), y], 3.0);
            assert!(c.singular[1] && c.std_error[1].is_none(), "{c:?}");
        }
    }

    #[test]
    fn duplicate_columns_are_singular() {
        let x: Vec<f64> = (0..20).map(|i| i as f64).collect();
        let c = covariance(&[x.clone(), x.iter().map(|v| 2.0 * v).collect(), vec![1.0; 20]], 3.0);
        assert!(c.singular[0] && c.singular[1] && !c.singular[2]);
        assert!(c.std_error[0].is_none());
    }
}
