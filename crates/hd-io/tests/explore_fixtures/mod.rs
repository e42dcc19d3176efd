//! Small tables with known contents for the explore tests.
#![allow(dead_code)] // Each test file uses some of the fixtures.

use hd_io::explore::write_table;
use hd_io::{ColumnData, Table};
use std::path::Path;

/// Six runs: two share the cell (Kbar = 1e5, voltage = 12), one failed, one alone at
/// Kbar = 4e5.
pub fn runs_table() -> Table {
    let text = |v: &[&str]| ColumnData::Text(v.iter().map(|s| Some(s.to_string())).collect());
    let nan = f64::NAN;
    Table {
        names: ["run_id", "variant", "status", "error", "Kbar", "voltage", "thz_amp", "tb_peak"]
            .map(String::from)
            .to_vec(),
        columns: vec![
            text(&["r0", "r1", "r2", "r3", "r4", "r5"]),
            text(&["full", "full", "damped", "damped", "full", "linear"]),
            text(&["ok", "ok", "ok", "failed", "ok", "ok"]),
            ColumnData::Text(vec![
                None,
                None,
                None,
                Some("step size too small".into()),
                None,
                None,
            ]),
            ColumnData::Num(vec![1e5, 1e5, 2e5, 2e5, 1e5, 4e5]),
            ColumnData::Num(vec![12.0, 24.0, 12.0, 24.0, 12.0, 12.0]),
            ColumnData::Num(vec![1.0, 2.0, 3.0, nan, 3.0, 5.0]),
            ColumnData::Num(vec![10.0, 20.0, 30.0, nan, 40.0, 50.0]),
        ],
        height: 6,
    }
}

/// Rows `range` of a table.
pub fn rows(t: &Table, range: std::ops::Range<usize>) -> Table {
    let columns = t
        .columns
        .iter()
        .map(|c| match c {
            ColumnData::Num(v) => ColumnData::Num(v[range.clone()].to_vec()),
            ColumnData::Text(v) => ColumnData::Text(v[range.clone()].to_vec()),
        })
        .collect();
    Table { names: t.names.clone(), columns, height: range.len() }
}

/// Write the runs table to `dir/runs.parquet`; returns the path as text.
pub fn write_runs(dir: &Path) -> String {
    let p = dir.join("runs.parquet");
    write_table(&p, &runs_table()).unwrap();
    p.display().to_string()
}

/// A long-format traces table: two runs, three samples each.
pub fn traces_table() -> Table {
    let ids = ["r0", "r0", "r0", "r1", "r1", "r1"];
    Table {
        names: ["run_id", "t", "theta_z", "theta", "Tb"].map(String::from).to_vec(),
        columns: vec![
            ColumnData::Text(ids.iter().map(|s| Some(s.to_string())).collect()),
            ColumnData::Num(vec![0.0, 0.1, 0.2, 0.0, 0.1, 0.2]),
            ColumnData::Num(vec![0.0, 1e-3, 2e-3, 0.0, 2e-3, 4e-3]),
            ColumnData::Num(vec![0.0, 1e-4, -1e-4, 0.0, 2e-4, -2e-4]),
            ColumnData::Num(vec![0.0, 5.0, -5.0, 0.0, 9.0, -9.0]),
        ],
        height: 6,
    }
}

/// The numbers of a result column.
pub fn num<'a>(t: &'a Table, name: &str) -> &'a [f64] {
    t.num(name).unwrap_or_else(|| panic!("no numeric column {name} in {:?}", t.names))
}

/// Whether two slices agree, NaN matching NaN.
pub fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x == y || (x.is_nan() && y.is_nan()))
}
