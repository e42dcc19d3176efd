//! Closed-loop position control of the load (docs/model.md §6): a PID controller with
//! derivative filter, anti-windup and voltage saturation, optionally sampled with a
//! zero-order hold and a quantising encoder, plus model-based compensation (LuGre
//! friction observer, compliance pre-distortion) and a transmitted-torque estimate.
//!
//! [`ControllerConfig`] is the `[controller]` table of params and study files;
//! [`Controller`] is the assembled controller a [`crate::DriveSystem`] carries.

mod law;
mod reference;
mod sampled;

pub use law::{Controller, CtlEval, CtlStates, Measured};
pub use reference::Reference;
pub use sampled::{Hold, quantise};

use crate::error::ConfigError;
use crate::params::Params;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;
use std::str::FromStr;

/// Which angle the controller measures and feeds back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Feedback {
    /// The load angle θz (an output-side encoder).
    #[default]
    Load,
    /// The motor angle divided by the ratio, θj/N (a motor encoder only).
    Motor,
}

/// Model-based compensation added to the PID.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Compensation {
    /// PID alone.
    #[default]
    #[serde(rename = "none")]
    None,
    /// PID plus the LuGre friction-observer feedforward.
    #[serde(rename = "friction")]
    Friction,
    /// Friction feedforward plus the compliance pre-distortion of the motor-side reference.
    #[serde(rename = "friction+compliance")]
    FrictionCompliance,
}

impl Compensation {
    /// All settings, in the order studies list them.
    pub const ALL: [Compensation; 3] =
        [Compensation::None, Compensation::Friction, Compensation::FrictionCompliance];

    /// The name used on the command line, in study files and in run tables.
    pub fn name(self) -> &'static str {
        match self {
            Compensation::None => "none",
            Compensation::Friction => "friction",
            Compensation::FrictionCompliance => "friction+compliance",
        }
    }

    /// Whether the friction feedforward is on.
    pub fn friction(self) -> bool {
        self != Compensation::None
    }

    /// Whether the compliance pre-distortion is on.
    pub fn compliance(self) -> bool {
        self == Compensation::FrictionCompliance
    }
}

impl fmt::Display for Compensation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Compensation {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Compensation::ALL.into_iter().find(|c| c.name() == s).ok_or_else(|| {
            format!("unknown compensation '{s}': expected none, friction or friction+compliance")
        })
    }
}

impl FromStr for Feedback {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "load" => Ok(Feedback::Load),
            "motor" => Ok(Feedback::Motor),
            _ => Err(format!("unknown feedback '{s}': expected load or motor")),
        }
    }
}

/// The `[controller]` table: gains, limits, sampling, reference, compensation and the
/// controller model's parameters where they differ from the plant's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControllerConfig {
    /// Proportional gain kp [V/rad].
    pub kp: f64,
    /// Integral gain ki [V/(rad·s)].
    pub ki: f64,
    /// Derivative gain kd [V·s/rad].
    pub kd: f64,
    /// Time constant τd of the derivative filter [s]; default 1e-3.
    pub tau_d: f64,
    /// Voltage limit: the command is clipped to ±u_max [V]; default 48.
    pub u_max: f64,
    /// Sampling period with zero-order hold [s]; 0 (the default) is a continuous-time
    /// controller.
    pub period: f64,
    /// Encoder resolution [rad] of each measured shaft (load angle, motor angle); 0 is an
    /// ideal sensor. Needs a sampling period.
    pub enc_res: f64,
    /// Fed-back angle; default `load`.
    pub feedback: Feedback,
    /// Compensation; default `none`.
    pub compensation: Compensation,
    /// Load-angle reference; default a 1 mrad sine at 0.2 Hz.
    pub reference: Reference,
    /// Controller-model parameters that differ from the plant's, by registry name
    /// (e.g. `Tc = 0.2`); the others equal the plant's.
    pub model: BTreeMap<String, f64>,
    /// Factor on the controller model's friction (Tc, Ts, their negative-side levels, σ0,
    /// σ1) and stiffness (c, mem_A, Kbar) parameters, applied after `model` [–]; default 1.
    /// 0.7 and 1.3 are the ±30 % mismatch of the control study.
    pub model_scale: f64,
}

impl Default for ControllerConfig {
    fn default() -> Self {
        Self {
            kp: 2000.0,
            ki: 20_000.0,
            kd: 0.0,
            tau_d: 1e-3,
            u_max: 48.0,
            period: 0.0,
            enc_res: 0.0,
            feedback: Feedback::Load,
            compensation: Compensation::None,
            reference: Reference::default(),
            model: BTreeMap::new(),
            model_scale: 1.0,
        }
    }
}

impl ControllerConfig {
    /// The controller model's parameters: the plant's with `model`'s entries applied.
    pub fn model_params(&self, plant: &Params) -> Result<Params, ConfigError> {
        let mut p = plant.clone();
        for (name, &v) in &self.model {
            p.set(name, v).map_err(|e| ConfigError::Invalid {
                field: format!("controller.model.{name}"),
                value: crate::error::num(v),
                expected: e.to_string(),
            })?;
        }
        let k = self.model_scale;
        for v in [&mut p.tc, &mut p.ts, &mut p.sigma0, &mut p.sigma1, &mut p.c, &mut p.mem_a] {
            *v *= k;
        }
        p.kbar *= k;
        for side in [&mut p.tc_neg, &mut p.ts_neg].into_iter().flatten() {
            *side *= k;
        }
        Ok(p)
    }

    /// Check every setting; the error names the field and what was expected.
    pub fn validate(&self, plant: &Params) -> Result<(), ConfigError> {
        let bad = |field: &str, value: f64, expected: &str| {
            Err(ConfigError::Invalid {
                field: format!("controller.{field}"),
                value: crate::error::num(value),
                expected: expected.to_string(),
            })
        };
        for (field, v, unit) in
            [("kp", self.kp, "V/rad"), ("ki", self.ki, "V/(rad·s)"), ("kd", self.kd, "V·s/rad")]
        {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, v, &format!("a finite gain >= 0 [{unit}]"));
            }
        }
        if self.ki > 0.0 && self.kp <= 0.0 {
            return bad("kp", self.kp, "kp > 0 when ki > 0 (the anti-windup tracks with kp/ki)");
        }
        if !(self.tau_d.is_finite() && self.tau_d > 0.0) {
            return bad("tau_d", self.tau_d, "a finite time constant > 0 [s]");
        }
        if self.u_max.is_nan() || self.u_max <= 0.0 {
            return bad("u_max", self.u_max, "a voltage limit > 0 [V]");
        }
        if !(self.period.is_finite() && self.period >= 0.0) {
            return bad("period", self.period, "a sampling period >= 0 [s] (0: continuous)");
        }
        if !(self.enc_res.is_finite() && self.enc_res >= 0.0) {
            return bad("enc_res", self.enc_res, "a resolution >= 0 [rad] (0: ideal)");
        }
        if self.enc_res > 0.0 && self.period == 0.0 {
            return bad("enc_res", self.enc_res, "0 unless a sampling period is set (period > 0)");
        }
        if !(self.model_scale.is_finite() && self.model_scale > 0.0) {
            return bad("model_scale", self.model_scale, "a finite factor > 0");
        }
        self.reference.validate()?;
        self.model_params(plant)?.validate().map_err(|e| ConfigError::Invalid {
            field: "controller.model".to_string(),
            value: String::new(),
            expected: e.to_string(),
        })?;
        Ok(())
    }
}
