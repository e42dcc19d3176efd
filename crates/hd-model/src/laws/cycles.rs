//! sin(2π·p) and cos(2π·p) of a phase p given in cycles, for the periodic inputs and
//! closed-loop references that every stage of a solve evaluates (sine, chirp, stepped sine,
//! S-curve) and the fundamental-fit basis.
//!
//! Reducing a phase in cycles is exact in binary floating point: p minus its nearest
//! integer, then minus the nearest quarter, loses no bit and leaves s with |s| ≤ 1/8.
//! Only x = 2π·s [rad] is rounded, once. On |x| ≤ π/4 polynomials of degree 13 (sin) and
//! 14 (cos) fitted on Chebyshev nodes are within 2e-17 of the exact values, so both agree
//! with them to about one unit in the last place; the quarter picks sin or cos and the
//! sign. libm's `sin` of the radian argument 2π·f·t cost 113 instructions a call in the
//! solver (callgrind) and rounded the argument twice; the sine input's whole evaluation
//! took 57 with the Taylor series this replaced, and whole and half cycles give exact
//! zeros.

use crate::fma::fmadd;
use std::f64::consts::TAU;

/// The sine's polynomial after its leading x, in powers of x² (sin x ≈ x + x³·P(x²), to
/// x¹³): P fitted to (sin x − x)/x³ on Chebyshev nodes of x² ∈ [0, (π/4)²] with 50-digit
/// arithmetic (mpmath's `chebyfit`), relative error 2.0e-17 with these rounded
/// coefficients. The Taylor series needs x¹⁷ for the same accuracy: two more dependent
/// multiply–adds in every evaluation of the input.
const SIN: [f64; 6] = [
    -0.16666666666666666,
    0.008333333333330948,
    -0.00019841269836758574,
    2.755731610255244e-06,
    -2.5051131845003624e-08,
    1.5918129294866608e-10,
];

/// The cosine's polynomial after 1 − x²/2, in powers of x² (cos x ≈ 1 − x²/2 + x⁴·Q(x²), to
/// x¹⁴), fitted the same way: relative error 1.3e-18 (Taylor needs x¹⁶).
const COS: [f64; 6] = [
    0.041666666666666664,
    -0.0013888888888887398,
    2.480158729876569e-05,
    -2.7557317271729793e-07,
    2.08761462684032e-09,
    -1.1382632425521717e-11,
];

/// Horner evaluation of Σ c_k·u^k for k = 0…n−1.
#[inline(always)]
fn poly<const N: usize>(c: &[f64; N], u: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ck| fmadd(acc, u, ck))
}

/// 1.5·2⁵²: adding and subtracting it rounds any |u| < 2⁵¹ to an integer (ties to even),
/// in two additions where `f64::round` is a libm call on baseline x86-64.
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// `u` rounded to an integer (any tie rule) [–].
#[inline(always)]
fn nearest(u: f64) -> f64 {
    if u.abs() < 2_251_799_813_685_248.0 { (u + ROUNDER) - ROUNDER } else { u.round() }
}

/// The phase reduced to its quarter: (q, x) with p = n + q/4 + x/(2π) for an integer n,
/// q ∈ {−2, −1, 0, 1, 2} (kept as a float: the saturating conversion to an integer
/// costs more than the comparisons) and |x| ≤ π/4 [rad].
#[inline(always)]
fn reduce(p: f64) -> (f64, f64) {
    let r = p - nearest(p);
    // |4r| ≤ 2: no range check needed.
    let q = (4.0 * r + ROUNDER) - ROUNDER;
    (q, (r - 0.25 * q) * TAU)
}

/// sin x for |x| ≤ π/4.
#[inline(always)]
fn sin_series(x: f64) -> f64 {
    let x2 = x * x;
    fmadd(x * x2, poly(&SIN, x2), x)
}

/// cos x for |x| ≤ π/4.
#[inline(always)]
fn cos_series(x: f64) -> f64 {
    let x2 = x * x;
    fmadd(x2, fmadd(x2, poly(&COS, x2), -0.5), 1.0)
}

/// sin x and cos x for |x| ≤ π/4.
#[inline(always)]
fn kernel(x: f64) -> (f64, f64) {
    (sin_series(x), cos_series(x))
}

/// sin(2π·p) [–] for a phase p [cycles]. Only the series the quarter needs is summed
/// (the quarter changes four times a cycle, so the branch is predictable).
#[inline]
pub fn sin_cycles(p: f64) -> f64 {
    let (q, x) = reduce(p);
    if q == 0.0 {
        sin_series(x)
    } else if q == 1.0 {
        cos_series(x)
    } else if q == -1.0 {
        -cos_series(x)
    } else {
        -sin_series(x)
    }
}

/// (sin(2π·p), cos(2π·p)) [–] for a phase p [cycles].
#[inline]
pub fn sin_cos_cycles(p: f64) -> (f64, f64) {
    let (q, x) = reduce(p);
    let (s, c) = kernel(x);
    if q == 0.0 {
        (s, c)
    } else if q == 1.0 {
        (c, -s)
    } else if q == -1.0 {
        (-c, s)
    } else {
        (-s, -c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series against libm on the reduced range, and the Pythagorean identity
    /// (measured: 1.1e-16 and 2.2e-16).
    #[test]
    fn series_agree_with_libm_to_the_last_place() {
        let (mut worst, mut worst_unit) = (0.0f64, 0.0f64);
        for k in -200_000..=200_000 {
            let x = k as f64 / 200_000.0 * std::f64::consts::FRAC_PI_4;
            let (s, c) = kernel(x);
            worst = worst.max((s - x.sin()).abs()).max((c - x.cos()).abs());
            worst_unit = worst_unit.max((s * s + c * c - 1.0).abs());
        }
        assert!(worst < 1e-15, "largest difference from libm {worst:e}");
        assert!(worst_unit < 2e-15, "largest |sin² + cos² − 1| {worst_unit:e}");
    }

    /// Every quarter maps to the right function and sign: phases from −3 to 3 cycles
    /// against libm's sin and cos of 2π·p, whose own argument is rounded to about 4e-15
    /// [rad] there (measured: 2.5e-15).
    #[test]
    fn quarters_pick_the_right_function_and_sign() {
        let mut worst = 0.0f64;
        for k in -300_000..=300_000 {
            let p = k as f64 * 1.000_013e-5;
            let (s, c) = sin_cos_cycles(p);
            assert_eq!(s, sin_cycles(p));
            worst = worst.max((s - (TAU * p).sin()).abs()).max((c - (TAU * p).cos()).abs());
        }
        assert!(worst < 3e-14, "largest difference from libm {worst:e}");
    }

    /// Whole, half and quarter cycles are exact, and whole cycles added to a phase that
    /// holds them exactly change nothing.
    #[test]
    fn quarter_cycles_are_exact_and_the_period_is_exact() {
        for n in -4..=4 {
            let n = n as f64;
            assert_eq!(sin_cycles(n), 0.0);
            assert_eq!(sin_cycles(n + 0.5), 0.0);
            assert_eq!(sin_cos_cycles(n).1, 1.0);
            assert_eq!(sin_cycles(n + 0.25), 1.0);
            assert_eq!(sin_cycles(n - 0.25), -1.0);
        }
        let p = 0.123_456_789;
        for n in [1.0, 17.0, 1024.0, 65_536.0] {
            let moved = p + n;
            // The sum is exact when it keeps p's last bit; compare only those.
            if moved - n == p {
                assert_eq!(sin_cycles(moved), sin_cycles(p));
            }
        }
    }
}
