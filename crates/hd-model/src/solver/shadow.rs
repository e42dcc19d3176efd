//! A trial candidate run in shadow: on a copy of the state, with an attempt budget and no
//! observer, so that `auto` can score it without its steps entering the solution (see
//! [`super::switching::Switcher::take_shadow`]).

use super::driver::{Budget, integrate};
use super::{Method, OdeSystem, SolverOptions, SolverStats, switching};
use nalgebra::SVector;

/// Run a trial's shadow candidate `m` from (t, y) with first step `h` on a copy of the
/// state, and return the time it advanced per counted attempt [s] (0 if it failed). The
/// copy is dropped: the solution never sees the shadow's steps.
#[allow(clippy::too_many_arguments)]
pub(super) fn run<const D: usize, S: OdeSystem<D>>(
    sys: &S,
    t: f64,
    y: &SVector<f64, D>,
    h: f64,
    t_end: f64,
    breakpoints: &[f64],
    opts: &SolverOptions,
    m: Method,
    shadow: switching::Shadow,
    stats: &mut SolverStats,
) -> f64 {
    let shadow_opts = SolverOptions { method: m, h_init: h, ..*opts };
    let budget = Budget {
        warmup: u64::from(shadow.warmup),
        total: u64::from(shadow.warmup + shadow.counted),
    };
    match integrate(sys, t, *y, t_end, breakpoints, &shadow_opts, &mut |_| {}, Some(budget)) {
        Ok(done) => {
            stats.rhs_evals += done.stats.rhs_evals;
            stats.jac_evals += done.stats.jac_evals;
            stats.lu_decomps += done.stats.lu_decomps;
            let attempts = done.stats.steps + done.stats.rejected;
            // A shadow that reached the end within its warm-up is scored on all of it.
            let (from, counted) = if attempts > budget.warmup {
                (done.t_warm, attempts - budget.warmup)
            } else {
                (t, attempts)
            };
            (done.t - from) / counted.max(1) as f64
        }
        Err(_) => 0.0,
    }
}
