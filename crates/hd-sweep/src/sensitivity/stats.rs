//! Small statistics helpers shared by the estimators.

/// Quantile `q ∈ [0, 1]` of already sorted values, by linear interpolation between order
/// statistics (the "type 7" definition, as NumPy's default). NaN for an empty slice.
pub fn quantile_sorted(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => f64::NAN,
        1 => sorted[0],
        n => {
            let h = q.clamp(0.0, 1.0) * (n - 1) as f64;
            let lo = h.floor() as usize;
            let hi = (lo + 1).min(n - 1);
            sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
        }
    }
}

/// Equal-tailed interval `(lo, hi)` at confidence `level` from samples (NaNs ignored);
/// `(NaN, NaN)` when no finite sample is left.
pub fn percentile_interval(samples: &mut Vec<f64>, level: f64) -> (f64, f64) {
    samples.retain(|x| x.is_finite());
    samples.sort_by(f64::total_cmp);
    let tail = (1.0 - level) / 2.0;
    (quantile_sorted(samples, tail), quantile_sorted(samples, 1.0 - tail))
}

/// Mean; NaN for an empty slice.
pub fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

/// Sample standard deviation (divisor n − 1); NaN with fewer than two values.
pub fn sample_std(xs: &[f64]) -> f64 {
    if xs.len() < 2 {
        return f64::NAN;
    }
    let m = mean(xs);
    (xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (xs.len() - 1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_interpolate() {
        let xs = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile_sorted(&xs, 0.5), 3.0);
        assert_eq!(quantile_sorted(&xs, 0.125), 1.5);
        assert_eq!(quantile_sorted(&xs, 1.0), 5.0);
        let mut v = vec![f64::NAN, 3.0, 1.0, 2.0];
        assert_eq!(percentile_interval(&mut v, 1.0), (1.0, 3.0));
    }

    #[test]
    fn std_of_known_values() {
        assert!(
            (sample_std(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]) - 2.138_089_935).abs() < 1e-8
        );
        assert!(sample_std(&[1.0]).is_nan());
    }
}
