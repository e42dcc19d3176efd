//! Time the harmonic-drive full model on diffsol's solvers and compare θz with hd-model.
//!
//! ```text
//! cargo run --release -- <hd-model.json> [<reference.json>] [reps] [methods]
//! ```
//! `hd-model.json` is the output of hd-model's `bench_case` example; it fixes the case
//! (rtol, atol, t_end) and the θz grid. `reference.json` (optional) is a tight hd-model run
//! of the same case used to report each solver's own error. `methods` is a comma list of
//! bdf, esdirk34, tr_bdf2, tsit45 (default bdf,esdirk34,tsit45); `bdf:nolimit` (any
//! implicit method) lifts `max_nonlinear_solver_failures`, which diffsol 0.18 counts over the
//! whole run rather than per step.

mod model;

use diffsol::{
    NalgebraLU, NalgebraMat, OdeBuilder, OdeEquations, OdeSolverMethod, OdeSolverStopReason, Vector,
};
use std::time::Instant;

type M = NalgebraMat<f64>;
type LS = NalgebraLU<f64>;

/// What one solve produced.
struct RunOut {
    steps: usize,
    rejected: usize,
    newton_iters: usize,
    lu_setups: usize,
    thz: Vec<f64>,
}

/// Step `s` to `t_end`, sampling θz on `grid` (if given) by the solver's interpolant.
fn drive<'a, Eqn, S>(mut s: S, t_end: f64, grid: Option<&[f64]>) -> Result<RunOut, String>
where
    Eqn: OdeEquations<T = f64> + 'a,
    S: OdeSolverMethod<'a, Eqn>,
{
    s.set_stop_time(t_end).map_err(|e| e.to_string())?;
    let mut thz = Vec::new();
    let mut k = 0;
    if let Some(g) = grid {
        while k < g.len() && g[k] <= 0.0 {
            thz.push(model::theta_z(&s.state().y.clone_as_vec()));
            k += 1;
        }
    }
    loop {
        let reason = s.step().map_err(|e| format!("t = {}: {e}", s.state().t))?;
        if let Some(g) = grid {
            let t = s.state().t;
            while k < g.len() && g[k] <= t {
                let y = s.interpolate(g[k]).map_err(|e| e.to_string())?;
                thz.push(model::theta_z(&y.clone_as_vec()));
                k += 1;
            }
        }
        if matches!(reason, OdeSolverStopReason::TstopReached) {
            break;
        }
    }
    let st = s.get_statistics();
    Ok(RunOut {
        steps: st.number_of_steps,
        rejected: st.number_of_error_test_failures,
        newton_iters: st.number_of_nonlinear_solver_iterations,
        lu_setups: st.number_of_linear_solver_setups,
        thz,
    })
}

/// Build the problem and solve it with `method` (the build is inside the timed region, as
/// hd-model's `simulate` includes its own setup).
fn solve(
    method: &str,
    rtol: f64,
    atol: f64,
    t_end: f64,
    grid: Option<&[f64]>,
) -> Result<RunOut, String> {
    // `name:nolimit` lifts diffsol's cap on Newton failures, which counts over the whole run.
    let (method, no_limit) = match method.split_once(':') {
        Some((m, "nolimit")) => (m, true),
        _ => (method, false),
    };
    let mut problem = OdeBuilder::<M>::new()
        .rtol(rtol)
        .atol(model::atol_vector(atol))
        .rhs_implicit(model::rhs, model::jac_vec)
        .init(model::init, model::NX)
        .build()
        .map_err(|e| e.to_string())?;
    if no_limit {
        problem.ode_options.max_nonlinear_solver_failures = usize::MAX;
    }
    let e = |e: diffsol::DiffsolError| e.to_string();
    match method {
        "bdf" => drive(problem.bdf::<LS>().map_err(e)?, t_end, grid),
        "esdirk34" => drive(problem.esdirk34::<LS>().map_err(e)?, t_end, grid),
        "tr_bdf2" => drive(problem.tr_bdf2::<LS>().map_err(e)?, t_end, grid),
        "tsit45" => drive(problem.tsit45().map_err(e)?, t_end, grid),
        other => Err(format!("unknown method {other}")),
    }
}

