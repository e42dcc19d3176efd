//! The checks shared by every data set.

use crate::error::DataError;

/// Samples a fit asks for per free parameter: fewer leave the residual too short to
/// estimate the noise and the standard errors meaningfully.
pub const SAMPLES_PER_PARAMETER: usize = 10;

/// Check that `have` samples suffice for the free parameters `names`.
pub fn require_samples(have: usize, names: &[&str]) -> Result<(), DataError> {
    let need = SAMPLES_PER_PARAMETER * names.len();
    if have < need {
        return Err(DataError::TooFewSamples {
            have,
            need,
            free: names.len(),
            names: names.join(", "),
            per: SAMPLES_PER_PARAMETER,
        });
    }
    Ok(())
}

/// Check that `col` has the length of the reference column and holds finite values.
pub(crate) fn column(
    name: &'static str,
    col: &[f64],
    reference: &'static str,
    expected: usize,
) -> Result<(), DataError> {
    if col.len() != expected {
        return Err(DataError::LengthMismatch {
            column: name,
            len: col.len(),
            reference,
            expected,
        });
    }
    if let Some((i, &v)) = col.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(DataError::NonFinite { column: name, row: i + 1, value: v });
    }
    Ok(())
}

/// Check that time increases strictly.
pub(crate) fn increasing_time(t: &[f64]) -> Result<(), DataError> {
    for (i, w) in t.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(DataError::NonIncreasingTime { row: i + 2, time: w[1], previous: w[0] });
        }
    }
    Ok(())
}

/// Check that a column varies.
pub(crate) fn varies(name: &'static str, col: &[f64]) -> Result<(), DataError> {
    match col.first() {
        Some(&first) if col.iter().all(|&v| v == first) => {
            Err(DataError::Constant { column: name, value: first })
        }
        _ => Ok(()),
    }
}
