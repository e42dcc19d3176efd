//! Levenberg–Marquardt with an exact Jacobian and box bounds, for the drive's output-error
//! fits. The minimiser works on the normal equations: at each iterate it needs Σr², JᵀJ
//! and Jᵀr ([`Normal`]), which a problem may accumulate row by row as its simulation runs
//! ([`super::normal::Accumulator`]) without ever holding the n × p Jacobian; trial points
//! need only Σr². A trial that cannot be evaluated counts as a rejected step. Bounds are
//! kept by projecting each trial onto the box. [`minimise`] takes the residuals and the
//! Jacobian as whole columns (the compliant drive's fit); [`minimise_problem`] takes a
//! [`LeastSquares`] problem (the rigid drive's fit, whose working storage does not grow
//! with the record).

use nalgebra::{DMatrix, DVector};
use std::cell::RefCell;

/// Settings of [`minimise`].
#[derive(Clone, Debug, PartialEq)]
pub struct LmSettings {
    /// Jacobian evaluations at most.
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this share.
    pub cost_tolerance: f64,
    /// Add the geodesic acceleration to each step (Transtrum and Sethna, 2012): the
    /// residuals' second derivative along the step, from one more residual evaluation, bends
    /// the step along a curved valley. Steps whose acceleration is not small against their
    /// velocity (2‖a‖ > [`ACCELERATION_LIMIT`]·‖v‖, scaled norms) are refused.
    pub geodesic: bool,
}

impl Default for LmSettings {
    fn default() -> Self {
        LmSettings { max_iterations: 100, cost_tolerance: 1e-10, geodesic: false }
    }
}

/// Largest ratio 2‖a‖/‖v‖ of a geodesic step's acceleration to its velocity [–].
pub const ACCELERATION_LIMIT: f64 = 0.75;

/// Finite step along the velocity, as a share of it, for the second derivative [–].
pub const ACCELERATION_STEP: f64 = 0.1;

/// Result of [`minimise`].
#[derive(Clone, Debug, PartialEq)]
pub struct LmResult {
    /// Parameters at the best point.
    pub x: Vec<f64>,
    /// ½‖r‖²·2 = Σ r² there.
    pub cost: f64,
    /// Jacobian evaluations.
    pub iterations: usize,
    /// Trials that could not be evaluated.
    pub failed_trials: usize,
    /// Why it stopped.
    pub termination: String,
}

/// The normal equations of a least-squares problem at a point: p × p, whatever the number
/// of residuals.
#[derive(Clone, Debug, PartialEq)]
pub struct Normal {
    /// Σ r² [squared residual unit].
    pub cost: f64,
    /// JᵀJ (p × p).
    pub jtj: DMatrix<f64>,
    /// Jᵀr (p).
    pub jtr: DVector<f64>,
}

/// A least-squares problem as the minimiser sees it.
pub trait LeastSquares {
    /// Σr², JᵀJ and Jᵀr at `x`, or `None` where a residual cannot be evaluated (or is not
    /// finite).
    fn normal(&self, x: &[f64]) -> Option<Normal>;
    /// Σr² at `x`, or `None` where a residual cannot be evaluated (or is not finite).
    fn cost(&self, x: &[f64]) -> Option<f64>;
    /// Jᵀ·r_vv at `x` (J and r at `x`) for the geodesic acceleration along `v`, with the
    /// directional second derivative r_vv ≈ (2/h)·((r(x + h·v) − r(x))/h − J·v); `None`
    /// where the residuals cannot be evaluated at x + h·v or r_vv is not finite.
    fn curvature(&self, x: &[f64], v: &DVector<f64>, h: f64) -> Option<DVector<f64>>;
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

    /// Add the residual `r` and its row `j` of the Jacobian (length p).
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

    /// The normal equations, or `None` when a residual was not finite.
    pub fn finish(mut self) -> Option<Normal> {
        self.flush();
        self.finite.then_some(Normal { cost: self.cost, jtj: self.jtj, jtr: self.jtr })
    }
}

/// Residuals and their Jacobian at a point, or `None` where the model fails there.
pub type WithJacobian<'a> = &'a dyn Fn(&[f64]) -> Option<(Vec<f64>, DMatrix<f64>)>;

fn ss(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// A problem given as whole columns: the residuals and Jacobian of the latest
/// [`LeastSquares::normal`] are kept for the curvature at the same point.
struct Columns<'a> {
    with_jacobian: WithJacobian<'a>,
    residuals: &'a dyn Fn(&[f64]) -> Option<Vec<f64>>,
    last: RefCell<Option<(Vec<f64>, DMatrix<f64>)>>,
}

