//! Checks of every number of a compliant `hdw fit drive` configuration (`transmission =
//! "compliant"`, voltage tests or closed-loop records), run when it is parsed, before a
//! record or the params file is read; [`starts_in_bounds`] once the params file's start
//! values are known. Each failure is one line naming the file, the table and the key. The
//! `[params]` ranges are hd-model's registry's, the same `hdw simulate` applies.

use crate::drive::compliant::config::CompliantConfig;
use crate::drive::compliant::params::{NAMES, P, ix};
use crate::drive::config::validate::{
    MAX_DELAY, MAX_ITERATIONS, MAX_SUBSTEPS, at, bounds, delays, gain, inside, names,
    number_or_name, saturation_and_filter, scale, start_magnitude, whole,
};
use crate::drive::config::{DelayChoice, NumberOrVariable};
use crate::drive::error::DriveError;

/// Checks of a compliant configuration's TOML table before it is deserialised.
pub fn raw(t: &toml::Table, file: &str) -> Result<(), DriveError> {
    number_or_name(t, file, "controller", "kp", "the position-loop gain [1/s]")?;
    number_or_name(t, file, "controller", "kv", "the speed-loop gain [V or A per rad/s]")?;
    delays(t, file)?;
    whole(
        t,
        file,
        "",
        "substeps",
        (1, MAX_SUBSTEPS as i64),
        "the Runge–Kutta substeps per sample (leave it out to have them chosen)",
    )?;
    whole(t, file, "fit", "max_iterations", (0, MAX_ITERATIONS as i64), "an iteration budget")?;
    Ok(())
}

/// The registry's range of parameter `name`: (lowest value, whether it is allowed, what
/// it is, unit).
fn range(name: &str) -> (f64, bool, &'static str, &'static str) {
    match hd_model::registry::find(name) {
        Some(i) => (i.min, i.min_inclusive, i.doc, i.unit),
        None => (f64::NEG_INFINITY, false, "a parameter", "-"),
    }
}

/// Checks of a parsed compliant configuration, before any record is read.
pub fn compliant(c: &CompliantConfig, file: &str) -> Result<(), DriveError> {
    names(file, c.experiment.iter().map(|e| e.name.as_str()))?;
    for e in &c.experiment {
        let key = |k: &str| format!("[[experiment]] '{}' {k}", e.name);
        if e.file.trim().is_empty() {
            return Err(DriveError::config(
                at(file, &key("file")),
                "empty; expected a record's path",
            ));
        }
        for (k, v) in [
            ("motor_scale", e.motor_scale),
            ("load_scale", e.load_scale),
            ("current_scale", e.current_scale),
            ("voltage_scale", e.voltage_scale),
            ("command_scale", e.command_scale),
            ("reference_scale", e.reference_scale),
        ] {
            scale(file, &key(k), v)?;
        }
    }
    if let Some(ctl) = &c.controller {
        for (k, v) in [("kp", &ctl.kp), ("kv", &ctl.kv)] {
            if let Some(NumberOrVariable::Number(x)) = v {
                gain(file, &format!("[controller] {k}"), *x)?;
            }
        }
        for (k, v) in [("p", ctl.p), ("d", ctl.d)] {
            if let Some(x) = v {
                gain(file, &format!("[controller] {k}"), x)?;
            }
        }
        saturation_and_filter(file, ctl.saturation, ctl.speed_filter.as_deref())?;
        if let Some(DelayChoice::Samples(d)) = ctl.delay
            && d > MAX_DELAY
        {
            return Err(DriveError::config(
                at(file, "[controller] delay"),
                format!("{d}; expected at most {MAX_DELAY} samples"),
            ));
        }
    }
    if let Some(s) = c.substeps
        && !(1..=MAX_SUBSTEPS).contains(&s)
    {
        return Err(DriveError::config(
            at(file, "substeps"),
            format!("{s}; expected 1 to {MAX_SUBSTEPS} substeps per sample"),
        ));
    }
    for (name, &v) in &c.params {
        if !NAMES.contains(&name.as_str()) {
            continue; // named as unknown by the configuration's own check
        }
        let (lo, incl, what, unit) = range(name);
        let below = if incl { v < lo } else { v <= lo };
        if !v.is_finite() || below {
            let limit = match (lo.is_finite(), incl) {
                (false, _) => String::new(),
                (true, true) => format!(" ≥ {lo}"),
                (true, false) => format!(" > {lo}"),
            };
            return Err(DriveError::config(
                at(file, &format!("[params] {name}")),
                format!("{v}; expected a finite value{limit} [{unit}] ({what})"),
            ));
        }
        start_magnitude(file, &format!("[params] {name}"), v)?;
    }
    for (name, &[lo, hi]) in &c.bounds {
        if !NAMES.contains(&name.as_str()) {
            continue;
        }
        let (min, incl, what, unit) = range(name);
        bounds(file, name, lo, hi, (min, incl, what), unit)?;
        if let Some(&v) = c.params.get(name) {
            inside(file, name, v, lo, hi, "[params]")?;
        }
    }
    Ok(())
}

/// Every `[bounds]` entry holds its start: `[params]`'s value, else the params file's
/// (`base`, [`NAMES`] order; Km follows Ke unless `km_equals_ke = false`).
pub fn starts_in_bounds(
    c: &CompliantConfig,
    file: &str,
    base: &[f64; P],
) -> Result<(), DriveError> {
    for (name, &[lo, hi]) in &c.bounds {
        let Some(k) = NAMES.iter().position(|n| n == name) else { continue };
        let mut k_start = k;
        if k == ix::KM && c.km_equals_ke.unwrap_or(true) {
            k_start = ix::KE;
        }
        let (v, source) = match c.params.get(NAMES[k_start]) {
            Some(&v) => (v, "[params]"),
            None => (base[k_start], "the params file"),
        };
        inside(file, name, v, lo, hi, source)?;
    }
    Ok(())
}

/// Checks that need the records: `rows` the shortest record's length [samples]. A delay
/// (fixed, or one of those compared) must leave the loop samples to act on.
pub fn with_records(c: &CompliantConfig, file: &str, rows: usize) -> Result<(), DriveError> {
    let Some(ctl) = &c.controller else { return Ok(()) };
    let mut asked: Vec<usize> = ctl.delays.clone().unwrap_or_default();
    if let Some(DelayChoice::Samples(d)) = ctl.delay {
        asked.push(d);
    }
    let taps = ctl.speed_filter.as_ref().map_or(1, Vec::len);
    match asked.into_iter().find(|&d| d + taps + 1 >= rows) {
        Some(d) => Err(DriveError::config(
            at(file, "[controller] delay"),
            format!(
                "{d} samples; expected fewer than the shortest record's {rows} samples (with this delay the loop would never act on it)"
            ),
        )),
        None => Ok(()),
    }
}
