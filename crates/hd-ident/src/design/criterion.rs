//! Criteria on the information matrix M (log coordinates: relative changes of the free
//! parameters), and the standard errors and verdicts it predicts.
//!
//! - **D-optimal**: maximise ln det(M_prior + M + ε·I) over every free parameter.
//! - **A-optimal** on chosen parameters: minimise the sum of their relative variances,
//!   Σ_k [(M_prior + M + ε·I)⁻¹]_kk.
//! - **Targeted**: minimise the variances along the weakest directions of the prior
//!   information (the eigenvectors of M_prior + ε·I with the smallest eigenvalues), each
//!   by its logarithm, Σ_k ln v_kᵀ (M_prior + M + ε·I)⁻¹ v_k: halving any one counts the
//!   same, so a direction that no input can reach (a bristle damping seen through the
//!   gear) does not swallow the search.
//!
//! ε ([`RIDGE`]) gives every parameter a vague prior (a relative standard error of 10, a
//! factor e^10), so that the criteria are finite where a direction is not seen at all.

use crate::drive::compliant::NAMES;
use crate::drive::compliant::model::ix;
use crate::drive::identifiability::{CORRELATION_LIMIT, NULL_TOLERANCE};
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Prior information per log-unit of every parameter [–] (relative SE 10).
pub const RIDGE: f64 = 1e-2;

/// An eigenvalue of the prior below this is a weak direction (a relative standard error
/// above 10 %) [–].
pub const WEAK: f64 = 100.0;

/// Most weak directions a targeted design aims at [–].
pub const MAX_TARGETS: usize = 6;

/// What a design optimises.
#[derive(Clone, Debug, PartialEq)]
pub enum Criterion {
    /// ln det of the total information over every free parameter.
    D,
    /// The sum of the relative variances of these free-parameter slots.
    A(Vec<usize>),
    /// The variance along these directions (columns, unit norm).
    Targeted(DMatrix<f64>),
}

impl Criterion {
    /// Its name.
    pub fn name(&self) -> &'static str {
        match self {
            Criterion::D => "D-optimal",
            Criterion::A(_) => "A-optimal",
            Criterion::Targeted(_) => "targeted",
        }
    }

    /// The value to minimise for total information `total` (prior + design, without the
    /// ridge, which is added here).
    pub fn cost(&self, total: &DMatrix<f64>) -> f64 {
        let m = ridged(total);
        match self {
            Criterion::D => {
                let e = SymmetricEigen::new(m);
                -e.eigenvalues.iter().map(|l| l.max(RIDGE).ln()).sum::<f64>()
            }
            Criterion::A(slots) => {
                let inv = inverse(&m);
                slots.iter().map(|&s| inv[(s, s)]).sum()
            }
            Criterion::Targeted(v) => {
                let inv = inverse(&m);
                let q = v.transpose() * inv * v;
                (0..q.nrows()).map(|i| q[(i, i)].max(f64::MIN_POSITIVE).ln()).sum()
            }
        }
    }
}

/// `m + ε·I`.
pub fn ridged(m: &DMatrix<f64>) -> DMatrix<f64> {
    m + DMatrix::identity(m.nrows(), m.ncols()) * RIDGE
}

/// Inverse of a symmetric positive (semi)definite matrix, its eigenvalues floored at
/// [`RIDGE`].
pub fn inverse(m: &DMatrix<f64>) -> DMatrix<f64> {
    let e = SymmetricEigen::new(m.clone());
    let v = &e.eigenvectors;
    let d = DMatrix::from_diagonal(&e.eigenvalues.map(|l| 1.0 / l.max(RIDGE)));
    v * d * v.transpose()
}

/// The weakest directions of the prior information (eigenvectors of `prior + ε·I` with
/// eigenvalue below [`WEAK`], at most [`MAX_TARGETS`], at least the weakest one), weakest
/// first, with their eigenvalues.
pub fn weakest(prior: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>) {
    let e = SymmetricEigen::new(ridged(prior));
    let mut order: Vec<usize> = (0..e.eigenvalues.len()).collect();
    order.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
    let keep: Vec<usize> = order
        .iter()
        .copied()
        .enumerate()
        .filter(|&(rank, k)| rank == 0 || (e.eigenvalues[k] < WEAK && rank < MAX_TARGETS))
        .map(|(_, k)| k)
        .collect();
    let cols: Vec<DVector<f64>> =
        keep.iter().map(|&k| e.eigenvectors.column(k).into_owned()).collect();
    (DMatrix::from_columns(&cols), keep.iter().map(|&k| e.eigenvalues[k]).collect())
}

