//! The printed text reads back to the value within the precision it shows.

use super::*;
use proptest::prelude::*;

/// Place value of the last digit a printed number shows (`142510` → 1, `1.25` → 0.01,
/// `3.5e-7` → 1e-8).
fn last_place(s: &str) -> f64 {
    let (mantissa, exp) = match s.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().unwrap()),
        None => (s, 0),
    };
    let decimals = mantissa.split_once('.').map_or(0, |(_, f)| f.len()) as i32;
    10f64.powi(exp - decimals)
}

fn reads_back(x: f64, s: &str) {
    let back: f64 = s.parse().unwrap_or_else(|_| panic!("{s:?} does not parse"));
    let place = last_place(s);
    // Half a unit in the last place, plus the rounding of the decimal-to-binary reading.
    let bound = 0.5 * place * (1.0 + 1e-9) + 4.0 * f64::EPSILON * x.abs();
    assert!((back - x).abs() <= bound, "{x:e} printed {s:?} reads back {back:e}");
    // And it keeps six significant digits: the error is at most half a unit in the sixth.
    assert!(
        (back - x).abs() <= 5e-6 * x.abs() * (1.0 + 1e-9),
        "{x:e} printed {s:?} loses significant digits"
    );
}

#[test]
fn table4_axis_values_keep_their_zeros() {
    // The explore pivot printed K̄ = 142 510.27 as 14251 and 744 380 as 74438.
    assert_eq!(number(142_510.27), "142510");
    assert_eq!(number(744_380.0), "744380");
    assert_eq!(number(744_380.4), "744380");
    assert_eq!(number(100.0), "100");
    assert_eq!(number(120.5), "120.5");
    assert_eq!(number(999_999.7), "1000000");
}

#[test]
fn large_and_small_values_go_scientific() {
    assert_eq!(number(1e308), "1e308");
    assert_eq!(number(-2.5e-5), "-2.5e-5");
    assert_eq!(number(1.23e7 + 0.5), "1.23e7");
    assert_eq!(number(0.0123456789), "0.0123457");
    assert_eq!(number(f64::NAN), "NaN");
    assert_eq!(number(f64::NEG_INFINITY), "-inf");
    assert_eq!(sci(1.5e-7, 6), "1.5e-7");
    assert_eq!(sci_fixed(1.5e-7, 6), "1.50000e-7");
}

#[test]
fn whole_numbers_print_exactly() {
    for x in [1.0, -7.0, 6400.0, 1e6, 123_456_789_012.0, 9.99e14] {
        let s = number(x);
        assert_eq!(s.parse::<f64>().unwrap(), x, "{s}");
        assert!(!s.contains('e'), "{s}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn any_number_reads_back(m in -1.0f64..1.0, e in -320i32..309) {
        let x = m * 10f64.powi(e);
        prop_assume!(x.is_finite() && x != 0.0 && x.abs() > 1e-300);
        reads_back(x, &number(x));
        reads_back(x, &sci(x, 6));
    }

    #[test]
    fn numbers_near_the_boundaries_read_back(k in 0usize..8, d in -1.0f64..1.0) {
        // Values close to where the notation changes and to where rounding carries.
        let edge = [1e-3, 1.0, 10.0, 1e5, 1e6, 1e15, 999_999.5, 9.999_995][k];
        let x = edge * (1.0 + d * 1e-5);
        reads_back(x, &number(x));
    }

    #[test]
    fn integers_read_back(i in -1_000_000_000_000i64..1_000_000_000_000) {
        let x = i as f64 * 10.0;
        prop_assert_eq!(number(x).parse::<f64>().unwrap(), x);
    }
}
