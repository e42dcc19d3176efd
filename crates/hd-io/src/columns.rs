//! Reading named numeric columns from a CSV or Parquet file, checking every value.

use crate::error::IoError;
use polars::prelude::*;
use std::path::Path;

/// Read a CSV (header row) or Parquet file, chosen by extension, into a frame.
pub fn read_frame(path: &Path) -> Result<DataFrame, IoError> {
    if !path.is_file() {
        return Err(IoError::fs(
            path,
            std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
        ));
    }
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "parquet" | "pq" => {
            std::fs::File::open(path).map_err(|e| IoError::fs(path, e)).and_then(|f| {
                ParquetReader::new(f).finish().map_err(|e| IoError::format(path, e.to_string()))
            })
        }
        "csv" | "txt" => CsvReadOptions::default()
            .with_has_header(true)
            .try_into_reader_with_file_path(Some(path.to_path_buf()))
            .and_then(|r| r.finish())
            .map_err(|e| IoError::format(path, format!("cannot read CSV: {e}"))),
        _ => Err(IoError::format(
            path,
            format!("unknown file type '.{ext}': expected .csv or .parquet"),
        )),
    }
}

/// Read the named columns as `f64`, in the order asked. Errors name the file and the
/// missing column (listing those present), or the first row (1-based, counting data rows)
/// with a missing, NaN or infinite value.
pub fn read_columns(path: &Path, names: &[&str]) -> Result<Vec<Vec<f64>>, IoError> {
    let df = read_frame(path)?;
    let present: Vec<String> = df.get_column_names().iter().map(|s| s.to_string()).collect();
    names
        .iter()
        .map(|&name| {
            let col = df.column(name).map_err(|_| {
                IoError::format(
                    path,
                    format!("missing column '{name}' (found: {})", present.join(", ")),
                )
            })?;
            let cast = col.cast(&DataType::Float64).map_err(|_| {
                IoError::format(
                    path,
                    format!("column '{name}': expected numbers, found {}", col.dtype()),
                )
            })?;
            let ca = cast.f64().map_err(|e| IoError::format(path, e.to_string()))?;
            let mut out = Vec::with_capacity(ca.len());
            for (row, v) in ca.iter().enumerate() {
                match v {
                    Some(x) if x.is_finite() => out.push(x),
                    other => {
                        let shown = other
                            .map_or("an empty or non-numeric cell".to_string(), |x| x.to_string());
                        return Err(IoError::format(
                            path,
                            format!(
                                "column '{name}', row {}: {shown}; expected a finite number",
                                row + 1
                            ),
                        ));
                    }
                }
            }
            Ok(out)
        })
        .collect()
}

/// Read a recorded voltage profile (columns `t` [s] and `u` [V], strictly increasing t).
pub fn read_profile(path: &Path) -> Result<hd_model::Profile, IoError> {
    let mut cols = read_columns(path, &["t", "u"])?;
    let u = cols.pop().unwrap_or_default();
    let t = cols.pop().unwrap_or_default();
    hd_model::Profile::new(t, u, "recorded input").map_err(|e| IoError::format(path, e.to_string()))
}
