//! The closed-loop options of `hdw simulate` (docs/model.md §6): they build a
//! `[controller]` table, or override the one of the params file.

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use hd_model::control::{Compensation, ControllerConfig, Feedback, Reference};
use hd_model::laws::input::{Input, Profile};
use hd_model::laws::load::LoadTorque;
use std::path::Path;

/// Controller names on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ControllerArg {
    /// Open loop: the motor is driven by --input.
    None,
    /// PID position control of the load (derivative filter, anti-windup, saturation).
    Pid,
}

/// Closed-loop options; each one given overrides the params file's `[controller]` table.
#[derive(Args, Debug, Default)]
pub struct ControlArgs {
    /// Closed-loop controller (a params file's [controller] table also turns it on).
    #[arg(long, value_name = "none|pid")]
    pub controller: Option<ControllerArg>,
    /// Proportional gain kp [V/rad] (default 2000).
    #[arg(long)]
    pub kp: Option<f64>,
    /// Integral gain ki [V/(rad·s)] (default 20 000).
    #[arg(long)]
    pub ki: Option<f64>,
    /// Derivative gain kd [V·s/rad] (default 0).
    #[arg(long)]
    pub kd: Option<f64>,
    /// Derivative-filter time constant τd [s] (default 1e-3).
    #[arg(long)]
    pub tau_d: Option<f64>,
    /// Voltage limit [V] (default 48).
    #[arg(long)]
    pub u_max: Option<f64>,
    /// Sampling period with zero-order hold [s] (default 0: continuous).
    #[arg(long)]
    pub ctl_period: Option<f64>,
    /// Encoder resolution [rad] (needs --ctl-period; default 0: ideal).
    #[arg(long)]
    pub enc_res: Option<f64>,
    /// Fed-back angle: load (θz) or motor (θj/N).
    #[arg(long, value_name = "load|motor")]
    pub feedback: Option<String>,
    /// Reference θz_ref: sine, step, trapezoid, scurve, or a CSV/Parquet file with columns
    /// t [s] and ref [rad].
    #[arg(long, value_name = "KIND|FILE")]
    pub reference: Option<String>,
    /// Reference amplitude, step height or move distance [rad] (default 1e-3).
    #[arg(long)]
    pub ref_amplitude: Option<f64>,
    /// Reference frequency [Hz] (sine; default 0.2).
    #[arg(long)]
    pub ref_freq: Option<f64>,
    /// Move time of trapezoid and scurve references [s] (default 1).
    #[arg(long)]
    pub ref_duration: Option<f64>,
    /// Compensation: none, friction, or friction+compliance.
    #[arg(long, value_name = "none|friction|friction+compliance")]
    pub compensation: Option<String>,
    /// Controller-model parameter differing from the plant's, e.g. `--model Tc=1.2`
    /// (repeatable).
    #[arg(long = "model", value_name = "NAME=VALUE")]
    pub model: Vec<String>,
    /// Factor on the controller model's friction and stiffness parameters (default 1).
    #[arg(long)]
    pub model_scale: Option<f64>,
    /// Constant external load torque on the load side [N·m], opposing positive motion.
    #[arg(long, value_name = "N·m")]
    pub load_torque: Option<f64>,
}

impl ControlArgs {
    /// The external load torque.
    pub fn load_torque(&self) -> LoadTorque {
        self.load_torque.map_or_else(LoadTorque::default, |tl| {
            LoadTorque::new(Input::Constant { amplitude: tl })
        })
    }

    /// The controller: the params file's table (`from_file`) with the given options
    /// applied; `None` for an open-loop run.
    pub fn controller(
        &self,
        from_file: Option<ControllerConfig>,
    ) -> Result<Option<ControllerConfig>> {
        let mut c = match (self.controller, from_file) {
            (Some(ControllerArg::None), _) => return Ok(None),
            (Some(ControllerArg::Pid), file) => file.unwrap_or_default(),
            (None, Some(file)) => file,
            (None, None) => {
                if self.any_given() {
                    bail!(
                        "closed-loop options need --controller pid (or a [controller] table in --params)"
                    );
                }
                return Ok(None);
            }
        };
        let set = |slot: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *slot = v;
            }
        };
        set(&mut c.kp, self.kp);
        set(&mut c.ki, self.ki);
        set(&mut c.kd, self.kd);
        set(&mut c.tau_d, self.tau_d);
        set(&mut c.u_max, self.u_max);
        set(&mut c.period, self.ctl_period);
        set(&mut c.enc_res, self.enc_res);
        set(&mut c.model_scale, self.model_scale);
        if let Some(f) = &self.feedback {
            c.feedback = f.parse::<Feedback>().map_err(anyhow::Error::msg).context("--feedback")?;
        }
        if let Some(k) = &self.compensation {
            c.compensation =
                k.parse::<Compensation>().map_err(anyhow::Error::msg).context("--compensation")?;
        }
        if self.reference.is_some() || self.ref_amplitude.is_some() || self.ref_freq.is_some() {
            c.reference = self.reference_of(&c.reference)?;
        }
        for m in &self.model {
            let (info, v) =
                hd_model::registry::parse_assignment(m).with_context(|| format!("--model {m}"))?;
            c.model.insert(info.name.to_string(), v);
        }
        Ok(Some(c))
    }

    fn any_given(&self) -> bool {
        [self.kp, self.ki, self.kd, self.tau_d, self.u_max, self.ctl_period, self.enc_res]
            .iter()
            .any(Option::is_some)
            || self.feedback.is_some()
            || self.reference.is_some()
            || self.compensation.is_some()
            || !self.model.is_empty()
    }

    /// The reference from --reference, --ref-amplitude, --ref-freq, --ref-duration, with
    /// `current`'s kind when --reference is not given.
    fn reference_of(&self, current: &Reference) -> Result<Reference> {
        let amplitude = self.ref_amplitude.unwrap_or(1e-3);
        let freq = self.ref_freq.unwrap_or(0.2);
        let duration = self.ref_duration.unwrap_or(1.0);
        let kind = match (&self.reference, current) {
            (Some(k), _) => k.as_str(),
            (None, Reference::Step { .. }) => "step",
            (None, Reference::Trapezoid { .. }) => "trapezoid",
            (None, Reference::SCurve { .. }) => "scurve",
            (None, _) => "sine",
        };
        Ok(match kind {
            "sine" => Reference::Sine { amplitude, freq },
            "step" => Reference::Step { amplitude, t0: 0.0 },
            "trapezoid" => Reference::Trapezoid { amplitude, duration, t0: 0.0 },
            "scurve" => Reference::SCurve { amplitude, duration, t0: 0.0 },
            file if Path::new(file).extension().is_some() => {
                let mut cols = hd_io::read_columns(Path::new(file), &["t", "ref"])?;
                let r = cols.pop().unwrap_or_default();
                let t = cols.pop().unwrap_or_default();
                Reference::Recorded(Profile::new(t, r, file)?)
            }
            other => bail!(
                "--reference {other}: expected sine, step, trapezoid, scurve or a CSV/Parquet file with columns t, ref"
            ),
        })
    }
}
