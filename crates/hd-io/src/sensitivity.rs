//! Files of a global-sensitivity analysis: reading every runs table of a study folder as
//! one table, and writing `sensitivity.parquet`.
//!
//! `sensitivity.parquet` has one row per (part, metric, parameter) of a sobol or morris
//! design, with the columns `part`, `method`, `parameter`, `metric`, `S1`, `S1_lo`, `S1_hi`,
//! `ST`, `ST_lo`, `ST_hi` (Sobol' indices [-] and their bootstrap interval), `mu`,
//! `mu_star`, `sigma` (Morris statistics [metric unit per parameter range]), `n_used`,
//! `n_dropped` (base rows or trajectories used and dropped, u64) and `note`. Values that
//! were not computed or are undefined are null, never zero.

use crate::columns::read_frame;
use crate::error::IoError;
use crate::runs::write_frame;
use crate::table::{Table, frame_to_table};
use hd_sweep::sensitivity::SensitivityRow;
use polars::prelude::*;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// The runs tables of a study folder: `runs.parquet` and any `runs-shard-K-of-N.parquet`,
/// in name order.
pub fn runs_files(dir: &Path) -> Result<Vec<PathBuf>, IoError> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| IoError::fs(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("runs") && n.ends_with(".parquet"))
        })
        .collect();
    files.sort();
    Ok(files)
}

/// Every run of a study folder as one table: the runs tables stacked (they share the
/// study's schema), one row per `run_id` (the first seen), sorted by `run_index`.
pub fn read_study_runs(dir: &Path) -> Result<Table, IoError> {
    let files = runs_files(dir)?;
    let mut merged: Option<DataFrame> = None;
    for f in &files {
        let df = read_frame(f)?;
        match merged.as_mut() {
            None => merged = Some(df),
            Some(m) => {
                m.vstack_mut(&df).map_err(|e| {
                    IoError::format(f, format!("columns differ from the other runs tables: {e}"))
                })?;
            }
        }
    }
    let Some(mut df) = merged else {
        return Err(IoError::format(dir, "no runs table (runs.parquet or runs-shard-*.parquet)"));
    };
    let ids = df.column("run_id").and_then(|c| c.str().cloned());
    let ids = ids.map_err(|e| IoError::format(dir, format!("runs table: {e}")))?;
    let mut seen = HashSet::new();
    let mask: BooleanChunked =
        ids.iter().map(|id| Some(seen.insert(id.unwrap_or("").to_string()))).collect();
    df = df.filter(&mask).map_err(|e| IoError::format(dir, e.to_string()))?;
    df = df
        .sort(["run_index"], SortMultipleOptions::default())
        .map_err(|e| IoError::format(dir, e.to_string()))?;
    frame_to_table(&df, dir)
}

/// The result rows as a frame (see the module docs for the columns); `rows` pairs each
/// result with the study part it belongs to.
pub fn sensitivity_frame(rows: &[(String, SensitivityRow)]) -> Result<DataFrame, PolarsError> {
    let text = |f: &dyn Fn(&SensitivityRow) -> String| {
        rows.iter().map(|(_, r)| f(r)).collect::<Vec<String>>()
    };
    let num = |f: &dyn Fn(&SensitivityRow) -> f64| {
        rows.iter().map(|(_, r)| Some(f(r)).filter(|v| v.is_finite())).collect::<Vec<_>>()
    };
    let count = |f: &dyn Fn(&SensitivityRow) -> usize| {
        rows.iter().map(|(_, r)| f(r) as u64).collect::<Vec<u64>>()
    };
    let cols = vec![
        Column::new("part".into(), rows.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>()),
        Column::new("method".into(), text(&|r| r.method.as_str().to_string())),
        Column::new("parameter".into(), text(&|r| r.parameter.clone())),
        Column::new("metric".into(), text(&|r| r.metric.clone())),
        Column::new("S1".into(), num(&|r| r.s1)),
        Column::new("S1_lo".into(), num(&|r| r.s1_lo)),
        Column::new("S1_hi".into(), num(&|r| r.s1_hi)),
        Column::new("ST".into(), num(&|r| r.st)),
        Column::new("ST_lo".into(), num(&|r| r.st_lo)),
        Column::new("ST_hi".into(), num(&|r| r.st_hi)),
        Column::new("mu".into(), num(&|r| r.mu)),
        Column::new("mu_star".into(), num(&|r| r.mu_star)),
        Column::new("sigma".into(), num(&|r| r.sigma)),
        Column::new("n_used".into(), count(&|r| r.n_used)),
        Column::new("n_dropped".into(), count(&|r| r.n_dropped)),
        Column::new(
            "note".into(),
            rows.iter().map(|(_, r)| r.note.clone()).collect::<Vec<Option<String>>>(),
        ),
    ];
    DataFrame::new_infer_height(cols)
}

/// Write `sensitivity.parquet` (or any path) atomically.
pub fn write_sensitivity(path: &Path, rows: &[(String, SensitivityRow)]) -> Result<(), IoError> {
    let mut df = sensitivity_frame(rows).map_err(|e| IoError::format(path, e.to_string()))?;
    write_frame(path, &mut df)
}
