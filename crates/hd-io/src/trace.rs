//! `trace.parquet`: one row per output sample, the columns of [`hd_model::TRACE_COLUMNS`].

use crate::error::IoError;
use crate::parquet_out::write_out_table;
use hd_model::Trace;
use std::path::Path;

/// Write a trace to a Parquet file (atomically), units in the field metadata.
pub fn write_trace(path: &Path, trace: &Trace) -> Result<(), IoError> {
    write_out_table(path, &trace.to_table())
}
