use hd_model::{Method, SimConfig, SolverOptions, Variant, simulate};
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let method = serde_json::from_value::<Method>(serde_json::Value::String(a[0].clone())).unwrap();
    for c in [1e4, 1e5, 1e6] {
        for fs in [0.1, 1.0, 10.0] {
            let mut cfg = SimConfig {
                variant: Variant::Full,
                t_end: 0.2,
                record_trace: false,
                solver: SolverOptions { method, rtol: 1e-6, atol: 1e-9, ..Default::default() },
                ..SimConfig::default()
            };
            cfg.params.c = c;
            cfg.params.tc *= fs;
            cfg.params.ts *= fs;
            if let Ok(l) = std::env::var("IND") {
                cfg.params.l = l.parse().unwrap();
            }
            let mut best = f64::INFINITY;
            let mut st = None;
            for _ in 0..5 {
                let o = simulate(&cfg).unwrap();
                best = best.min(o.wall_time);
                st = Some(o.stats);
            }
            let st = st.unwrap();
            println!(
                "c {c:8.0e} fs {fs:5} {:7.3} ms steps {:6} rej {:5} implicit {:6} switches {}",
                best * 1e3,
                st.steps,
                st.rejected,
                st.implicit_steps,
                st.switches
            );
        }
    }
}
