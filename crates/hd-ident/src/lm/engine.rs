//! The iteration of [`super::minimise`]: damped steps on the normal equations, the active
//! set of bounds, the trust radius, the geodesic acceleration and the secant model, and
//! the state a paused run keeps.

use super::secant::Secant;
use super::{ACCELERATION_LIMIT, ACCELERATION_STEP, LeastSquares, LmOptions, LmOutcome, Normal};
use crate::error::{FitError, chain};
use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

/// A run stopped after a given number of iterations, to be resumed exactly where it stood
/// ([`super::resume`]).
pub struct LmPaused {
    x: Vec<f64>,
    /// The normal equations at `x` where the last trial carried them.
    normal: Option<Normal>,
    cost: f64,
    lambda: f64,
    radius: f64,
    secant: Option<Secant>,
    iterations: usize,
    evaluations: usize,
    failed: usize,
}

impl LmPaused {
    /// The cost Σr² at the point reached.
    pub fn cost(&self) -> f64 {
        self.cost
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

/// A run that ended, or one paused before its end.
pub enum LmStep {
    /// It ended (converged, stuck or out of budget).
    Done(LmOutcome),
    /// It was paused after the asked number of iterations.
    Paused(LmPaused),
}

impl LmStep {
    /// The outcome of a run asked for no pause.
    pub(super) fn ended(self) -> LmOutcome {
        match self {
            LmStep::Done(out) => out,
            LmStep::Paused(_) => unreachable!("no pause was asked"),
        }
    }
}

/// Where [`run`] begins.
pub(super) enum Start<'a> {
    At(&'a [f64]),
    Resume(Box<LmPaused>),
}

/// The iteration from `start`, paused after `pause_after` iterations if asked.
pub(super) fn run(
    problem: &dyn LeastSquares,
    start: Start,
    bounds: &[(f64, f64)],
    opts: &LmOptions,
    pause_after: Option<usize>,
    progress: &dyn Fn(usize, f64),
) -> Result<LmStep, FitError> {
    let bound = |k: usize| bounds.get(k).copied().unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
    let clamp = |x: &mut [f64]| {
        for (k, v) in x.iter_mut().enumerate() {
            *v = v.clamp(bound(k).0, bound(k).1);
        }
    };
    let mut s = match start {
        Start::At(x0) => {
            let mut x = x0.to_vec();
            clamp(&mut x);
            let normal = match problem.normal(&x) {
                Ok(n) if n.is_finite() => n,
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
            LmPaused {
                cost: normal.cost,
                normal: Some(normal),
                secant: opts.secant.then(|| Secant::new(x.len())),
                x,
                lambda: 1e-3,
                radius: opts.max_step,
                iterations: 0,
                evaluations: 1,
                failed: 0,
            }
        }
        Start::Resume(paused) => *paused,
    };
    let d = opts.damping;
    let p = s.x.len();
    let mut termination = format!("iteration budget of {} reached", opts.max_iterations);
    if p == 0 {
        termination = "no free parameter".into();
    }
    let mut converged = false;
    while p > 0 && !converged && s.iterations < opts.max_iterations {
        if pause_after == Some(s.iterations) {
            return Ok(LmStep::Paused(s));
        }
        let normal = match s.normal.take() {
            Some(n) => n,
            None => {
                s.evaluations += 1;
                match problem.normal(&s.x) {
                    Ok(n) if n.is_finite() => n,
                    _ => {
                        termination =
                            "the model could not be evaluated at the accepted point".into();
                        break;
                    }
                }
            }
        };
        s.iterations += 1;
        s.cost = normal.cost;
        progress(s.iterations, s.cost);
        let a = &normal.jtj;
        let g = -&normal.jtr; // the descent direction
        let diag: Vec<f64> = (0..p).map(|k| a[(k, k)].max(1e-300)).collect();
        if let Some(sec) = s.secant.as_mut() {
            sec.update(a, &g);
        }
        let augmented = s.secant.as_ref().and_then(|sec| sec.hessian(a));
        // The active set: on a bound with the descent direction pointing out of the box.
        // Those parameters do not move this iteration (projecting their step would bend
        // every other one).
        let x = &s.x;
        let held: Vec<bool> = (0..p)
            .map(|k| (x[k] <= bound(k).0 && g[k] <= 0.0) || (x[k] >= bound(k).1 && g[k] >= 0.0))
            .collect();
        let mut g_free = g.clone();
        for k in (0..p).filter(|&k| held[k]) {
            g_free[k] = 0.0;
        }
        let mut accepted = false;
        let mut tries = 0;
        while !accepted && tries < d.tries {
            tries += 1;
            let damped = |h: &DMatrix<f64>| {
                let mut m = h.clone();
                for k in 0..p {
                    m[(k, k)] += s.lambda * diag[k];
                }
                for k in (0..p).filter(|&k| held[k]) {
                    m.row_mut(k).fill(0.0);
                    m.column_mut(k).fill(0.0);
                    m[(k, k)] = 1.0;
                }
                m.cholesky()
            };
            // The augmented model where it is positive definite here, else Gauss–Newton's.
            let Some(chol) = augmented.as_ref().and_then(&damped).or_else(|| damped(a)) else {
                s.lambda *= 10.0;
                continue;
            };
            let mut delta = chol.solve(&g_free);
            let largest = delta.amax();
            if !largest.is_finite() {
                s.lambda *= 10.0;
                continue;
            }
            if largest == 0.0 {
                termination = "on its bounds: no free direction lowers the cost".into();
                converged = true;
                break;
            }
            if opts.geodesic {
                s.evaluations += 1;
                if let Some(acc) = acceleration(problem, &s.x, &delta, &chol, &held, &diag) {
                    delta += acc * 0.5;
                }
            }
            let largest = delta.amax();
            if largest > s.radius {
                delta *= s.radius / largest;
            }
            // Projected onto the bounds; the step is what was actually taken.
            let mut trial: Vec<f64> = s.x.iter().zip(delta.iter()).map(|(a, d)| a + d).collect();
            clamp(&mut trial);
            for k in 0..p {
                delta[k] = trial[k] - s.x[k];
            }
            s.evaluations += 1;
            let evaluated = if problem.normal_with_trial() {
                problem.normal(&trial).map(|n| (n.cost, Some(n)))
            } else {
                problem.cost(&trial).map(|c| (c, None))
            };
            match evaluated {
                Ok((new, n)) if new.is_finite() && n.as_ref().is_none_or(Normal::is_finite) => {
                    if new < s.cost {
                        let gain = (s.cost - new) / s.cost.max(f64::MIN_POSITIVE);
                        if let Some(sec) = s.secant.as_mut() {
                            sec.accepted(&delta, a, &g, 0.5 * (s.cost - new));
                        }
                        s.x = trial;
                        s.normal = n;
                        s.cost = new;
                        s.lambda = (s.lambda * d.accept).max(d.floor);
                        s.radius = (2.0 * s.radius).min(opts.max_step);
                        accepted = true;
                        if gain < opts.cost_tolerance {
                            termination = format!("cost change below {:e}", opts.cost_tolerance);
                            converged = true;
                        } else if delta.amax() < opts.step_tolerance {
                            termination = format!("step below {:e}", opts.step_tolerance);
                            converged = true;
                        }
                    } else {
                        s.lambda *= d.reject;
                        s.radius *= 0.5;
                    }
                }
                _ => {
                    s.failed += 1;
                    s.lambda *= d.fail;
                    s.radius *= 0.5;
                }
            }
        }
        if !accepted && !converged {
            termination = "no step lowers the cost further (local minimum)".into();
            break;
        }
    }
    Ok(LmStep::Done(LmOutcome {
        x: s.x,
        cost: s.cost,
        iterations: s.iterations,
        evaluations: s.evaluations,
        failed_trials: s.failed,
        termination,
    }))
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
    chol: &Cholesky<f64, Dyn>,
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
