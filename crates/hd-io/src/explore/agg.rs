//! Aggregation functions and `--agg METRIC:FN` / `--sort COL[:desc]` specifications.

use crate::explore::error::ExploreError;
use crate::explore::units::unit_of;
use polars::prelude::{Expr, col};

/// How the values of a group are combined.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AggFn {
    /// Number of non-missing values [-].
    Count,
    /// Arithmetic mean.
    Mean,
    /// Median.
    Median,
    /// Smallest value.
    Min,
    /// Largest value.
    Max,
    /// Sum.
    Sum,
    /// Sample standard deviation (n − 1).
    Std,
}

/// Every function, with its name on the command line.
pub const AGG_FNS: [(&str, AggFn); 7] = [
    ("count", AggFn::Count),
    ("mean", AggFn::Mean),
    ("median", AggFn::Median),
    ("min", AggFn::Min),
    ("max", AggFn::Max),
    ("sum", AggFn::Sum),
    ("std", AggFn::Std),
];

impl AggFn {
    /// Parse a function name; `option` names the option in the error.
    pub fn parse(name: &str, option: &str) -> Result<AggFn, ExploreError> {
        AGG_FNS.iter().find(|(n, _)| *n == name.trim()).map(|(_, f)| *f).ok_or_else(|| {
            let all: Vec<&str> = AGG_FNS.iter().map(|(n, _)| *n).collect();
            ExploreError::usage(
                option,
                format!("unknown function '{name}': expected one of {}", all.join(", ")),
            )
        })
    }

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        AGG_FNS.iter().find(|(_, f)| *f == self).map_or("?", |(n, _)| n)
    }

    /// The polars aggregation of `column`.
    pub(crate) fn expr(self, column: &str) -> Expr {
        let c = col(column);
        match self {
            AggFn::Count => c.count(),
            AggFn::Mean => c.mean(),
            AggFn::Median => c.median(),
            AggFn::Min => c.min(),
            AggFn::Max => c.max(),
            AggFn::Sum => c.sum(),
            AggFn::Std => c.std(1),
        }
    }

    /// The unit of the result, given the column (none for a count).
    pub fn unit(self, column: &str) -> String {
        match self {
            AggFn::Count => String::new(),
            _ => unit_of(column).unwrap_or("").to_string(),
        }
    }
}

/// One `METRIC:FN` of `--agg`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AggSpec {
    /// The column aggregated.
    pub column: String,
    /// The function.
    pub func: AggFn,
}

impl AggSpec {
    /// Name of the result column: `METRIC_FN`, e.g. `thz_amp_mean`.
    pub fn output_name(&self) -> String {
        format!("{}_{}", self.column, self.func.name())
    }
}

/// Parse `--agg` values: each holds one or more comma-separated `METRIC:FN`; a bare
/// `METRIC` means its mean.
pub fn parse_aggs(values: &[String]) -> Result<Vec<AggSpec>, ExploreError> {
    let mut out = Vec::new();
    for item in values.iter().flat_map(|v| v.split(',')).map(str::trim) {
        if item.is_empty() {
            return Err(ExploreError::usage(
                "--agg",
                "empty item: expected METRIC:FN, e.g. thz_amp:max",
            ));
        }
        let (column, func) = match item.split_once(':') {
            Some((c, f)) => (c.trim(), AggFn::parse(f, "--agg")?),
            None => (item, AggFn::Mean),
        };
        out.push(AggSpec { column: column.to_string(), func });
    }
    Ok(out)
}

/// `--sort COL[:asc|:desc]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SortSpec {
    /// Column of the result to sort by.
    pub column: String,
    /// Largest first.
    pub descending: bool,
}

/// Parse `--sort COL`, `COL:asc` or `COL:desc`.
pub fn parse_sort(value: &str) -> Result<SortSpec, ExploreError> {
    let (column, order) = match value.rsplit_once(':') {
        Some((c, o)) => (c, Some(o)),
        None => (value, None),
    };
    let descending = match order {
        None | Some("asc") => false,
        Some("desc") => true,
        Some(o) => {
            return Err(ExploreError::usage(
                "--sort",
                format!("'{o}' in '{value}': expected COL, COL:asc or COL:desc"),
            ));
        }
    };
    Ok(SortSpec { column: column.trim().to_string(), descending })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agg_and_sort_specs() {
        let a = parse_aggs(&["thz_amp:max, tb_peak".into(), "steps:sum".into()]).unwrap();
        assert_eq!(a.len(), 3);
        assert_eq!(a[1], AggSpec { column: "tb_peak".into(), func: AggFn::Mean });
        assert_eq!(a[0].output_name(), "thz_amp_max");
        assert!(parse_aggs(&["x:avg".into()]).unwrap_err().to_string().contains("avg"));
        assert!(parse_sort("n:desc").unwrap().descending);
        assert!(parse_sort("n:down").is_err());
    }
}
