//! Typed errors of the physics crate.

use thiserror::Error;

/// A problem with a parameter name, value or parameter file.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ParamError {
    /// The name is not in the registry.
    #[error("unknown parameter '{name}'{}", suggestion.as_ref().map(|s| format!(" (did you mean '{s}'?)")).unwrap_or_default())]
    Unknown { name: String, suggestion: Option<String> },
    /// The value is outside the valid range or not finite.
    #[error("parameter '{name}' = {value}: expected {expected}")]
    OutOfRange { name: String, value: f64, expected: String },
    /// The text could not be read.
    #[error("cannot read '{text}': expected {expected}")]
    Syntax { text: String, expected: String },
    /// A parameter file problem, with its location.
    #[error("{file}:{line}: {message}")]
    File { file: String, line: usize, message: String },
}

/// A problem with the simulation set-up (input, options) found before integrating.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ConfigError {
    /// A setting is outside what it accepts.
    #[error("{field} = {value}: expected {expected}")]
    Invalid { field: String, value: String, expected: String },
    /// A parameter problem.
    #[error(transparent)]
    Param(#[from] ParamError),
}

/// The integrator could not continue.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SolverError {
    /// Error control asked for a step below the smallest representable progress.
    #[error("step size too small at t = {time} s (h = {step:e} s)")]
    StepSizeTooSmall { time: f64, step: f64 },
    /// The step budget ran out.
    #[error("more than {steps} steps before t = {time} s (raise max_steps or loosen rtol)")]
    TooManySteps { time: f64, steps: u64 },
    /// The state or its derivative became NaN or infinite.
    #[error("state became non-finite at t = {time} s")]
    NonFinite { time: f64 },
}
