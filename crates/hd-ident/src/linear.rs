//! Linear least squares with column scaling and simple bounds: the inner problem of every
//! separable fit (the model is linear in all parameters but one).

use nalgebra::{DMatrix, DVector, Dyn, SVD, SymmetricEigen};

/// Largest number of iterations of an SVD or symmetric eigen-decomposition of a matrix
/// whose smaller side is `n` [–]: a finite matrix converges in a few `n`; LAPACK's limit is
/// 6·n², this is five times that, plus a floor for tiny matrices.
pub fn max_iterations(n: usize) -> usize {
    1_000 + 30 * n * n
}

/// Whether every entry of `m` is finite.
pub fn all_finite(m: &DMatrix<f64>) -> bool {
    m.iter().all(|v| v.is_finite())
}

/// The SVD of `m`, or None when `m` holds a NaN or an infinity (on which nalgebra's
/// iteration never converges: it runs for minutes at full CPU) or when it has not
/// converged within [`max_iterations`].
pub fn bounded_svd(m: DMatrix<f64>, u: bool, v: bool) -> Option<SVD<f64, Dyn, Dyn>> {
    if !all_finite(&m) {
        return None;
    }
    let n = m.nrows().min(m.ncols());
    m.try_svd(u, v, f64::EPSILON, max_iterations(n))
}

/// The eigen-decomposition of the symmetric matrix `m`, refused as [`bounded_svd`] is.
pub fn bounded_symmetric_eigen(m: DMatrix<f64>) -> Option<SymmetricEigen<f64, Dyn>> {
    if !all_finite(&m) || m.nrows() != m.ncols() {
        return None;
    }
    let n = m.nrows();
    m.try_symmetric_eigen(f64::EPSILON, max_iterations(n))
}

/// Relative singular-value cutoff below which a direction of the scaled design counts as
/// having no information (the solve then returns the minimum-norm solution).
pub const RANK_TOLERANCE: f64 = 1e-12;

/// Solution of a bounded linear least-squares problem.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearSolution {
    /// Coefficients, one per column.
    pub coef: Vec<f64>,
    /// Residual sum of squares ‖y − X·β‖².
    pub rss: f64,
    /// Whether each coefficient was held at one of its bounds.
    pub at_bound: Vec<bool>,
}

/// Minimise ‖y − Σ β_j·col_j‖² without bounds. Columns are scaled to unit norm before a
/// QR factorisation and an SVD of the small triangular factor, so columns of very
/// different size (θ³ next to θ) and nearly dependent columns are handled; an all-zero
/// column gets coefficient 0.
pub fn least_squares(cols: &[&[f64]], y: &[f64]) -> Vec<f64> {
    let n = y.len();
    let norms: Vec<f64> =
        cols.iter().map(|c| c.iter().map(|v| v * v).sum::<f64>().sqrt()).collect();
    let used: Vec<usize> =
        (0..cols.len()).filter(|&j| norms[j] > 0.0 && norms[j].is_finite()).collect();
    let mut coef = vec![0.0; cols.len()];
    if used.is_empty() || n == 0 {
        return coef;
    }
    let k = used.len();
    let x = DMatrix::from_fn(n, k, |i, j| cols[used[j]][i] / norms[used[j]]);
    let qr = x.qr();
    let mut qty = DVector::from_column_slice(y);
    qr.q_tr_mul(&mut qty);
    let r = qr.r();
    let rhs = qty.rows(0, k).into_owned();
    // A non-finite design (or one that does not converge) has no least-squares answer:
    // every coefficient 0, as for an all-zero design.
    let Some(svd) = bounded_svd(r, true, true) else { return coef };
    let smax = svd.singular_values.max();
    let beta = svd.solve(&rhs, RANK_TOLERANCE * smax).unwrap_or_else(|_| DVector::zeros(k));
    for (j, &col) in used.iter().enumerate() {
        coef[col] = beta[j] / norms[col];
    }
    coef
}

/// Residual sum of squares of `y − Σ β_j·col_j`.
pub fn rss(cols: &[&[f64]], coef: &[f64], y: &[f64]) -> f64 {
    (0..y.len())
        .map(|i| {
            let pred: f64 = cols.iter().zip(coef).map(|(c, b)| b * c[i]).sum();
            let r = y[i] - pred;
            r * r
        })
        .sum()
}

