//! Refining a set of starts to their ends, optionally with a race that stops the starts
//! far above the others early ([`DROP_FACTOR`] after [`RACE_ITERATIONS`]).

use super::{DROP_FACTOR, JointProblem, RACE_ITERATIONS};
use crate::error::{FitError, chain};
use crate::lm::{LmOptions, LmOutcome, LmStep};
use rayon::prelude::*;

/// One refined start.
pub(super) struct Refined {
    /// Every nonlinear value at the end (Tc, Ts, ωs, σ0, Tc_neg, Ts_neg) [N·m, N·m, rad/s,
    /// N·m/rad, N·m, N·m].
    pub(super) values: [f64; 6],
    /// Residual sum of squares there [N²·m²].
    pub(super) rss: f64,
    pub(super) iterations: usize,
    pub(super) evaluations: usize,
    pub(super) failed: usize,
    pub(super) termination: String,
    /// Stopped early as far above the other starts ([`DROP_FACTOR`]).
    pub(super) dropped: bool,
}

impl Refined {
    pub(super) fn from_outcome(problem: &JointProblem, out: LmOutcome) -> Self {
        Refined {
            values: problem.values(&out.x),
            rss: out.cost,
            iterations: out.iterations,
            evaluations: out.evaluations,
            failed: out.failed_trials,
            termination: out.termination,
            dropped: false,
        }
    }
}

/// What a set of starts gave.
pub(super) struct RaceOutcome {
    /// The lowest cost among the starts that ran to their end.
    pub(super) best: Option<Refined>,
    /// One line per start: how it ended.
    pub(super) ends: Vec<String>,
    pub(super) iterations: usize,
    pub(super) evaluations: usize,
    pub(super) failed: usize,
    /// Starts that could not be evaluated, with the reason.
    pub(super) start_failures: Vec<String>,
    /// Starts stopped early by the race.
    pub(super) dropped: usize,
    /// Where every evaluated start ended (stopped early or not), in the starts' order, with
    /// its RSS there [N²·m²].
    pub(super) end_values: Vec<([f64; 6], f64)>,
}

/// Refine every start of `starts` on `problem`. With `race`, every start first runs
/// [`RACE_ITERATIONS`] iterations and those whose cost is then above [`DROP_FACTOR`] × the
/// lowest any start reached (or `reference`, a cost already reached on the same objective,
/// if lower) stop there; the comparison is made at the same point for every start, so the
/// outcome does not depend on which thread ran first. Without `race`, every start runs to
/// its own end.
pub(super) fn refine_starts(
    problem: &JointProblem,
    starts: &[[f64; 6]],
    lm: &LmOptions,
    race: bool,
    reference: f64,
) -> RaceOutcome {
    let refined: Vec<Result<Refined, FitError>> = if race {
        let first: Vec<Result<LmStep, FitError>> = starts
            .par_iter()
            .map(|v| problem.refine_paused(&problem.x_of(v), lm, RACE_ITERATIONS))
            .collect();
        let lowest = first
            .iter()
            .filter_map(|r| match r {
                Ok(LmStep::Done(out)) => Some(out.cost),
                Ok(LmStep::Paused(p)) => Some(p.cost()),
                Err(_) => None,
            })
            .fold(reference, f64::min);
        first
            .into_par_iter()
            .map(|r| match r? {
                LmStep::Done(out) => Ok(Refined::from_outcome(problem, out)),
                LmStep::Paused(p) if p.cost() > DROP_FACTOR * lowest => Ok(Refined {
                    values: problem.values(p.x()),
                    rss: p.cost(),
                    iterations: p.iterations(),
                    evaluations: p.evaluations(),
                    failed: p.failed_trials(),
                    termination: format!(
                        "stopped after {} iterations: RSS {:.6e} above {DROP_FACTOR} × the lowest of all starts then or before ({lowest:.6e})",
                        p.iterations(),
                        p.cost()
                    ),
                    dropped: true,
                }),
                LmStep::Paused(p) => Ok(Refined::from_outcome(problem, problem.resume(p, lm)?)),
            })
            .collect()
    } else {
        starts
            .par_iter()
            .map(|v| Ok(Refined::from_outcome(problem, problem.refine(&problem.x_of(v), lm)?)))
            .collect()
    };
    let ends: Vec<String> = refined
        .iter()
        .map(|r| match r {
            Ok(r) if r.dropped => r.termination.clone(),
            Ok(r) => {
                format!("RSS {:.6e} after {} iterations ({})", r.rss, r.iterations, r.termination)
            }
            Err(e) => format!("could not be evaluated: {}", chain(e)),
        })
        .collect();
    let mut out = RaceOutcome {
        best: None,
        dropped: ends.iter().filter(|e| e.starts_with("stopped after")).count(),
        ends,
        iterations: 0,
        evaluations: 0,
        failed: 0,
        start_failures: Vec::new(),
        end_values: Vec::new(),
    };
    for r in refined {
        match r {
            Ok(r) => {
                out.iterations += r.iterations;
                out.evaluations += r.evaluations;
                out.failed += r.failed;
                out.end_values.push((r.values, r.rss));
                if !r.dropped && out.best.as_ref().is_none_or(|b| r.rss < b.rss) {
                    out.best = Some(r);
                }
            }
            Err(e) => out.start_failures.push(chain(&e)),
        }
    }
    out
}
