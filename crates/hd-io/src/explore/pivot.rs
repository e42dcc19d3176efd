//! Pivot tables (`--pivot ROW,COL,METRIC[:FN]`): one row per value of ROW, one column per
//! value of COL, each cell the aggregate (default: mean) of METRIC over the runs with
//! those two values. Computed as a polars group-by on (ROW, COL), then laid out here, so
//! polars' own pivot feature is not needed.

use crate::explore::agg::{AggFn, SortSpec};
use crate::explore::dataset::Dataset;
use crate::explore::error::ExploreError;
use crate::explore::format::{Report, Section};
use crate::explore::key::Key;
use crate::explore::schema::{find, find_numeric};
use crate::explore::units::unit_of;
use crate::table::{ColumnData, Table};
use polars::prelude::*;
use serde_json::json;

/// Most distinct COL values a pivot lays out as columns.
pub const MAX_PIVOT_COLUMNS: usize = 100;

/// What a pivot computes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PivotSpec {
    /// Column whose values become rows.
    pub row: String,
    /// Column whose values become columns.
    pub column: String,
    /// Column aggregated in the cells.
    pub value: String,
    /// How the runs of a cell are combined.
    pub func: AggFn,
}

/// Parse `ROW,COL,METRIC` or `ROW,COL,METRIC:FN`.
pub fn parse_pivot(text: &str) -> Result<PivotSpec, ExploreError> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [row, column, value] = parts[..] else {
        return Err(ExploreError::usage(
            "--pivot",
            format!("'{text}': expected ROW,COL,METRIC[:FN], e.g. Kbar,voltage,thz_amp:max"),
        ));
    };
    let (value, func) = match value.split_once(':') {
        Some((v, f)) => (v, AggFn::parse(f, "--pivot")?),
        None => (value, AggFn::Mean),
    };
    if [row, column, value].iter().any(|s| s.is_empty()) {
        return Err(ExploreError::usage("--pivot", format!("'{text}': a name is empty")));
    }
    Ok(PivotSpec { row: row.into(), column: column.into(), value: value.into(), func })
}

impl Dataset {
    /// The pivot table of `spec`. Cells without runs are missing (NaN). Rows are in
    /// ascending ROW order unless `sort` names a column of the result.
    pub fn pivot(&self, spec: &PivotSpec, sort: Option<&SortSpec>) -> Result<Report, ExploreError> {
        find(self.columns(), &spec.row, "--pivot")?;
        find(self.columns(), &spec.column, "--pivot")?;
        if spec.func == AggFn::Count {
            find(self.columns(), &spec.value, "--pivot")?;
        } else {
            find_numeric(self.columns(), &spec.value, "--pivot")?;
        }
        let by = [col(spec.row.as_str()), col(spec.column.as_str())];
        let lf = self.lazy().group_by(by).agg([spec.func.expr(&spec.value).alias("\u{1}cell")]);
        let cells = self.run(lf)?;
        let row_keys = Key::column(&cells.columns[0]);
        let col_keys = Key::column(&cells.columns[1]);
        let values = match &cells.columns[2] {
            ColumnData::Num(v) => v.clone(),
            ColumnData::Text(_) => vec![f64::NAN; cells.height],
        };
        let rows = Key::distinct(&row_keys);
        let cols = Key::distinct(&col_keys);
        if cols.len() > MAX_PIVOT_COLUMNS {
            return Err(ExploreError::usage(
                "--pivot",
                format!(
                    "column '{}' has {} distinct values; a pivot lays out at most {MAX_PIVOT_COLUMNS}: choose a swept column or filter first",
                    spec.column,
                    cols.len()
                ),
            ));
        }
        let index = |keys: &[Key], k: &Key| keys.binary_search_by(|x| x.cmp_keys(k)).ok();
        let mut grid = vec![vec![f64::NAN; rows.len()]; cols.len()];
        for i in 0..cells.height {
            if let (Some(r), Some(c)) = (index(&rows, &row_keys[i]), index(&cols, &col_keys[i])) {
                grid[c][r] = values[i];
            }
        }
        let mut table = Table { height: rows.len(), ..Default::default() };
        table.names.push(spec.row.clone());
        table.columns.push(match &cells.columns[0] {
            ColumnData::Num(_) => ColumnData::Num(
                rows.iter().map(|k| if let Key::Num(x) = k { *x } else { f64::NAN }).collect(),
            ),
            ColumnData::Text(_) => ColumnData::Text(
                rows.iter().map(|k| if let Key::Text(s) = k { s.clone() } else { None }).collect(),
            ),
        });
        let mut units = vec![unit_of(&spec.row).unwrap_or("").to_string()];
        for (k, column) in cols.iter().zip(grid) {
            table.names.push(format!("{}={k}", spec.column));
            table.columns.push(ColumnData::Num(column));
            units.push(String::new());
        }
        if let Some(s) = sort {
            sort_table(&mut table, s)?;
        }
        let cell_unit = spec.func.unit(&spec.value);
        let title = format!(
            "{}{} ({}) by {} (rows) and {}{} (columns)",
            spec.value,
            if cell_unit.is_empty() { String::new() } else { format!(" [{cell_unit}]") },
            spec.func.name(),
            spec.row,
            spec.column,
            unit_of(&spec.column)
                .filter(|u| !u.is_empty())
                .map(|u| format!(" [{u}]"))
                .unwrap_or_default(),
        );
        let mut report = Report::default();
        report.facts.push(("source".into(), json!(self.source().name)));
        if !self.filters().is_empty() {
            report.facts.push(("filters".into(), json!(self.filters())));
        }
        report.sections.push(Section { key: "pivot".into(), title, table, units });
        Ok(report)
    }
}

/// Reorder the rows of a small result table by one of its columns.
fn sort_table(t: &mut Table, s: &SortSpec) -> Result<(), ExploreError> {
    let Some(k) = t.names.iter().position(|n| *n == s.column) else {
        return Err(ExploreError::usage(
            "--sort",
            format!("no column '{}' in the pivot (columns: {})", s.column, t.names.join(", ")),
        ));
    };
    let keys = Key::column(&t.columns[k]);
    let mut order: Vec<usize> = (0..t.height).collect();
    order.sort_by(|&a, &b| {
        let o = keys[a].cmp_keys(&keys[b]);
        let either_missing = keys[a].is_missing() || keys[b].is_missing();
        if s.descending && !either_missing { o.reverse() } else { o }
    });
    for c in &mut t.columns {
        *c = match c {
            ColumnData::Num(v) => ColumnData::Num(order.iter().map(|&i| v[i]).collect()),
            ColumnData::Text(v) => ColumnData::Text(order.iter().map(|&i| v[i].clone()).collect()),
        };
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pivot_specs() {
        let p = parse_pivot("Kbar, voltage, thz_amp:max").unwrap();
        assert_eq!((p.row.as_str(), p.value.as_str(), p.func), ("Kbar", "thz_amp", AggFn::Max));
        assert_eq!(parse_pivot("a,b,c").unwrap().func, AggFn::Mean);
        assert!(parse_pivot("a,b").is_err());
        assert!(parse_pivot("a,,c").is_err());
    }
}
