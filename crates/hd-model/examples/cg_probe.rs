use hd_model::{Method, SimConfig, SolverOptions, Variant, simulate};
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let t_end: f64 = a[0].parse().unwrap();
    let reps: usize = a[1].parse().unwrap();
    let method = serde_json::from_value::<Method>(serde_json::Value::String(a[2].clone())).unwrap();
    let cfg = SimConfig {
        variant: Variant::Full,
        t_end,
        record_trace: false,
        solver: SolverOptions { method, rtol: 1e-6, atol: 1e-9, ..Default::default() },
        ..SimConfig::default()
    };
    let mut best = f64::INFINITY;
    let mut steps = 0;
    for _ in 0..reps {
        let t = std::time::Instant::now();
        let o = simulate(&cfg).unwrap();
        best = best.min(t.elapsed().as_secs_f64());
        steps = o.stats.steps + o.stats.rejected;
    }
    println!(
        "best {:.3} ms, {} attempts, {:.0} ns/attempt",
        best * 1e3,
        steps,
        best * 1e9 / steps as f64
    );
}
