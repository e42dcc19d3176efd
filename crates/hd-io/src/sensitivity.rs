//! Files of a global-sensitivity analysis: reading every runs table of a study folder as
//! one table, and writing `sensitivity.parquet`.
//!
//! `sensitivity.parquet` has one row per (part, metric, parameter) of a sobol or morris
//! design, with the columns `part`, `method`, `parameter`, `metric`, `S1`, `S1_lo`, `S1_hi`,
//! `ST`, `ST_lo`, `ST_hi` (Sobol' indices [-] and their bootstrap interval), `mu`,
//! `mu_star`, `sigma` (Morris statistics [metric unit per parameter range]), `n_used`,
//! `n_dropped` (base rows or trajectories used and dropped, u64) and `note`. Values that
//! were not computed or are undefined are null, never zero.

use crate::error::IoError;
use crate::parquet_out::write_out_table;
use crate::runs::stack_files;
use crate::table::{Table, frame_to_table};
use hd_model::OutTable;
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
    match stack_files(&files, true, Some("run_index"))? {
        Some(df) => frame_to_table(&df, dir),
        None => Err(IoError::format(dir, "no runs table (runs.parquet or runs-shard-*.parquet)")),
    }
}

/// Write `sensitivity.parquet` (or any path) atomically; the table comes from
/// `hd_sweep::tables::sensitivity_table`.
pub fn write_sensitivity(path: &Path, table: &OutTable) -> Result<(), IoError> {
    write_out_table(path, table)
}
