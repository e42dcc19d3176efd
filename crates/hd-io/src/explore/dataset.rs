//! A data set: the Parquet files of a [`Source`] scanned lazily as one table, with the
//! filters applied so far.

use crate::explore::error::ExploreError;
use crate::explore::filter::parse_filter;
use crate::explore::key::Key;
use crate::explore::schema::{ColumnInfo, columns_of};
use crate::explore::source::{Kind, Source, resolve};
use crate::table::{Table, frame_to_table};
use polars::prelude::*;
use std::path::Path;

/// One table read lazily from one or more Parquet files with the same columns.
#[derive(Clone)]
pub struct Dataset {
    source: Source,
    lf: LazyFrame,
    columns: Vec<ColumnInfo>,
    filters: Vec<String>,
}

impl Dataset {
    /// Open a file, a folder or a pattern (see [`resolve`]); `want` picks the kind of
    /// table in a folder that holds several.
    pub fn open(spec: &str, want: Option<Kind>) -> Result<Dataset, ExploreError> {
        let source = resolve(spec, want)?;
        let mut scans = Vec::with_capacity(source.files.len());
        let mut first: Option<(SchemaRef, &Path)> = None;
        for f in &source.files {
            let path = PlRefPath::try_from_path(f)
                .map_err(|e| ExploreError::source(spec, format!("{}: {e}", f.display())))?;
            let mut lf = LazyFrame::scan_parquet(path, ScanArgsParquet::default())?;
            let schema = lf.collect_schema().map_err(|e| {
                ExploreError::source(spec, format!("cannot read {}: {e}", f.display()))
            })?;
            match &first {
                None => first = Some((schema, f)),
                Some((s0, f0)) if **s0 != *schema => {
                    return Err(ExploreError::source(
                        spec,
                        format!(
                            "{} and {} have different columns ({}); read them one at a time",
                            f0.display(),
                            f.display(),
                            schema_difference(s0, &schema)
                        ),
                    ));
                }
                Some(_) => {}
            }
            scans.push(lf);
        }
        let lf = if scans.len() == 1 {
            scans.remove(0)
        } else {
            concat(scans, UnionArgs { rechunk: false, ..Default::default() })?
        };
        let columns = first.map(|(s, _)| columns_of(&s)).unwrap_or_default();
        Ok(Dataset { source, lf, columns, filters: Vec::new() })
    }

    /// Keep the rows that pass every `--filter` expression.
    pub fn filtered(mut self, exprs: &[String]) -> Result<Dataset, ExploreError> {
        for e in exprs {
            let f = parse_filter(e)?;
            self.lf = self.lf.filter(f.to_expr(&self.columns)?);
            self.filters.push(e.clone());
        }
        Ok(self)
    }

    /// Keep the rows whose `column` equals one of `keys`.
    pub fn where_in(mut self, column: &str, keys: &[Key]) -> Result<Dataset, ExploreError> {
        crate::explore::schema::find(&self.columns, column, "selection")?;
        let pred = keys.iter().map(|k| k.equals(column)).reduce(|a, b| a.or(b));
        self.lf = self.lf.filter(pred.unwrap_or_else(|| lit(false)));
        self.filters.push(format!("{column} in [{}]", join_keys(keys)));
        Ok(self)
    }

    /// The files and their kind.
    pub fn source(&self) -> &Source {
        &self.source
    }

    /// The columns, in file order.
    pub fn columns(&self) -> &[ColumnInfo] {
        &self.columns
    }

    /// Whether a column of that name exists.
    pub fn has_column(&self, name: &str) -> bool {
        self.columns.iter().any(|c| c.name == name)
    }

    /// The filters applied so far, as written.
    pub fn filters(&self) -> &[String] {
        &self.filters
    }

    /// The lazy query so far.
    pub(crate) fn lazy(&self) -> LazyFrame {
        self.lf.clone()
    }

    /// Run `lf` and convert the result to a [`Table`].
    pub(crate) fn run(&self, lf: LazyFrame) -> Result<Table, ExploreError> {
        let df = lf.collect()?;
        Ok(frame_to_table(&df, Path::new(&self.source.name))?)
    }

    /// The distinct values of `column` (after the filters), sorted, missing last.
    pub fn distinct(&self, column: &str) -> Result<Vec<Key>, ExploreError> {
        crate::explore::schema::find(&self.columns, column, "selection")?;
        let t =
            self.run(self.lazy().select([col(column)]).unique(None, UniqueKeepStrategy::Any))?;
        Ok(t.columns.first().map(|c| Key::distinct(&Key::column(c))).unwrap_or_default())
    }
}

fn join_keys(keys: &[Key]) -> String {
    keys.iter().map(Key::to_string).collect::<Vec<_>>().join(", ")
}

/// Which columns two schemas disagree on.
fn schema_difference(a: &Schema, b: &Schema) -> String {
    let only = |x: &Schema, y: &Schema| -> Vec<String> {
        x.iter()
            .filter(|(n, t)| y.get(n.as_str()) != Some(*t))
            .map(|(n, t)| format!("{n}: {t}"))
            .collect()
    };
    let (ab, ba) = (only(a, b), only(b, a));
    let mut parts = Vec::new();
    if !ab.is_empty() {
        parts.push(format!("only or differently typed in the first: {}", ab.join(", ")));
    }
    if !ba.is_empty() {
        parts.push(format!("in the second: {}", ba.join(", ")));
    }
    if parts.is_empty() { "same columns in another order".into() } else { parts.join("; ") }
}
