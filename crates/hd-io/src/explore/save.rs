//! Writing a polars-free [`Table`] as Parquet, for callers that build small tables (a
//! query result to keep, or test fixtures) without knowing polars.

use crate::error::IoError;
use crate::runs::write_frame;
use crate::table::{ColumnData, Table};
use polars::prelude::*;
use std::path::Path;

/// Write `table` to `path` as Parquet, atomically. Numeric columns become `f64` (NaN is
/// written as null, as the workbench's own tables do), text columns `str`.
pub fn write_table(path: &Path, table: &Table) -> Result<(), IoError> {
    let cols: Vec<Column> = table
        .names
        .iter()
        .zip(&table.columns)
        .map(|(name, data)| match data {
            ColumnData::Num(v) => Column::new(
                name.as_str().into(),
                v.iter().map(|x| (!x.is_nan()).then_some(*x)).collect::<Vec<Option<f64>>>(),
            ),
            ColumnData::Text(v) => Column::new(name.as_str().into(), v.clone()),
        })
        .collect();
    let mut df = DataFrame::new_infer_height(cols)
        .map_err(|e| IoError::format(path, format!("cannot build the table: {e}")))?;
    write_frame(path, &mut df)
}
