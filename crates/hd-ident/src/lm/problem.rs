//! What the minimiser ([`super`]) sees of a least-squares problem: Σr², JᵀJ and Jᵀr at a
//! point ([`Normal`], p × p whatever the number of residuals), Σr² alone at a trial point,
//! and optionally the curvature along a step for the geodesic acceleration. The fits give
//! their problems in one of three forms: a type of their own that implements
//! [`LeastSquares`] (the rigid drive, which streams its rows into an [`Accumulator`]),
//! whole columns of residuals and Jacobian ([`Columns`], the compliant drive), or a closure
//! that forms the normal equations at every point ([`Formed`], the friction and stiffness
//! fits, whose trials carry them so an accepted step needs no further pass).
//!
//! Sign convention: J = ∂r/∂x, so Jᵀr is the gradient of ½Σr² and −Jᵀr the descent.

use crate::error::FitError;
use nalgebra::{DMatrix, DVector};
use std::cell::RefCell;

/// The normal equations of a least-squares problem at a point.
#[derive(Clone, Debug, PartialEq)]
pub struct Normal {
    /// Σ r² [squared residual unit].
    pub cost: f64,
    /// JᵀJ (p × p), J = ∂r/∂x.
    pub jtj: DMatrix<f64>,
    /// Jᵀr (p): the gradient of ½Σr².
    pub jtr: DVector<f64>,
}

impl Normal {
    /// From the residuals `r` = data − model and the model's sensitivity columns
    /// ∂model/∂x_j (so J = −columns).
    pub fn from_model_columns(columns: &[Vec<f64>], r: &[f64]) -> Self {
        let p = columns.len();
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let mut jtj = DMatrix::zeros(p, p);
        for i in 0..p {
            for j in 0..=i {
                let v = dot(&columns[i], &columns[j]);
                jtj[(i, j)] = v;
                jtj[(j, i)] = v;
            }
        }
        let jtr = DVector::from_fn(p, |i, _| -dot(&columns[i], r));
        Self { cost: dot(r, r), jtj, jtr }
    }

    /// Whether every number is finite.
    pub fn is_finite(&self) -> bool {
        self.cost.is_finite() && self.jtj.iter().chain(self.jtr.iter()).all(|v| v.is_finite())
    }
}

/// A least-squares problem as the minimiser sees it.
pub trait LeastSquares {
    /// Σr², JᵀJ and Jᵀr at `x`, or an error where a residual cannot be evaluated.
    fn normal(&self, x: &[f64]) -> Result<Normal, FitError>;
    /// Σr² at `x` (a trial point), or an error where a residual cannot be evaluated.
    fn cost(&self, x: &[f64]) -> Result<f64, FitError> {
        self.normal(x).map(|n| n.cost)
    }
    /// Jᵀ·r_vv at `x` (J and r at `x`) for the geodesic acceleration along `v`, with the
    /// directional second derivative r_vv ≈ (2/h)·((r(x + h·v) − r(x))/h − J·v); `None`
    /// where it cannot be evaluated (the plain step is then taken).
    fn curvature(&self, _x: &[f64], _v: &DVector<f64>, _h: f64) -> Option<DVector<f64>> {
        None
    }
    /// Whether a trial point is evaluated with [`LeastSquares::normal`] (the normal
    /// equations come at little more than the cost's price, and an accepted step then
    /// needs no further pass) rather than [`LeastSquares::cost`].
    fn normal_with_trial(&self) -> bool {
        false
    }
}

/// The error of a residual that is not finite.
pub fn not_finite() -> FitError {
    FitError::Optimiser("a residual is not finite".into())
}

/// A problem given by a closure that forms the normal equations at every point.
pub struct Formed<F>(pub F);

impl<F: Fn(&[f64]) -> Result<Normal, FitError>> LeastSquares for Formed<F> {
    fn normal(&self, x: &[f64]) -> Result<Normal, FitError> {
        (self.0)(x)
    }
    fn normal_with_trial(&self) -> bool {
        true
    }
}

/// Residuals and their Jacobian ∂r/∂x (n × p) at a point, or `None` where the model fails.
pub type WithJacobian<'a> = &'a dyn Fn(&[f64]) -> Option<(Vec<f64>, DMatrix<f64>)>;

/// A problem given as whole columns: `with_jacobian` at the iterates, `residuals` alone at
/// the trials. The residuals and Jacobian of the latest [`LeastSquares::normal`] are kept
/// for the curvature at the same point.
pub struct Columns<'a> {
    with_jacobian: WithJacobian<'a>,
    residuals: &'a dyn Fn(&[f64]) -> Option<Vec<f64>>,
    last: RefCell<Option<(Vec<f64>, DMatrix<f64>)>>,
}

