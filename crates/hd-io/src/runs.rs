//! Run tables on disk: the run ids already written, and the one routine that stacks
//! shards and part files into one table (one row per run, sorted). The tables themselves
//! are built by `hd_sweep::tables` and written by [`crate::parquet_out`]. Sweeps merge with
//! [`merge_runs`] and [`concat_files`], which hold one window of rows at a time.

use crate::atomic::{Staged, write_atomically};
use crate::error::IoError;
use crate::parquet_out::write_frame;
use crate::trace::STREAM_CHUNK;
use polars::prelude::*;
use std::collections::HashSet;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// The run ids present in the given Parquet files.
pub fn read_run_ids(files: &[PathBuf]) -> Result<HashSet<String>, IoError> {
    let mut ids = HashSet::new();
    for f in files {
        for_each_run(f, &mut |_, id| {
            ids.insert(id.to_string());
        })?;
    }
    Ok(ids)
}

/// Call `visit(run_index, run_id)` for every row of the runs table `file`, reading only
/// those two columns.
pub fn for_each_run(file: &Path, visit: &mut dyn FnMut(u64, &str)) -> Result<(), IoError> {
    let df = read_columns_of(file, &["run_index", "run_id"])?;
    let index = u64_column(&df, file, "run_index")?;
    let ids = df.column("run_id").map_err(IoError::polars(file, "no run_id column"))?;
    let ids = ids.str().map_err(IoError::polars(file, "run_id is not text"))?;
    for (i, id) in index.iter().zip(ids.iter()) {
        visit(*i, id.unwrap_or(""));
    }
    Ok(())
}

/// Only the named columns of a Parquet file.
pub fn read_columns_of(file: &Path, names: &[&str]) -> Result<DataFrame, IoError> {
    let f = std::fs::File::open(file).map_err(|e| IoError::fs(file, e))?;
    ParquetReader::new(f)
        .with_columns(Some(names.iter().map(|n| n.to_string()).collect()))
        .finish()
        .map_err(IoError::polars(file, format!("cannot read the columns {}", names.join(", "))))
}

