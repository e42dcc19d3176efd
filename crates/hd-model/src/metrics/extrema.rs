//! Exact extrema of a cubic Hermite segment, so amplitudes do not depend on sampling.

/// Minimum and maximum over `[0, h]` of the cubic Hermite interpolant with end values
/// `p0, p1` and end slopes `m0, m1` (per unit time) over a step of length `h`.
pub fn cubic_extrema(p0: f64, p1: f64, m0: f64, m1: f64, h: f64) -> (f64, f64) {
    let (a0, a1) = (h * m0, h * m1);
    // dH/ds = qa·s² + qb·s + qc on s ∈ [0, 1].
    let qa = 6.0 * p0 + 3.0 * a0 - 6.0 * p1 + 3.0 * a1;
    let qb = -6.0 * p0 - 4.0 * a0 + 6.0 * p1 - 2.0 * a1;
    let qc = a0;
    let eval = |s: f64| {
        let [w0, w1, w2, w3] = crate::interp::hermite_basis(s);
        w0 * p0 + w1 * a0 + w2 * p1 + w3 * a1
    };
    let mut lo = p0.min(p1);
    let mut hi = p0.max(p1);
    let mut consider = |s: f64| {
        if s > 0.0 && s < 1.0 {
            let v = eval(s);
            lo = lo.min(v);
            hi = hi.max(v);
        }
    };
    if qa.abs() < 1e-300 {
        if qb != 0.0 {
            consider(-qc / qb);
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let r = disc.sqrt();
            // Numerically stable roots.
            let q = -0.5 * (qb + qb.signum() * r);
            if q != 0.0 {
                consider(q / qa);
                consider(qc / q);
            } else {
                consider(0.0);
            }
        }
    }
    (lo, hi)
}

/// A range `[lo, hi]` that holds the same cubic Hermite segment as [`cubic_extrema`]:
/// the segment is a convex combination of its end values plus `h·m0·s(1−s)²` and
/// `−h·m1·s²(1−s)`, whose sizes peak at 4/27 of `h·|m|`. It costs a few operations, so a
/// collector can skip the exact extrema when this range cannot move what it tracks.
#[inline]
pub fn hermite_range(p0: f64, p1: f64, m0: f64, m1: f64, h: f64) -> (f64, f64) {
    let reach = 4.0 / 27.0 * h * (m0.abs() + m1.abs());
    (p0.min(p1) - reach, p0.max(p1) + reach)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cheap range holds the exact extrema of every segment, and its reach is tight:
    /// a segment with p0 = p1 = 0, m1 = 0 peaks at exactly 4/27·h·m0.
    #[test]
    fn the_cheap_range_holds_the_exact_extrema_and_is_tight() {
        let mut x = 0.123_456_789_f64;
        let mut next = || {
            x = (x * 3.987_654_321 + 0.314_159).fract();
            2.0 * x - 1.0
        };
        for _ in 0..100_000 {
            let (p0, p1, m0, m1, h) = (next(), next(), 10.0 * next(), 10.0 * next(), next().abs());
            let (lo, hi) = cubic_extrema(p0, p1, m0, m1, h);
            let (blo, bhi) = hermite_range(p0, p1, m0, m1, h);
            assert!(blo <= lo + 1e-15 && hi <= bhi + 1e-15, "{blo} {lo} {hi} {bhi}");
        }
        let (_, hi) = cubic_extrema(0.0, 0.0, 1.0, 0.0, 1.0);
        assert!((hi - 4.0 / 27.0).abs() < 1e-15, "{hi}");
        assert_eq!(hermite_range(0.0, 0.0, 1.0, 0.0, 1.0).1, 4.0 / 27.0);
    }

    #[test]
    fn finds_the_interior_maximum_of_a_parabola_like_segment() {
        // x(t) = sin t on [0, π]: max 1 at π/2; the Hermite cubic is close to it.
        let h = std::f64::consts::PI / 200.0;
        let t0 = std::f64::consts::FRAC_PI_2 - 0.3 * h;
        let (lo, hi) = cubic_extrema(t0.sin(), (t0 + h).sin(), t0.cos(), (t0 + h).cos(), h);
        assert!((hi - 1.0).abs() < 1e-9, "{hi}");
        assert_eq!(lo, t0.sin().min((t0 + h).sin()));
    }
}
