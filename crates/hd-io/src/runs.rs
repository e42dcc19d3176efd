//! Run tables on disk: the run ids already written, and the one routine that stacks
//! shards and part files into one table (one row per run, sorted). The tables themselves
//! are built by `hd_sweep::tables` and written by [`crate::parquet_out`].

use crate::error::IoError;
use crate::parquet_out::write_frame;
use polars::prelude::*;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// The run ids present in the given Parquet files.
pub fn read_run_ids(files: &[PathBuf]) -> Result<HashSet<String>, IoError> {
    let mut ids = HashSet::new();
    for f in files {
        let df = crate::columns::read_frame(f)?;
        let col = df.column("run_id").map_err(IoError::polars(f, "no run_id column"))?;
        let ca = col.str().map_err(IoError::polars(f, "run_id is not text"))?;
        ids.extend(ca.iter().flatten().map(str::to_string));
    }
    Ok(ids)
}

/// Stack Parquet files that share one schema; with `dedupe_runs`, keep only the first row
/// of each `run_id` (shards and part files may overlap after an interruption); sort by
/// `sort_by` when given. `None` when there are no files. This is the one place where
/// shards are merged.
pub fn stack_files(
    files: &[PathBuf],
    dedupe_runs: bool,
    sort_by: Option<&str>,
) -> Result<Option<DataFrame>, IoError> {
    let mut merged: Option<DataFrame> = None;
    for f in files {
        let df = crate::columns::read_frame(f)?;
        match merged.as_mut() {
            None => merged = Some(df),
            Some(m) => {
                m.vstack_mut(&df)
                    .map_err(IoError::polars(f, "columns differ from the other parts"))?;
            }
        }
    }
    let Some(mut df) = merged else { return Ok(None) };
    let first = files[0].as_path();
    if dedupe_runs {
        let ids = df.column("run_id").map_err(IoError::polars(first, "no run_id column"))?;
        let ca = ids.str().map_err(IoError::polars(first, "run_id is not text"))?;
        let mut seen = HashSet::new();
        let mask: BooleanChunked =
            ca.iter().map(|id| Some(seen.insert(id.unwrap_or("").to_string()))).collect();
        df = df.filter(&mask).map_err(IoError::polars(first, "cannot drop repeated runs"))?;
    }
    if let Some(col) = sort_by {
        df = df
            .sort([col], SortMultipleOptions::default())
            .map_err(IoError::polars(first, format!("cannot sort by {col}")))?;
    }
    df.rechunk_mut();
    Ok(Some(df))
}

/// [`stack_files`] written atomically to `out`. Returns the number of rows.
pub fn merge_files(
    files: &[PathBuf],
    out: &Path,
    dedupe_runs: bool,
    sort_by: Option<&str>,
) -> Result<usize, IoError> {
    let Some(mut df) = stack_files(files, dedupe_runs, sort_by)? else { return Ok(0) };
    let n = df.height();
    write_frame(out, &mut df)?;
    Ok(n)
}
