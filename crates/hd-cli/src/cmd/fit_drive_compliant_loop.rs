//! The compliant fit of records logged in closed loop: the `[controller]` built from the
//! configuration, checked against every record's recorded command for each delay
//! considered (the delay used is chosen there, as the rigid fit chooses it), and attached
//! to the records (docs/fit-drive.md, "The compliant drive in its loop").

use super::fit_drive::resolve;
use anyhow::{Result, anyhow};
use hd_ident::drive::compliant::fit::Signal;
use hd_ident::drive::compliant::loop_config::check_delays;
use hd_ident::drive::compliant::model::{P, ix};
use hd_ident::drive::compliant::units::signal_unit;
use hd_ident::drive::compliant::{Amplifier, ClosedLoop, CompliantConfig, Feedback, VoltageRecord};
use hd_ident::drive::config::DelayChoice;
use hd_ident::drive::controller::{Controller, Reproduction};
use serde_json::{Value, json};
use std::path::Path;

/// The loop of a closed-loop fit, as reported.
#[derive(Clone, Debug)]
pub struct LoopInfo {
    /// The controller, with the delay used.
    pub controller: Controller,
    /// The encoder it reads.
    pub feedback: Feedback,
    /// What its output drives.
    pub amplifier: Amplifier,
    /// The controller check per delay considered (pooled over the fitted records).
    pub checks: Vec<Reproduction>,
    /// Whether the configuration fixed the delay (else the check chose it).
    pub fixed: bool,
    /// The unit of the fed-back position: m for a linear axis's load encoder, else rad.
    pub position_unit: &'static str,
}

impl LoopInfo {
    /// fit.json's `controller`.
    pub fn json(&self) -> Value {
        let c = &self.controller;
        json!({
            "kp": c.kp, "kv": c.kv, "saturation": c.saturation, "speed_filter": c.speed_filter,
            "sample_period": c.h, "delay": c.delay,
            "delay_from": if self.fixed { "configuration" } else { "check" },
            "feedback": self.feedback.name(), "amplifier": self.amplifier.name(),
            "command_unit": self.amplifier.unit(), "position_unit": self.position_unit,
            "check": self.checks.iter()
                .map(|r| json!({"delay": r.delay, "rms": r.rms, "percent": r.percent}))
                .collect::<Vec<_>>(),
        })
    }

    /// The controller check in words (report.md and the terminal).
    pub fn lines(&self) -> Vec<String> {
        let c = &self.controller;
        let u = self.amplifier.unit();
        let mut out = vec![format!(
            "The controller (kp {} 1/s, kv {} {u}·s/{}, saturation ±{} {u}, speed filter {:?}, feedback on the {} encoder, {} amplifier) applied to the recorded encoder and reference reproduces the recorded command with:",
            c.kp,
            c.kv,
            self.position_unit,
            c.saturation,
            c.speed_filter,
            self.feedback.name(),
            self.amplifier.name()
        )];
        for r in &self.checks {
            out.push(format!(
                "delay {} sample(s): residual {:.5e} {u} RMS ({:.3} % of the command's RMS)",
                r.delay, r.rms, r.percent
            ));
        }
        let why = if self.fixed { "as configured" } else { "it reproduces the command best" };
        out.push(format!("Delay used: {} sample(s) ({why}).", c.delay));
        out
    }
}

/// A record and its reference column, as read.
type Loaded = (VoltageRecord, Option<Vec<f64>>);

/// Attach the configured loop to the fitted records and the validation record; the loop's
/// check is printed. Voltage tests (no `[controller]`) pass through unchanged.
pub fn attach(
    cfg: &CompliantConfig,
    file: &str,
    first_file: &Path,
    loaded: Vec<Loaded>,
    validation: Option<Loaded>,
) -> Result<(Vec<VoltageRecord>, Option<VoltageRecord>, Option<LoopInfo>)> {
    let Some(ctl) = &cfg.controller else {
        return Ok((loaded.into_iter().map(|l| l.0).collect(), validation.map(|v| v.0), None));
    };
    let (kp, kv) = ctl.gains();
    let missing = || anyhow!("{file}, [controller]: no gains");
    let kp = resolve(&kp.ok_or_else(missing)?, "[controller] kp", first_file)?;
    let kv = resolve(&kv.ok_or_else(missing)?, "[controller] kv", first_file)?;
    let h = loaded[0].0.h;
    if let Some((r, _)) =
        loaded.iter().chain(validation.iter()).find(|(r, _)| ((r.h - h) / h).abs() > 1e-3)
    {
        return Err(anyhow!(
            "{}: sample period {} s differs from the first record's {h} s; one controller runs at one rate",
            r.source,
            r.h
        ));
    }
    let controller = ctl.controller(file, kp, kv, h)?;
    let (feedback, amplifier) = (ctl.feedback(file)?, ctl.amplifier(file)?);
    let bind = |(rec, reference): Loaded, c: &Controller| -> Result<VoltageRecord> {
        let reference = reference
            .ok_or_else(|| anyhow!("{}: no reference column for the closed loop", rec.source))?;
        Ok(rec.in_loop(ClosedLoop { controller: c.clone(), feedback, amplifier, reference })?)
    };
    let records: Vec<VoltageRecord> =
        loaded.into_iter().map(|l| bind(l, &controller)).collect::<Result<_>>()?;
    let delays = ctl.delays.clone().unwrap_or_else(|| vec![0, 1]);
    let fixed = match &ctl.delay {
        Some(DelayChoice::Samples(d)) => Some(*d),
        _ => None,
    };
    let pairs: Vec<_> = records.iter().filter_map(|r| Some((r, r.closed.as_ref()?))).collect();
    let (delay, checks) = check_delays(&controller, &pairs, &delays, fixed);
    let controller = Controller { delay, ..controller };
    let records: Vec<VoltageRecord> = records
        .into_iter()
        .map(|mut r| {
            if let Some(cl) = r.closed.as_mut() {
                cl.controller.delay = delay;
            }
            r
        })
        .collect();
    let validation = validation.map(|v| bind(v, &controller)).transpose()?;
    let fed_back = if feedback == Feedback::Load { Signal::Load } else { Signal::Motor };
    let position_unit = signal_unit(fed_back, cfg.axis(file)?);
    let fixed = fixed.is_some();
    let info = LoopInfo { controller, feedback, amplifier, checks, fixed, position_unit };
    for l in info.lines() {
        eprintln!("{l}");
    }
    Ok((records, validation, Some(info)))
}

/// With an ideal current amplifier the motor's resistance and back-EMF act on nothing the
/// loop records (the current is the command; Km × command is the torque): R is not fitted,
/// nor Ke when Km is its own parameter.
pub fn unfree_for_current(free: &mut [bool; P], km_is_ke: bool) {
    free[ix::R] = false;
    if !km_is_ke {
        free[ix::KE] = false;
    }
}
