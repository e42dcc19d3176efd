//! One untraced run of the full model (24 V sine at 50 Hz, rtol 1e-6, atol 1e-9), for
//! counting instructions with callgrind: a solve's instruction count does not depend on
//! what else the machine runs, so it measures a change to the cost of a step where wall
//! times on a shared machine cannot (benches/README.md, "Cheaper steps").
//!
//! ```text
//! cargo build --release -p hd-model --example cg_probe
//! valgrind --tool=callgrind target/release/examples/cg_probe 0.2 1 imex
//! ```
//! Arguments: simulated time [s], repetitions (the best wall time is printed), and the
//! method by the name study files use (auto, dopri5, imex, rodas4, dop853).

use hd_model::{Method, SimConfig, SolverOptions, Variant, simulate};

const USAGE: &str = "usage: cg_probe <t_end> <reps> <method>";

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let t_end: f64 = args.first().and_then(|s| s.parse().ok()).expect(USAGE);
    let reps: usize = args.get(1).and_then(|s| s.parse().ok()).expect(USAGE);
    let name = args.get(2).expect(USAGE);
    let method = serde_json::from_value::<Method>(serde_json::Value::String(name.clone()))
        .unwrap_or_else(|e| panic!("bad method '{name}': {e}"));
    let cfg = SimConfig {
        variant: Variant::Full,
        t_end,
        record_trace: false,
        solver: SolverOptions { method, rtol: 1e-6, atol: 1e-9, ..Default::default() },
        ..SimConfig::default()
    };
    let mut best = f64::INFINITY;
    let mut attempts = 0;
    for _ in 0..reps.max(1) {
        let start = std::time::Instant::now();
        let out = simulate(&cfg).expect("run failed");
        best = best.min(start.elapsed().as_secs_f64());
        attempts = out.stats.steps + out.stats.rejected;
    }
    println!(
        "best {:.3} ms, {attempts} attempts, {:.0} ns per attempt",
        best * 1e3,
        best * 1e9 / attempts as f64
    );
}
