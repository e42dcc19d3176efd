//! The joint fit's inner evaluations without per-trial allocation: the bristle run, the
//! projection onto the linear parameters and the buffers of the Levenberg–Marquardt
//! normal equations ([`super::normal`]), all kept by one start (or one search thread) for
//! its whole run.
//!
//! The linear parameters (σ1, σ2, offset: at most three columns) are solved from the
//! column-scaled Gram matrix of their columns (one pass of dot products, no n × k copy).
//! Where that matrix is too ill-conditioned for normal equations (a Cholesky pivot below
//! [`MIN_PIVOT`]) the solve falls back to the QR/SVD path of [`crate::linear`].

use super::super::bristle::{BristleRun, bristle_run_into};
use super::JointProblem;
use crate::error::FitError;
use crate::fix::OFFSET;
use crate::linear::bounded_least_squares;
use hd_model::registry::lookup;
use nalgebra::{DMatrix, DVector};
use std::sync::Mutex;

/// Smallest squared Cholesky pivot of the unit-diagonal Gram matrix accepted: below it the
/// normal equations would lose more than about half the digits (condition number above
/// 1e5 of the scaled columns), and the QR/SVD solve is used instead.
pub const MIN_PIVOT: f64 = 1e-10;

/// Buffers of one evaluation.
#[derive(Default)]
pub(super) struct Workspace {
    pub(super) run: BristleRun,
    /// Measured torque less the bristle torque and fixed linear terms, then the residual.
    pub(super) resid: Vec<f64>,
    /// The gradient evaluation's bristle torque and slip rate ([`super::normal`]).
    pub(super) w: Vec<f64>,
    pub(super) slip: Vec<f64>,
    /// Its ∂w/∂p, then ∂(w + σ1·ṡ)/∂p, then J, one column per free nonlinear parameter.
    pub(super) dw: Vec<Vec<f64>>,
    /// Its ∂ṡ/∂p, one column per free nonlinear parameter.
    pub(super) ds: Vec<Vec<f64>>,
}

/// Workspaces handed out to concurrent evaluations (the search's grid runs in parallel).
#[derive(Default)]
pub(super) struct Pool(Mutex<Vec<Workspace>>);

impl Pool {
    /// Run `f` with a workspace from the pool (a new one when all are in use).
    pub(super) fn with<R>(&self, f: impl FnOnce(&mut Workspace) -> R) -> R {
        let mut ws = self.0.lock().map(|mut p| p.pop()).ok().flatten().unwrap_or_default();
        let out = f(&mut ws);
        if let Ok(mut p) = self.0.lock() {
            p.push(ws);
        }
        out
    }
}

/// The projection at one point: the linear parameters (every model linear parameter, the
/// fixed ones at their values) and the free ones not held at a bound.
pub(super) struct Solved {
    pub(super) beta: Vec<f64>,
    /// Indices (into `JointProblem::linear`) of the free columns not at a bound.
    pub(super) active: Vec<usize>,
}

/// Σ aᵢ·bᵢ, summed in 16 interleaved partial sums: independent chains that the CPU
/// overlaps (one running sum waits on every addition) and the compiler keeps in vector
/// registers; 1.5× (long columns) to 2× (a block in the cache) faster than four.
#[inline]
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    const LANES: usize = 16;
    let n = a.len().min(b.len());
    let (mut s, split) = ([0.0f64; LANES], n - n % LANES);
    for (x, y) in a[..split].chunks_exact(LANES).zip(b[..split].chunks_exact(LANES)) {
        for l in 0..LANES {
            s[l] += x[l] * y[l];
        }
    }
    let tail: f64 = a[split..n].iter().zip(&b[split..n]).map(|(x, y)| x * y).sum();
    s.iter().sum::<f64>() + tail
}

/// Cholesky factor of the scaled Gram matrix restricted to `set`, when every squared pivot
/// is at least [`MIN_PIVOT`].
pub(super) fn factor(
    scaled: &DMatrix<f64>,
    set: &[usize],
) -> Option<nalgebra::Cholesky<f64, nalgebra::Dyn>> {
    let m = DMatrix::from_fn(set.len(), set.len(), |a, b| scaled[(set[a], set[b])]);
    let chol = m.cholesky()?;
    let l = chol.l_dirty();
    (0..set.len()).all(|i| l[(i, i)] * l[(i, i)] >= MIN_PIVOT).then_some(chol)
}

