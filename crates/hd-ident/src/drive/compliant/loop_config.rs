//! The `[controller]` of a compliant fit whose records were logged in closed loop
//! (docs/fit-drive.md, "The compliant drive in its loop"): its keys, their checks (one-line
//! errors naming the file and the key), and the controller check that picks the delay by
//! applying the law to the recorded encoder and reference and comparing with the recorded
//! command, as the rigid fit does ([`crate::drive::controller::reproduce`]).

use super::closed_loop::{Amplifier, ClosedLoop, Feedback};
use super::config::CompliantConfig;
use super::record::VoltageRecord;
use crate::drive::config::{DelayChoice, NumberOrVariable};
use crate::drive::controller::{Controller, Reproduction, reproduce};
use crate::drive::error::DriveError;
use serde::Deserialize;

/// `[controller]` of a compliant fit: the rigid fit's keys (cascade P–P as `kp`, `kv`, or
/// PD as `p`, `d`), plus the encoder it reads and what its output drives.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoopControllerConfig {
    /// Position-loop gain [1/s] (number or scalar name).
    pub kp: Option<NumberOrVariable>,
    /// Speed-loop gain [V or A per rad/s] (number or scalar name).
    pub kv: Option<NumberOrVariable>,
    /// PD form: proportional gain [V or A per rad] (with `d`; instead of kp, kv).
    pub p: Option<f64>,
    /// PD form: derivative gain [V or A per rad/s].
    pub d: Option<f64>,
    /// Output limit [V or A]; none when absent.
    pub saturation: Option<f64>,
    /// Computation delay: samples or "auto"; default "auto".
    pub delay: Option<DelayChoice>,
    /// Delays compared by the controller check; default [0, 1].
    pub delays: Option<Vec<usize>>,
    /// FIR coefficients of the position filter before the speed difference; default [1].
    pub speed_filter: Option<Vec<f64>>,
    /// The encoder the loop reads: `motor` (default) or `load`.
    pub feedback: Option<String>,
    /// What the output drives: `voltage` (default) or `current`.
    pub amplifier: Option<String>,
}

impl LoopControllerConfig {
    /// The encoder read.
    pub fn feedback(&self, file: &str) -> Result<Feedback, DriveError> {
        let s = self.feedback.as_deref().unwrap_or("motor");
        Feedback::parse(s).ok_or_else(|| {
            DriveError::config(
                format!("{file}, [controller] feedback"),
                format!("'{s}'; expected \"motor\" or \"load\""),
            )
        })
    }

    /// What the output drives.
    pub fn amplifier(&self, file: &str) -> Result<Amplifier, DriveError> {
        let s = self.amplifier.as_deref().unwrap_or("voltage");
        Amplifier::parse(s).ok_or_else(|| {
            DriveError::config(
                format!("{file}, [controller] amplifier"),
                format!("'{s}'; expected \"voltage\" or \"current\""),
            )
        })
    }

    /// The controller with the gains `kp` [1/s], `kv` [V or A per rad/s] (resolved by the
    /// caller: they may name scalars of a record), delay 0, at sample period `h` [s].
    pub fn controller(
        &self,
        file: &str,
        kp: f64,
        kv: f64,
        h: f64,
    ) -> Result<Controller, DriveError> {
        let at = |k: &str| format!("{file}, [controller] {k}");
        let speed_filter = self.speed_filter.clone().unwrap_or_else(|| vec![1.0]);
        let sum: f64 = speed_filter.iter().sum();
        if speed_filter.is_empty() || (sum - 1.0).abs() > 1e-9 {
            return Err(DriveError::config(
                at("speed_filter"),
                format!("coefficients sum to {sum}; expected 1 (a filter of unit DC gain)"),
            ));
        }
        let saturation = self.saturation.unwrap_or(f64::INFINITY);
        if saturation.is_nan() || saturation <= 0.0 {
            return Err(DriveError::config(at("saturation"), "expected a positive limit"));
        }
        for (k, v) in [("kp", kp), ("kv", kv)] {
            if !v.is_finite() {
                return Err(DriveError::config(at(k), format!("{v}; expected a finite gain")));
            }
        }
        Ok(Controller { kp, kv, saturation, delay: 0, speed_filter, h, open_loop: None })
    }

    /// The gains as given: `(kp, kv)` of the cascade, or the PD form's converted
    /// (kv = d, kp = p/d). Names of scalars are left to the caller.
    pub fn gains(&self) -> (Option<NumberOrVariable>, Option<NumberOrVariable>) {
        match (self.p, self.d) {
            (Some(p), Some(d)) => {
                (Some(NumberOrVariable::Number(p / d)), Some(NumberOrVariable::Number(d)))
            }
            _ => (self.kp.clone(), self.kv.clone()),
        }
    }
}

