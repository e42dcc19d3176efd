//! How much of the seed case's equal-error run is the model itself (issue #18's scipy
//! target): the run that first reaches an error of 1e-6 of the amplitude (the fifth-order
//! implicit–explicit pair at rtol 5e-6, atol 5e-9, 1 s from rest) beside the same number of
//! right-hand-side evaluations with no solver around them.
//!
//! - `solve_imex5`: the solve alone (no metrics, no trace);
//! - `simulate_auto`: what `benches/peers.py` times (`simulate` with `auto`, metrics on);
//! - `stages_only`: as many implicit stages (`implicit_stage`, one evaluation of the laws
//!   each) as `solve_imex5` evaluates, at the states and step sizes that solve visited, each
//!   fed by the previous one's rates as a stage is. What is left of `solve_imex5`'s time is
//!   the solver's own work: combining the stages, the error norm, step control and kinks.
//!
//! `cargo bench -p hd-model --bench stage_floor` (about 20 s).

use criterion::{Criterion, criterion_group, criterion_main};
use hd_model::solver::{OdeSystem, Step, solve};
use hd_model::state::{OMEGA_J, State, W};
use hd_model::{DriveSystem, Method, SimConfig, SolverOptions, Variant, simulate};
use std::hint::black_box;
use std::time::Duration;

/// The equal-error tolerances: the loosest of `peers.py`'s grid whose error is ≤ 1e-6 of the
/// amplitude for `auto` and the fifth-order pair (measured 4.8e-7 and 4.7e-7).
const RTOL: f64 = 5e-6;
/// Diagonal γ of the fifth-order pair's implicit part [–].
const GAMMA: f64 = 41.0 / 200.0;

fn config(method: Method) -> SimConfig {
    SimConfig {
        variant: Variant::Full,
        t_end: 1.0,
        record_trace: false,
        solver: SolverOptions { method, rtol: RTOL, atol: RTOL * 1e-3, ..SolverOptions::default() },
        ..SimConfig::default()
    }
}

/// The solve's accepted steps as (start time [s], length [s], start state), and its number
/// of right-hand-side evaluations.
fn visited(sys: &DriveSystem, cfg: &SimConfig) -> (Vec<(f64, f64, State)>, u64) {
    let mut steps = Vec::new();
    let mut obs = |s: &Step<{ hd_model::state::DIM }>| steps.push((s.t0, s.t1 - s.t0, *s.y0));
    let (_, stats) =
        solve(sys, 0.0, sys.rest_state(), cfg.t_end, &cfg.breakpoints(), &cfg.solver, &mut obs)
            .expect("the seed case solves");
    (steps, stats.rhs_evals)
}

/// `n` implicit stages over the visited steps in turn, each stage's input carrying a
/// dependence on the previous stage's rate too small to change it (as a stage's input
/// depends on the stage before).
fn stages(sys: &DriveSystem, steps: &[(f64, f64, State)], n: u64) -> f64 {
    let mut rate = State::zeros();
    let mut acc = 0.0;
    for k in 0..n as usize {
        let (t, h, y) = &steps[k % steps.len()];
        let mut yi = *y;
        yi[OMEGA_J] += 1e-300 * rate[OMEGA_J];
        acc += sys.implicit_stage(*t, &mut yi, W, h * GAMMA, &mut rate);
    }
    acc
}

fn equal_error(c: &mut Criterion) {
    let cfg = config(Method::Imex5);
    let sys = cfg.system().expect("seed system");
    let (steps, evals) = visited(&sys, &cfg);
    let mut g = c.benchmark_group("seed_equal_error");
    g.sample_size(30).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(4));
    let bp = cfg.breakpoints();
    g.bench_function("solve_imex5", |b| {
        b.iter(|| {
            let mut obs = |_: &Step<{ hd_model::state::DIM }>| {};
            solve(&sys, 0.0, sys.rest_state(), 1.0, &bp, &cfg.solver, &mut obs).map(|r| r.0)
        })
    });
    let auto = config(Method::Auto);
    g.bench_function("simulate_auto", |b| {
        b.iter(|| simulate(black_box(&auto)).expect("runs").metrics.thz_amp)
    });
    g.bench_function("stages_only", |b| b.iter(|| stages(&sys, black_box(&steps), evals)));
    g.finish();
}

criterion_group!(benches, equal_error);
criterion_main!(benches);
