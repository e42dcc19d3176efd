//! External load torque T_L(t) on the load side (docs/model.md §2.6).
//!
//! The torque is a time signal of the same kinds as the voltage input (constant, step,
//! sine, recorded, …), so it reuses [`Input`]'s formulas with the amplitude read in N·m.
//! It acts against positive load motion: `Jz·ω̇z = T_out − Cz·ωz − T_L`.

use crate::error::ConfigError;
use crate::laws::input::Input;
use serde::{Deserialize, Serialize};

/// An external load torque; `None` (the default) is an unloaded output shaft.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct LoadTorque(pub Option<Input>);

impl LoadTorque {
    /// A load torque following `signal`, whose amplitude is read in [N·m].
    pub fn new(signal: Input) -> Self {
        Self(Some(signal))
    }

    /// T_L(t) [N·m] (0 without a load torque).
    #[inline]
    pub fn value(&self, t: f64) -> f64 {
        self.0.as_ref().map_or(0.0, |s| s.value(t))
    }

    /// dT_L/dt [N·m/s].
    pub fn rate(&self, t: f64) -> f64 {
        self.0.as_ref().map_or(0.0, |s| s.value_and_rate(t).1)
    }

    /// Times where T_L or its slope jumps.
    pub fn breakpoints(&self) -> Vec<f64> {
        self.0.as_ref().map_or_else(Vec::new, Input::breakpoints)
    }

    /// Check the signal; errors name `load_torque.<field>`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.0.as_ref().map_or(Ok(()), |s| s.validate_as("load_torque"))
    }
}
