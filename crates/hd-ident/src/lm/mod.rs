//! The identifier's one optimiser: Levenberg–Marquardt within box bounds on exact
//! Jacobians, for every fit (the friction and stiffness laws, the rigid and the compliant
//! drive). A problem gives its normal equations and its cost at a point ([`LeastSquares`]);
//! a point where the model cannot be evaluated — an integration that breaks down, a
//! non-finite value — is a rejected trial, never the end of the fit.
//!
//! Each iteration solves the damped normal equations (JᵀJ + λD)δ = −Jᵀr with Marquardt's
//! diagonal scaling D = diag JᵀJ, so parameters of very different size are treated alike.
//! Bounds are kept by an active set: a parameter on a bound whose descent direction points
//! out of the box is held there for the step, and a step that would cross a bound is
//! projected onto it, so an optimum on a bound is reached exactly. Options add a trust
//! radius on the largest move ([`LmOptions::max_step`]), the geodesic acceleration
//! ([`LmOptions::geodesic`]), a secant estimate of the curvature Gauss–Newton leaves out
//! ([`LmOptions::secant`], [`secant`]), and a pause after a number of iterations that a
//! resume continues bit for bit ([`minimise_paused`], [`resume`], [`resume_until`]; the
//! `argmin_frame` example drives it through argmin's `Executor` one iteration at a time).

mod engine;
mod problem;
pub(crate) mod secant;

use crate::error::FitError;
pub use engine::{LmPaused, LmStep};
pub use problem::{Accumulator, Columns, Formed, LeastSquares, Normal, WithJacobian, not_finite};

/// Settings of the minimiser.
#[derive(Clone, Debug, PartialEq)]
pub struct LmOptions {
    /// Iteration budget (step searches, one Jacobian each).
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this share.
    pub cost_tolerance: f64,
    /// Stop when no parameter moves by more than this (0: never).
    pub step_tolerance: f64,
    /// Largest move of any parameter in one step, the trust radius's ceiling (halved with
    /// every rejected trial, doubled with every accepted one up to this); ∞: none.
    pub max_step: f64,
    /// Estimate the residual curvature that Gauss–Newton leaves out from the steps taken
    /// and use it where it predicts better ([`secant`]).
    pub secant: bool,
    /// Add the geodesic acceleration to each step (Transtrum and Sethna, 2012): the
    /// residuals' second derivative along the step, from one more residual evaluation, bends
    /// the step along a curved valley. Steps whose acceleration is not small against their
    /// velocity (2‖a‖ > [`ACCELERATION_LIMIT`]·‖v‖, scaled norms) are taken without it.
    pub geodesic: bool,
    /// How λ moves.
    pub damping: Damping,
}

/// How the damping λ moves: multiplied by `accept` (not below `floor`) after an accepted
/// step, by `reject` after a trial that did not lower the cost, by `fail` after one that
/// could not be evaluated, by 10 when the damped matrix is not positive definite; at most
/// `tries` trials per iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Damping {
    /// Factor after an accepted step [–].
    pub accept: f64,
    /// Smallest λ [–].
    pub floor: f64,
    /// Factor after a rejected trial [–].
    pub reject: f64,
    /// Factor after a failed trial [–].
    pub fail: f64,
    /// Trials per iteration at most.
    pub tries: usize,
}

impl Damping {
    /// For logarithmic parameters under a trust radius (the friction and stiffness laws):
    /// λ falls slowly, a failed trial counts as a rejected one.
    pub const GUARDED: Damping =
        Damping { accept: 0.3, floor: 1e-12, reject: 5.0, fail: 5.0, tries: 30 };
    /// For simulated drives without a trust radius: λ falls faster after a success and
    /// rises faster after a trial the simulation could not run.
    pub const OPEN: Damping =
        Damping { accept: 0.2, floor: 1e-15, reject: 4.0, fail: 10.0, tries: 40 };
}

impl Default for LmOptions {
    /// For the laws' fits over logarithms: 60 iterations, cost tolerance 1e-9, step
    /// tolerance 1e-8, largest move 1.5 (a factor e^1.5 ≈ 4.5), [`Damping::GUARDED`].
    fn default() -> Self {
        Self {
            max_iterations: 60,
            cost_tolerance: 1e-9,
            step_tolerance: 1e-8,
            max_step: 1.5,
            secant: false,
            geodesic: false,
            damping: Damping::GUARDED,
        }
    }
}

