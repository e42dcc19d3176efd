//! Group-by tables: one row per combination of the key columns, with the row count, the
//! failed runs and the requested aggregates (`--group-by COLS --agg METRIC:FN,...`).

use crate::explore::agg::{AggFn, AggSpec, SortSpec};
use crate::explore::dataset::Dataset;
use crate::explore::error::ExploreError;
use crate::explore::format::{Report, Section};
use crate::explore::schema::{find, find_numeric};
use crate::explore::units::unit_of;
use polars::prelude::*;
use serde_json::json;

impl Dataset {
    /// Aggregate per group of `keys` (or over all rows when `keys` is empty). Every table
    /// has `n` (rows per group) and, for run tables, `failed`; then one column per
    /// aggregate, named `METRIC_FN`. Rows are sorted by the keys unless `sort` says
    /// otherwise.
    pub fn group_by(
        &self,
        keys: &[String],
        aggs: &[AggSpec],
        sort: Option<&SortSpec>,
    ) -> Result<Report, ExploreError> {
        for k in keys {
            find(self.columns(), k, "--group-by")?;
        }
        // (aggregate, result name, unit)
        let mut outs: Vec<(Expr, String, String)> =
            vec![(len().cast(DataType::UInt64), "n".into(), String::new())];
        if self.has_column("status") {
            let failed = col("status").neq(lit("ok")).cast(DataType::UInt64).sum();
            outs.push((failed, "failed".into(), String::new()));
        }
        for a in aggs {
            if a.func == AggFn::Count {
                find(self.columns(), &a.column, "--agg")?;
            } else {
                find_numeric(self.columns(), &a.column, "--agg")?;
            }
            outs.push((a.func.expr(&a.column), a.output_name(), a.func.unit(&a.column)));
        }
        let mut names: Vec<String> = keys.to_vec();
        let mut units: Vec<String> =
            keys.iter().map(|k| unit_of(k).unwrap_or("").to_string()).collect();
        let mut exprs = Vec::with_capacity(outs.len());
        for (e, name, unit) in outs {
            exprs.push(e.alias(name.as_str()));
            names.push(name);
            units.push(unit);
        }
        let lf = if keys.is_empty() {
            self.lazy().select(exprs)
        } else {
            let by: Vec<Expr> = keys.iter().map(|k| col(k.as_str())).collect();
            self.lazy().group_by(by).agg(exprs)
        };
        let lf = match sort {
            Some(s) => {
                if !names.contains(&s.column) {
                    return Err(ExploreError::usage(
                        "--sort",
                        format!(
                            "no column '{}' in the result (columns: {})",
                            s.column,
                            names.join(", ")
                        ),
                    ));
                }
                let opts = SortMultipleOptions::default()
                    .with_order_descending(s.descending)
                    .with_nulls_last(true);
                lf.sort([s.column.as_str()], opts)
            }
            None if !keys.is_empty() => {
                let opts = SortMultipleOptions::default().with_nulls_last(true);
                lf.sort(keys.iter().map(String::as_str).collect::<Vec<_>>(), opts)
            }
            None => lf,
        };
        let table = self.run(lf)?;
        let title = if keys.is_empty() {
            "All rows".to_string()
        } else {
            format!("Grouped by {}", keys.join(", "))
        };
        let mut report = Report::default();
        report.facts.push(("source".into(), json!(self.source().name)));
        if !self.filters().is_empty() {
            report.facts.push(("filters".into(), json!(self.filters())));
        }
        report.facts.push(("groups".into(), json!(table.height)));
        report.sections.push(Section { key: "rows".into(), title, table, units });
        Ok(report)
    }
}
