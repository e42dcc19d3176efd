//! Explore engine on a generated 1 000 000-row runs table (the columns of a real
//! `runs.parquet`: identity, 22 parameters, voltage, freq, 20 metrics, solver work).
//!
//! - `summary/one_file`: open `runs.parquet` and compute the summary (row count, failed
//!   runs, count/min/median/max of the 20 metrics);
//! - `summary/four_shards`: the same table split into `runs-shard-K-of-4.parquet`;
//! - `pivot`: `--pivot Kbar,voltage,thz_amp:mean` (10 × 10 cells);
//! - `group_by`: `--group-by variant --agg thz_amp:max,tb_peak:mean,wall_time:sum`;
//! - `filter_summary`: the summary after `status == "ok"` and `Kbar > 5e5`.
//!
//! Every iteration opens the files again, so the times include reading the Parquet
//! metadata and the columns used. `cargo bench -p hd-io --bench explore` (about 2 min,
//! most of it writing the table).

mod runs_like;

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};
use hd_io::explore::{Dataset, parse_aggs, parse_pivot};
use runs_like::{ROWS, write_data};
use std::hint::black_box;
use std::time::Duration;

fn explore(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    write_data(dir.path());
    let one = dir.path().join("one").display().to_string();
    let shards = dir.path().join("shards").display().to_string();
    let rows = |r: &hd_io::explore::Report| r.fact("rows").and_then(|v| v.as_u64());
    assert_eq!(rows(&Dataset::open(&one, None).unwrap().summary().unwrap()), Some(ROWS as u64));

    let mut g = c.benchmark_group("explore_1M_runs");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(8));
    g.bench_function("summary/one_file", |b| {
        b.iter(|| Dataset::open(black_box(&one), None).unwrap().summary().unwrap())
    });
    g.bench_function("summary/four_shards", |b| {
        b.iter(|| Dataset::open(black_box(&shards), None).unwrap().summary().unwrap())
    });
    let spec = parse_pivot("Kbar,voltage,thz_amp:mean").unwrap();
    g.bench_function("pivot", |b| {
        b.iter(|| Dataset::open(black_box(&one), None).unwrap().pivot(&spec, None).unwrap())
    });
    let aggs = parse_aggs(&["thz_amp:max,tb_peak:mean,wall_time:sum".into()]).unwrap();
    let keys = vec!["variant".to_string()];
    g.bench_function("group_by", |b| {
        b.iter(|| {
            Dataset::open(black_box(&one), None).unwrap().group_by(&keys, &aggs, None).unwrap()
        })
    });
    let filters = vec!["status == \"ok\"".to_string(), "Kbar > 5e5".to_string()];
    g.bench_function("filter_summary", |b| {
        b.iter(|| {
            Dataset::open(black_box(&one), None)
                .unwrap()
                .filtered(&filters)
                .unwrap()
                .summary()
                .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, explore);
criterion_main!(benches);