impl<'a> Columns<'a> {
    /// The problem of `with_jacobian` and `residuals`.
    pub fn new(
        with_jacobian: WithJacobian<'a>,
        residuals: &'a dyn Fn(&[f64]) -> Option<Vec<f64>>,
    ) -> Self {
        Columns { with_jacobian, residuals, last: RefCell::new(None) }
    }
}

fn ss(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

impl LeastSquares for Columns<'_> {
    fn normal(&self, x: &[f64]) -> Result<Normal, FitError> {
        let (r, jac) = (self.with_jacobian)(x).ok_or_else(not_finite)?;
        let n = Normal {
            cost: ss(&r),
            jtj: jac.transpose() * &jac,
            jtr: jac.transpose() * DVector::from_column_slice(&r),
        };
        *self.last.borrow_mut() = Some((r, jac));
        Ok(n)
    }

    fn cost(&self, x: &[f64]) -> Result<f64, FitError> {
        let r = (self.residuals)(x).ok_or_else(not_finite)?;
        let c = ss(&r);
        if c.is_finite() { Ok(c) } else { Err(not_finite()) }
    }

    fn curvature(&self, x: &[f64], v: &DVector<f64>, h: f64) -> Option<DVector<f64>> {
        let last = self.last.borrow();
        let (r, jac) = last.as_ref()?;
        let probe: Vec<f64> = x.iter().zip(v.iter()).map(|(a, d)| a + h * d).collect();
        let rp = (self.residuals)(&probe)?;
        let jv = jac * v;
        let rvv: Vec<f64> =
            (0..r.len()).map(|i| (2.0 / h) * ((rp[i] - r[i]) / h - jv[i])).collect();
        if !rvv.iter().all(|x| x.is_finite()) {
            return None;
        }
        Some(jac.transpose() * DVector::from_column_slice(&rvv))
    }
}

/// Rows per block of [`Accumulator`].
const BLOCK: usize = 256;

/// The normal equations accumulated from rows (residual, Jacobian row) as they come: each
/// block of [`BLOCK`] rows is added to JᵀJ and Jᵀr and dropped, so the storage is
/// p × (p + [`BLOCK`] + 1) numbers for any number of rows.
#[derive(Clone, Debug)]
pub struct Accumulator {
    block: DMatrix<f64>,
    block_r: DVector<f64>,
    fill: usize,
    jtj: DMatrix<f64>,
    jtr: DVector<f64>,
    cost: f64,
    rows: usize,
    finite: bool,
}

impl Accumulator {
    /// Empty, for `p` parameters.
    pub fn new(p: usize) -> Self {
        Accumulator {
            block: DMatrix::zeros(BLOCK, p),
            block_r: DVector::zeros(BLOCK),
            fill: 0,
            jtj: DMatrix::zeros(p, p),
            jtr: DVector::zeros(p),
            cost: 0.0,
            rows: 0,
            finite: true,
        }
    }

    /// Add the residual `r` and its row `j` = ∂r/∂x of the Jacobian (length p).
    pub fn push(&mut self, r: f64, j: &[f64]) {
        self.finite &= r.is_finite();
        self.cost += r * r;
        self.rows += 1;
        for (c, &v) in j.iter().enumerate() {
            self.block[(self.fill, c)] = v;
        }
        self.block_r[self.fill] = r;
        self.fill += 1;
        if self.fill == BLOCK {
            self.flush();
        }
    }

    fn flush(&mut self) {
        if self.fill > 0 {
            let b = self.block.rows(0, self.fill);
            self.jtj.gemm_tr(1.0, &b, &b, 1.0);
            self.jtr.gemv_tr(1.0, &b, &self.block_r.rows(0, self.fill), 1.0);
            self.fill = 0;
        }
    }

    /// Rows added so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Numbers held (block, JᵀJ, Jᵀr): independent of the rows added.
    pub fn storage(&self) -> usize {
        self.block.len() + self.block_r.len() + self.jtj.len() + self.jtr.len()
    }

    /// The normal equations, or an error when a residual was not finite.
    pub fn finish(mut self) -> Result<Normal, FitError> {
        self.flush();
        if self.finite {
            Ok(Normal { cost: self.cost, jtj: self.jtj, jtr: self.jtr })
        } else {
            Err(not_finite())
        }
    }
}