impl LmOptions {
    /// For the drives' output-error fits: 100 iterations, cost tolerance 1e-10, no step
    /// tolerance and no trust radius, [`Damping::OPEN`].
    pub fn drive() -> Self {
        Self {
            max_iterations: 100,
            cost_tolerance: 1e-10,
            step_tolerance: 0.0,
            max_step: f64::INFINITY,
            secant: false,
            geodesic: false,
            damping: Damping::OPEN,
        }
    }
}

/// Largest ratio 2‖a‖/‖v‖ of a geodesic step's acceleration to its velocity [–].
pub const ACCELERATION_LIMIT: f64 = 0.75;

/// Finite step along the velocity, as a share of it, for the second derivative [–].
pub const ACCELERATION_STEP: f64 = 0.1;

/// Result of a minimisation.
#[derive(Clone, Debug, PartialEq)]
pub struct LmOutcome {
    /// The parameters at the best point found.
    pub x: Vec<f64>,
    /// Σ r² there.
    pub cost: f64,
    /// Iterations (step searches, one Jacobian each).
    pub iterations: usize,
    /// Evaluations of the problem (normal equations, costs and curvatures).
    pub evaluations: usize,
    /// Trials that could not be evaluated (counted as rejected steps).
    pub failed_trials: usize,
    /// Why the iteration stopped.
    pub termination: String,
}

/// No progress report.
pub fn silent(_: usize, _: f64) {}

/// Minimise Σr² of `problem` from `x0` within `bounds` ((lower, upper) of the first
/// parameters; the rest, and every one when it is empty, unbounded; ±∞ means none on that
/// side). `progress(iteration, cost)` is called at the start of each iteration. Fails
/// only when the starting point cannot be evaluated.
pub fn minimise(
    problem: &dyn LeastSquares,
    x0: &[f64],
    bounds: &[(f64, f64)],
    opts: &LmOptions,
    progress: &dyn Fn(usize, f64),
) -> Result<LmOutcome, FitError> {
    engine::run(problem, engine::Start::At(x0), bounds, opts, None, progress).map(LmStep::ended)
}

/// [`minimise`], paused after `pause_after` iterations unless it ends before; the pause
/// changes nothing of the run [`resume`] continues.
pub fn minimise_paused(
    problem: &dyn LeastSquares,
    x0: &[f64],
    bounds: &[(f64, f64)],
    opts: &LmOptions,
    pause_after: usize,
) -> Result<LmStep, FitError> {
    engine::run(problem, engine::Start::At(x0), bounds, opts, Some(pause_after), &silent)
}

/// Resume a paused [`minimise_paused`] run to its end, with the same problem, bounds and
/// options.
pub fn resume(
    problem: &dyn LeastSquares,
    paused: LmPaused,
    bounds: &[(f64, f64)],
    opts: &LmOptions,
) -> Result<LmOutcome, FitError> {
    resume_until(problem, paused, bounds, opts, None).map(LmStep::ended)
}

/// [`resume`], paused again once `pause_after` iterations are done in all (counting those
/// before the pause) unless it ends before: a run resumed one iteration at a time ends bit
/// for bit where the uninterrupted one does.
pub fn resume_until(
    problem: &dyn LeastSquares,
    paused: LmPaused,
    bounds: &[(f64, f64)],
    opts: &LmOptions,
    pause_after: Option<usize>,
) -> Result<LmStep, FitError> {
    let start = engine::Start::Resume(Box::new(paused));
    engine::run(problem, start, bounds, opts, pause_after, &silent)
}

/// (lower, upper) pairs of two bound vectors.
pub fn pairs(lower: &[f64], upper: &[f64]) -> Vec<(f64, f64)> {
    lower.iter().copied().zip(upper.iter().copied()).collect()
}

/// Whether an outcome's termination says the iteration budget ran out.
pub fn hit_budget(termination: &str) -> bool {
    termination.starts_with("iteration budget")
}

#[cfg(test)]
mod tests;
