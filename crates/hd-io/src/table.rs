//! A polars-free view of a table for callers outside this crate: numeric columns as `f64`
//! (null → NaN) and text columns as optional strings.

use crate::columns::read_frame;
use crate::error::IoError;
use polars::prelude::*;
use std::path::Path;

/// One column's data.
#[derive(Clone, Debug, PartialEq)]
pub enum ColumnData {
    /// Numbers (integers and booleans converted; null → NaN).
    Num(Vec<f64>),
    /// Text (null → None).
    Text(Vec<Option<String>>),
}

/// A table read from CSV or Parquet.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    /// Column names, in file order.
    pub names: Vec<String>,
    /// Column data, parallel to `names`.
    pub columns: Vec<ColumnData>,
    /// Number of rows.
    pub height: usize,
}

impl Table {
    /// A numeric column by name.
    pub fn num(&self, name: &str) -> Option<&[f64]> {
        let k = self.names.iter().position(|n| n == name)?;
        match &self.columns[k] {
            ColumnData::Num(v) => Some(v),
            ColumnData::Text(_) => None,
        }
    }

    /// A text column by name.
    pub fn text(&self, name: &str) -> Option<&[Option<String>]> {
        let k = self.names.iter().position(|n| n == name)?;
        match &self.columns[k] {
            ColumnData::Text(v) => Some(v),
            ColumnData::Num(_) => None,
        }
    }
}

/// Convert a frame into a [`Table`].
pub fn frame_to_table(df: &DataFrame, path: &Path) -> Result<Table, IoError> {
    let mut t = Table { height: df.height(), ..Default::default() };
    for col in df.columns() {
        let name = col.name().to_string();
        let data = match col.dtype() {
            DataType::String => {
                let ca = col.str().map_err(IoError::polars(path, "a text column"))?;
                ColumnData::Text(ca.iter().map(|s| s.map(str::to_string)).collect())
            }
            dt if dt.is_primitive_numeric() || dt.is_bool() => {
                let cast = col
                    .cast(&DataType::Float64)
                    .map_err(IoError::polars(path, format!("column '{name}' as numbers")))?;
                let ca = cast.f64().map_err(IoError::polars(path, "a numeric column"))?;
                ColumnData::Num(ca.iter().map(|v| v.unwrap_or(f64::NAN)).collect())
            }
            _ => {
                let cast = col
                    .cast(&DataType::String)
                    .map_err(IoError::polars(path, format!("column '{name}' as text")))?;
                let ca = cast.str().map_err(IoError::polars(path, "a text column"))?;
                ColumnData::Text(ca.iter().map(|s| s.map(str::to_string)).collect())
            }
        };
        t.names.push(name);
        t.columns.push(data);
    }
    Ok(t)
}

/// Read a CSV or Parquet file into a [`Table`].
pub fn read_table(path: &Path) -> Result<Table, IoError> {
    let df = read_frame(path)?;
    frame_to_table(&df, path)
}

/// A lazy scan of a Parquet file and the selection of those of `names` it has.
fn scan_present(path: &Path, names: &[&str]) -> Result<(LazyFrame, Vec<Expr>), IoError> {
    let pl_path = PlRefPath::try_from_path(path)
        .map_err(|e| IoError::format(path, format!("not a usable path: {e}")))?;
    let mut lf = LazyFrame::scan_parquet(pl_path, ScanArgsParquet::default())
        .map_err(IoError::polars(path, "cannot read Parquet"))?;
    let schema = lf.collect_schema().map_err(IoError::polars(path, "cannot read Parquet"))?;
    let present = names.iter().filter(|n| schema.contains(n)).map(|n| col(*n)).collect();
    Ok((lf, present))
}

/// Only the named columns of a Parquet file (those it has), read with a polars scan that
/// decodes nothing else: a report needs a few columns of a table of millions of rows.
pub fn read_table_columns(path: &Path, names: &[&str]) -> Result<Table, IoError> {
    let (lf, present) = scan_present(path, names)?;
    let df = lf.select(present).collect().map_err(IoError::polars(path, "cannot read Parquet"))?;
    frame_to_table(&df, path)
}

/// The named columns of the rows of a Parquet file whose `key` column holds one of `keys`,
/// read with a scan that decodes nothing else and keeps only those rows: a report overlays
/// the traces of a few runs out of a traces table of any length.
pub fn read_rows_with(
    path: &Path,
    names: &[&str],
    key: &str,
    keys: &[String],
) -> Result<Table, IoError> {
    let Some(wanted) = keys.iter().map(|k| col(key).eq(lit(k.as_str()))).reduce(|a, b| a.or(b))
    else {
        return Ok(Table::default());
    };
    let (lf, present) = scan_present(path, names)?;
    let df = lf
        .filter(wanted)
        .select(present)
        .collect()
        .map_err(IoError::polars(path, "cannot read Parquet"))?;
    frame_to_table(&df, path)
}
