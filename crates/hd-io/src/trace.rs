//! `trace.parquet`: one row per output sample, the columns of [`hd_model::TRACE_COLUMNS`].

use crate::atomic::write_atomically;
use crate::error::IoError;
use hd_model::{TRACE_COLUMNS, Trace};
use polars::prelude::*;
use std::path::Path;

/// The trace as a polars frame.
pub fn trace_frame(trace: &Trace) -> Result<DataFrame, PolarsError> {
    let cols: Vec<Column> = TRACE_COLUMNS
        .iter()
        .zip(trace.columns())
        .map(|((name, _), data)| Column::new((*name).into(), data))
        .collect();
    DataFrame::new_infer_height(cols)
}

/// Write a trace to a Parquet file (atomically).
pub fn write_trace(path: &Path, trace: &Trace) -> Result<(), IoError> {
    let mut df = trace_frame(trace).map_err(|e| IoError::format(path, e.to_string()))?;
    write_atomically(path, |file| {
        ParquetWriter::new(file)
            .finish(&mut df)
            .map(|_| ())
            .map_err(|e| IoError::format(path, format!("cannot write Parquet: {e}")))
    })
}
