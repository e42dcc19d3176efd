//! What a study can vary: registry parameters plus a few settings of the run, and how a
//! value is applied to a run's configuration.

use hd_model::registry::{ParamInfo, REGISTRY, lookup, nearest_of};
use hd_model::{Compensation, Feedback, HystLaw, Input, SimConfig, Variant};
use serde::{Deserialize, Serialize};

/// Names that are not registry parameters but can be swept.
pub const SPECIAL: [&str; 13] = [
    "voltage",
    "freq",
    "variant",
    "stiffness",
    "friction_scale",
    "load_torque",
    "ctl_kp",
    "ctl_ki",
    "ctl_kd",
    "ctl_period",
    "ctl_model_scale",
    "compensation",
    "feedback",
];

/// The quantity an axis or sampled dimension sets.
#[derive(Clone, Copy, Debug)]
pub enum Knob {
    /// A registry parameter.
    Param(&'static ParamInfo),
    /// Input amplitude or level [V].
    Voltage,
    /// A constant external load torque T_L [N·m].
    LoadTorque,
    /// Sine frequency [Hz]: of the input open loop, of the sine reference closed loop.
    Freq,
    /// Factor on both Coulomb and static friction torques Tc, Ts [–].
    FrictionScale,
    /// Model variant.
    Variant,
    /// Hysteretic stiffness law of the full variant (names).
    Stiffness,
    /// Controller gains kp [V/rad], ki [V/(rad·s)], kd [V·s/rad].
    CtlKp,
    /// See [`Knob::CtlKp`].
    CtlKi,
    /// See [`Knob::CtlKp`].
    CtlKd,
    /// Controller sampling period [s].
    CtlPeriod,
    /// Factor on the controller model's friction and stiffness parameters [–].
    CtlModelScale,
    /// Compensation setting (names).
    Compensation,
    /// Fed-back angle (names).
    Feedback,
}

/// One value on an axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Value {
    /// A number.
    Num(f64),
    /// A variant.
    Variant(Variant),
    /// A stiffness law.
    Stiffness(HystLaw),
    /// A compensation setting.
    Compensation(Compensation),
    /// A fed-back angle.
    Feedback(Feedback),
}

impl Knob {
    /// Resolve a name; the error suggests the nearest valid name.
    pub fn from_name(name: &str) -> Result<Knob, String> {
        match name {
            "voltage" => Ok(Knob::Voltage),
            "freq" => Ok(Knob::Freq),
            "friction_scale" => Ok(Knob::FrictionScale),
            "load_torque" => Ok(Knob::LoadTorque),
            "variant" => Ok(Knob::Variant),
            "stiffness" => Ok(Knob::Stiffness),
            "ctl_kp" => Ok(Knob::CtlKp),
            "ctl_ki" => Ok(Knob::CtlKi),
            "ctl_kd" => Ok(Knob::CtlKd),
            "ctl_period" => Ok(Knob::CtlPeriod),
            "ctl_model_scale" => Ok(Knob::CtlModelScale),
            "compensation" => Ok(Knob::Compensation),
            "feedback" => Ok(Knob::Feedback),
            _ => lookup(name).map(Knob::Param).map_err(|_| {
                let all = REGISTRY.iter().map(|p| p.name).chain(SPECIAL);
                match nearest_of(name, all) {
                    Some(s) => format!("unknown parameter '{name}' (did you mean '{s}'?)"),
                    None => format!(
                        "unknown parameter '{name}': expected a registry name ({}) or one of {}",
                        REGISTRY.iter().map(|p| p.name).collect::<Vec<_>>().join(", "),
                        SPECIAL.join(", ")
                    ),
                }
            }),
        }
    }

