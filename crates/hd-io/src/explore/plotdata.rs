//! The data behind plots: curves (y against x, one per value of a column) and grids
//! (a value on the distinct x and y values), aggregated with polars.

use crate::explore::agg::AggFn;
use crate::explore::dataset::Dataset;
use crate::explore::error::ExploreError;
use crate::explore::key::Key;
use crate::explore::schema::{find, find_numeric};
use crate::table::ColumnData;
use polars::prelude::*;

/// One curve [units of its columns].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Curve {
    /// Legend text: the value of the `by` column, or the y column's name.
    pub name: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates, one per x.
    pub y: Vec<f64>,
}

/// Values on a grid: `values[iy * xs.len() + ix]` at `(xs[ix], ys[iy])`, NaN where no row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Grid {
    /// Distinct finite x values, ascending.
    pub xs: Vec<f64>,
    /// Distinct finite y values, ascending.
    pub ys: Vec<f64>,
    /// Cell values, row by row (one row per y).
    pub values: Vec<f64>,
    /// Largest number of rows combined into one cell.
    pub most_per_cell: usize,
}

/// Numbers of a column of a small result table.
fn nums(data: &ColumnData) -> Vec<f64> {
    match data {
        ColumnData::Num(v) => v.clone(),
        ColumnData::Text(v) => vec![f64::NAN; v.len()],
    }
}

impl Dataset {
    /// `y` against `x`, one curve per value of `by` (or one curve). With `func`, rows that
    /// share (by, x) are combined and the points sorted by x; the second result is then
    /// the largest number of rows combined into one point. Without `func`, the rows are
    /// taken as stored (e.g. a trace in time order) and that number is 1.
    pub fn curves(
        &self,
        x: &str,
        y: &str,
        by: Option<&str>,
        func: Option<AggFn>,
    ) -> Result<(Vec<Curve>, usize), ExploreError> {
        find_numeric(self.columns(), x, "--x")?;
        find_numeric(self.columns(), y, "--line")?;
        if let Some(b) = by {
            find(self.columns(), b, "--by")?;
        }
        let mut keys: Vec<Expr> = by.into_iter().map(col).collect();
        keys.push(col(x));
        let lf = match func {
            Some(f) => {
                let aggs =
                    [f.expr(y).alias("\u{1}y"), len().cast(DataType::Float64).alias("\u{1}n")];
                let order: Vec<&str> = by.into_iter().chain([x]).collect();
                self.lazy()
                    .group_by(keys)
                    .agg(aggs)
                    .sort(order, SortMultipleOptions::default().with_nulls_last(true))
            }
            None => {
                let mut sel = keys;
                sel.push(col(y).alias("\u{1}y"));
                sel.push(lit(1.0).alias("\u{1}n"));
                self.lazy().select(sel)
            }
        };
        let t = self.run(lf)?;
        let off = usize::from(by.is_some());
        let (xs, ys, ns) =
            (nums(&t.columns[off]), nums(&t.columns[off + 1]), nums(&t.columns[off + 2]));
        let most = ns.iter().fold(0.0f64, |a, &b| a.max(b)) as usize;
        let Some(b) = by else {
            return Ok((vec![Curve { name: y.to_string(), x: xs, y: ys }], most));
        };
        let groups = Key::column(&t.columns[0]);
        let curves = Key::distinct(&groups)
            .into_iter()
            .map(|k| {
                let rows: Vec<usize> = (0..t.height).filter(|&i| groups[i].same(&k)).collect();
                Curve {
                    name: format!("{b}={k}"),
                    x: rows.iter().map(|&i| xs[i]).collect(),
                    y: rows.iter().map(|&i| ys[i]).collect(),
                }
            })
            .collect();
        Ok((curves, most))
    }

    /// `value` combined with `func` over the rows at each distinct (x, y).
    pub fn grid(&self, x: &str, y: &str, value: &str, func: AggFn) -> Result<Grid, ExploreError> {
        find_numeric(self.columns(), x, "--x")?;
        find_numeric(self.columns(), y, "--y")?;
        find_numeric(self.columns(), value, "--color")?;
        let lf = self
            .lazy()
            .group_by([col(x), col(y)])
            .agg([func.expr(value).alias("\u{1}v"), len().cast(DataType::Float64).alias("\u{1}n")]);
        let t = self.run(lf)?;
        let (cx, cy, cv, cn) =
            (nums(&t.columns[0]), nums(&t.columns[1]), nums(&t.columns[2]), nums(&t.columns[3]));
        let axis = |v: &[f64]| {
            let mut a: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
            a.sort_by(f64::total_cmp);
            a.dedup();
            a
        };
        let (xs, ys) = (axis(&cx), axis(&cy));
        let mut values = vec![f64::NAN; xs.len() * ys.len()];
        let mut most = 0usize;
        for i in 0..t.height {
            let ix = xs.binary_search_by(|v| v.total_cmp(&cx[i]));
            let iy = ys.binary_search_by(|v| v.total_cmp(&cy[i]));
            if let (Ok(ix), Ok(iy)) = (ix, iy) {
                values[iy * xs.len() + ix] = cv[i];
                most = most.max(cn[i] as usize);
            }
        }
        Ok(Grid { xs, ys, values, most_per_cell: most })
    }
}
