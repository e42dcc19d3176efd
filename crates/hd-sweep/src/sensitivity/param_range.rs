//! From unit-cube coordinates to parameter values: bounds with an optional log scale.

use super::error::{Result, SensitivityError};
use serde::{Deserialize, Serialize};

/// The range over which one parameter varies in a sensitivity design.
///
/// A unit coordinate `u ∈ [0, 1]` maps to `lo + u·(hi − lo)`, or with `log = true` to
/// `lo·(hi/lo)^u` (uniform in `ln x`). Morris elementary effects and the Sobol' design are
/// computed in unit coordinates, so "one range" means the full span `lo … hi` on the
/// chosen scale.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParamRange {
    /// Parameter name (a registry name in study files, e.g. `Kbar`).
    pub name: String,
    /// Lower bound, in the parameter's unit; finite, and > 0 when `log`.
    pub lo: f64,
    /// Upper bound, in the parameter's unit; finite and > `lo`.
    pub hi: f64,
    /// Sample uniformly in `ln x` instead of `x` (default false).
    #[serde(default)]
    pub log: bool,
}

impl ParamRange {
    /// A checked range: finite bounds, `lo < hi`, and `lo > 0` on a log scale.
    pub fn new(name: impl Into<String>, lo: f64, hi: f64, log: bool) -> Result<Self> {
        let r = Self { name: name.into(), lo, hi, log };
        r.validate()?;
        Ok(r)
    }

    /// Check the bounds (useful after deserialising).
    pub fn validate(&self) -> Result<()> {
        let reason = if !(self.lo.is_finite() && self.hi.is_finite()) {
            Some("must be finite")
        } else if self.lo >= self.hi {
            Some("must satisfy lo < hi")
        } else if self.log && self.lo <= 0.0 {
            Some("must be positive on a log scale")
        } else {
            None
        };
        match reason {
            Some(reason) => Err(SensitivityError::BadRange {
                name: self.name.clone(),
                lo: self.lo,
                hi: self.hi,
                reason,
            }),
            None => Ok(()),
        }
    }

    /// Parameter value at unit coordinate `u` (0 → `lo`, 1 → `hi`).
    pub fn from_unit(&self, u: f64) -> f64 {
        if self.log {
            let (a, b) = (self.lo.ln(), self.hi.ln());
            (a + u * (b - a)).exp()
        } else {
            self.lo + u * (self.hi - self.lo)
        }
    }

    /// Unit coordinate of value `x` (inverse of [`Self::from_unit`]).
    pub fn to_unit(&self, x: f64) -> f64 {
        if self.log {
            let (a, b) = (self.lo.ln(), self.hi.ln());
            (x.ln() - a) / (b - a)
        } else {
            (x - self.lo) / (self.hi - self.lo)
        }
    }
}

/// Map one unit-cube point to parameter values, coordinate `i` through `ranges[i]`.
pub fn map_point(ranges: &[ParamRange], unit: &[f64]) -> Vec<f64> {
    assert_eq!(ranges.len(), unit.len(), "one range per coordinate");
    ranges.iter().zip(unit).map(|(r, &u)| r.from_unit(u)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_and_log_round_trip() {
        let lin = ParamRange::new("c", -2.0, 6.0, false).unwrap();
        assert_eq!(lin.from_unit(0.25), 0.0);
        let log = ParamRange::new("Kbar", 1e4, 1e6, true).unwrap();
        assert!((log.from_unit(0.5) - 1e5).abs() < 1e-6);
        for u in [0.0, 0.3, 1.0] {
            assert!((log.to_unit(log.from_unit(u)) - u).abs() < 1e-12);
            assert!((lin.to_unit(lin.from_unit(u)) - u).abs() < 1e-12);
        }
    }

    #[test]
    fn rejects_bad_bounds() {
        assert!(ParamRange::new("x", 1.0, 1.0, false).is_err());
        assert!(ParamRange::new("x", 0.0, 1.0, true).is_err());
        assert!(ParamRange::new("x", f64::NAN, 1.0, false).is_err());
    }
}
