//! `runs.parquet`: one row per run with its identity, every parameter used, the swept
//! settings, the kept metrics, the status and the solver work. Also the long-format
//! `traces.parquet`, and the part files a sweep commits while it runs.
//!
//! Studies with a sobol or morris design add, after `wall_time`, the columns
//! `design_method` (text: `sobol`/`morris`), `design_group` (u64: Saltelli base row or
//! Morris trajectory), `design_slot` (u64: position in the base row, A = 0, AB(i) = i + 1,
//! B = d + 1, or Morris step) and one `u_<name>` column (f64, unit-cube coordinate in
//! [0, 1]) per design parameter. They are null for runs outside a design.

use crate::atomic::write_atomically;
use crate::error::IoError;
use hd_model::registry::REGISTRY;
use hd_model::{TRACE_COLUMNS, registry::lookup};
use hd_sweep::RunRow;
use hd_sweep::axis::Value;
use polars::prelude::*;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// Columns of a runs table, given the study's swept names and kept metrics.
pub fn runs_frame(
    rows: &[RunRow],
    swept: &[&str],
    metrics: &[&str],
) -> Result<DataFrame, PolarsError> {
    let mut cols: Vec<Column> = Vec::new();
    let text = |f: &dyn Fn(&RunRow) -> String| rows.iter().map(f).collect::<Vec<String>>();
    let num = |f: &dyn Fn(&RunRow) -> f64| rows.iter().map(f).collect::<Vec<f64>>();
    let count = |f: &dyn Fn(&RunRow) -> u64| rows.iter().map(f).collect::<Vec<u64>>();
    cols.push(Column::new("run_id".into(), text(&|r| r.run_id.clone())));
    cols.push(Column::new("run_index".into(), count(&|r| r.run_index as u64)));
    cols.push(Column::new("part".into(), text(&|r| r.part.clone())));
    cols.push(Column::new("variant".into(), text(&|r| r.variant.clone())));
    cols.push(Column::new("status".into(), text(&|r| r.status.to_string())));
    cols.push(Column::new(
        "error".into(),
        rows.iter().map(|r| r.error.clone()).collect::<Vec<Option<String>>>(),
    ));
    for p in REGISTRY {
        cols.push(Column::new(p.name.into(), num(&|r| p.get(&r.params))));
    }
    cols.push(Column::new("voltage".into(), num(&|r| r.voltage)));
    cols.push(Column::new("freq".into(), num(&|r| r.freq)));
    // Swept settings that are not parameters or input columns (e.g. friction_scale).
    for name in
        swept.iter().filter(|n| lookup(n).is_err() && !["voltage", "freq", "variant"].contains(n))
    {
        cols.push(Column::new((*name).into(), num(&|r| swept_value(r, name))));
    }
    // Metric values by position in `Metrics::to_pairs` order, looked up once per column.
    let order: Vec<&str> = hd_model::Metrics::UNITS.iter().map(|(n, _)| *n).collect();
    let pairs: Vec<Vec<(&str, f64)>> = rows.iter().map(|r| r.metrics.to_pairs()).collect();
    for m in metrics {
        let k = order.iter().position(|n| n == m);
        let vals: Vec<Option<f64>> =
            pairs.iter().map(|p| k.map(|k| p[k].1).filter(|v| v.is_finite())).collect();
        cols.push(Column::new((*m).into(), vals));
    }
    cols.push(Column::new(
        "method".into(),
        text(&|r| format!("{:?}", r.stats.method).to_lowercase()),
    ));
    cols.push(Column::new("steps".into(), count(&|r| r.stats.steps)));
    cols.push(Column::new("rejected_steps".into(), count(&|r| r.stats.rejected)));
    cols.push(Column::new("rhs_evals".into(), count(&|r| r.stats.rhs_evals)));
    cols.push(Column::new("jac_evals".into(), count(&|r| r.stats.jac_evals)));
    cols.push(Column::new("wall_time".into(), num(&|r| r.wall_time)));
    cols.extend(design_columns(rows));
    DataFrame::new_infer_height(cols)
}

