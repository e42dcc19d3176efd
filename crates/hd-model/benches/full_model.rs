//! Solver benchmarks on the seed case (24 V sine at 50 Hz, seed parameters, from rest).
//!
//! - `full_1s_rtol1e-8`: the full model, 1 s simulated, rtol 1e-8, atol 1e-11 (the case
//!   `benches/scipy_compare.py` times in scipy), with Rodas4 and with Dopri5 (`auto` runs
//!   the full model on an implicit–explicit pair; `stage_floor` times that);
//! - `full_0.2s_default`: the full model, 0.2 s, default tolerances (rtol 1e-6, atol 1e-9);
//! - `damped_0.2s_default`: the `damped` variant, 0.2 s, default tolerances — one unit of
//!   work of a parameter sweep.
//!
//! No trace is recorded; the metrics are computed, as in a sweep.
//! `cargo bench -p hd-model --bench full_model` (about a minute).

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};
use hd_model::{Method, SimConfig, SolverOptions, Variant, simulate};
use std::hint::black_box;
use std::time::Duration;

fn config(variant: Variant, t_end: f64, rtol: f64, atol: f64, method: Method) -> SimConfig {
    SimConfig {
        variant,
        t_end,
        record_trace: false,
        solver: SolverOptions { method, rtol, atol, ..SolverOptions::default() },
        ..SimConfig::default()
    }
}

fn run(cfg: &SimConfig) -> f64 {
    let out = simulate(black_box(cfg)).expect("benchmark case runs");
    out.metrics.thz_amp
}

fn full_1s_tight(c: &mut Criterion) {
    let mut g = c.benchmark_group("full_1s_rtol1e-8");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));
    for (name, method) in [("rodas4", Method::Rodas4), ("dopri5", Method::Dopri5)] {
        let cfg = config(Variant::Full, 1.0, 1e-8, 1e-11, method);
        g.bench_function(name, |b| b.iter(|| run(&cfg)));
    }
    g.finish();
}

fn full_default(c: &mut Criterion) {
    let mut g = c.benchmark_group("full_0.2s_default");
    g.sample_size(20).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3));
    let d = SolverOptions::default();
    for (name, method) in [("rodas4", Method::Rodas4), ("dopri5", Method::Dopri5)] {
        let cfg = config(Variant::Full, 0.2, d.rtol, d.atol, method);
        g.bench_function(name, |b| b.iter(|| run(&cfg)));
    }
    g.finish();
}

fn damped_default(c: &mut Criterion) {
    let mut g = c.benchmark_group("damped_0.2s_default");
    g.sample_size(30).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3));
    let d = SolverOptions::default();
    // `auto` resolves to Dopri5: the damped variant has no stiff part.
    let cfg = config(Variant::Damped, 0.2, d.rtol, d.atol, Method::Auto);
    g.bench_function("auto", |b| b.iter(|| run(&cfg)));
    g.finish();
}

criterion_group!(benches, full_1s_tight, full_default, damped_default);
criterion_main!(benches);
