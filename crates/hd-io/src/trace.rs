//! `trace.parquet`: one row per output sample, the columns of [`hd_model::TRACE_COLUMNS`].

use crate::atomic::write_atomically;
use crate::error::IoError;
use crate::parquet_out::{metadata, out_table_frame, write_out_table};
use hd_model::Trace;
use hd_model::signals::Sample;
use polars::io::parquet::write::BatchedWriter;
use polars::prelude::ParquetWriter;
use std::path::Path;

/// Write a trace to a Parquet file (atomically), units in the field metadata.
pub fn write_trace(path: &Path, trace: &Trace) -> Result<(), IoError> {
    write_out_table(path, &trace.to_table())
}

/// Samples per Parquet row group of a streamed trace (≈ 10 MB of columns in memory).
pub const STREAM_CHUNK: usize = 65_536;

/// The file a streamed trace goes to (buffered, see [`write_atomically`]).
type Sink<'a, 'f> = &'a mut std::io::BufWriter<&'f mut std::fs::File>;

/// The open state of a streamed trace file.
struct Stream<'a, 'f> {
    path: &'a Path,
    file: Option<Sink<'a, 'f>>,
    writer: Option<BatchedWriter<Sink<'a, 'f>>>,
    buf: Trace,
    failed: Option<IoError>,
}

impl Stream<'_, '_> {
    fn push(&mut self, s: &Sample) {
        if self.failed.is_some() {
            return;
        }
        self.buf.push(s);
        if self.buf.len() >= STREAM_CHUNK
            && let Err(e) = self.flush()
        {
            self.failed = Some(e);
        }
    }

    /// Write the buffered samples as one row group (the first creates the writer).
    fn flush(&mut self) -> Result<(), IoError> {
        let path = self.path;
        let mut df = out_table_frame(&std::mem::take(&mut self.buf).to_table())
            .map_err(IoError::polars(path, "cannot build the table"))?;
        if self.writer.is_none()
            && let Some(file) = self.file.take()
        {
            let w = ParquetWriter::new(file)
                .with_key_value_metadata(Some(metadata(&df)))
                .batched(&df.schema().clone())
                .map_err(IoError::polars(path, "cannot write Parquet"))?;
            self.writer = Some(w);
        }
        df.rechunk_mut();
        match self.writer.as_mut() {
            Some(w) => w.write_batch(&df).map_err(IoError::polars(path, "cannot write Parquet")),
            None => Ok(()),
        }
    }
}

/// Write a trace to `path` while it is being produced: `produce` gets a sink for the
/// samples and runs (the simulation); every [`STREAM_CHUNK`] samples become one row group,
/// so memory does not grow with the run's length. The file appears (atomically) only when
/// everything is written; a write error stops the writing and is returned once `produce`
/// is done.
pub fn stream_trace<T>(
    path: &Path,
    produce: impl FnOnce(&mut dyn FnMut(&Sample)) -> T,
) -> Result<T, IoError> {
    write_atomically(path, |file| {
        let mut st =
            Stream { path, file: Some(file), writer: None, buf: Trace::default(), failed: None };
        let out = produce(&mut |s: &Sample| st.push(s));
        if let Some(e) = st.failed.take() {
            return Err(e);
        }
        st.flush()?;
        if let Some(w) = st.writer.take() {
            w.finish().map_err(IoError::polars(path, "cannot write Parquet"))?;
        }
        Ok(out)
    })
}