impl JointProblem<'_> {
    /// The column of linear parameter `j` (σ1: ṡ from `run`; σ2: ω; offset: 1).
    pub(super) fn linear_column<'b>(&'b self, j: usize, slip: &'b [f64]) -> &'b [f64] {
        match self.linear[j].0 {
            "sigma1" => slip,
            "sigma2" => self.data.omega(),
            _ => &self.ones,
        }
    }

    fn linear_bounds(&self, j: usize) -> (f64, f64) {
        match self.linear[j].0 {
            OFFSET => (f64::NEG_INFINITY, f64::INFINITY),
            name => lookup(name).map_or((f64::NEG_INFINITY, f64::INFINITY), |i| (i.min, i.max)),
        }
    }

    /// Run the state at `v` and project: afterwards `ws.resid` holds the residuals.
    pub(super) fn project_into(
        &self,
        v: &[f64; 6],
        grad: bool,
        ws: &mut Workspace,
    ) -> Result<Solved, FitError> {
        let law = self.law(v);
        let (t, omega, y) = (self.data.t(), self.data.omega(), self.data.torque());
        bristle_run_into(&mut ws.run, t, omega, &law, y[0] - self.first_bias, grad)?;
        let Workspace { run, resid, .. } = ws;
        Ok(self.project_run(&run.w, &run.slip, resid))
    }

    /// Project the measured torque less the bristle torque `w` onto the linear
    /// parameters' columns (`slip` is ṡ): `resid` is refilled with the residuals.
    pub(super) fn project_run(&self, w: &[f64], slip: &[f64], resid: &mut Vec<f64>) -> Solved {
        let y = self.data.torque();
        resid.clear();
        resid.extend(y.iter().zip(w).map(|(a, b)| a - b));
        let mut free = Vec::with_capacity(self.linear.len());
        for (j, (_, fixed)) in self.linear.iter().enumerate() {
            match fixed {
                Some(val) => {
                    let col = self.linear_column(j, slip);
                    resid.iter_mut().zip(col).for_each(|(r, c)| *r -= val * c);
                }
                None => free.push(j),
            }
        }
        let mut beta: Vec<f64> = self.linear.iter().map(|(_, f)| f.unwrap_or(0.0)).collect();
        let mut at_bound = vec![false; beta.len()];
        let cols: Vec<&[f64]> = free.iter().map(|&j| self.linear_column(j, slip)).collect();
        let lo: Vec<f64> = free.iter().map(|&j| self.linear_bounds(j).0).collect();
        let hi: Vec<f64> = free.iter().map(|&j| self.linear_bounds(j).1).collect();
        let (coef, held) = match gram_bounded(&cols, resid, &lo, &hi) {
            Some(s) => s,
            None => {
                let s = bounded_least_squares(&cols, resid, &lo, &hi);
                (s.coef, s.at_bound)
            }
        };
        for (k, &j) in free.iter().enumerate() {
            beta[j] = coef[k];
            at_bound[j] = held[k];
            resid.iter_mut().zip(cols[k]).for_each(|(r, c)| *r -= coef[k] * c);
        }
        let active = free.iter().copied().filter(|&j| !at_bound[j]).collect();
        Solved { beta, active }
    }

    /// Index of linear parameter `j`'s column in the σ0 search's Gram matrix
    /// (ṡ, ω, 1, then the target).
    pub(super) fn kind(&self, j: usize) -> usize {
        match self.linear[j].0 {
            "sigma1" => 0,
            "sigma2" => 1,
            _ => 2,
        }
    }

    /// The projected residual sum of squares from Gram entries: `cc(a, b)` = A_aᵀA_b and
    /// `ct(a)` = A_aᵀt over the linear parameters' columns, `tt` = tᵀt, t the measured
    /// torque less the bristle torque. Fixed linear parameters move to the target. `None`
    /// where the matrix is not usable or the sum cancels to under 1e-9 of tᵀt (too few
    /// digits left): the caller then evaluates the trial by the general path.
    pub(super) fn rss_from_gram(
        &self,
        cc: impl Fn(usize, usize) -> f64,
        tt: f64,
        ct: impl Fn(usize) -> f64,
    ) -> Option<f64> {
        let fixed: Vec<(usize, f64)> =
            self.linear.iter().enumerate().filter_map(|(j, (_, f))| f.map(|v| (j, v))).collect();
        let free: Vec<usize> =
            (0..self.linear.len()).filter(|&j| self.linear[j].1.is_none()).collect();
        let mut tt = tt;
        for &(f, vf) in &fixed {
            tt -= 2.0 * vf * ct(f);
            for &(g, vg) in &fixed {
                tt += vf * vg * cc(f, g);
            }
        }
        let aty: Vec<f64> = free
            .iter()
            .map(|&a| ct(a) - fixed.iter().map(|&(f, vf)| vf * cc(a, f)).sum::<f64>())
            .collect();
        let gram = DMatrix::from_fn(free.len(), free.len(), |a, b| cc(free[a], free[b]));
        let lo: Vec<f64> = free.iter().map(|&j| self.linear_bounds(j).0).collect();
        let hi: Vec<f64> = free.iter().map(|&j| self.linear_bounds(j).1).collect();
        let (coef, _) = gram_solve(&gram, &aty, &lo, &hi)?;
        let mut rss = tt;
        for a in 0..free.len() {
            rss -= 2.0 * coef[a] * aty[a];
            for b in 0..free.len() {
                rss += coef[a] * coef[b] * gram[(a, b)];
            }
        }
        (rss.is_finite() && rss >= 1e-9 * tt).then_some(rss)
    }

    /// RSS at nonlinear values `v` (the search's cost), in a pooled workspace.
    pub(super) fn rss_fast(&self, v: &[f64; 6]) -> Result<f64, FitError> {
        self.pool.with(|ws| {
            self.project_into(v, false, ws)?;
            Ok(dot(&ws.resid, &ws.resid))
        })
    }
}

