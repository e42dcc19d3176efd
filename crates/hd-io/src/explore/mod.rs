//! Exploring result tables with polars' lazy API: summaries, filters, group-by tables,
//! pivots and the data behind plots, returned as polars-free [`Report`]s and curves.
//!
//! Main items: [`Dataset`] (one file, a folder of shards or a pattern, read as one table),
//! [`parse_filter`] (the `--filter` language), [`AggSpec`] / [`PivotSpec`] (what to
//! compute), [`Report`] and [`render`] (tables as text, CSV, Markdown or JSON),
//! [`unit_of`] (the unit of every column the workbench writes), [`write_table`] (a
//! polars-free table saved as Parquet).

mod agg;
mod dataset;
mod error;
mod filter;
mod format;
mod groupby;
mod key;
mod pivot;
mod plotdata;
mod save;
mod schema;
mod source;
mod summary;
mod token;
mod units;

pub use agg::{AGG_FNS, AggFn, AggSpec, SortSpec, parse_aggs, parse_sort};
pub use dataset::Dataset;
pub use error::ExploreError;
pub use filter::{Filter, FilterError, Test, Value, parse_filter};
pub use format::{Format, Report, Section, render, short_number, table_json};
pub use key::Key;
pub use pivot::{PivotSpec, parse_pivot};
pub use plotdata::{Curve, Grid};
pub use save::write_table;
pub use schema::ColumnInfo;
pub use source::{Kind, Source, resolve};
pub use token::Op;
pub use units::{is_metric, label, unit_of};