impl LeastSquares for Columns<'_> {
    fn normal(&self, x: &[f64]) -> Option<Normal> {
        let (r, jac) = (self.with_jacobian)(x)?;
        let n = Normal {
            cost: ss(&r),
            jtj: jac.transpose() * &jac,
            jtr: jac.transpose() * DVector::from_column_slice(&r),
        };
        *self.last.borrow_mut() = Some((r, jac));
        Some(n)
    }

    fn cost(&self, x: &[f64]) -> Option<f64> {
        let r = (self.residuals)(x)?;
        r.iter().all(|v| v.is_finite()).then(|| ss(&r))
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

/// Minimise Σ r(x)² within `lower ≤ x ≤ upper` from `x0`. `with_jacobian(x)` returns the
/// residuals and the Jacobian ∂r/∂x (n × p); `residuals(x)` the residuals alone. Either
/// returns `None` where the model cannot be evaluated. `progress` is called after each
/// iteration with (iteration, cost).
pub fn minimise(
    with_jacobian: WithJacobian<'_>,
    residuals: &dyn Fn(&[f64]) -> Option<Vec<f64>>,
    x0: &[f64],
    lower: &[f64],
    upper: &[f64],
    s: &LmSettings,
    progress: &dyn Fn(usize, f64),
) -> Option<LmResult> {
    let problem = Columns { with_jacobian, residuals, last: RefCell::new(None) };
    minimise_problem(&problem, x0, lower, upper, s, progress)
}

/// [`minimise`] on a [`LeastSquares`] problem: the minimiser's own storage is a few p × p
/// matrices, whatever the number of residuals.
pub fn minimise_problem(
    problem: &dyn LeastSquares,
    x0: &[f64],
    lower: &[f64],
    upper: &[f64],
    s: &LmSettings,
    progress: &dyn Fn(usize, f64),
) -> Option<LmResult> {
    let p = x0.len();
    let clamp = |x: &mut [f64]| {
        for k in 0..p {
            x[k] = x[k].clamp(lower[k], upper[k]);
        }
    };
    let mut x = x0.to_vec();
    clamp(&mut x);
    let mut normal = problem.normal(&x)?;
    let mut cost = normal.cost;
    let mut lambda = 1e-3;
    let mut failed = 0;
    let mut iterations = 1;
    let mut termination = format!("iteration budget of {} reached", s.max_iterations);
    if p == 0 {
        return Some(LmResult {
            x,
            cost,
            iterations: 1,
            failed_trials: 0,
            termination: "no free parameter".into(),
        });
    }
    loop {
        progress(iterations, cost);
        let a = &normal.jtj;
        let g = -&normal.jtr;
        let diag: Vec<f64> = (0..p).map(|k| a[(k, k)].max(1e-300)).collect();
        // A parameter on a bound that the descent direction pushes outward is held for this
        // iteration (an active bound): projecting its step would bend every other one.
        let held: Vec<bool> = (0..p)
            .map(|k| (x[k] <= lower[k] && g[k] < 0.0) || (x[k] >= upper[k] && g[k] > 0.0))
            .collect();
        let mut accepted = false;
        for _ in 0..40 {
            let mut m = a.clone();
            for k in 0..p {
                m[(k, k)] += lambda * diag[k];
            }
            let mut g = g.clone();
            for k in (0..p).filter(|&k| held[k]) {
                for j in 0..p {
                    m[(k, j)] = 0.0;
                    m[(j, k)] = 0.0;
                }
                m[(k, k)] = 1.0;
                g[k] = 0.0;
            }
            let Some(chol) = m.cholesky() else {
                lambda *= 10.0;
                continue;
            };
            let mut delta = chol.solve(&g);
            if s.geodesic {
                // Where the acceleration is unknown or large, the plain step is tried.
                if let Some(a) = acceleration(problem, &x, &delta, &chol, &held, &diag) {
                    delta += a * 0.5;
                }
            }
            let mut trial: Vec<f64> = x.iter().zip(delta.iter()).map(|(a, d)| a + d).collect();
            clamp(&mut trial);
            match problem.cost(&trial) {
                Some(new) if new < cost => {
                    let gain = (cost - new) / cost.max(f64::MIN_POSITIVE);
                    x = trial;
                    lambda = (lambda * 0.2).max(1e-15);
                    accepted = true;
                    if gain < s.cost_tolerance {
                        cost = new;
                        termination = format!("cost change below {:e}", s.cost_tolerance);
                        return Some(LmResult {
                            x,
                            cost,
                            iterations,
                            failed_trials: failed,
                            termination,
                        });
                    }
                    break;
                }
                Some(_) => lambda *= 4.0,
                None => {
                    failed += 1;
                    lambda *= 10.0;
                }
            }
        }
        if !accepted {
            termination = "no step lowers the cost further (local minimum)".into();
            break;
        }
        if iterations >= s.max_iterations {
            break;
        }
        match problem.normal(&x) {
            Some(next) => {
                cost = next.cost;
                normal = next;
            }
            None => {
                termination = "the model could not be evaluated at the accepted point".into();
                break;
            }
        }
        iterations += 1;
    }
    Some(LmResult { x, cost, iterations, failed_trials: failed, termination })
}

/// The geodesic acceleration `a` of the step `v` at `x`: a = −(JᵀJ + λD)⁻¹·Jᵀ·r_vv with
/// the step's own factor `chol` ([`LeastSquares::curvature`] gives Jᵀ·r_vv); held
/// parameters get none. None when the residuals cannot be evaluated there, or the
/// acceleration is too large against the velocity ([`ACCELERATION_LIMIT`], norms scaled by
/// √diag(JᵀJ)).
fn acceleration(
    problem: &dyn LeastSquares,
    x: &[f64],
    v: &DVector<f64>,
    chol: &nalgebra::Cholesky<f64, nalgebra::Dyn>,
    held: &[bool],
    diag: &[f64],
) -> Option<DVector<f64>> {
    let mut rhs = -problem.curvature(x, v, ACCELERATION_STEP)?;
    for (k, &hk) in held.iter().enumerate() {
        if hk {
            rhs[k] = 0.0;
        }
    }
    let a = chol.solve(&rhs);
    let norm = |w: &DVector<f64>| w.iter().zip(diag).map(|(x, d)| x * x * d).sum::<f64>().sqrt();
    (2.0 * norm(&a) <= ACCELERATION_LIMIT * norm(v)).then_some(a)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = a·e^{−k·t} from a poor start, with k bounded above the optimum's side: the
    /// unbounded fit recovers (3, 0.7); bounded to k ≤ 0.5 it stops on the bound.
    #[test]
    fn exponential_with_and_without_a_bound() {
        let t: Vec<f64> = (0..60).map(|k| 0.1 * k as f64).collect();
        let y: Vec<f64> = t.iter().map(|&t| 3.0 * (-0.7 * t).exp()).collect();
        let res = |x: &[f64]| -> Option<Vec<f64>> {
            Some(t.iter().zip(&y).map(|(&t, &y)| x[0] * (-x[1] * t).exp() - y).collect())
        };
        let jac = |x: &[f64]| {
            let r = res(x)?;
            let j = DMatrix::from_fn(t.len(), 2, |i, c| {
                let e = (-x[1] * t[i]).exp();
                if c == 0 { e } else { -x[0] * t[i] * e }
            });
            Some((r, j))
        };
        let s = LmSettings::default();
        let out =
            minimise(&jac, &res, &[1.0, 0.1], &[0.0, 0.0], &[10.0, 10.0], &s, &|_, _| {}).unwrap();
        assert!((out.x[0] - 3.0).abs() < 1e-7 && (out.x[1] - 0.7).abs() < 1e-7, "{out:?}");
        let out =
            minimise(&jac, &res, &[1.0, 0.1], &[0.0, 0.0], &[10.0, 0.5], &s, &|_, _| {}).unwrap();
        assert_eq!(out.x[1], 0.5, "{out:?}");
    }

    /// r = (x0 − 2, x1 + 1, x0 + x1 − 0.5) with x1 ≥ 0: the optimum puts x1 on its bound and
    /// x0 = 1.25 (the mean of 2 and 0.5). With the bound held out of the step, the other
    /// parameter reaches it in a few iterations, not by ever smaller projected steps.
    #[test]
    fn an_active_bound_is_held_and_the_rest_converges() {
        let res = |x: &[f64]| Some(vec![x[0] - 2.0, x[1] + 1.0, x[0] + x[1] - 0.5]);
        let jac = |x: &[f64]| {
            let j = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
            Some((res(x)?, j))
        };
        let s = LmSettings::default();
        let lo = [f64::NEG_INFINITY, 0.0];
        let hi = [f64::INFINITY; 2];
        let out = minimise(&jac, &res, &[5.0, 3.0], &lo, &hi, &s, &|_, _| {}).unwrap();
        assert!((out.x[0] - 1.25).abs() < 5e-8 && out.x[1] == 0.0, "{out:?}");
        assert!(out.iterations <= 10, "{out:?}");
    }

    /// The accumulated normal equations equal JᵀJ and Jᵀr of the whole matrix (rows over
    /// several blocks), and the accumulator holds the same numbers for 10 rows as for 5000.
    #[test]
    fn accumulated_normal_equations_match_and_do_not_grow() {
        let row = |i: usize| [1.0, (i as f64 * 0.01).sin(), 1e-3 * (i as f64).sqrt()];
        let res = |i: usize| (i as f64 * 0.7).cos();
        let n = 5000;
        let mut acc = Accumulator::new(3);
        let small = {
            let mut a = Accumulator::new(3);
            (0..10).for_each(|i| a.push(res(i), &row(i)));
            a.storage()
        };
        (0..n).for_each(|i| acc.push(res(i), &row(i)));
        assert_eq!(acc.storage(), small);
        assert_eq!(acc.rows(), n);
        let j = DMatrix::from_fn(n, 3, |i, c| row(i)[c]);
        let r = DVector::from_fn(n, |i, _| res(i));
        let got = acc.finish().unwrap();
        let (jtj, jtr) = (j.transpose() * &j, j.transpose() * &r);
        assert!((&got.jtj - &jtj).norm() <= 1e-12 * jtj.norm(), "{}", got.jtj);
        assert!((&got.jtr - &jtr).norm() <= 1e-12 * jtr.norm(), "{}", got.jtr);
        assert!((got.cost - r.norm_squared()).abs() <= 1e-12 * got.cost);
        let mut bad = Accumulator::new(1);
        bad.push(f64::NAN, &[1.0]);
        assert!(bad.finish().is_none());
    }
}
