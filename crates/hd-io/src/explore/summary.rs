//! The overview of a data set: its columns with units, the row count, the failed runs,
//! and the count, minimum, median and maximum of every metric.

use crate::explore::dataset::Dataset;
use crate::explore::error::ExploreError;
use crate::explore::format::{Report, Section};
use crate::explore::units::is_metric;
use crate::table::{ColumnData, Table};
use polars::prelude::*;
use serde_json::json;

/// How many failed runs the summary lists by name.
pub const FAILED_LISTED: usize = 20;

/// The value of the one-row frame `df` in `column`, as `f64` (null → NaN).
fn scalar(df: &DataFrame, column: &str) -> Result<f64, ExploreError> {
    let c = df.column(column)?.cast(&DataType::Float64)?;
    Ok(c.f64()?.get(0).unwrap_or(f64::NAN))
}

impl Dataset {
    /// The columns summarised: the run metrics if the table has any, else every numeric
    /// column.
    pub fn summary_columns(&self) -> Vec<String> {
        let metrics: Vec<String> =
            self.columns().iter().filter(|c| is_metric(&c.name)).map(|c| c.name.clone()).collect();
        if !metrics.is_empty() {
            return metrics;
        }
        self.columns().iter().filter(|c| c.numeric).map(|c| c.name.clone()).collect()
    }

    /// Schema with units, row count, failed runs, and statistics of every metric, all
    /// after the filters. One pass over the data for the numbers, one for the failures.
    pub fn summary(&self) -> Result<Report, ExploreError> {
        let stats_of = self.summary_columns();
        let has_status = self.has_column("status");
        let mut exprs = vec![len().alias("\u{1}rows")];
        if has_status {
            let failed = col("status").neq(lit("ok")).cast(DataType::UInt64).sum();
            exprs.push(failed.alias("\u{1}failed"));
        }
        for m in &stats_of {
            exprs.push(col(m.as_str()).count().alias(format!("{m}\u{1}count")));
            exprs.push(col(m.as_str()).min().alias(format!("{m}\u{1}min")));
            exprs.push(col(m.as_str()).median().alias(format!("{m}\u{1}median")));
            exprs.push(col(m.as_str()).max().alias(format!("{m}\u{1}max")));
        }
        let df = self.lazy().select(exprs).collect()?;
        let rows = scalar(&df, "\u{1}rows")? as u64;

        let mut report = Report::default();
        report.facts.push(("source".into(), json!(self.source().name)));
        let files: Vec<String> =
            self.source().files.iter().map(|f| f.display().to_string()).collect();
        report.facts.push(("files".into(), json!(files)));
        if !self.filters().is_empty() {
            report.facts.push(("filters".into(), json!(self.filters())));
        }
        report.facts.push(("rows".into(), json!(rows)));
        report.sections.push(self.schema_section());
        if has_status {
            let failed = scalar(&df, "\u{1}failed")? as u64;
            report.facts.push(("failed".into(), json!(failed)));
            if failed > 0 {
                report.sections.push(self.failed_section(failed)?);
            }
        }
        let mut stats = Table {
            names: ["column", "unit", "count", "min", "median", "max"].map(String::from).to_vec(),
            ..Default::default()
        };
        let mut cols: [Vec<f64>; 4] = Default::default();
        for m in &stats_of {
            for (k, what) in ["count", "min", "median", "max"].iter().enumerate() {
                cols[k].push(scalar(&df, &format!("{m}\u{1}{what}"))?);
            }
        }
        let units = stats_of
            .iter()
            .map(|m| self.columns().iter().find(|c| &c.name == m).and_then(|c| c.unit))
            .map(|u| Some(u.unwrap_or("").to_string()))
            .collect();
        stats.columns.push(ColumnData::Text(stats_of.iter().cloned().map(Some).collect()));
        stats.columns.push(ColumnData::Text(units));
        stats.columns.extend(cols.into_iter().map(ColumnData::Num));
        stats.height = stats_of.len();
        report.sections.push(Section {
            key: "metrics".into(),
            title: "Statistics (count of non-missing values, min, median, max)".into(),
            table: stats,
            units: Vec::new(),
        });
        Ok(report)
    }

    /// Every column with its type and unit.
    fn schema_section(&self) -> Section {
        let text = |f: &dyn Fn(&crate::explore::schema::ColumnInfo) -> String| {
            ColumnData::Text(self.columns().iter().map(|c| Some(f(c))).collect())
        };
        let table = Table {
            names: ["column", "type", "unit"].map(String::from).to_vec(),
            columns: vec![
                text(&|c| c.name.clone()),
                text(&|c| c.dtype.clone()),
                text(&|c| {
                    c.unit
                        .map_or("?".into(), |u| if u.is_empty() { "text".into() } else { u.into() })
                }),
            ],
            height: self.columns().len(),
        };
        Section { key: "columns".into(), title: "Columns".into(), table, units: Vec::new() }
    }

    /// The first failed runs with their error messages.
    fn failed_section(&self, failed: u64) -> Result<Section, ExploreError> {
        let wanted = ["run_id", "part", "variant", "error"];
        let keep: Vec<Expr> =
            wanted.iter().filter(|c| self.has_column(c)).map(|c| col(*c)).collect();
        let lf = self.lazy().filter(col("status").neq(lit("ok"))).select(keep);
        let table = self.run(lf.limit(FAILED_LISTED as IdxSize))?;
        let title = if failed as usize > FAILED_LISTED {
            format!("Failed runs (first {FAILED_LISTED} of {failed})")
        } else {
            "Failed runs".to_string()
        };
        Ok(Section { key: "failed_runs".into(), title, table, units: Vec::new() })
    }
}
