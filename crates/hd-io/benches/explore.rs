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

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};
use hd_io::explore::{Dataset, parse_aggs, parse_pivot, write_table};
use hd_io::{ColumnData, Table};
use hd_model::Metrics;
use hd_model::registry::REGISTRY;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

/// Rows of the generated table.
const ROWS: usize = 1_000_000;

/// A small deterministic generator (64-bit LCG), uniform on [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn pick<T: Copy>(&mut self, from: &[T]) -> T {
        from[(self.next() * from.len() as f64) as usize % from.len()]
    }
}

/// Rows `lo..hi` of the runs-like table (the same rows whatever the split).
fn runs_table(lo: usize, hi: usize) -> Table {
    let n = hi - lo;
    let mut rng = Lcg(lo as u64 + 1);
    let kbar: Vec<f64> = (0..10).map(|k| 1e5 * 1.5f64.powi(k)).collect();
    let volts: Vec<f64> = (0..10).map(|k| 3.0 * 1.35f64.powi(k)).collect();
    let freqs: Vec<f64> = (0..10).map(|k| 5.0 * 1.6f64.powi(k)).collect();
    let mut t = Table { height: n, ..Default::default() };
    let mut text = |name: &str, v: Vec<Option<String>>| {
        t.names.push(name.into());
        t.columns.push(ColumnData::Text(v));
    };
    text(
        "run_id",
        (lo..hi)
            .map(|i| Some(format!("{:016x}", (i as u64).wrapping_mul(0x9e3779b97f4a7c15))))
            .collect(),
    );
    let failed: Vec<bool> = (0..n).map(|_| rng.next() < 0.01).collect();
    let mut num_cols: Vec<(String, Vec<f64>)> =
        vec![("run_index".into(), (lo..hi).map(|i| i as f64).collect())];
    text("part", vec![Some("grid".into()); n]);
    text("variant", (0..n).map(|_| Some(rng.pick(&["linear", "damped", "full"]).into())).collect());
    text("status", failed.iter().map(|&f| Some(if f { "failed" } else { "ok" }.into())).collect());
    text(
        "error",
        failed.iter().map(|&f| f.then(|| "step size too small at t = 0.1 s".into())).collect(),
    );
    for p in REGISTRY {
        let v = if p.name == "Kbar" {
            (0..n).map(|_| rng.pick(&kbar)).collect()
        } else {
            vec![p.default_value(); n]
        };
        num_cols.push((p.name.into(), v));
    }
    num_cols.push(("voltage".into(), (0..n).map(|_| rng.pick(&volts)).collect()));
    num_cols.push(("freq".into(), (0..n).map(|_| rng.pick(&freqs)).collect()));
    for (m, _) in Metrics::UNITS {
        let v = (0..n).map(|i| if failed[i] { f64::NAN } else { rng.next() * 1e-3 }).collect();
        num_cols.push((m.into(), v));
    }
    text("method", vec![Some("rodas4".into()); n]);
    for s in ["steps", "rejected_steps", "rhs_evals", "jac_evals"] {
        num_cols.push((s.into(), (0..n).map(|_| (rng.next() * 5000.0).floor()).collect()));
    }
    num_cols.push(("wall_time".into(), (0..n).map(|_| rng.next() * 0.05).collect()));
    for (name, v) in num_cols {
        t.names.push(name);
        t.columns.push(ColumnData::Num(v));
    }
    t
}

/// Write the table once as one file and once as four shards.
fn write_data(root: &Path) {
    std::fs::create_dir_all(root.join("one")).unwrap();
    std::fs::create_dir_all(root.join("shards")).unwrap();
    write_table(&root.join("one/runs.parquet"), &runs_table(0, ROWS)).unwrap();
    for k in 0..4 {
        let t = runs_table(k * ROWS / 4, (k + 1) * ROWS / 4);
        write_table(&root.join(format!("shards/runs-shard-{}-of-4.parquet", k + 1)), &t).unwrap();
    }
}

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
