//! Parameters held fixed during a fit (`--fix NAME=VALUE`), by registry name.

use crate::error::FitError;
use hd_model::registry::{lookup, parse_assignment};

/// A set of parameters held at given values, checked against the registry.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fixed {
    values: Vec<(&'static str, f64)>,
}

impl Fixed {
    /// No parameter fixed.
    pub fn none() -> Self {
        Self::default()
    }

    /// Parse `NAME=VALUE` assignments: the name must be in the registry (an unknown name
    /// is an error with the nearest valid name) and the value finite and in range. A later
    /// assignment of the same name replaces an earlier one.
    pub fn parse<S: AsRef<str>>(assignments: &[S]) -> Result<Self, FitError> {
        let mut fixed = Self::none();
        for text in assignments {
            let text = text.as_ref();
            let (info, value) = parse_assignment(text)?;
            fixed.insert(info.name, value)?;
        }
        Ok(fixed)
    }

    /// Fix `name` at `value` (checked against the registry).
    pub fn insert(&mut self, name: &str, value: f64) -> Result<(), FitError> {
        let info = lookup(name)?;
        info.check(value)?;
        self.values.retain(|(n, _)| *n != info.name);
        self.values.push((info.name, value));
        Ok(())
    }

    /// The value `name` is fixed at, if any.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.values.iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
    }

    /// Whether nothing is fixed.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The fixed names, in the order given.
    pub fn names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.values.iter().map(|(n, _)| *n)
    }

    /// Check that every fixed name is one of `allowed` (the parameters of `fit`).
    pub fn check_allowed(&self, fit: &'static str, allowed: &[&str]) -> Result<(), FitError> {
        match self.names().find(|n| !allowed.contains(n)) {
            Some(name) => {
                Err(FitError::NotInFit { name: name.to_string(), fit, allowed: allowed.join(", ") })
            }
            None => Ok(()),
        }
    }

    /// The subset of assignments whose names are in `names`.
    pub fn restricted_to(&self, names: &[&str]) -> Self {
        Self { values: self.values.iter().filter(|(n, _)| names.contains(n)).copied().collect() }
    }
}

/// Name of a measurement's constant torque offset in fit reports [N·m]: fitted with the
/// drive's parameters but not one of them (it is not in the registry).
pub const OFFSET: &str = "offset";

/// Unit and valid range `(unit, min, max)` of a fitted quantity: a registry parameter, or
/// the [`OFFSET`] (unbounded).
pub fn fitted_info(name: &str) -> Result<(&'static str, f64, f64), FitError> {
    if name == OFFSET {
        return Ok(("N·m", f64::NEG_INFINITY, f64::INFINITY));
    }
    let info = lookup(name)?;
    Ok((info.unit, info.min, info.max))
}