fn read_json(path: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn floats(v: &serde_json::Value, key: &str) -> Vec<f64> {
    v[key]
        .as_array()
        .unwrap_or_else(|| panic!("no array {key}"))
        .iter()
        .map(|x| x.as_f64().unwrap_or(f64::NAN))
        .collect()
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "grids differ");
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let hd = read_json(
        args.first().expect("usage: diffsol-compare <hd-model.json> [ref.json] [reps] [methods]"),
    );
    let reference = args.get(1).filter(|s| !s.is_empty() && *s != "-").map(|p| read_json(p));
    let reps: usize = args.get(2).map_or(5, |s| s.parse().expect("reps"));
    let methods = args.get(3).map_or("bdf,esdirk34,tsit45", String::as_str);

    let num = |k: &str| hd[k].as_f64().unwrap_or_else(|| panic!("no number {k}"));
    let (rtol, atol, t_end, amp) = (num("rtol"), num("atol"), num("t_end"), num("thz_amp"));
    let grid = floats(&hd, "t");
    let hd_thz = floats(&hd, "theta_z");
    let ref_thz = reference.as_ref().map(|r| floats(r, "theta_z"));
    let hd_wall = num("wall_best_s");

    println!(
        "case: full model, t_end {t_end} s, rtol {rtol:e}, atol {atol:e} (θ: atol/(c+A)); \
         θz grid {} points; amplitude {amp:.6e} rad",
        grid.len()
    );
    println!(
        "{:<22} {:>10} {:>7} {:>8} {:>8} {:>9} {:>8} {:>16} {:>11}",
        "solver",
        "wall [s]",
        "x hd",
        "steps",
        "rejected",
        "newton",
        "LU",
        "max|Δθz|/amp",
        "err vs ref"
    );
    let hd_err = ref_thz.as_ref().map_or(f64::NAN, |r| max_abs_diff(&hd_thz, r) / amp);
    println!(
        "{:<22} {:>10.5} {:>7.2} {:>8} {:>8} {:>9} {:>8} {:>16.2e} {:>11.2e}",
        format!("hd-model {}", hd["method"].as_str().unwrap_or("?")),
        hd_wall,
        1.0,
        hd["steps"].as_u64().unwrap_or(0),
        hd["rejected"].as_u64().unwrap_or(0),
        "-",
        hd["lu_decomps"].as_u64().unwrap_or(0),
        0.0,
        hd_err
    );
    for method in methods.split(',') {
        let mut best = f64::INFINITY;
        let mut failed = None;
        for _ in 0..reps.max(1) {
            let start = Instant::now();
            match solve(method, rtol, atol, t_end, None) {
                Ok(_) => best = best.min(start.elapsed().as_secs_f64()),
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
            if best > 20.0 {
                break;
            }
        }
        if let Some(e) = failed {
            println!("{:<22} failed: {e}", format!("diffsol {method}"));
            continue;
        }
        let out = match solve(method, rtol, atol, t_end, Some(&grid)) {
            Ok(o) => o,
            Err(e) => {
                println!("{:<22} failed on the sampled run: {e}", format!("diffsol {method}"));
                continue;
            }
        };
        let d = max_abs_diff(&out.thz, &hd_thz) / amp;
        let err = ref_thz.as_ref().map_or(f64::NAN, |r| max_abs_diff(&out.thz, r) / amp);
        println!(
            "{:<22} {:>10.5} {:>7.2} {:>8} {:>8} {:>9} {:>8} {:>16.2e} {:>11.2e}",
            format!("diffsol {method}"),
            best,
            best / hd_wall,
            out.steps,
            out.rejected,
            out.newton_iters,
            out.lu_setups,
            d,
            err
        );
    }
}