/// The design columns (see the module docs); none when the study has no sobol or morris
/// design. Every row of a study carries the same `design_names`, so every part file of a
/// sweep gets the same columns.
fn design_columns(rows: &[RunRow]) -> Vec<Column> {
    let Some(names) = rows.first().map(|r| r.design_names.clone()) else { return Vec::new() };
    if names.is_empty() {
        return Vec::new();
    }
    let parts = |r: &RunRow| r.design.as_ref().map(|d| d.tag.to_parts(d.unit.len()));
    let mut cols = vec![
        Column::new(
            "design_method".into(),
            rows.iter().map(|r| parts(r).map(|p| p.0.as_str())).collect::<Vec<Option<&str>>>(),
        ),
        Column::new(
            "design_group".into(),
            rows.iter().map(|r| parts(r).map(|p| p.1 as u64)).collect::<Vec<Option<u64>>>(),
        ),
        Column::new(
            "design_slot".into(),
            rows.iter().map(|r| parts(r).map(|p| p.2 as u64)).collect::<Vec<Option<u64>>>(),
        ),
    ];
    for name in names.iter() {
        let unit: Vec<Option<f64>> =
            rows.iter().map(|r| r.design.as_ref().and_then(|d| d.unit_of(name))).collect();
        cols.push(Column::new(format!("u_{name}").into(), unit));
    }
    cols
}

fn swept_value(r: &RunRow, name: &str) -> f64 {
    r.swept.iter().find(|(n, _)| n == name).map_or(f64::NAN, |(_, v)| match v {
        Value::Num(x) => *x,
        Value::Variant(_) => f64::NAN,
    })
}

/// Long-format traces of the rows that kept one: `run_id, t, u, …, C0`.
pub fn traces_frame(rows: &[RunRow]) -> Result<DataFrame, PolarsError> {
    let kept: Vec<&RunRow> = rows.iter().filter(|r| r.trace.is_some()).collect();
    let mut ids = Vec::new();
    let mut data: Vec<Vec<f64>> = vec![Vec::new(); TRACE_COLUMNS.len()];
    for r in kept {
        let tr = r.trace.as_ref().expect("filtered");
        ids.extend(std::iter::repeat_n(r.run_id.clone(), tr.len()));
        for (k, c) in tr.columns().iter().enumerate() {
            data[k].extend_from_slice(c);
        }
    }
    let mut cols = vec![Column::new("run_id".into(), ids)];
    cols.extend(TRACE_COLUMNS.iter().zip(data).map(|((n, _), d)| Column::new((*n).into(), d)));
    DataFrame::new_infer_height(cols)
}

/// Write a frame to Parquet atomically.
pub fn write_frame(path: &Path, df: &mut DataFrame) -> Result<(), IoError> {
    write_atomically(path, |file| {
        ParquetWriter::new(file)
            .finish(df)
            .map(|_| ())
            .map_err(|e| IoError::format(path, format!("cannot write Parquet: {e}")))
    })
}

/// The run ids present in the given Parquet files.
pub fn read_run_ids(files: &[PathBuf]) -> Result<HashSet<String>, IoError> {
    let mut ids = HashSet::new();
    for f in files {
        let df = crate::columns::read_frame(f)?;
        let col = df.column("run_id").map_err(|e| IoError::format(f, e.to_string()))?;
        let ca = col.str().map_err(|e| IoError::format(f, e.to_string()))?;
        ids.extend(ca.iter().flatten().map(str::to_string));
    }
    Ok(ids)
}

/// Concatenate Parquet files with one schema, optionally keep only the first row of each
/// `run_id` (for run tables), sort by `sort_by` (when given) and write the result
/// atomically to `out`. Returns the number of rows.
pub fn merge_files(
    files: &[PathBuf],
    out: &Path,
    dedupe_runs: bool,
    sort_by: Option<&str>,
) -> Result<usize, IoError> {
    let mut merged: Option<DataFrame> = None;
    for f in files {
        let df = crate::columns::read_frame(f)?;
        match merged.as_mut() {
            None => merged = Some(df),
            Some(m) => {
                m.vstack_mut(&df).map_err(|e| {
                    IoError::format(f, format!("schema differs from the other parts: {e}"))
                })?;
            }
        }
    }
    let Some(mut df) = merged else { return Ok(0) };
    if dedupe_runs {
        // One row per run, whatever an interrupted sweep left behind.
        let ids = df.column("run_id").map_err(|e| IoError::format(out, e.to_string()))?;
        let ca = ids.str().map_err(|e| IoError::format(out, e.to_string()))?;
        let mut seen = HashSet::new();
        let mask: BooleanChunked =
            ca.iter().map(|id| Some(seen.insert(id.unwrap_or("").to_string()))).collect();
        df = df.filter(&mask).map_err(|e| IoError::format(out, e.to_string()))?;
    }
    if let Some(col) = sort_by {
        df = df
            .sort([col], SortMultipleOptions::default())
            .map_err(|e| IoError::format(out, e.to_string()))?;
    }
    df.rechunk_mut();
    let n = df.height();
    write_frame(out, &mut df)?;
    Ok(n)
}
