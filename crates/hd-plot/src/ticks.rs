//! Tick positions and tick labels. Linear ticks are at multiples of 1, 2 or 5 × 10ᵏ; log
//! ticks at powers of ten (with 2× and 5× in between on narrow ranges). Labels switch to
//! scientific notation (`3.0e-4`) when the axis values are tiny or huge.

/// Axis magnitudes below this get scientific labels.
const SCI_BELOW: f64 = 1e-3;
/// Axis magnitudes at or above this get scientific labels.
const SCI_FROM: f64 = 1e5;
/// Guard against absurd tick counts.
const MAX_TICKS: usize = 2000;

/// `floor(log10(v))`, robust to rounding just below an exact power of ten.
fn decade(v: f64) -> i32 {
    (v.abs().log10() + 1e-9).floor() as i32
}

/// The smallest step of the form 1, 2 or 5 × 10ᵏ that puts at most `max_ticks` ticks
/// (and at least one interval's worth) on the axis `[lo, hi]`.
pub(crate) fn nice_step(lo: f64, hi: f64, max_ticks: usize) -> f64 {
    let span = hi - lo;
    let max_ticks = max_ticks.max(2);
    if !(span > 0.0 && span.is_finite()) {
        return 1.0;
    }
    // Start one decade below the step that certainly fits, and walk up.
    let upper = span / (max_ticks - 1) as f64;
    let mut base = 10f64.powi(decade(upper) - 1);
    loop {
        for m in [1.0, 2.0, 5.0] {
            let step = m * base;
            if step >= upper * (1.0 - 1e-9) || count_ticks(lo, hi, step) <= max_ticks {
                return step;
            }
        }
        base *= 10.0;
    }
}

/// Number of multiples of `step` inside `[lo, hi]`.
fn count_ticks(lo: f64, hi: f64, step: f64) -> usize {
    let first = (lo / step - 1e-9).ceil();
    let last = (hi / step + 1e-9).floor();
    if last >= first { (last - first) as usize + 1 } else { 0 }
}

/// Multiples of `step` inside `[lo, hi]`.
pub(crate) fn linear_ticks(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let first = (lo / step - 1e-9).ceil();
    let last = (hi / step + 1e-9).floor();
    if !(first.is_finite() && last.is_finite()) || last < first {
        return Vec::new();
    }
    let count = ((last - first) as usize + 1).min(MAX_TICKS);
    (0..count)
        .map(|k| {
            let v = (first + k as f64) * step;
            if v.abs() < step * 1e-9 { 0.0 } else { v }
        })
        .collect()
}

/// Ticks for a log axis over the positive `[lo, hi]`, at most `max_ticks` of them.
/// With `minor`, the in-between multiples 2…9 × 10ᵏ are returned as well.
pub(crate) fn log_ticks(lo: f64, hi: f64, max_ticks: usize, minor: bool) -> Vec<f64> {
    let max_ticks = max_ticks.max(2);
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    let with_mantissas = |mantissas: &[f64]| -> Vec<f64> {
        (decade(lo)..=decade(hi))
            .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
            .filter(inside)
            .collect()
    };
    if minor {
        let all = with_mantissas(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
        return if all.len() <= max_ticks { all } else { with_mantissas(&[1.0]) };
    }
    let decades = with_mantissas(&[1.0]);
    if decades.len() > max_ticks {
        let stride = decades.len().div_ceil(max_ticks);
        return decades.into_iter().step_by(stride).collect();
    }
    for mantissas in [&[1.0][..], &[1.0, 2.0, 5.0], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]]
    {
        let ticks = with_mantissas(mantissas);
        if ticks.len() >= 3 && ticks.len() <= max_ticks {
            return ticks;
        }
    }
    // Less than a decade wide: plain linear ticks read best.
    linear_ticks(lo, hi, nice_step(lo, hi, max_ticks.min(6)))
}

/// Label for the tick `v` of a linear axis whose ticks are `step` apart and whose values
/// reach `magnitude` (the larger absolute end of the axis).
pub(crate) fn linear_label(v: f64, step: f64, magnitude: f64) -> String {
    if v.abs() < step.abs() * 1e-6 || v == 0.0 {
        return "0".to_string();
    }
    if !(SCI_BELOW..SCI_FROM).contains(&magnitude) {
        let digits = (decade(v) - decade(step)).clamp(1, 6) as usize;
        format!("{v:.digits$e}")
    } else {
        let decimals = (-decade(step)).clamp(0, 12) as usize;
        format!("{v:.decimals$}")
    }
}

/// Label for the tick `v` of a log axis over `[lo, hi]`: plain decimals when the whole
/// axis is in the everyday range, otherwise scientific (`2e-4`), trailing zeros dropped.
pub(crate) fn log_label(v: f64, lo: f64, hi: f64) -> String {
    if !(v > 0.0 && v.is_finite()) {
        return format!("{v}");
    }
    if lo >= SCI_BELOW && hi < SCI_FROM {
        let decimals = (2 - decade(v)).max(0) as usize;
        let text = format!("{v:.decimals$}");
        trim_zeros(&text)
    } else {
        let text = format!("{v:.2e}");
        match text.split_once('e') {
            Some((mantissa, exp)) => format!("{}e{exp}", trim_zeros(mantissa)),
            None => text,
        }
    }
}

/// Drop trailing zeros after a decimal point (and the point if nothing is left after it).
fn trim_zeros(text: &str) -> String {
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_nice() {
        assert_eq!(nice_step(0.0, 10.0, 11), 1.0);
        assert_eq!(nice_step(0.0, 10.0, 6), 2.0);
        assert_eq!(nice_step(-0.465, 0.965, 8), 0.2);
        assert!((nice_step(-1e-5, 3e-4, 8) - 5e-5).abs() < 1e-18);
        assert_eq!(linear_ticks(-0.1, 1.05, 0.5), vec![0.0, 0.5, 1.0]);
    }

    #[test]
    fn tiny_values_get_scientific_labels() {
        assert_eq!(linear_label(3e-4, 5e-5, 3.2e-4), "3.0e-4");
        assert_eq!(linear_label(2.5e-4, 5e-5, 3.2e-4), "2.5e-4");
        assert_eq!(linear_label(0.0, 5e-5, 3.2e-4), "0");
        assert_eq!(linear_label(0.30000000000000004, 0.1, 1.0), "0.3");
        assert_eq!(linear_label(20.0, 5.0, 40.0), "20");
        assert_eq!(linear_label(2.5e5, 5e4, 3e5), "2.5e5");
    }

    #[test]
    fn log_ticks_and_labels() {
        assert_eq!(log_ticks(0.5, 2000.0, 10, false), vec![1.0, 10.0, 100.0, 1000.0]);
        let narrow = log_ticks(1.5, 30.0, 10, false);
        assert!(narrow.len() >= 3, "{narrow:?}");
        assert_eq!(log_label(0.01, 0.01, 100.0), "0.01");
        assert_eq!(log_label(100.0, 0.01, 100.0), "100");
        assert_eq!(log_label(2e-4, 1e-4, 1.0), "2e-4");
        assert_eq!(log_label(1.0, 1e-4, 1.0), "1e0");
        assert_eq!(log_label(1e6, 1e3, 1e6), "1e6");
        assert_eq!(log_label(1e3, 1e3, 1e6), "1e3");
    }
}
