//! The columns of a data set as the explore engine sees them: name, type, unit, and
//! lookups that turn a misspelt name into an error with a suggestion.

use crate::explore::error::ExploreError;
use crate::explore::units::unit_of;
use polars::prelude::{DataType, Schema};

/// One column of a data set.
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnInfo {
    /// Column name.
    pub name: String,
    /// Storage type as polars names it, e.g. `f64`, `str`, `u64`.
    pub dtype: String,
    /// Whether the column holds numbers (integers, floats or booleans).
    pub numeric: bool,
    /// Unit from the workbench's column tables; `None` for a column it does not write.
    pub unit: Option<&'static str>,
}

/// The columns of a polars schema, in order.
pub(crate) fn columns_of(schema: &Schema) -> Vec<ColumnInfo> {
    schema
        .iter()
        .map(|(name, dt)| ColumnInfo {
            name: name.to_string(),
            dtype: dt.to_string(),
            numeric: is_numeric(dt),
            unit: unit_of(name),
        })
        .collect()
}

fn is_numeric(dt: &DataType) -> bool {
    dt.is_primitive_numeric() || dt.is_bool()
}

/// The column called `name`, or an error naming `context` (the option that asked), the
/// nearest column name and all those present.
pub(crate) fn find<'a>(
    columns: &'a [ColumnInfo],
    name: &str,
    context: &str,
) -> Result<&'a ColumnInfo, ExploreError> {
    columns.iter().find(|c| c.name == name).ok_or_else(|| ExploreError::UnknownColumn {
        context: context.to_string(),
        name: name.to_string(),
        hint: suggestion(columns, name)
            .map(|s| format!(" (did you mean '{s}'?)"))
            .unwrap_or_default(),
        available: columns.iter().map(|c| c.name.as_str()).collect::<Vec<_>>().join(", "),
    })
}

/// The column name nearest to `name`, if one is close.
pub(crate) fn suggestion<'a>(columns: &'a [ColumnInfo], name: &str) -> Option<&'a str> {
    hd_model::registry::nearest_of(name, columns.iter().map(|c| c.name.as_str()))
}

/// Like [`find`], and the column must hold numbers.
pub(crate) fn find_numeric<'a>(
    columns: &'a [ColumnInfo],
    name: &str,
    context: &str,
) -> Result<&'a ColumnInfo, ExploreError> {
    let c = find(columns, name, context)?;
    if !c.numeric {
        return Err(ExploreError::usage(
            context,
            format!("column '{name}' holds {} values, not numbers", c.dtype),
        ));
    }
    Ok(c)
}