/// Minimise ‖y − Σ β_j·col_j‖² with `lo ≤ β ≤ hi` from the column-scaled Gram matrix, by
/// the same active set as [`bounded_least_squares`]; `None` where a column is zero or the
/// matrix is too ill-conditioned for normal equations (see [`MIN_PIVOT`]).
fn gram_bounded(
    cols: &[&[f64]],
    y: &[f64],
    lo: &[f64],
    hi: &[f64],
) -> Option<(Vec<f64>, Vec<bool>)> {
    let k = cols.len();
    let gram = DMatrix::from_fn(k, k, |a, b| dot(cols[a], cols[b]));
    let aty: Vec<f64> = (0..k).map(|a| dot(cols[a], y)).collect();
    gram_solve(&gram, &aty, lo, hi)
}

/// [`gram_bounded`] from the Gram matrix `gram` = AᵀA of the columns and `aty` = Aᵀy.
pub(super) fn gram_solve(
    gram: &DMatrix<f64>,
    aty: &[f64],
    lo: &[f64],
    hi: &[f64],
) -> Option<(Vec<f64>, Vec<bool>)> {
    let k = aty.len();
    let norms: Vec<f64> = (0..k).map(|a| gram[(a, a)].sqrt()).collect();
    if norms.iter().any(|n| !(*n > 0.0 && n.is_finite())) {
        return None;
    }
    let scaled = DMatrix::from_fn(k, k, |a, b| gram[(a, b)] / (norms[a] * norms[b]));
    let aty: Vec<f64> = (0..k).map(|a| aty[a] / norms[a]).collect();
    let mut held: Vec<Option<f64>> = vec![None; k];
    loop {
        let free: Vec<usize> = (0..k).filter(|&j| held[j].is_none()).collect();
        // Scaled unknowns u_j = norm_j·β_j; held ones move to the right-hand side.
        let rhs = DVector::from_fn(free.len(), |a, _| {
            let f = free[a];
            aty[f]
                - (0..k).filter_map(|h| held[h].map(|v| scaled[(f, h)] * v * norms[h])).sum::<f64>()
        });
        let u =
            if free.is_empty() { DVector::zeros(0) } else { factor(&scaled, &free)?.solve(&rhs) };
        let mut violated = false;
        for (a, &j) in free.iter().enumerate() {
            let b = u[a] / norms[j];
            if b < lo[j] {
                held[j] = Some(lo[j]);
                violated = true;
            } else if b > hi[j] {
                held[j] = Some(hi[j]);
                violated = true;
            }
        }
        if !violated || free.is_empty() {
            let mut coef: Vec<f64> = held.iter().map(|h| h.unwrap_or(0.0)).collect();
            for (a, &j) in free.iter().enumerate() {
                coef[j] = u[a] / norms[j];
            }
            return Some((coef, held.iter().map(Option::is_some).collect()));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gram_solve_matches_the_qr_solve_with_and_without_bounds() {
        let n = 400;
        let c1: Vec<f64> = (0..n).map(|i| (0.05 * i as f64).sin()).collect();
        let c2: Vec<f64> = (0..n).map(|i| 1e-3 * i as f64).collect();
        let c3 = vec![1.0; n];
        let y: Vec<f64> = (0..n)
            .map(|i| 2.0 * c1[i] - 30.0 * c2[i] + 0.5 + 0.01 * (1.7 * i as f64).cos())
            .collect();
        let cols: [&[f64]; 3] = [&c1, &c2, &c3];
        for (lo, hi) in [
            ([f64::NEG_INFINITY; 3], [f64::INFINITY; 3]),
            ([0.0, 0.0, f64::NEG_INFINITY], [f64::INFINITY; 3]),
        ] {
            let (coef, held) = gram_bounded(&cols, &y, &lo, &hi).unwrap();
            let qr = bounded_least_squares(&cols, &y, &lo, &hi);
            assert_eq!(held, qr.at_bound);
            for (a, b) in coef.iter().zip(&qr.coef) {
                assert!((a - b).abs() <= 1e-10 * b.abs().max(1.0), "{coef:?} vs {:?}", qr.coef);
            }
        }
        // Dependent columns: left to the QR/SVD solve.
        let twice: Vec<f64> = c1.iter().map(|v| 2.0 * v).collect();
        assert!(
            gram_bounded(&[&c1, &twice], &y, &[f64::NEG_INFINITY; 2], &[f64::INFINITY; 2])
                .is_none()
        );
    }
}
