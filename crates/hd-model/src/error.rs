//! Typed errors of the physics crate.

use thiserror::Error;

/// A problem with a parameter name, value or parameter file.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ParamError {
    /// The name is not in the registry.
    #[error("unknown parameter '{name}'{}", suggestion.as_ref().map(|s| format!(" (did you mean '{s}'?)")).unwrap_or_default())]
    Unknown { name: String, suggestion: Option<String> },
    /// The value is outside the valid range or not finite.
    #[error("parameter '{name}' = {}: expected {expected}", num(*.value))]
    OutOfRange { name: String, value: f64, expected: String },
    /// The text could not be read.
    #[error("cannot read '{text}': expected {expected}")]
    Syntax { text: String, expected: String },
    /// A parameter file problem, with its location.
    #[error("{file}:{line}: {message}")]
    File { file: String, line: usize, message: String },
}

/// A number as messages show it: as typed for everyday magnitudes, in exponent form
/// beyond them (1e308 is `1e308`, not a 309-digit integer).
pub fn num(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e15).contains(&a) {
        x.to_string()
    } else {
        format!("{x:e}")
    }
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

#[cfg(test)]
mod tests {
    use super::num;

    #[test]
    fn huge_and_tiny_numbers_are_shown_in_exponent_form() {
        assert_eq!(num(1e308), "1e308");
        assert_eq!(num(-2.5e-9), "-2.5e-9");
        assert_eq!(num(12.5), "12.5");
        assert_eq!(num(0.0), "0");
        assert_eq!(num(f64::INFINITY), "inf");
    }
}
