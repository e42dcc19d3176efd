//! Writing named numeric columns as a CSV or Parquet file, chosen by extension.

use crate::atomic::write_atomically;
use crate::error::IoError;
use polars::prelude::*;
use std::path::Path;

/// Write `cols` under `names` to `path`: `.csv` (header row, full precision) or
/// `.parquet`, atomically. Every column must have the same length and there must be one
/// name per column.
pub fn write_columns(path: &Path, names: &[&str], cols: &[Vec<f64>]) -> Result<(), IoError> {
    if names.len() != cols.len() {
        return Err(IoError::format(
            path,
            format!("{} column names for {} columns", names.len(), cols.len()),
        ));
    }
    if let Some((name, col)) = names.iter().zip(cols).find(|(_, c)| c.len() != cols[0].len()) {
        return Err(IoError::format(
            path,
            format!(
                "column '{name}' has {} values but '{}' has {}",
                col.len(),
                names[0],
                cols[0].len()
            ),
        ));
    }
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let columns: Vec<Column> =
        names.iter().zip(cols).map(|(n, c)| Column::new((*n).into(), c.as_slice())).collect();
    let mut df = DataFrame::new_infer_height(columns)
        .map_err(IoError::polars(path, "cannot build the table"))?;
    match ext.as_str() {
        "csv" => write_atomically(path, |file| {
            CsvWriter::new(file)
                .include_header(true)
                .finish(&mut df)
                .map_err(IoError::polars(path, "cannot write CSV"))
        }),
        "parquet" | "pq" => write_atomically(path, |file| {
            ParquetWriter::new(file)
                .finish(&mut df)
                .map(|_| ())
                .map_err(IoError::polars(path, "cannot write Parquet"))
        }),
        _ => Err(IoError::format(
            path,
            format!("unknown file type '.{ext}': expected .csv or .parquet"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::columns::read_columns;

    #[test]
    fn round_trips_through_csv_and_parquet() {
        let dir = std::env::temp_dir().join(format!("hd-io-write-columns-{}", std::process::id()));
        let cols = vec![vec![0.0, 1e-3, 2e-3], vec![1.0 / 3.0, -2.5e-7, 4e5]];
        for ext in ["csv", "parquet"] {
            let path = dir.join(format!("x.{ext}"));
            write_columns(&path, &["t", "theta"], &cols).unwrap();
            let back = read_columns(&path, &["theta", "t"]).unwrap();
            assert_eq!(back, vec![cols[1].clone(), cols[0].clone()], "{ext}");
        }
        let e = write_columns(&dir.join("x.txt"), &["t"], &cols[..1]).unwrap_err();
        assert!(e.to_string().contains("expected .csv or .parquet"));
        let _ = std::fs::remove_dir_all(dir);
    }
}
