//! Rust errors as Python exceptions: bad input is a `ValueError` whose message names the
//! field and what was expected; a run the integrator could not finish is a
//! `hdw.SimulationError`.

use hd_ident::FitError;
use hd_model::SimError;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    _hdw,
    SimulationError,
    PyRuntimeError,
    "The integrator could not finish a run (step size too small, step budget spent, or a non-finite state); the message says when and why."
);

/// A `ValueError` with `message`.
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// A run's error: a rejected configuration is a `ValueError`, anything else a
/// `SimulationError`.
pub fn sim_error(e: SimError) -> PyErr {
    match e {
        SimError::Config(c) => value_error(c.to_string()),
        other => SimulationError::new_err(format!("simulation failed: {other}")),
    }
}

/// A fit's error: an integration failure is a `SimulationError`, bad data, names or
/// settings a `ValueError`, an optimiser that stopped a `RuntimeError`.
pub fn fit_error(e: FitError) -> PyErr {
    let text = error_chain(&e);
    match e {
        FitError::Solver { .. } => SimulationError::new_err(text),
        FitError::Optimiser(_) => PyRuntimeError::new_err(text),
        _ => value_error(text),
    }
}

/// An error and its sources as one sentence (`a: b: c`).
pub fn error_chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let more = s.to_string();
        if !text.ends_with(&more) {
            text.push_str(": ");
            text.push_str(&more);
        }
        source = s.source();
    }
    text
}
