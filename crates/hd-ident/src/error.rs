//! Typed errors of the identifier: bad data, bad `--fix` assignments, failed fits.

use hd_model::{ParamError, SolverError};
use thiserror::Error;

/// Something wrong with a data set, found before fitting. Rows are 1-based data rows
/// (the header is not counted), as in `hd-io`'s messages.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DataError {
    /// No rows at all.
    #[error("the data set is empty")]
    Empty,
    /// Two columns have different lengths.
    #[error("column '{column}' has {len} values but column '{reference}' has {expected}")]
    LengthMismatch {
        /// The shorter or longer column.
        column: &'static str,
        /// Its length.
        len: usize,
        /// The column it is compared with.
        reference: &'static str,
        /// That column's length.
        expected: usize,
    },
    /// A NaN or infinite value.
    #[error("column '{column}', row {row}: {value}; expected a finite number")]
    NonFinite {
        /// Column (its role, e.g. `theta`).
        column: &'static str,
        /// 1-based row.
        row: usize,
        /// The offending value.
        value: f64,
    },
    /// Time does not increase strictly.
    #[error(
        "column 't', row {row}: time {time} s does not come after the previous row's {previous} s; time must increase strictly"
    )]
    NonIncreasingTime {
        /// 1-based row of the later sample.
        row: usize,
        /// Its time [s].
        time: f64,
        /// The previous row's time [s].
        previous: f64,
    },
    /// A steady-state friction point at zero speed, where the steady torque is undefined.
    #[error(
        "column 'omega', row {row}: speed 0 in a steady-state sweep; the steady friction torque is only defined while sliding (remove the row)"
    )]
    ZeroSpeed {
        /// 1-based row.
        row: usize,
    },
    /// A column that must vary is constant.
    #[error("column '{column}' is constant ({value}) over all rows; it carries no information")]
    Constant {
        /// Column.
        column: &'static str,
        /// Its only value.
        value: f64,
    },
    /// Fewer samples than the free parameters need.
    #[error(
        "{have} samples are too few to fit {free} free parameter(s) ({names}): need at least {need} (the free parameters plus {dof}, so the noise can be estimated)"
    )]
    TooFewSamples {
        /// Rows in the data set.
        have: usize,
        /// Rows required.
        need: usize,
        /// Number of free parameters.
        free: usize,
        /// Their names.
        names: String,
        /// Degrees of freedom required beyond the free parameters.
        dof: usize,
    },
}

/// A fit that could not be set up or carried out.
#[derive(Debug, Error)]
pub enum FitError {
    /// Bad data.
    #[error(transparent)]
    Data(#[from] DataError),
    /// Unknown parameter name, bad value or bad `NAME=VALUE` text.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A registry parameter that this fit does not estimate.
    #[error("'{name}' is not a parameter of the {fit} fit (its parameters: {allowed})")]
    NotInFit {
        /// The name given.
        name: String,
        /// The fit.
        fit: &'static str,
        /// The names it accepts.
        allowed: String,
    },
    /// Every parameter was fixed.
    #[error("every parameter of the {fit} fit is fixed; nothing is left to fit")]
    NothingFree {
        /// The fit.
        fit: &'static str,
    },
    /// Neither a steady nor a transient friction data set was given.
    #[error("no friction data: give a steady-state sweep, a transient time series, or both")]
    NoData,
    /// The integrator failed while computing a model response.
    #[error("integrating {what}")]
    Solver {
        /// What was being integrated, with the parameter values.
        what: String,
        /// The solver's error.
        source: SolverError,
    },
    /// The optimiser stopped with an error.
    #[error("optimiser: {0}")]
    Optimiser(String),
    /// Every trial of a search failed: nothing to fit from.
    #[error(
        "no trial gave a finite cost: all {trials} trial values over {range} failed ({why}); check the data's units and sign, or fix the parameter with --fix"
    )]
    NoFiniteTrial {
        /// Trials evaluated.
        trials: usize,
        /// The searched range.
        range: String,
        /// The first failure, or why the cost was not finite.
        why: String,
    },
    /// An excitation or synthesis setting is outside what it accepts.
    #[error("{field} = {value}: expected {expected}")]
    Setting {
        /// The setting.
        field: &'static str,
        /// Its value as given.
        value: String,
        /// What it accepts.
        expected: String,
    },
}

/// An error with its causes, joined by ": " (each cause once).
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}
