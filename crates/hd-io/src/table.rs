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
    let file = std::fs::File::open(path).map_err(|e| IoError::fs(path, e))?;
    let arrow =
        ParquetReader::new(file).schema().map_err(IoError::polars(path, "cannot read Parquet"))?;
    crate::columns::refuse_decimals(path, &arrow)?;
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

/// Read the named columns of a Parquet file (those it has) `chunk` rows at a time, handing
/// each piece to `each` in file order: memory follows the chunk, not the file (a report
/// thins a study's kept traces, which may hold hundreds of millions of rows).
pub fn for_each_chunk(
    path: &Path,
    names: &[&str],
    chunk: usize,
    mut each: impl FnMut(&Table) -> Result<(), IoError>,
) -> Result<(), IoError> {
    let file = std::fs::File::open(path).map_err(|e| IoError::fs(path, e))?;
    let rows = ParquetReader::new(file)
        .num_rows()
        .map_err(IoError::polars(path, "cannot read Parquet"))?;
    let (lf, present) = scan_present(path, names)?;
    let chunk = chunk.max(1);
    let mut offset = 0;
    while offset < rows {
        let df = lf
            .clone()
            .slice(offset as i64, chunk as IdxSize)
            .select(present.clone())
            .collect()
            .map_err(IoError::polars(path, "cannot read Parquet"))?;
        each(&frame_to_table(&df, path)?)?;
        offset += chunk;
    }
    Ok(())
}
