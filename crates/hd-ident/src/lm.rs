//! Levenberg–Marquardt least squares for the fits whose model is nonlinear in several
//! parameters (the joint friction fit). The residual vector comes from a function that may
//! fail — an integration that breaks down, a non-finite value — and such a trial is simply
//! a rejected step (its cost counts as infinite), never the end of the fit.
//!
//! The Jacobian is the model's own where it has one ([`levenberg_marquardt_exact`]: the
//! joint friction fit carries exact sensitivities), otherwise a forward difference with its
//! columns evaluated in parallel (rayon); the damped normal equations use Marquardt's diagonal scaling, so parameters of very
//! different size (ln σ0 next to ln ωs) are treated alike.

use crate::error::{FitError, chain};
use crate::lm_secant::Secant;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Settings of [`levenberg_marquardt`].
#[derive(Clone, Debug, PartialEq)]
pub struct LmOptions {
    /// Iteration budget (Jacobian evaluations); default 60.
    pub max_iterations: usize,
    /// Forward-difference step in the parameters [parameter units]; default 1e-4 (the
    /// callers use logarithms of the physical parameters, so this is a relative step).
    pub fd_step: f64,
    /// Stop when an accepted step lowers the cost by less than this share; default 1e-9.
    pub cost_tolerance: f64,
    /// Stop when no parameter moves by more than this; default 1e-8.
    pub step_tolerance: f64,
    /// Largest move of any parameter in one step; default 1.5 (a factor e^1.5 ≈ 4.5 for
    /// logarithmic parameters).
    pub max_step: f64,
    /// Estimate the residual curvature that Gauss–Newton leaves out from the steps taken
    /// and use it where it predicts better ([`crate::lm_secant`]); default false.
    pub secant: bool,
}

impl Default for LmOptions {
    fn default() -> Self {
        Self {
            max_iterations: 60,
            fd_step: 1e-4,
            cost_tolerance: 1e-9,
            step_tolerance: 1e-8,
            max_step: 1.5,
            secant: false,
        }
    }
}

/// Result of [`levenberg_marquardt`].
#[derive(Clone, Debug, PartialEq)]
pub struct LmOutcome {
    /// The parameters at the best point found.
    pub x: Vec<f64>,
    /// Sum of squared residuals there.
    pub cost: f64,
    /// Jacobian evaluations.
    pub iterations: usize,
    /// Residual evaluations.
    pub evaluations: usize,
    /// Trials whose residuals could not be computed (counted as rejected steps).
    pub failed_trials: usize,
    /// Why the iteration stopped.
    pub termination: String,
}

