//! Axis ranges from data: only finite values count (only positive ones on a log axis), the
//! extent is padded so nothing sits on the frame, and an extent of zero width (all values
//! equal) is widened so the axis still has a scale.

/// Fraction of the data extent added on each side of a padded axis.
const PAD: f64 = 0.05;

/// Smallest and largest finite value, if any.
pub(crate) fn finite_extent<'a>(values: impl IntoIterator<Item = &'a f64>) -> Option<(f64, f64)> {
    extent(values.into_iter().copied().filter(|v| v.is_finite()))
}

/// Smallest and largest of the (already filtered) values.
pub(crate) fn extent(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values.into_iter().fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// Union of two optional extents.
pub(crate) fn union(a: Option<(f64, f64)>, b: Option<(f64, f64)>) -> Option<(f64, f64)> {
    match (a, b) {
        (Some((a0, a1)), Some((b0, b1))) => Some((a0.min(b0), a1.max(b1))),
        (a, None) => a,
        (None, b) => b,
    }
}

/// A degenerate extent made usable: all-equal values get ±10 % of their size around them
/// (±1 around zero). Extents of normal width are returned unchanged.
pub(crate) fn widen(lo: f64, hi: f64) -> (f64, f64) {
    let size = lo.abs().max(hi.abs());
    if hi - lo > size * 1e-12 && hi > lo {
        return (lo, hi);
    }
    let mid = 0.5 * (lo + hi);
    let half = if size > 0.0 { 0.1 * size } else { 1.0 };
    (mid - half, mid + half)
}

/// A linear axis range around `(lo, hi)`: widened if degenerate, then padded.
pub(crate) fn linear_range(lo: f64, hi: f64) -> (f64, f64) {
    let (lo, hi) = widen(lo, hi);
    let pad = PAD * (hi - lo);
    (lo - pad, hi + pad)
}

/// A log axis range around the positive `(lo, hi)`: a degenerate extent becomes a factor
/// of 2 either way, then the range is padded by a fraction of its decades.
pub(crate) fn log_range(lo: f64, hi: f64) -> (f64, f64) {
    let (lo, hi) = if hi > lo * (1.0 + 1e-12) { (lo, hi) } else { (lo / 2.0, hi * 2.0) };
    let factor = (hi / lo).powf(PAD);
    (lo / factor, hi * factor)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extent_ignores_non_finite() {
        let v = [f64::NAN, 2.0, f64::INFINITY, -1.0, f64::NEG_INFINITY];
        assert_eq!(finite_extent(&v), Some((-1.0, 2.0)));
        assert_eq!(finite_extent(&[f64::NAN]), None);
    }

    #[test]
    fn padding_and_widening() {
        let (lo, hi) = linear_range(0.0, 10.0);
        assert!((lo + 0.5).abs() < 1e-12 && (hi - 10.5).abs() < 1e-12);
        let (lo, hi) = linear_range(3e-4, 3e-4);
        assert!(lo < 3e-4 && hi > 3e-4 && lo > 0.0);
        let (lo, hi) = linear_range(0.0, 0.0);
        assert!(lo < -0.9 && hi > 0.9);
        let (lo, hi) = log_range(10.0, 10.0);
        assert!(lo < 5.0 && hi > 20.0);
        let (lo, hi) = log_range(1.0, 1000.0);
        assert!(lo < 1.0 && lo > 0.5 && hi > 1000.0 && hi < 2000.0);
    }
}