/// The variance along unit direction `v` given total information `total` (ridge added).
pub fn direction_variance(total: &DMatrix<f64>, v: &DVector<f64>) -> f64 {
    (v.transpose() * inverse(&ridged(total)) * v)[(0, 0)]
}

/// A direction in words: its members with weight ≥ 0.2 of the largest.
pub fn describe_direction(v: &DVector<f64>, free: &[usize]) -> String {
    let big = v.amax().max(f64::MIN_POSITIVE);
    let mut parts: Vec<(f64, String)> = v
        .iter()
        .enumerate()
        .filter(|(_, w)| w.abs() >= 0.2 * big)
        .map(|(s, w)| (w.abs(), format!("{:+.2}·ln {}", w / big, NAMES[free[s]])))
        .collect();
    parts.sort_by(|a, b| b.0.total_cmp(&a.0));
    parts.into_iter().map(|p| p.1).collect::<Vec<_>>().join(" ")
}

/// Standard errors and verdicts predicted from an information matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// Relative standard error per free parameter (None: in a direction the information
    /// does not see).
    pub relative: Vec<Option<f64>>,
    /// Correlations.
    pub correlation: DMatrix<f64>,
    /// Whether the fit would call each determined: seen, its 95 % interval clear of zero
    /// (relative SE < 0.5), no correlation of 0.99 or more with another, and the fit's
    /// rules on the load (Jz undetermined: neither Jj, Cz, c nor mem_A; any of c, mem_A,
    /// mem_B undetermined: all three).
    pub determined: Vec<bool>,
}

/// The prediction of information `m` (log coordinates, no ridge: a direction it does not
/// see has no standard error) over free parameters `free` ([`NAMES`] indices).
pub fn predict(m: &DMatrix<f64>, free: &[usize]) -> Prediction {
    let k = m.nrows();
    let d: Vec<f64> = (0..k).map(|i| m[(i, i)].max(0.0).sqrt()).collect();
    let c = DMatrix::from_fn(k, k, |i, j| {
        if d[i] > 0.0 && d[j] > 0.0 { m[(i, j)] / (d[i] * d[j]) } else { 0.0 }
    });
    let e = SymmetricEigen::new(c);
    let lmax = e.eigenvalues.amax().max(f64::MIN_POSITIVE);
    let tol = NULL_TOLERANCE * NULL_TOLERANCE * lmax;
    let mut seen: Vec<bool> = d.iter().map(|&x| x > 0.0).collect();
    let mut cov_c = DMatrix::<f64>::zeros(k, k);
    for (l, &lam) in e.eigenvalues.iter().enumerate() {
        let v = e.eigenvectors.column(l);
        if lam > tol {
            cov_c += v * v.transpose() / lam;
        } else {
            let big = v.amax();
            for (s, w) in v.iter().enumerate() {
                if w.abs() >= 0.1 * big {
                    seen[s] = false;
                }
            }
        }
    }
    let var = |i: usize| cov_c[(i, i)] / (d[i] * d[i]);
    let relative: Vec<Option<f64>> =
        (0..k).map(|i| (seen[i] && var(i) > 0.0).then(|| var(i).sqrt())).collect();
    let correlation = DMatrix::from_fn(k, k, |i, j| {
        let s = (cov_c[(i, i)] * cov_c[(j, j)]).sqrt();
        if s > 0.0 { cov_c[(i, j)] / s } else { 0.0 }
    });
    let mut determined: Vec<bool> = (0..k)
        .map(|i| {
            relative[i].is_some_and(|r| r < 0.5)
                && (0..k)
                    .all(|j| j == i || !seen[j] || correlation[(i, j)].abs() < CORRELATION_LIMIT)
        })
        .collect();
    let slot = |p: usize| free.iter().position(|&f| f == p);
    if slot(ix::JZ).is_some_and(|jz| !determined[jz]) {
        for p in [ix::JJ, ix::CZ, ix::C, ix::MEM_A] {
            if let Some(s) = slot(p) {
                determined[s] = false;
            }
        }
    }
    let gear = [ix::C, ix::MEM_A, ix::MEM_B];
    if gear.iter().any(|&p| slot(p).is_some_and(|s| !determined[s])) {
        for p in gear {
            if let Some(s) = slot(p) {
                determined[s] = false;
            }
        }
    }
    Prediction { relative, correlation, determined }
}