/// Check the closed-loop keys of `c` (file `file`): a `[controller]` and every experiment's
/// `reference` and `command` come together; a voltage test has `voltage` and neither.
pub fn check(c: &CompliantConfig, file: &str) -> Result<(), DriveError> {
    let exp = |name: &str, key: &str| format!("{file}, [[experiment]] '{name}' {key}");
    match &c.controller {
        Some(ctl) => {
            let at = |k: &str| format!("{file}, [controller] {k}");
            ctl.feedback(file)?;
            ctl.amplifier(file)?;
            let cascade = ctl.kp.is_some() || ctl.kv.is_some();
            let pd = ctl.p.is_some() || ctl.d.is_some();
            if cascade && pd {
                return Err(DriveError::config(
                    at("p"),
                    "give the gains once: kp and kv (cascade) or p and d (PD), not both",
                ));
            }
            if pd && !(ctl.p.is_some() && ctl.d.is_some()) {
                return Err(DriveError::config(at("d"), "the PD form needs both p and d"));
            }
            if pd && ctl.d.is_some_and(|d| d == 0.0 || !d.is_finite()) {
                return Err(DriveError::config(at("d"), "expected a finite non-zero gain"));
            }
            let both = ctl.kp.is_some() && ctl.kv.is_some();
            if !pd && !both {
                let missing = if ctl.kp.is_none() { "kp" } else { "kv" };
                return Err(DriveError::config(
                    at(missing),
                    "missing; expected kp and kv (cascade) or p and d (PD)",
                ));
            }
            if let Some(DelayChoice::Auto(s)) = &ctl.delay
                && s != "auto"
            {
                return Err(DriveError::config(
                    at("delay"),
                    format!("'{s}'; expected a number of samples or \"auto\""),
                ));
            }
            if ctl.delays.as_ref().is_some_and(|d| d.is_empty()) {
                return Err(DriveError::config(at("delays"), "empty; expected delays to compare"));
            }
            for e in &c.experiment {
                if e.voltage.is_some() {
                    return Err(DriveError::config(
                        exp(&e.name, "voltage"),
                        "in a closed-loop record the controller's output is `command` (V or A); remove `voltage`",
                    ));
                }
                for (key, v) in [("reference", &e.reference), ("command", &e.command)] {
                    if v.is_none() {
                        return Err(DriveError::config(
                            exp(&e.name, key),
                            format!("missing; a record with a [controller] needs its {key} column"),
                        ));
                    }
                }
            }
        }
        None => {
            for e in &c.experiment {
                for (key, v) in [("reference", &e.reference), ("command", &e.command)] {
                    if v.is_some() {
                        return Err(DriveError::config(
                            exp(&e.name, key),
                            format!(
                                "a {key} column needs a [controller] (the loop it was logged in)"
                            ),
                        ));
                    }
                }
                if e.voltage.is_none() {
                    return Err(DriveError::config(
                        exp(&e.name, "voltage"),
                        "missing; a voltage test needs its voltage column (or give a [controller], reference and command)",
                    ));
                }
            }
            if c.fit.outputs.iter().flatten().any(|o| o == "command") {
                return Err(DriveError::config(
                    format!("{file}, [fit] outputs"),
                    "'command' needs a [controller]: a voltage test's voltage is an input",
                ));
            }
        }
    }
    Ok(())
}

/// The controller check: the law with each delay in `delays` applied to every record's
/// recorded feedback encoder and reference (`loops[k]` for `records[k]`, whose `u` is the
/// recorded command), pooled in quadrature over the records; and the delay used (`fixed`,
/// or the best reproducing one).
pub fn check_delays(
    c: &Controller,
    loops: &[(&VoltageRecord, &ClosedLoop)],
    delays: &[usize],
    fixed: Option<usize>,
) -> (usize, Vec<Reproduction>) {
    let mut pooled: Vec<Reproduction> =
        delays.iter().map(|&d| Reproduction { delay: d, rms: 0.0, percent: 0.0 }).collect();
    let m = loops.len().max(1) as f64;
    for (rec, cl) in loops {
        let zero = vec![0.0; rec.len()];
        let q = cl.measured_feedback(rec);
        for (acc, r) in pooled.iter_mut().zip(reproduce(c, q, &cl.reference, &zero, &rec.u, delays))
        {
            acc.rms += r.rms * r.rms / m;
            acc.percent += r.percent * r.percent / m;
        }
    }
    for r in &mut pooled {
        r.rms = r.rms.sqrt();
        r.percent = r.percent.sqrt();
    }
    let best = pooled.iter().min_by(|a, b| a.rms.total_cmp(&b.rms)).map_or(0, |r| r.delay);
    (fixed.unwrap_or(best), pooled)
}
