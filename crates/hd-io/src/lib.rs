//! Reading and writing the workbench's files with polars: traces and run tables as
//! Parquet, recorded inputs and measured data sets as CSV or Parquet. This is the only
//! crate that knows polars.
