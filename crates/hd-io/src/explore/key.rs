//! Group keys: the values of a column used to split a table (pivot rows and columns,
//! curves, facets), compared and shown the same way everywhere.

use crate::explore::format::short_number;
use crate::table::ColumnData;
use polars::prelude::{DataType, Expr, col, lit};
use std::cmp::Ordering;
use std::fmt;

/// One value of a key column. Missing values are `Num(NaN)` or `Text(None)`.
#[derive(Clone, Debug, PartialEq)]
pub enum Key {
    /// A number [the column's unit].
    Num(f64),
    /// A text.
    Text(Option<String>),
}

impl Key {
    /// Order: numbers ascending, texts by name, missing values last.
    pub fn cmp_keys(&self, other: &Key) -> Ordering {
        match (self, other) {
            (Key::Num(a), Key::Num(b)) => match (a.is_nan(), b.is_nan()) {
                (false, false) => a.total_cmp(b),
                (a, b) => a.cmp(&b),
            },
            (Key::Text(a), Key::Text(b)) => match (a, b) {
                (Some(a), Some(b)) => a.cmp(b),
                (a, b) => a.is_none().cmp(&b.is_none()),
            },
            (Key::Num(_), Key::Text(_)) => Ordering::Less,
            (Key::Text(_), Key::Num(_)) => Ordering::Greater,
        }
    }

    /// Whether the value is missing.
    pub fn is_missing(&self) -> bool {
        matches!(self, Key::Num(x) if x.is_nan()) || matches!(self, Key::Text(None))
    }

    /// Whether two keys are the same value (missing equals missing).
    pub fn same(&self, other: &Key) -> bool {
        self.cmp_keys(other) == Ordering::Equal
    }

    /// The keys of a column, one per row.
    pub fn column(data: &ColumnData) -> Vec<Key> {
        match data {
            ColumnData::Num(v) => v.iter().map(|&x| Key::Num(x)).collect(),
            ColumnData::Text(v) => v.iter().map(|s| Key::Text(s.clone())).collect(),
        }
    }

    /// The distinct keys of `keys`, sorted.
    pub fn distinct(keys: &[Key]) -> Vec<Key> {
        let mut out = keys.to_vec();
        out.sort_by(Key::cmp_keys);
        out.dedup_by(|a, b| a.same(b));
        out
    }

    /// A polars predicate: `column` equals this key (is null for a missing key).
    pub(crate) fn equals(&self, column: &str) -> Expr {
        match self {
            Key::Num(x) if x.is_nan() => {
                col(column).is_null().or(col(column).cast(DataType::Float64).is_nan())
            }
            Key::Num(x) => col(column).eq(lit(*x)),
            Key::Text(None) => col(column).is_null(),
            Key::Text(Some(s)) => col(column).eq(lit(s.clone())),
        }
    }
}

impl fmt::Display for Key {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Key::Num(x) if x.is_nan() => f.write_str("null"),
            Key::Num(x) => f.write_str(&short_number(*x)),
            Key::Text(Some(s)) => f.write_str(s),
            Key::Text(None) => f.write_str("null"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorted_distinct_with_missing_last() {
        let keys = [Key::Num(3.0), Key::Num(f64::NAN), Key::Num(1.0), Key::Num(3.0)];
        let d = Key::distinct(&keys);
        assert_eq!(d.len(), 3);
        assert_eq!(d[0], Key::Num(1.0));
        assert!(matches!(d[2], Key::Num(x) if x.is_nan()));
        assert_eq!(Key::Num(5e5).to_string(), "500000");
    }
}
