//! Least squares with some coefficients held non-negative (Lawson–Hanson), exact: the
//! Maxwell-slip stiffnesses kᵢ ≥ 0 beside the unbounded spring coefficients.
//!
//! The tall problem (n samples × p columns) is reduced once by a QR factorisation of the
//! column-scaled design: ‖y − Xβ‖² = ‖Qᵀy − Rβ‖² + ‖y‖² − ‖Qᵀy‖², so the active-set
//! iterations run on the p × p triangle and cost nothing next to the factorisation (the
//! final residual is then summed from the original columns).

use crate::linear::least_squares;
use nalgebra::{DMatrix, DVector};

/// Result of [`nnls`].
#[derive(Clone, Debug, PartialEq)]
pub struct NnlsSolution {
    /// Coefficients, one per column; the constrained ones are ≥ 0.
    pub coef: Vec<f64>,
    /// Residual sum of squares ‖y − Σ βⱼ·colⱼ‖².
    pub rss: f64,
    /// Active-set iterations.
    pub iterations: usize,
}

/// Minimise ‖y − Σ βⱼ·colⱼ‖² subject to βⱼ ≥ 0 wherever `nonneg[j]`.
pub fn nnls(cols: &[&[f64]], y: &[f64], nonneg: &[bool]) -> NnlsSolution {
    let n = y.len();
    let p = cols.len();
    let norms: Vec<f64> = cols
        .iter()
        .map(|c| c.iter().map(|v| v * v).sum::<f64>().sqrt())
        .map(|s| if s > 0.0 && s.is_finite() { s } else { 1.0 })
        .collect();
    let x = DMatrix::from_fn(n, p, |i, j| cols[j][i] / norms[j]);
    let qr = x.qr();
    let mut qty = DVector::from_column_slice(y);
    qr.q_tr_mul(&mut qty);
    let k = p.min(n);
    let r = qr.r();
    let b: Vec<f64> = qty.rows(0, k).iter().copied().collect();
    let rcols: Vec<Vec<f64>> = (0..p).map(|j| (0..k).map(|i| r[(i, j)]).collect()).collect();
    let (z, iterations) = lawson_hanson(&rcols, &b, nonneg);
    let coef: Vec<f64> = z.iter().zip(&norms).map(|(v, s)| v / s).collect();
    // The residual from the original columns (no cancellation against ‖y‖²).
    let rss = crate::linear::rss(cols, &coef, y);
    NnlsSolution { coef, rss, iterations }
}

/// Lawson–Hanson on a small dense problem (columns `a`, right-hand side `b`); the
/// unconstrained columns are always in the passive set.
fn lawson_hanson(a: &[Vec<f64>], b: &[f64], nonneg: &[bool]) -> (Vec<f64>, usize) {
    let p = a.len();
    let m = b.len();
    let solve = |passive: &[bool]| -> Vec<f64> {
        let idx: Vec<usize> = (0..p).filter(|&j| passive[j]).collect();
        let cols: Vec<&[f64]> = idx.iter().map(|&j| a[j].as_slice()).collect();
        let sol = least_squares(&cols, b);
        let mut z = vec![0.0; p];
        for (f, &j) in idx.iter().enumerate() {
            z[j] = sol[f];
        }
        z
    };
    let mut passive: Vec<bool> = nonneg.iter().map(|c| !c).collect();
    let mut x = solve(&passive);
    // Start feasible: unconstrained solve on the free columns leaves constrained ones 0.
    let scale = b.iter().map(|v| v.abs()).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let tol = 1e-12 * scale * (m as f64);
    let mut iterations = 0;
    while iterations < 3 * p + 10 {
        iterations += 1;
        let resid: Vec<f64> =
            (0..m).map(|i| b[i] - (0..p).map(|j| a[j][i] * x[j]).sum::<f64>()).collect();
        let grad = |j: usize| -> f64 { (0..m).map(|i| a[j][i] * resid[i]).sum() };
        let Some((best, g)) = (0..p)
            .filter(|&j| !passive[j])
            .map(|j| (j, grad(j)))
            .max_by(|x, y| x.1.total_cmp(&y.1))
        else {
            break;
        };
        if g <= tol {
            break;
        }
        passive[best] = true;
        loop {
            let z = solve(&passive);
            let bad: Vec<usize> =
                (0..p).filter(|&j| passive[j] && nonneg[j] && z[j] <= 0.0).collect();
            if bad.is_empty() {
                x = z;
                break;
            }
            let alpha = bad
                .iter()
                .map(|&j| x[j] / (x[j] - z[j]))
                .fold(f64::INFINITY, f64::min)
                .clamp(0.0, 1.0);
            for j in 0..p {
                x[j] += alpha * (z[j] - x[j]);
                if nonneg[j]
                    && passive[j]
                    && x[j] <= 1e-15 * x.iter().map(|v| v.abs()).fold(0.0, f64::max)
                {
                    x[j] = 0.0;
                    passive[j] = false;
                }
            }
        }
    }
    (x, iterations)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_unconstrained_solution_when_it_is_feasible_and_clips_otherwise() {
        let t: Vec<f64> = (0..300).map(|i| i as f64 / 300.0).collect();
        let c1: Vec<f64> = t.iter().map(|v| v.sin()).collect();
        let c2: Vec<f64> = t.iter().map(|v| (3.0 * v).cos()).collect();
        let c3: Vec<f64> = t.iter().map(|v| v * v).collect();
        // y = 2·c1 + 0.5·c2 − 1·c3: with c3 ≥ 0 required, c3 goes to 0.
        let y: Vec<f64> = (0..300).map(|i| 2.0 * c1[i] + 0.5 * c2[i] - 1.0 * c3[i]).collect();
        let free = nnls(&[&c1, &c2, &c3], &y, &[true, true, false]);
        assert!((free.coef[2] + 1.0).abs() < 1e-9 && free.rss < 1e-18, "{free:?}");
        let held = nnls(&[&c1, &c2, &c3], &y, &[true, true, true]);
        assert_eq!(held.coef[2], 0.0);
        // Optimality: no constrained direction at zero can lower the cost.
        let r: Vec<f64> =
            (0..300).map(|i| y[i] - held.coef[0] * c1[i] - held.coef[1] * c2[i]).collect();
        let g3: f64 = r.iter().zip(&c3).map(|(a, b)| a * b).sum();
        assert!(g3 <= 1e-9, "{g3}");
        let direct: f64 = r.iter().map(|v| v * v).sum();
        assert!((direct - held.rss).abs() < 1e-9 * direct.max(1e-12));
    }
}