fn cost_of(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// The normal equations of a trial's linearisation: JᵀJ and Jᵀr, with J's columns
/// ∂model/∂x_j and r = data − model (so Jᵀr is the descent direction's right-hand side).
#[derive(Clone, Debug, PartialEq)]
pub struct Normal {
    /// JᵀJ (p × p).
    pub jtj: DMatrix<f64>,
    /// Jᵀr (p).
    pub jtr: DVector<f64>,
}

impl Normal {
    /// From J's columns and the residuals.
    pub fn from_columns(columns: &[Vec<f64>], r: &[f64]) -> Self {
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
        let jtr = DVector::from_fn(p, |i, _| dot(&columns[i], r));
        Self { jtj, jtr }
    }

    fn is_finite(&self) -> bool {
        self.jtj.iter().chain(self.jtr.iter()).all(|v| v.is_finite())
    }
}

/// One evaluated trial point: its cost, and either its residuals (for a difference
/// Jacobian) or the model's exact normal equations.
struct Trial {
    cost: f64,
    residuals: Option<Vec<f64>>,
    normal: Option<Normal>,
}

impl Trial {
    fn finite(&self) -> bool {
        self.cost.is_finite()
            && self.residuals.as_ref().is_none_or(|r| r.iter().all(|v| v.is_finite()))
            && self.normal.as_ref().is_none_or(Normal::is_finite)
    }
}

/// Minimise ‖r(x)‖² from `x0`. `residuals` returns the residual vector (always of the
/// same length) or an error; an error or a non-finite entry rejects the trial. Fails only
/// when the starting point itself cannot be evaluated. The Jacobian is a forward
/// difference (columns in parallel).
pub fn levenberg_marquardt<F>(
    residuals: &F,
    x0: &[f64],
    opts: &LmOptions,
) -> Result<LmOutcome, FitError>
where
    F: Fn(&[f64]) -> Result<Vec<f64>, FitError> + Sync,
{
    let trial = |x: &[f64]| {
        residuals(x).map(|r| Trial { cost: cost_of(&r), residuals: Some(r), normal: None })
    };
    lm_core(&trial, Some(residuals), x0, opts)
}

/// [`levenberg_marquardt`] for a model that returns its exact Jacobian with the
/// residuals: `model(x)` gives `(r, J)` with J's columns ∂model/∂x_j (r = data − model).
/// Every trial evaluates both, so an accepted step needs no further pass.
pub fn levenberg_marquardt_exact<F>(
    model: &F,
    x0: &[f64],
    opts: &LmOptions,
) -> Result<LmOutcome, FitError>
where
    F: Fn(&[f64]) -> Result<(Vec<f64>, Vec<Vec<f64>>), FitError> + Sync,
{
    let trial = |x: &[f64]| {
        model(x).map(|(r, j)| Trial {
            cost: cost_of(&r),
            normal: Some(Normal::from_columns(&j, &r)),
            residuals: None,
        })
    };
    lm_core::<_, fn(&[f64]) -> Result<Vec<f64>, FitError>>(&trial, None, x0, opts)
}

/// A model giving its cost and normal equations, as the trials the LM core evaluates.
fn normal_trial<F>(model: &F) -> impl Fn(&[f64]) -> Result<Trial, FitError> + Sync + '_
where
    F: Fn(&[f64]) -> Result<(f64, Normal), FitError> + Sync,
{
    |x: &[f64]| model(x).map(|(cost, normal)| Trial { cost, normal: Some(normal), residuals: None })
}

/// [`levenberg_marquardt_exact`] for a model that forms its own normal equations:
/// `model(x)` gives the cost ‖r‖² and [`Normal`] at x (no n-long vector crosses the
/// interface, so a model can keep its buffers).
///
/// `bounds` gives (lower, upper) bounds of the first parameters (the rest, and every one
/// when it is empty, are unbounded; ±∞ means none on that side). The bounds are kept by an
/// active set: a parameter on a bound whose descent direction points out of the box is
/// held there for the step, and a step that would cross a bound is projected onto it, so
/// an optimum on a bound is reached exactly (in a few steps, where a logarithm would only
/// approach it).
pub fn levenberg_marquardt_normal<F>(
    model: &F,
    x0: &[f64],
    bounds: &[(f64, f64)],
    opts: &LmOptions,
) -> Result<LmOutcome, FitError>
where
    F: Fn(&[f64]) -> Result<(f64, Normal), FitError> + Sync,
{
    let trial = normal_trial(model);
    lm_core_step::<_, fn(&[f64]) -> Result<Vec<f64>, FitError>>(
        &trial,
        None,
        Start::At(x0),
        bounds,
        opts,
        None,
    )
    .map(ran_to_end)
}

/// A refinement stopped after a given number of iterations, to be resumed exactly where
/// it stood ([`lm_normal_resume`]).
pub struct LmPaused {
    x: Vec<f64>,
    current: Trial,
    lambda: f64,
    radius: f64,
    secant: Option<Secant>,
    iterations: usize,
    evaluations: usize,
    failed: usize,
}

impl LmPaused {
    /// The cost ‖r‖² at the point reached.
    pub fn cost(&self) -> f64 {
        self.current.cost
    }
    /// Iterations done so far.
    pub fn iterations(&self) -> usize {
        self.iterations
    }
    /// Evaluations so far.
    pub fn evaluations(&self) -> usize {
        self.evaluations
    }
    /// Trials that failed so far.
    pub fn failed_trials(&self) -> usize {
        self.failed
    }
    /// The point reached.
    pub fn x(&self) -> &[f64] {
        &self.x
    }
}

/// A refinement that ended, or one paused before its end.
pub enum LmStep {
    /// It ended (converged, stuck or out of budget).
    Done(LmOutcome),
    /// It was paused after the asked number of iterations.
    Paused(LmPaused),
}

/// [`levenberg_marquardt_normal`] from `x0`, paused after `pause_after` iterations unless
/// it ends before; the pause changes nothing of the run resumed by [`lm_normal_resume`].
pub fn lm_normal_paused<F>(
    model: &F,
    x0: &[f64],
    bounds: &[(f64, f64)],
    opts: &LmOptions,
    pause_after: usize,
) -> Result<LmStep, FitError>
where
    F: Fn(&[f64]) -> Result<(f64, Normal), FitError> + Sync,
{
    let trial = normal_trial(model);
    lm_core_step::<_, fn(&[f64]) -> Result<Vec<f64>, FitError>>(
        &trial,
        None,
        Start::At(x0),
        bounds,
        opts,
        Some(pause_after),
    )
}

/// Resume a paused [`lm_normal_paused`] run to its end, with the same `model`, `bounds`
/// and `opts`.
pub fn lm_normal_resume<F>(
    model: &F,
    paused: LmPaused,
    bounds: &[(f64, f64)],
    opts: &LmOptions,
) -> Result<LmOutcome, FitError>
where
    F: Fn(&[f64]) -> Result<(f64, Normal), FitError> + Sync,
{
    let trial = normal_trial(model);
    lm_core_step::<_, fn(&[f64]) -> Result<Vec<f64>, FitError>>(
        &trial,
        None,
        Start::Resume(Box::new(paused)),
        bounds,
        opts,
        None,
    )
    .map(ran_to_end)
}

/// Where [`lm_core`] begins.
enum Start<'a> {
    At(&'a [f64]),
    Resume(Box<LmPaused>),
}

/// [`lm_core_step`] run to its end.
fn lm_core<T, F>(
    model: &T,
    residuals: Option<&F>,
    x0: &[f64],
    opts: &LmOptions,
) -> Result<LmOutcome, FitError>
where
    T: Fn(&[f64]) -> Result<Trial, FitError> + Sync,
    F: Fn(&[f64]) -> Result<Vec<f64>, FitError> + Sync,
{
    lm_core_step(model, residuals, Start::At(x0), &[], opts, None).map(ran_to_end)
}

/// The outcome of a run asked for no pause.
fn ran_to_end(step: LmStep) -> LmOutcome {
    match step {
        LmStep::Done(out) => out,
        LmStep::Paused(_) => unreachable!("no pause was asked"),
    }
}

fn lm_core_step<T, F>(
    model: &T,
    residuals: Option<&F>,
    start: Start,
    bounds: &[(f64, f64)],
    opts: &LmOptions,
    pause_after: Option<usize>,
) -> Result<LmStep, FitError>
where
    T: Fn(&[f64]) -> Result<Trial, FitError> + Sync,
    F: Fn(&[f64]) -> Result<Vec<f64>, FitError> + Sync,
{
    let (done_evals, done_failed) = match &start {
        Start::At(_) => (0, 0),
        Start::Resume(p) => (p.evaluations, p.failed),
    };
    let evaluations = AtomicUsize::new(done_evals);
    let failed = AtomicUsize::new(done_failed);
    let eval = |x: &[f64]| -> Option<Trial> {
        evaluations.fetch_add(1, Ordering::Relaxed);
        match model(x) {
            Ok(t) if t.finite() => Some(t),
            _ => {
                failed.fetch_add(1, Ordering::Relaxed);
                None
            }
        }
    };
    let eval_r = |x: &[f64]| -> Option<Vec<f64>> {
        evaluations.fetch_add(1, Ordering::Relaxed);
        match residuals.map(|f| f(x)) {
            Some(Ok(r)) if r.iter().all(|v| v.is_finite()) => Some(r),
            _ => {
                failed.fetch_add(1, Ordering::Relaxed);
                None
            }
        }
    };
    let (mut x, mut current, mut lambda, mut radius, mut secant, mut iterations) = match start {
        Start::At(x0) => {
            let current = match model(x0) {
                Ok(t) if t.finite() => t,
                Ok(_) => {
                    return Err(FitError::Optimiser(
                        "the starting point gives non-finite residuals".into(),
                    ));
                }
                Err(e) => {
                    return Err(FitError::Optimiser(format!(
                        "the starting point fails: {}",
                        chain(&e)
                    )));
                }
            };
            evaluations.fetch_add(1, Ordering::Relaxed);
            // Trust radius: the largest move of any parameter; halved with every rejected
            // trial, so a failing region is backed away from even where the gradient says
            // nothing.
            let secant = opts.secant.then(|| Secant::new(x0.len()));
            (x0.to_vec(), current, 1e-3, opts.max_step, secant, 0)
        }
        Start::Resume(s) => {
            let s = *s;
            (s.x, s.current, s.lambda, s.radius, s.secant, s.iterations)
        }
    };
    let p = x.len();
    let mut cost = current.cost;
    let mut termination = format!("iteration budget of {} reached", opts.max_iterations);
    if p == 0 {
        termination = "no free parameter".into();
    }
    let mut converged = false;
    while p > 0 && !converged && iterations < opts.max_iterations {
        if pause_after == Some(iterations) {
            return Ok(LmStep::Paused(LmPaused {
                x,
                current,
                lambda,
                radius,
                secant,
                iterations,
                evaluations: evaluations.into_inner(),
                failed: failed.into_inner(),
            }));
        }
        iterations += 1;
        let Normal { jtj: a, jtr: g } = match (current.normal.take(), &current.residuals) {
            (Some(normal), _) => normal,
            (None, Some(r)) => {
                // Forward-difference Jacobian, one column per parameter, in parallel; a
                // column whose trial fails is tried backwards, then left at zero (frozen
                // this iteration).
                let h = opts.fd_step;
                let columns: Vec<Vec<f64>> = (0..p)
                    .into_par_iter()
                    .map(|j| {
                        for step in [h, -h] {
                            let mut xj = x.clone();
                            xj[j] += step;
                            if let Some(rj) = eval_r(&xj) {
                                // Residual = data − model, so ∂model/∂x = −∂r/∂x.
                                return rj.iter().zip(r).map(|(a, b)| -(a - b) / step).collect();
                            }
                        }
                        vec![0.0; r.len()]
                    })
                    .collect();
                Normal::from_columns(&columns, r)
            }
            (None, None) => unreachable!("a trial carries its residuals or its normal equations"),
        };
        let diag: Vec<f64> = (0..p).map(|k| a[(k, k)].max(1e-300)).collect();
        if let Some(sec) = secant.as_mut() {
            sec.update(&a, &g);
        }
        let model = secant.as_ref().and_then(|sec| sec.hessian(&a));
        // The active set: on a bound with the descent direction (+Jᵀr) pointing out of the
        // box. Those parameters do not move this iteration.
        let bound = |k: usize| bounds.get(k).copied().unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
        let held: Vec<bool> = (0..p)
            .map(|k| (x[k] <= bound(k).0 && g[k] <= 0.0) || (x[k] >= bound(k).1 && g[k] >= 0.0))
            .collect();
        let mut g_free = g.clone();
        for k in (0..p).filter(|&k| held[k]) {
            g_free[k] = 0.0;
        }
        let mut accepted = false;
        let mut tries = 0;
        while !accepted && tries < 30 {
            tries += 1;
            let damped = |h: &DMatrix<f64>| {
                let mut m = h.clone();
                for k in 0..p {
                    m[(k, k)] += lambda * diag[k];
                }
                for k in (0..p).filter(|&k| held[k]) {
                    m.row_mut(k).fill(0.0);
                    m.column_mut(k).fill(0.0);
                    m[(k, k)] = 1.0;
                }
                m.cholesky()
            };
            // The augmented model where it is positive definite here, else Gauss–Newton's.
            let Some(chol) = model.as_ref().and_then(&damped).or_else(|| damped(&a)) else {
                lambda *= 10.0;
                continue;
            };
            let mut delta = chol.solve(&g_free);
            let largest = delta.amax();
            if !largest.is_finite() {
                lambda *= 10.0;
                continue;
            }
            if largest == 0.0 {
                // Every parameter that could lower the cost is held on its bound.
                termination = "on its bounds: no free direction lowers the cost".into();
                converged = true;
                accepted = true;
                break;
            }
            if largest > radius {
                delta *= radius / largest;
            }
            // Projected onto the bounds; the step is what was actually taken.
            let trial: Vec<f64> = x
                .iter()
                .zip(delta.iter())
                .enumerate()
                .map(|(k, (a, d))| (a + d).clamp(bound(k).0, bound(k).1))
                .collect();
            for k in 0..p {
                delta[k] = trial[k] - x[k];
            }
            match eval(&trial) {
                Some(t) if t.cost < cost => {
                    let new_cost = t.cost;
                    let gain = (cost - new_cost) / cost.max(f64::MIN_POSITIVE);
                    if let Some(sec) = secant.as_mut() {
                        sec.accepted(&delta, &a, &g, 0.5 * (cost - new_cost));
                    }
                    x = trial;
                    current = t;
                    cost = new_cost;
                    lambda = (lambda * 0.3).max(1e-12);
                    radius = (2.0 * radius).min(opts.max_step);
                    accepted = true;
                    if gain < opts.cost_tolerance {
                        termination = format!("cost change below {:e}", opts.cost_tolerance);
                        converged = true;
                    } else if delta.amax() < opts.step_tolerance {
                        termination = format!("step below {:e}", opts.step_tolerance);
                        converged = true;
                    }
                }
                _ => {
                    lambda *= 5.0;
                    radius *= 0.5;
                }
            }
        }
        if !accepted {
            termination = "no step lowers the cost further (local minimum)".into();
            break;
        }
    }
    Ok(LmStep::Done(LmOutcome {
        x,
        cost,
        iterations,
        evaluations: evaluations.into_inner(),
        failed_trials: failed.into_inner(),
        termination,
    }))
}

/// Whether an outcome's termination says the iteration budget ran out.
pub fn hit_budget(termination: &str) -> bool {
    termination.starts_with("iteration budget")
}

#[cfg(test)]
mod tests;
