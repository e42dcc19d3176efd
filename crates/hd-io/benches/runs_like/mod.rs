//! A generated runs-like table (the columns of a real `runs.parquet`: identity, 22
//! parameters, voltage, freq, 20 metrics, solver work) for benchmarks and timing runs.
//! Kbar, voltage and freq take 10 values each, the variant 3; 1 % of the runs fail.

use hd_io::explore::write_table;
use hd_io::{ColumnData, Table};
use hd_model::METRICS;
use hd_model::registry::REGISTRY;
use std::path::Path;

/// Rows of the generated table.
pub const ROWS: usize = 1_000_000;

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
pub fn runs_table(lo: usize, hi: usize) -> Table {
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
    for m in METRICS.iter().map(|m| m.name) {
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
pub fn write_data(root: &Path) {
    std::fs::create_dir_all(root.join("one")).unwrap();
    std::fs::create_dir_all(root.join("shards")).unwrap();
    write_table(&root.join("one/runs.parquet"), &runs_table(0, ROWS)).unwrap();
    for k in 0..4 {
        let t = runs_table(k * ROWS / 4, (k + 1) * ROWS / 4);
        write_table(&root.join(format!("shards/runs-shard-{}-of-4.parquet", k + 1)), &t).unwrap();
    }
}
