//! Run the seed case (full model, 24 V, 50 Hz, 0.2 s) and print metrics and solver work.
//! `cargo run --release -p hd-model --example seed_case [variant] [rtol]`

use hd_model::{SimConfig, SolverOptions, Variant, simulate};

fn main() {
    let mut args = std::env::args().skip(1);
    let variant: Variant = args.next().map_or(Variant::Full, |s| s.parse().expect("variant"));
    let rtol: f64 = args.next().map_or(1e-6, |s| s.parse().expect("rtol"));
    let cfg = SimConfig {
        variant,
        record_trace: false,
        solver: SolverOptions { rtol, ..Default::default() },
        ..SimConfig::default()
    };
    let out = simulate(&cfg).expect("run");
    println!("{:#?}\n{:#?}\nwall {:.3} ms", out.metrics, out.stats, out.wall_time * 1e3);
}