/// Minimise ‖y − Σ β_j·col_j‖² subject to `lo[j] ≤ β_j ≤ hi[j]` by an active set: solve
/// without bounds, hold each coefficient that falls outside at the bound it crossed,
/// and solve again for the rest, until all are inside (at most one pass per column).
pub fn bounded_least_squares(cols: &[&[f64]], y: &[f64], lo: &[f64], hi: &[f64]) -> LinearSolution {
    let k = cols.len();
    let mut held: Vec<Option<f64>> = vec![None; k];
    loop {
        let free: Vec<usize> = (0..k).filter(|&j| held[j].is_none()).collect();
        let mut target = y.to_vec();
        for (j, v) in held.iter().enumerate() {
            if let Some(v) = v {
                for (t, c) in target.iter_mut().zip(cols[j]) {
                    *t -= v * c;
                }
            }
        }
        let free_cols: Vec<&[f64]> = free.iter().map(|&j| cols[j]).collect();
        let beta = least_squares(&free_cols, &target);
        let mut violated = false;
        for (f, &j) in free.iter().enumerate() {
            if beta[f] < lo[j] {
                held[j] = Some(lo[j]);
                violated = true;
            } else if beta[f] > hi[j] {
                held[j] = Some(hi[j]);
                violated = true;
            }
        }
        if !violated || free.is_empty() {
            let mut coef = vec![0.0; k];
            for (f, &j) in free.iter().enumerate() {
                coef[j] = beta[f];
            }
            for (j, v) in held.iter().enumerate() {
                if let Some(v) = v {
                    coef[j] = *v;
                }
            }
            let rss = rss(cols, &coef, y);
            return LinearSolution {
                coef,
                rss,
                at_bound: held.iter().map(Option::is_some).collect(),
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_badly_scaled_coefficients() {
        let x: Vec<f64> = (0..200).map(|i| -1e-3 + 1e-5 * i as f64).collect();
        let c1: Vec<f64> = x.iter().map(|v| v * v * v).collect();
        let c2: Vec<f64> = x.clone();
        let y: Vec<f64> = x.iter().map(|v| 3e7 * v * v * v + 5e4 * v).collect();
        let b = least_squares(&[&c1, &c2], &y);
        assert!((b[0] / 3e7 - 1.0).abs() < 1e-9, "{b:?}");
        assert!((b[1] / 5e4 - 1.0).abs() < 1e-12, "{b:?}");
    }

    /// A NaN or an infinity in the design is refused at once (nalgebra's SVD would loop
    /// for minutes on it); a finite matrix decomposes within the iteration bound.
    #[test]
    fn non_finite_matrices_are_refused_quickly() {
        let t0 = std::time::Instant::now();
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut m = DMatrix::from_fn(30, 4, |i, j| (0.1 * (i * (j + 1)) as f64).cos());
            m[(7, 2)] = bad;
            assert!(bounded_svd(m.clone(), true, true).is_none());
            let sym = m.transpose() * &m;
            assert!(bounded_symmetric_eigen(sym).is_none());
            let col: Vec<f64> = m.column(2).iter().copied().collect();
            let ones = vec![1.0; 30];
            let b = least_squares(&[&col, &ones], &ones);
            assert!(b[0] == 0.0 && (b[1] - 1.0).abs() < 1e-12, "{b:?}");
        }
        let m = DMatrix::from_fn(30, 4, |i, j| (0.1 * (i * (j + 1)) as f64).cos());
        let svd = bounded_svd(m.clone(), true, true).unwrap();
        assert!(svd.singular_values.iter().all(|s| *s > 0.0));
        let eig = bounded_symmetric_eigen(m.transpose() * &m).unwrap();
        assert!(eig.eigenvalues.iter().all(|e| *e > 0.0));
        assert!(t0.elapsed().as_secs_f64() < 1.0);
    }

    #[test]
    fn holds_a_coefficient_at_its_bound() {
        let c1: Vec<f64> = (0..50).map(|i| i as f64).collect();
        let c2: Vec<f64> = (0..50).map(|i| ((i as f64) * 0.3).sin()).collect();
        let y: Vec<f64> = c1.iter().zip(&c2).map(|(a, b)| -2.0 * a + 0.5 * b).collect();
        let s =
            bounded_least_squares(&[&c1, &c2], &y, &[0.0, f64::NEG_INFINITY], &[f64::INFINITY; 2]);
        assert_eq!(s.coef[0], 0.0);
        assert_eq!(s.at_bound, vec![true, false]);
        assert!(s.rss > 0.0);
    }
}
