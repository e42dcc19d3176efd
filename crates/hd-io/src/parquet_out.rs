//! Writing an [`OutTable`] as Parquet, with each column's unit and description (from
//! [`hd_model::schema`]) in the file's field metadata, and the same as one JSON document
//! under the file-level key `hdw.columns` for readers that do not show field metadata
//! (DuckDB: `SELECT * FROM parquet_kv_metadata('runs.parquet')`).

use crate::atomic::write_atomically;
use crate::error::IoError;
use hd_model::{Cells, OutTable, schema};
use polars::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// File-level metadata key holding `{column: {"unit": …, "description": …}}`.
pub const COLUMNS_KEY: &str = "hdw.columns";

/// The table as a polars frame: NaN numbers and missing cells become null.
pub fn out_table_frame(t: &OutTable) -> Result<DataFrame, PolarsError> {
    let cols: Vec<Column> = t
        .columns
        .iter()
        .map(|c| {
            let name: PlSmallStr = c.name.as_str().into();
            match &c.cells {
                // Straight into Arrow's buffers (8 bytes a value and a validity bit), not
                // through a vector of options (16 bytes a value): a long fit's table.
                Cells::F64(v) if v.iter().all(|x| x.is_finite()) => Column::new(name, v.as_slice()),
                Cells::F64(v) => {
                    let ca: Float64Chunked =
                        v.iter().map(|x| x.is_finite().then_some(*x)).collect();
                    Column::from(ca.with_name(name).into_series())
                }
                Cells::U64(v) => Column::new(name, v),
                Cells::OptU64(v) => Column::new(name, v),
                Cells::Text(v) => Column::new(name, v),
                Cells::OptText(v) => Column::new(name, v),
            }
        })
        .collect();
    DataFrame::new_infer_height(cols)
}

/// Write `df` to `path` atomically, with the schema's unit and description of each column
/// it knows in the field metadata.
pub fn write_frame(path: &Path, df: &mut DataFrame) -> Result<(), IoError> {
    let meta = metadata(df);
    write_atomically(path, |file| {
        ParquetWriter::new(file)
            .with_key_value_metadata(Some(meta))
            .finish(df)
            .map(|_| ())
            .map_err(IoError::polars(path, "cannot write Parquet"))
    })
}

/// Write `t` to `path` as Parquet (see [`write_frame`]).
pub fn write_out_table(path: &Path, t: &OutTable) -> Result<(), IoError> {
    let mut df = out_table_frame(t).map_err(IoError::polars(path, "cannot build the table"))?;
    write_frame(path, &mut df)
}

/// The Arrow schema (with field metadata) and the `hdw.columns` document of `df`.
pub(crate) fn metadata(df: &DataFrame) -> KeyValueMetadata {
    let mut arrow = df.schema().to_arrow(CompatLevel::newest());
    let mut doc = serde_json::Map::new();
    for (name, field) in arrow.iter_mut() {
        let Some(c) = schema::describe(name) else { continue };
        let mut md = field.metadata.as_deref().cloned().unwrap_or_default();
        md.insert("unit".into(), c.unit.into());
        md.insert("description".into(), c.doc.into());
        field.metadata = Some(Arc::new(md));
        doc.insert(name.to_string(), serde_json::json!({ "unit": c.unit, "description": c.doc }));
    }
    let key = polars_parquet::write::schema_to_metadata_key(&arrow);
    KeyValueMetadata::from_static(vec![
        (key.key, key.value.unwrap_or_default()),
        (COLUMNS_KEY.to_string(), serde_json::Value::Object(doc).to_string()),
    ])
}
