//! Time one case and print the result as JSON, for `benches/scipy_compare.py` and
//! `benches/diffsol-compare`.
//!
//! ```text
//! cargo run --release -q -p hd-model --example bench_case -- \
//!     <variant> <rtol> <atol> <t_end> <reps> [dt_out] [method]
//! ```
//! - `variant`: linear, damped or full (input: the seed's 24 V sine at 50 Hz);
//! - `reps`: the untraced run is timed this many times and the best time is reported;
//! - `dt_out`: spacing of the θz grid in the output, default 1e-4 s;
//! - `method`: auto (default), or any other method name that study files accept
//!   (dopri5, rodas4, …).
//!
//! The printed object holds `wall_best_s`: the best wall time of a run that returns θz at
//! `t_k = k·dt_out` (`simulate_states`, the load angle read from the interpolated state at
//! each grid time; configuration check and assembly included), which is what the peers'
//! solves return; `wall_all_s`; `wall_no_output_best_s`, the same run with no output grid;
//! the solver statistics, the metrics `thz_amp` and `thz_mean`, the final state in the
//! model's coordinates (θj, ωj, θz, ωz, z, s), and `theta_z` on the grid.

use hd_model::{Method, SimConfig, SolverOptions, Variant, simulate, simulate_states};
use std::fmt::Write as _;
use std::time::Instant;

const USAGE: &str = "usage: bench_case <variant> <rtol> <atol> <t_end> <reps> [dt_out] [method]";

fn arg<T: std::str::FromStr>(args: &[String], i: usize, name: &str, default: Option<T>) -> T {
    match args.get(i) {
        Some(s) => s.parse().unwrap_or_else(|_| panic!("bad {name} '{s}'\n{USAGE}")),
        None => default.unwrap_or_else(|| panic!("missing {name}\n{USAGE}")),
    }
}

/// A JSON number; non-finite values become `null`.
fn num(x: f64) -> String {
    if x.is_finite() { format!("{x:e}") } else { "null".to_string() }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let variant: Variant = arg(&args, 0, "variant", None);
    let rtol: f64 = arg(&args, 1, "rtol", None);
    let atol: f64 = arg(&args, 2, "atol", None);
    let t_end: f64 = arg(&args, 3, "t_end", None);
    let reps: usize = arg(&args, 4, "reps", None);
    let dt_out: f64 = arg(&args, 5, "dt_out", Some(1e-4));
    // Any method hd-model knows, by the name study files use (auto, dopri5, rodas4, …).
    let method = match args.get(6) {
        None => Method::Auto,
        Some(name) => serde_json::from_value::<Method>(serde_json::Value::String(name.clone()))
            .unwrap_or_else(|e| panic!("bad method '{name}': {e}")),
    };

    let cfg = SimConfig {
        variant,
        t_end,
        dt_out,
        record_trace: false,
        solver: SolverOptions { method, rtol, atol, ..Default::default() },
        ..SimConfig::default()
    };

    // θz on the output grid, as the peers return it.
    let grid_run = || {
        let mut thz = Vec::with_capacity((t_end / dt_out) as usize + 2);
        let out = simulate_states(&cfg, &mut |sys, _t, y| thz.push(sys.load_angle(y)))
            .expect("timed run failed");
        (out, thz)
    };
    let mut walls = Vec::with_capacity(reps.max(1));
    let mut timed = None;
    for _ in 0..reps.max(1) {
        let start = Instant::now();
        let out = grid_run();
        walls.push(start.elapsed().as_secs_f64());
        timed = Some(out);
    }
    let (timed, theta_z) = timed.expect("at least one run");
    let best = walls.iter().copied().fold(f64::INFINITY, f64::min);
    let bare = (0..reps.max(1))
        .map(|_| {
            let start = Instant::now();
            simulate(&cfg).expect("untimed run failed");
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min);
    let traced = SimConfig { record_trace: true, ..cfg.clone() };
    let full_trace = (0..reps.max(1))
        .map(|_| {
            let start = Instant::now();
            simulate(&traced).expect("traced run failed");
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min);

    let st = &timed.stats;
    let y = &timed.final_state;
    let n = cfg.params.n;
    let final_state =
        [y[0], y[1], y[0] / n - y[2], y[3], y[4], y[5] / cfg.params.sigma0.max(f64::MIN_POSITIVE)];

    let mut s = String::new();
    let _ = write!(
        s,
        "{{\"variant\":\"{variant}\",\"method\":\"{:?}\",\"rtol\":{},\"atol\":{},\"t_end\":{},",
        st.method,
        num(rtol),
        num(atol),
        num(t_end)
    );
    let _ = write!(
        s,
        "\"reps\":{},\"wall_best_s\":{},\"wall_no_output_best_s\":{},\"wall_full_trace_best_s\":{},\"wall_all_s\":[{}],",
        walls.len(),
        num(best),
        num(bare),
        num(full_trace),
        walls.iter().map(|&w| num(w)).collect::<Vec<_>>().join(",")
    );
    let _ = write!(
        s,
        "\"steps\":{},\"rejected\":{},\"rhs_evals\":{},\"jac_evals\":{},\"lu_decomps\":{},",
        st.steps, st.rejected, st.rhs_evals, st.jac_evals, st.lu_decomps
    );
    let _ = write!(
        s,
        "\"thz_amp\":{},\"thz_mean\":{},\"final_state\":[{}],",
        num(timed.metrics.thz_amp),
        num(timed.metrics.thz_mean),
        final_state.iter().map(|&v| num(v)).collect::<Vec<_>>().join(",")
    );
    let _ = write!(
        s,
        "\"dt_out\":{},\"t\":[{}],\"theta_z\":[{}]}}",
        num(dt_out),
        (0..theta_z.len())
            .map(|k| num((k as f64 * dt_out).min(t_end)))
            .collect::<Vec<_>>()
            .join(","),
        theta_z.iter().map(|&v| num(v)).collect::<Vec<_>>().join(",")
    );
    println!("{s}");
}
