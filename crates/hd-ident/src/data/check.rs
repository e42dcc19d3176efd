//! The checks shared by every data set.

use crate::error::DataError;

/// Samples per free parameter below which a fit still runs but warns: the residual is
/// then short for estimating the noise, so the standard errors are rough.
pub const SAMPLES_PER_PARAMETER: usize = 10;

/// Degrees of freedom (samples beyond the free parameters) a fit needs at least: with
/// fewer the noise, and so every standard error, cannot be estimated at all.
pub const MIN_DOF: usize = 3;

/// Check that `have` samples suffice for the free parameters `names`: an error below
/// `names.len() + MIN_DOF`, a warning (returned) below [`SAMPLES_PER_PARAMETER`] per
/// free parameter. A 38-point Stribeck table for four parameters is a normal experiment.
pub fn require_samples(have: usize, names: &[&str]) -> Result<Option<String>, DataError> {
    let need = names.len() + MIN_DOF;
    if have < need {
        return Err(DataError::TooFewSamples {
            have,
            need,
            free: names.len(),
            names: names.join(", "),
            dof: MIN_DOF,
        });
    }
    let comfortable = SAMPLES_PER_PARAMETER * names.len();
    Ok((have < comfortable).then(|| {
        format!(
            "warning: {have} samples for {} free parameters ({}) leave only {} degrees of freedom; the fit ran, but the noise estimate and so the standard errors are rough (about {comfortable} samples or more make them reliable)",
            names.len(),
            names.join(", "),
            have - names.len()
        )
    }))
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
