//! Reading and writing the workbench's files with polars: traces and run tables as
//! Parquet, recorded inputs and measured data sets as CSV or Parquet. This is the only
//! crate that knows polars.
//!
//! Main items: [`write_trace`], [`read_columns`], [`read_profile`], [`IoError`], [`atomic::write_atomically`].

pub mod atomic;
pub mod columns;
pub mod csv_sniff;
pub mod error;
pub mod explore;
pub mod fit_series;
pub mod fleet;
pub mod lock;
pub mod mat;
pub mod parquet_out;
pub mod pending;
pub mod runs;
pub mod sensitivity;
pub mod store;
pub mod table;
pub mod trace;
pub mod write_columns;

pub use columns::{read_columns, read_frame, read_profile};
pub use error::IoError;
pub use fit_series::{FitSeries, SeriesBlock, write_fit_series};
pub use mat::{MatVariable, read_mat, read_mat_vectors};
pub use parquet_out::{write_frame, write_out_table};
pub use table::{ColumnData, Table, read_table};
pub use trace::{stream_trace_into, write_trace};
pub use write_columns::write_columns;
