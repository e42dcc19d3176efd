//! The global stage: a one-dimensional search over the logarithm of the nonlinear
//! parameter. A grid over the whole practical range finds every basin; argmin's Brent
//! minimiser then refines the best few grid minima (a multi-start), and the best of those
//! wins. So the result does not hang on an initial guess.

use crate::error::FitError;
use argmin::core::{CostFunction, Executor, State};
use argmin::solver::brent::BrentOpt;
use rayon::prelude::*;

/// Grid points over the search range.
pub const GRID_POINTS: usize = 48;
/// Grid minima refined by Brent's method.
pub const STARTS: usize = 3;
/// Brent iteration budget per start.
pub const MAX_ITERS: u64 = 200;

/// Result of [`search_log`].
#[derive(Clone, Debug, PartialEq)]
pub struct SearchOutcome {
    /// Best parameter value found.
    pub value: f64,
    /// Cost there.
    pub cost: f64,
    /// Brent iterations summed over all starts.
    pub iterations: u64,
    /// Cost evaluations (grid plus refinement).
    pub evaluations: u64,
    /// How the winning start ended (argmin's termination reason).
    pub termination: String,
    /// Number of refined starts.
    pub starts: usize,
    /// Whether the best value lies at an edge of the searched range.
    pub at_edge: bool,
    /// Searched range, low end.
    pub lo: f64,
    /// Searched range, high end.
    pub hi: f64,
    /// Trials whose evaluation failed or was not finite (counted as the worst cost).
    pub failed_trials: u64,
    /// The first failure's message, when there was one.
    pub first_failure: Option<String>,
}

/// Cost given to a trial whose evaluation failed (the integration broke down or the
/// result was not finite): worse than any real cost, yet finite so that Brent's
/// parabolic steps stay defined. A failed trial is a bad trial, never a failed fit.
pub const FAILED_TRIAL_COST: f64 = 1e300;

/// The cost as a function of u = ln(value), for argmin; failed trials cost
/// [`FAILED_TRIAL_COST`].
struct LogCost<'a> {
    f: &'a (dyn Fn(f64) -> Result<f64, FitError> + Sync),
    failed: &'a std::sync::atomic::AtomicU64,
}

impl CostFunction for LogCost<'_> {
    type Param = f64;
    type Output = f64;
    fn cost(&self, u: &f64) -> Result<f64, argmin::core::Error> {
        match (self.f)(u.exp()) {
            Ok(c) if c.is_finite() => Ok(c),
            _ => {
                self.failed.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                Ok(FAILED_TRIAL_COST)
            }
        }
    }
}

