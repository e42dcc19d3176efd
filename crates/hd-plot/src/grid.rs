//! Heatmap grids: checking the cell centres along an axis and finding the cell edges.

use std::path::Path;

use crate::error::PlotError;
use crate::ranges;

/// A map of axis values to or from the space where cells are evenly split.
type Map = fn(f64) -> f64;

/// Check that the cell centres `c` (described as `what`) are non-empty, finite, strictly
/// increasing and, on a log axis, positive.
pub(crate) fn check_centres(
    path: &Path,
    what: &str,
    c: &[f64],
    log: bool,
) -> Result<(), PlotError> {
    let invalid = |reason: &str| PlotError::InvalidGrid {
        path: path.to_path_buf(),
        what: what.to_string(),
        reason: reason.to_string(),
    };
    if c.is_empty() {
        return Err(PlotError::EmptyInput { path: path.to_path_buf(), what: what.to_string() });
    }
    if c.iter().any(|v| !v.is_finite()) {
        return Err(invalid("contains NaN or infinite values"));
    }
    if c.windows(2).any(|w| w[1] <= w[0]) {
        return Err(invalid("is not strictly increasing"));
    }
    if log && c[0] <= 0.0 {
        return Err(invalid("has values ≤ 0, which a log axis cannot show"));
    }
    Ok(())
}

/// The `n + 1` cell edges around `n` checked centres: halfway between neighbours
/// (halfway in log₁₀ on a log axis), the outer cells as wide as their neighbours. A single
/// cell gets the width of a widened degenerate range.
pub(crate) fn edges(c: &[f64], log: bool) -> Vec<f64> {
    if c.len() == 1 {
        let (lo, hi) = if log { (c[0] / 2.0, c[0] * 2.0) } else { ranges::widen(c[0], c[0]) };
        return vec![lo, hi];
    }
    let (to, from): (Map, Map) = if log { (f64::log10, |v| 10f64.powf(v)) } else { (|v| v, |v| v) };
    let t: Vec<f64> = c.iter().map(|&v| to(v)).collect();
    let n = t.len();
    let mut e = Vec::with_capacity(n + 1);
    e.push(t[0] - 0.5 * (t[1] - t[0]));
    e.extend(t.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    e.push(t[n - 1] + 0.5 * (t[n - 1] - t[n - 2]));
    e.into_iter().map(from).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_and_log_edges() {
        assert_eq!(edges(&[0.0, 1.0, 2.0], false), vec![-0.5, 0.5, 1.5, 2.5]);
        let e = edges(&[1.0, 10.0, 100.0], true);
        let expect = [10f64.powf(-0.5), 10f64.powf(0.5), 10f64.powf(1.5), 10f64.powf(2.5)];
        for (a, b) in e.iter().zip(expect) {
            assert!((a / b - 1.0).abs() < 1e-12);
        }
        assert_eq!(edges(&[5.0], false).len(), 2);
    }

    #[test]
    fn centres_are_checked() {
        let p = Path::new("x.svg");
        assert!(check_centres(p, "xs", &[1.0, 2.0], true).is_ok());
        assert!(check_centres(p, "xs", &[2.0, 1.0], false).is_err());
        assert!(check_centres(p, "xs", &[0.0, 1.0], true).is_err());
        assert!(check_centres(p, "xs", &[], false).is_err());
        assert!(check_centres(p, "xs", &[f64::NAN], false).is_err());
    }
}