    /// The column name of this knob.
    pub fn name(&self) -> &'static str {
        match self {
            Knob::Param(p) => p.name,
            Knob::Voltage => "voltage",
            Knob::Freq => "freq",
            Knob::FrictionScale => "friction_scale",
            Knob::LoadTorque => "load_torque",
            Knob::Variant => "variant",
            Knob::Stiffness => "stiffness",
            Knob::CtlKp => "ctl_kp",
            Knob::CtlKi => "ctl_ki",
            Knob::CtlKd => "ctl_kd",
            Knob::CtlPeriod => "ctl_period",
            Knob::CtlModelScale => "ctl_model_scale",
            Knob::Compensation => "compensation",
            Knob::Feedback => "feedback",
        }
    }

    /// Check a numeric value for this knob.
    pub fn check(&self, v: f64) -> Result<(), String> {
        match self {
            Knob::Param(p) => p.check(v).map_err(|e| e.to_string()),
            Knob::Voltage if v.is_finite() => Ok(()),
            Knob::Voltage => Err(format!("voltage = {v}: expected a finite number [V]")),
            Knob::LoadTorque if v.is_finite() => Ok(()),
            Knob::LoadTorque => Err(format!("load_torque = {v}: expected a finite number [N·m]")),
            Knob::Freq | Knob::FrictionScale if v.is_finite() && v > 0.0 => Ok(()),
            Knob::Freq => Err(format!("freq = {v}: expected a finite number > 0 [Hz]")),
            Knob::FrictionScale => {
                Err(format!("friction_scale = {v}: expected a finite factor > 0"))
            }
            Knob::Variant => Err("variant takes names (linear, damped, full), not numbers".into()),
            Knob::Stiffness => Err(
                "stiffness takes names (memory, maxwell-slip, bouc-wen, catalogue), not numbers"
                    .into(),
            ),
            Knob::CtlKp | Knob::CtlKi | Knob::CtlKd | Knob::CtlPeriod
                if v.is_finite() && v >= 0.0 =>
            {
                Ok(())
            }
            Knob::CtlModelScale if v.is_finite() && v > 0.0 => Ok(()),
            Knob::CtlKp | Knob::CtlKi | Knob::CtlKd | Knob::CtlPeriod | Knob::CtlModelScale => {
                Err(format!("{} = {v}: expected a finite number >= 0", self.name()))
            }
            Knob::Compensation => {
                Err("compensation takes names (none, friction, friction+compliance), not numbers"
                    .into())
            }
            Knob::Feedback => Err("feedback takes names (load, motor), not numbers".into()),
        }
    }

    /// Whether the knob sets a controller setting (and so needs a `[controller]` table).
    pub fn is_controller(&self) -> bool {
        matches!(
            self,
            Knob::CtlKp
                | Knob::CtlKi
                | Knob::CtlKd
                | Knob::CtlPeriod
                | Knob::CtlModelScale
                | Knob::Compensation
                | Knob::Feedback
        )
    }

    /// Whether the knob can act on runs with this input.
    pub fn applies_to(&self, input: &Input) -> Result<(), String> {
        match (self, input) {
            (Knob::Voltage, Input::Recorded(_)) => {
                Err("voltage cannot be swept with a recorded input".to_string())
            }
            (Knob::Freq, Input::Sine { .. } | Input::SteppedSine { .. } | Input::Chirp { .. }) => {
                Ok(())
            }
            (Knob::Freq, _) => Err("freq can only be swept with a sine input".to_string()),
            _ => Ok(()),
        }
    }

    /// Apply a value to a configuration (the value was checked already).
    pub fn apply(&self, cfg: &mut SimConfig, value: Value) {
        match (self, value) {
            (Knob::Param(p), Value::Num(v)) => p.set_unchecked(&mut cfg.params, v),
            (Knob::Voltage, Value::Num(v)) => match &mut cfg.input {
                Input::Sine { amplitude, .. }
                | Input::Step { amplitude, .. }
                | Input::Constant { amplitude }
                | Input::Chirp { amplitude, .. }
                | Input::SteppedSine { amplitude, .. } => *amplitude = v,
                Input::Recorded(_) => {}
            },
            // In closed loop the frequency is the sine reference's.
            (Knob::Freq, Value::Num(v))
                if matches!(
                    cfg.controller.as_ref().map(|c| &c.reference),
                    Some(hd_model::control::Reference::Sine { .. })
                ) =>
            {
                if let Some(hd_model::control::Reference::Sine { freq, .. }) =
                    cfg.controller.as_mut().map(|c| &mut c.reference)
                {
                    *freq = v;
                }
            }
            (Knob::Freq, Value::Num(v)) => match &mut cfg.input {
                Input::Sine { freq, .. } => *freq = v,
                Input::Chirp { f0, f1, .. } => {
                    let ratio = *f1 / *f0;
                    *f0 = v;
                    *f1 = v * ratio;
                }
                Input::SteppedSine { freqs, .. } => {
                    let first = freqs[0];
                    freqs.iter_mut().for_each(|f| *f *= v / first);
                }
                _ => {}
            },
            (Knob::FrictionScale, Value::Num(v)) => {
                cfg.params.tc *= v;
                cfg.params.ts *= v;
                for side in [&mut cfg.params.tc_neg, &mut cfg.params.ts_neg].into_iter().flatten() {
                    *side *= v;
                }
            }
            (Knob::LoadTorque, Value::Num(v)) => {
                cfg.load_torque =
                    hd_model::laws::load::LoadTorque::new(Input::Constant { amplitude: v });
            }
            (Knob::Variant, Value::Variant(v)) => cfg.variant = v,
            (Knob::Stiffness, Value::Stiffness(s)) => cfg.stiffness = s,
            (k, v) if k.is_controller() => {
                if let Some(c) = cfg.controller.as_mut() {
                    match (k, v) {
                        (Knob::CtlKp, Value::Num(x)) => c.kp = x,
                        (Knob::CtlKi, Value::Num(x)) => c.ki = x,
                        (Knob::CtlKd, Value::Num(x)) => c.kd = x,
                        (Knob::CtlPeriod, Value::Num(x)) => c.period = x,
                        (Knob::CtlModelScale, Value::Num(x)) => c.model_scale = x,
                        (Knob::Compensation, Value::Compensation(x)) => c.compensation = x,
                        (Knob::Feedback, Value::Feedback(x)) => c.feedback = x,
                        _ => {}
                    }
                }
            }
            _ => {}
        }
    }
}

/// `num` evenly spaced values from `start` to `stop` inclusive.
pub fn linspace(start: f64, stop: f64, num: usize) -> Vec<f64> {
    match num {
        0 => Vec::new(),
        1 => vec![start],
        _ => (0..num).map(|k| start + (stop - start) * k as f64 / (num - 1) as f64).collect(),
    }
}

/// `num` logarithmically spaced values from `start` to `stop` inclusive (both > 0).
pub fn logspace(start: f64, stop: f64, num: usize) -> Vec<f64> {
    let mut v: Vec<f64> = linspace(start.ln(), stop.ln(), num).into_iter().map(f64::exp).collect();
    // Land exactly on the given end points.
    if let Some(first) = v.first_mut() {
        *first = start;
    }
    if num > 1 {
        v[num - 1] = stop;
    }
    v
}
