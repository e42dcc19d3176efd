//! Writing a polars-free [`Table`] as Parquet, for callers that build small tables (a
//! query result to keep, or test fixtures) without knowing polars.

use crate::error::IoError;
use crate::parquet_out::write_out_table;
use crate::table::{ColumnData, Table};
use hd_model::{Cells, OutTable};
use std::path::Path;

/// Write `table` to `path` as Parquet, atomically. Numeric columns become `f64` (NaN is
/// written as null, as the workbench's own tables do), text columns `str`.
pub fn write_table(path: &Path, table: &Table) -> Result<(), IoError> {
    let mut out = OutTable::default();
    for (name, data) in table.names.iter().zip(&table.columns) {
        let cells = match data {
            ColumnData::Num(v) => Cells::F64(v.clone()),
            ColumnData::Text(v) => Cells::OptText(v.clone()),
        };
        out.push(name.as_str(), cells);
    }
    write_out_table(path, &out)
}
