use hd_model::{Method, SimConfig, SolverOptions, Variant, simulate};
fn run(method: Method, rtol: f64, t_end: f64) -> (hd_model::Trace, u64) {
    let cfg = SimConfig {
        variant: Variant::Full,
        t_end,
        dt_out: t_end / 4000.0,
        record_trace: true,
        solver: SolverOptions { method, rtol, atol: rtol * 1e-3, ..Default::default() },
        ..SimConfig::default()
    };
    let o = simulate(&cfg).unwrap();
    (o.trace.unwrap(), o.stats.steps)
}
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let t_end: f64 = a[0].parse().unwrap();
    let m =
        |s: &str| serde_json::from_value::<Method>(serde_json::Value::String(s.into())).unwrap();
    let (r, _) = run(m("dop853"), 1e-12, t_end);
    for spec in &a[1..] {
        let (meth, rt) = spec.split_once(':').unwrap();
        let (tr, steps) = run(m(meth), rt.parse().unwrap(), t_end);
        let err = |x: &[f64], y: &[f64]| {
            let range = y.iter().cloned().fold(0.0f64, |a, b| a.max(b.abs()));
            x.iter().zip(y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / range
        };
        println!(
            "{spec:14} steps {steps:6} thz {:8.1e} s {:8.1e} Tf {:8.1e} z {:8.1e} Tb {:8.1e} i {:8.1e}",
            err(&tr.theta_z, &r.theta_z),
            err(&tr.s, &r.s),
            err(&tr.tf, &r.tf),
            err(&tr.z, &r.z),
            err(&tr.tb, &r.tb),
            err(&tr.i, &r.i)
        );
    }
}
