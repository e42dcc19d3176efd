//! `trace.parquet`: one row per output sample, the columns of [`hd_model::TRACE_COLUMNS`].

use crate::atomic::Staged;
use crate::error::IoError;
use crate::parquet_out::{metadata, out_table_frame, write_out_table};
use hd_model::Trace;
use hd_model::signals::Sample;
use polars::io::parquet::write::BatchedWriter;
use polars::prelude::{Column, ParquetWriter};
use std::path::Path;

/// Write a trace to a Parquet file (atomically), units in the field metadata.
pub fn write_trace(path: &Path, trace: &Trace) -> Result<(), IoError> {
    write_out_table(path, &trace.to_table())
}

/// Samples per Parquet row group of a streamed trace (≈ 10 MB of columns in memory).
pub const STREAM_CHUNK: usize = 65_536;

/// The file a streamed trace goes to (buffered, see [`Staged::write_with`]).
type Sink<'a, 'f> = &'a mut std::io::BufWriter<&'f mut std::fs::File>;

/// The open state of a streamed trace file.
struct Stream<'a, 'f> {
    path: &'a Path,
    run_id: Option<&'a str>,
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
        let n = self.buf.len();
        let mut df = out_table_frame(&std::mem::take(&mut self.buf).to_table())
            .map_err(IoError::polars(path, "cannot build the table"))?;
        if let Some(id) = self.run_id {
            let ids = Column::new("run_id".into(), vec![id; n]);
            df.insert_column(0, ids).map_err(IoError::polars(path, "cannot build the table"))?;
        }
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

/// Write a trace into the staged file `staged` while it is being produced: `produce` gets
/// a sink for the samples and runs (the simulation); every [`STREAM_CHUNK`] samples become
/// one row group, so memory does not grow with the run's length. With `run_id`, a first
/// column `run_id` holds it on every row (a study's long format). A write error stops
/// the writing and is returned once `produce` is done. Nothing appears at the staged
/// file's destination until it is committed ([`crate::atomic::commit`]): a caller whose
/// `produce` failed drops `staged` and the temporary is gone.
pub fn stream_trace_into<T>(
    staged: &mut Staged,
    run_id: Option<&str>,
    produce: impl FnOnce(&mut dyn FnMut(&Sample)) -> T,
) -> Result<T, IoError> {
    let path = staged.dest().to_path_buf();
    staged.write_with(|file| {
        let mut st = Stream {
            path: &path,
            run_id,
            file: Some(file),
            writer: None,
            buf: Trace::default(),
            failed: None,
        };
        let out = produce(&mut |s: &Sample| st.push(s));
        if let Some(e) = st.failed.take() {
            return Err(e);
        }
        st.flush()?;
        if let Some(w) = st.writer.take() {
            w.finish().map_err(IoError::polars(&path, "cannot write Parquet"))?;
        }
        Ok(out)
    })
}