/// Minimise `f(value)` for `value` in `[lo, hi]` (both > 0): a grid in ln(value), then
/// Brent's method (argmin `BrentOpt`) from the best [`STARTS`] grid minima.
pub fn search_log(
    f: &(dyn Fn(f64) -> Result<f64, FitError> + Sync),
    lo: f64,
    hi: f64,
) -> Result<SearchOutcome, FitError> {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return Err(FitError::Optimiser(format!("invalid search range [{lo}, {hi}]")));
    }
    let (u_lo, u_hi) = (lo.ln(), hi.ln());
    let step = (u_hi - u_lo) / (GRID_POINTS - 1) as f64;
    let grid: Vec<f64> = (0..GRID_POINTS).map(|i| u_lo + step * i as f64).collect();
    let evaluated: Vec<Result<f64, FitError>> = grid.par_iter().map(|u| f(u.exp())).collect();
    let mut first_error: Option<FitError> = None;
    let mut failed_grid = 0u64;
    let costs: Vec<f64> = evaluated
        .into_iter()
        .map(|r| match r {
            Ok(c) if c.is_finite() => c,
            Ok(_) => {
                failed_grid += 1;
                f64::INFINITY
            }
            Err(e) => {
                failed_grid += 1;
                first_error.get_or_insert(e);
                f64::INFINITY
            }
        })
        .collect();
    if costs.iter().all(|c| !c.is_finite()) {
        let why = first_error.map_or_else(
            || "the cost was not finite".to_string(),
            |e| format!("the first failure: {}", crate::error::chain(&e)),
        );
        return Err(FitError::NoFiniteTrial {
            trials: GRID_POINTS,
            range: format!("[{lo:.3e}, {hi:.3e}]"),
            why,
        });
    }
    let failed = std::sync::atomic::AtomicU64::new(failed_grid);
    let mut minima: Vec<usize> = (0..GRID_POINTS)
        .filter(|&i| {
            costs[i].is_finite()
                && (i == 0 || costs[i] <= costs[i - 1])
                && (i + 1 == GRID_POINTS || costs[i] <= costs[i + 1])
        })
        .collect();
    minima.sort_by(|&a, &b| costs[a].total_cmp(&costs[b]));
    minima.truncate(STARTS);

    let mut best_u = grid[minima[0]];
    let mut best_cost = costs[minima[0]];
    let mut termination = "grid point (no refinement improved it)".to_string();
    let mut iterations = 0;
    let mut evaluations = GRID_POINTS as u64;
    // The refinements are independent: run them in parallel, then take them in order.
    let runs: Vec<_> = minima
        .par_iter()
        .map(|&i| {
            let a = grid[i.saturating_sub(1)];
            let b = grid[(i + 1).min(GRID_POINTS - 1)];
            let solver = BrentOpt::new(a, b).set_tolerance(1.5e-8, 1e-8);
            let cost_fn = LogCost { f, failed: &failed };
            Executor::new(cost_fn, solver).configure(|s| s.max_iters(MAX_ITERS)).run()
        })
        .collect();
    for run in runs {
        let res = match run {
            Ok(r) => r,
            Err(e) => match e.downcast::<FitError>() {
                Ok(fe) => return Err(fe),
                Err(other) => return Err(FitError::Optimiser(other.to_string())),
            },
        };
        let state = res.state();
        iterations += state.get_iter();
        evaluations += res.problem.counts.get("cost_count").copied().unwrap_or(0);
        let cost = state.get_best_cost();
        if let Some(&u) = state.get_best_param()
            && cost < best_cost
        {
            best_u = u;
            best_cost = cost;
            termination = state.get_termination_status().to_string();
        }
    }
    let at_edge = (best_u - u_lo) < 0.05 * step || (u_hi - best_u) < 0.05 * step;
    Ok(SearchOutcome {
        value: best_u.exp(),
        cost: best_cost,
        iterations,
        evaluations,
        termination,
        starts: minima.len(),
        at_edge,
        lo,
        hi,
        failed_trials: failed.into_inner(),
        first_failure: first_error.map(|e| crate::error::chain(&e)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_global_of_two_minima() {
        // Two basins in ln x: a shallow one near x = 2 and the deeper one near x = 300.
        let f = |x: f64| -> Result<f64, FitError> {
            let u = x.ln();
            Ok(1.0
                - 0.5 * (-(u - 2f64.ln()).powi(2)).exp()
                - (-(u - 300f64.ln()).powi(2) / 0.5).exp())
        };
        let out = search_log(&f, 0.1, 1e5).unwrap();
        assert!((out.value / 300.0 - 1.0).abs() < 1e-5, "{out:?}");
        assert!(!out.at_edge);
        assert!(out.starts >= 2);
    }

    #[test]
    fn failing_trials_do_not_end_the_search() {
        // The cost cannot be evaluated below x = 50 (as an integration that breaks down
        // for soft trial values would); the minimum at x = 80 is found all the same.
        let f = |x: f64| -> Result<f64, FitError> {
            if x < 50.0 {
                return Err(FitError::Optimiser("step size too small".into()));
            }
            Ok((x.ln() - 80f64.ln()).powi(2))
        };
        let out = search_log(&f, 1.0, 1e4).unwrap();
        assert!((out.value / 80.0 - 1.0).abs() < 1e-5, "{out:?}");
        assert!(out.failed_trials >= 20, "{out:?}");
        assert!(out.first_failure.as_deref().is_some_and(|m| m.contains("step size")));
        // Nothing finite at all: one clear error.
        let never =
            |_: f64| -> Result<f64, FitError> { Err(FitError::Optimiser("diverged".into())) };
        let e = search_log(&never, 1.0, 1e4).unwrap_err();
        assert!(e.to_string().contains("no trial gave a finite cost"), "{e}");
    }
}