fn u64_column(df: &DataFrame, file: &Path, name: &str) -> Result<Vec<u64>, IoError> {
    let col = df.column(name).map_err(IoError::polars(file, format!("no {name} column")))?;
    let cast = col
        .cast(&DataType::UInt64)
        .map_err(IoError::polars(file, format!("{name} is not a count")))?;
    let ca = cast.u64().map_err(IoError::polars(file, format!("{name} is not a count")))?;
    Ok(ca.iter().map(|v| v.unwrap_or(0)).collect())
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

/// Rows per row group of a merged runs table, and the most rows a merge holds at once.
pub const MERGE_WINDOW_ROWS: u64 = 32_768;

/// Merge runs tables into `out` atomically in bounded memory: every row once per `run_id`
/// (the first in file order is kept), sorted by `run_index`, written one row group per
/// window of run indices. Only the rows of one window (about [`MERGE_WINDOW_ROWS`]) are
/// held at a time: each file's rows of the window are read with a filter on `run_index`,
/// which Parquet's row-group statistics turn into reading the row groups that hold them.
/// Returns the number of rows written.
pub fn merge_runs(files: &[PathBuf], out: &Path) -> Result<usize, IoError> {
    merge_runs_by(files, out, |body| write_atomically(out, body))
}

/// [`merge_runs`] into the staged file `staged` (committed by the caller, with its
/// siblings). Nothing is written when the inputs hold no row (0 is returned).
pub fn merge_runs_into(files: &[PathBuf], staged: &mut Staged) -> Result<usize, IoError> {
    let out = staged.dest().to_path_buf();
    merge_runs_by(files, &out, |body| staged.write_with(body))
}

/// The writer a merge's rows go through.
type MergeBody<'a> = Box<dyn FnOnce(&mut BufWriter<&mut File>) -> Result<usize, IoError> + 'a>;

/// [`merge_runs`] with the file to write given by `write` (which runs the body it is
/// handed), so the merged table can land alone or with a group.
fn merge_runs_by(
    files: &[PathBuf],
    out: &Path,
    write: impl FnOnce(MergeBody<'_>) -> Result<usize, IoError>,
) -> Result<usize, IoError> {
    // Each file's index range, from its run_index column alone.
    let mut ranges = Vec::with_capacity(files.len());
    let (mut lo, mut hi, mut rows) = (u64::MAX, 0u64, 0u64);
    for f in files {
        let df = read_columns_of(f, &["run_index"])?;
        let idx = u64_column(&df, f, "run_index")?;
        let r = (idx.iter().copied().min(), idx.iter().copied().max());
        if let (Some(a), Some(b)) = r {
            lo = lo.min(a);
            hi = hi.max(b);
            rows += idx.len() as u64;
            ranges.push(Some((a, b)));
        } else {
            ranges.push(None);
        }
    }
    if rows == 0 {
        return Ok(0);
    }
    let span = hi - lo + 1;
    let width = (span as u128 * MERGE_WINDOW_ROWS as u128 / rows as u128).max(1) as u64;
    write(Box::new(move |file: &mut BufWriter<&mut File>| {
        let mut writer = None;
        let mut written = 0usize;
        let mut a = lo;
        while a <= hi {
            let b = a.saturating_add(width);
            let mut window: Option<DataFrame> = None;
            for (f, r) in files.iter().zip(&ranges) {
                let Some((fa, fb)) = *r else { continue };
                if fb < a || fa >= b {
                    continue;
                }
                // A part wholly inside the window is read as it is: a filtered scan costs
                // a query plan per part (most of a small study's merge time).
                let part = if fa >= a && fb < b {
                    crate::columns::read_frame(f)?
                } else {
                    read_window(f, a, b)?
                };
                match window.as_mut() {
                    None => window = Some(part),
                    Some(w) => {
                        w.vstack_mut(&part)
                            .map_err(IoError::polars(f, "columns differ from the other parts"))?;
                    }
                }
            }
            if let Some(w) = window {
                let mut w = dedupe_and_sort(w, out)?;
                if w.height() > 0 {
                    if writer.is_none() {
                        let meta = crate::parquet_out::metadata(&w);
                        let bw = ParquetWriter::new(&mut *file)
                            .with_key_value_metadata(Some(meta))
                            .batched(&w.schema().clone())
                            .map_err(IoError::polars(out, "cannot write Parquet"))?;
                        writer = Some(bw);
                    }
                    w.rechunk_mut();
                    written += w.height();
                    if let Some(bw) = writer.as_mut() {
                        bw.write_batch(&w).map_err(IoError::polars(out, "cannot write Parquet"))?;
                    }
                }
            }
            if b > hi {
                break;
            }
            a = b;
        }
        if let Some(bw) = writer {
            bw.finish().map_err(IoError::polars(out, "cannot write Parquet"))?;
        }
        Ok(written)
    }))
}

/// The rows of `file` with `a <= run_index < b`.
fn read_window(file: &Path, a: u64, b: u64) -> Result<DataFrame, IoError> {
    let path = PlRefPath::try_from_path(file)
        .map_err(|e| IoError::format(file, format!("not a usable path: {e}")))?;
    let idx = col("run_index").cast(DataType::UInt64);
    LazyFrame::scan_parquet(path, ScanArgsParquet::default())
        .and_then(|lf| lf.filter(idx.clone().gt_eq(lit(a)).and(idx.lt(lit(b)))).collect())
        .map_err(IoError::polars(file, "cannot read Parquet"))
}

/// Drop repeated run ids (first kept) and sort by run_index.
fn dedupe_and_sort(df: DataFrame, out: &Path) -> Result<DataFrame, IoError> {
    let ids = df.column("run_id").map_err(IoError::polars(out, "no run_id column"))?;
    let ca = ids.str().map_err(IoError::polars(out, "run_id is not text"))?;
    let mut seen = HashSet::new();
    let mask: BooleanChunked = ca.iter().map(|id| Some(seen.insert(id.unwrap_or("")))).collect();
    let df = df.filter(&mask).map_err(IoError::polars(out, "cannot drop repeated runs"))?;
    df.sort(["run_index"], SortMultipleOptions::default())
        .map_err(IoError::polars(out, "cannot sort by run_index"))
}

/// Stack Parquet files (traces) into `out` in order, [`STREAM_CHUNK`] rows at a time:
/// memory does not grow with the files' length. Returns the number of rows.
pub fn concat_files(files: &[PathBuf], out: &Path) -> Result<usize, IoError> {
    write_atomically(out, |file| concat_into(files, out, file))
}

/// [`concat_files`] into the staged file `staged` (committed by the caller).
pub fn concat_files_into(files: &[PathBuf], staged: &mut Staged) -> Result<usize, IoError> {
    let out = staged.dest().to_path_buf();
    staged.write_with(|file| concat_into(files, &out, file))
}

/// The rows `[from, from + len)` of the Parquet file `path`.
fn read_slice(path: &Path, from: usize, len: usize) -> Result<DataFrame, IoError> {
    let f = std::fs::File::open(path).map_err(|e| IoError::fs(path, e))?;
    ParquetReader::new(f)
        .with_slice(Some((from, len)))
        .finish()
        .map_err(IoError::polars(path, "cannot read Parquet"))
}

/// Rows in the Parquet file `path` (from its footer).
fn row_count(path: &Path) -> Result<usize, IoError> {
    let f = std::fs::File::open(path).map_err(|e| IoError::fs(path, e))?;
    ParquetReader::new(f).num_rows().map_err(IoError::polars(path, "cannot read Parquet"))
}

fn concat_into(
    files: &[PathBuf],
    out: &Path,
    file: &mut std::io::BufWriter<&mut std::fs::File>,
) -> Result<usize, IoError> {
    {
        let mut writer = None;
        let mut written = 0usize;
        let slices =
            files.iter().map(|f| Ok((f, row_count(f)?))).collect::<Result<Vec<_>, IoError>>()?;
        let chunks = slices.iter().flat_map(|(f, n)| {
            (0..*n).step_by(STREAM_CHUNK).map(move |from| (*f, from, STREAM_CHUNK.min(n - from)))
        });
        for (f, from, len) in chunks {
            let mut df = read_slice(f, from, len)?;
            if df.height() == 0 {
                continue;
            }
            if writer.is_none() {
                let meta = crate::parquet_out::metadata(&df);
                let bw = ParquetWriter::new(&mut *file)
                    .with_key_value_metadata(Some(meta))
                    .batched(&df.schema().clone())
                    .map_err(IoError::polars(out, "cannot write Parquet"))?;
                writer = Some(bw);
            }
            df.rechunk_mut();
            written += df.height();
            if let Some(bw) = writer.as_mut() {
                bw.write_batch(&df)
                    .map_err(IoError::polars(f, "columns differ from the other parts"))?;
            }
        }
        match writer {
            Some(bw) => {
                bw.finish().map_err(IoError::polars(out, "cannot write Parquet"))?;
            }
            None => {
                let mut empty = DataFrame::empty();
                ParquetWriter::new(&mut *file)
                    .finish(&mut empty)
                    .map_err(IoError::polars(out, "cannot write Parquet"))?;
            }
        }
        Ok(written)
    }
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
