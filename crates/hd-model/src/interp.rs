//! The interpolants every part of the workbench shares: linear interpolation of samples
//! (recorded inputs, measured signals) and the cubic Hermite basis (the solver's dense
//! output, exact extrema of a step).

/// Value and slope at `at` of the samples `(t, x)` joined by straight lines, held
/// constant (slope 0) outside `[t[0], t[n−1]]`. At a sample time the slope is that of the
/// segment starting there. `t` must be strictly increasing with at least two samples;
/// with fewer, the first value (or 0) is returned.
pub fn linear_at(t: &[f64], x: &[f64], at: f64) -> (f64, f64) {
    let n = t.len().min(x.len());
    if n < 2 {
        return (x.first().copied().unwrap_or(0.0), 0.0);
    }
    if at <= t[0] {
        return (x[0], if at == t[0] { (x[1] - x[0]) / (t[1] - t[0]) } else { 0.0 });
    }
    if at >= t[n - 1] {
        return (x[n - 1], 0.0);
    }
    let k = t.partition_point(|&s| s <= at).saturating_sub(1).min(n - 2);
    let slope = (x[k + 1] - x[k]) / (t[k + 1] - t[k]);
    (x[k] + slope * (at - t[k]), slope)
}

/// The cubic Hermite basis at `s ∈ [0, 1]`: weights of `(p0, h·m0, p1, h·m1)` for end
/// values `p0, p1` and end slopes `m0, m1` over a step of length `h`.
pub fn hermite_basis(s: f64) -> [f64; 4] {
    let s2 = s * s;
    let s3 = s2 * s;
    [2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s, -2.0 * s3 + 3.0 * s2, s3 - s2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_interpolation_holds_outside_and_is_exact_on_lines() {
        let t = [0.0, 1.0, 3.0];
        let x = [1.0, 3.0, 2.0];
        assert_eq!(linear_at(&t, &x, 0.5), (2.0, 2.0));
        assert_eq!(linear_at(&t, &x, 2.0), (2.5, -0.5));
        assert_eq!(linear_at(&t, &x, -1.0), (1.0, 0.0));
        assert_eq!(linear_at(&t, &x, 5.0), (2.0, 0.0));
        assert_eq!(linear_at(&t, &x, 1.0), (3.0, -0.5));
    }

    #[test]
    fn hermite_basis_reproduces_cubics_and_sums_to_one() {
        // p(s) = s³ − 2s + 1 on [0, 1] with h = 1: p0 = 1, m0 = −2, p1 = 0, m1 = 1.
        for k in 0..=10 {
            let s = k as f64 / 10.0;
            let w = hermite_basis(s);
            let p = w[0] * 1.0 + w[1] * -2.0 + w[2] * 0.0 + w[3] * 1.0;
            assert!((p - (s * s * s - 2.0 * s + 1.0)).abs() < 1e-15);
            assert!((w[0] + w[2] - 1.0).abs() < 1e-15);
        }
    }
}
