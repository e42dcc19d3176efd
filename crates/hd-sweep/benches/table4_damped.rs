//! The sweep's unit of scale: the 1600-run `damped` K̄ × C̄0 grid of studies/table4.toml
//! (24 V, 50 Hz, 0.2 s each), on one and on two worker threads.

use criterion::{Criterion, criterion_group, criterion_main};
use hd_sweep::{load_study, run_batch};
use std::path::Path;

fn damped_grid(c: &mut Criterion) {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../studies/table4.toml");
    let loader = |_: &Path| Err("no recorded inputs here".to_string());
    let study = load_study(&file, &loader).expect("table4.toml");
    let runs: Vec<_> = study.expand().into_iter().filter(|r| &*r.part == "damped-sine").collect();
    assert_eq!(runs.len(), 1600);
    let mut group = c.benchmark_group("table4 damped-sine, 1600 runs");
    group.sample_size(10);
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        group.bench_function(format!("{threads} thread(s)"), |b| {
            b.iter(|| pool.install(|| run_batch(&runs, 1, &|_| {}, None)))
        });
    }
    group.finish();
}

criterion_group!(benches, damped_grid);
criterion_main!(benches);
