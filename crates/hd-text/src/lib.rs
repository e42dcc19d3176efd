//! How hdw prints a number for a person to read.
//!
//! Every table the workbench prints (explore's text and Markdown tables, study reports, fit
//! summaries) goes through these functions, so a value reads the same everywhere and always
//! reads back to itself within the precision it is printed with:
//!
//! - [`number`]: about six significant digits; whole numbers below 10¹⁵ exactly; fixed
//!   notation between 10⁻³ and 10⁶, scientific outside (`1e308`, never 309 digits);
//! - [`sci`]: scientific notation with a chosen count of significant digits, for columns of
//!   fitted values that span decades.
//!
//! Trailing zeros are trimmed only after a decimal point, never from the integer part.

/// Significant digits of [`number`].
pub const DIGITS: usize = 6;

/// A number in about [`DIGITS`] significant digits (see the crate doc). NaN prints as
/// `NaN`, infinities as `inf` and `-inf`; callers that mean "missing" print their own mark.
pub fn number(x: f64) -> String {
    if !x.is_finite() {
        return special(x);
    }
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    if x.fract() == 0.0 && a < 1e15 {
        return format!("{x:.0}");
    }
    if (1e-3..1e6).contains(&a) {
        let magnitude = a.log10().floor() as i32;
        let decimals = (DIGITS as i32 - 1 - magnitude).max(0) as usize;
        let s = format!("{x:.decimals$}");
        // Rounding may carry into a new leading digit (999999.7 → 1000000); still exact to
        // the printed precision.
        return trim_fraction(&s).to_string();
    }
    sci(x, DIGITS)
}

/// `x` in scientific notation with `digits` significant digits (at least 1), trailing zeros
/// of the mantissa trimmed: `sci(1.5e-7, 6)` is `1.5e-7`, `sci(0.0, 6)` is `0`.
pub fn sci(x: f64, digits: usize) -> String {
    if !x.is_finite() {
        return special(x);
    }
    if x == 0.0 {
        return "0".into();
    }
    let decimals = digits.max(1) - 1;
    let s = format!("{x:.decimals$e}");
    match s.split_once('e') {
        Some((m, e)) => format!("{}e{e}", trim_fraction(m)),
        None => s,
    }
}

/// `x` in scientific notation with `digits` significant digits, the mantissa's zeros kept,
/// so that numbers line up in a fixed-width column (`1.50000e-7`).
pub fn sci_fixed(x: f64, digits: usize) -> String {
    if !x.is_finite() {
        return special(x);
    }
    let decimals = digits.max(1) - 1;
    format!("{x:.decimals$e}")
}

fn special(x: f64) -> String {
    if x.is_nan() {
        "NaN".into()
    } else if x > 0.0 {
        "inf".into()
    } else {
        "-inf".into()
    }
}

/// Drop trailing zeros (and a bare decimal point) after a decimal point; a string without
/// one is returned whole, so `142510` stays `142510`.
fn trim_fraction(s: &str) -> &str {
    if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.') } else { s }
}

#[cfg(test)]
mod tests;
