//! Checks of every number of a rigid `hdw fit drive` configuration, run when it is parsed,
//! before a record is read or a fit starts: each failure is one line naming the file, the
//! table and the key, and what was expected. [`raw`] looks at the TOML table before serde
//! does (so `delay = -1` gets a plain sentence instead of serde's words about its own
//! types); [`rigid`] checks the typed configuration; [`with_records`] the keys that need the
//! records' sample period and length. The compliant configuration's checks are in
//! `validate_compliant.rs`.

use crate::drive::config::{DelayChoice, DriveConfig, NumberOrVariable};
use crate::drive::error::DriveError;
use crate::drive::model::{Axis, FrictionLaw};
use std::collections::BTreeSet;

/// Largest Runge–Kutta substep count per sample a configuration may ask for [–]: more
/// makes a fit of a short record run for hours without being more exact.
pub const MAX_SUBSTEPS: usize = 10_000;

/// Largest computation delay (and entry of `delays`) [samples]: a logged loop that acts
/// ten thousand samples after it measures is not a controller.
pub const MAX_DELAY: usize = 10_000;

/// Largest iteration budget of a fit [–].
pub const MAX_ITERATIONS: usize = 100_000;

/// Largest number of taps of a speed filter [–].
pub const MAX_FILTER_TAPS: usize = 1_000;

/// Largest Butterworth order of the inverse-model start's filter [–].
pub const MAX_ORDER: usize = 16;

/// Fewest samples the score rule must leave of each record.
pub const MIN_SCORED: usize = 10;

/// `"{file}, {key}"`.
pub(crate) fn at(file: &str, key: &str) -> String {
    format!("{file}, {key}")
}

/// A `[table] key` label (`key` alone at the top level).
pub(crate) fn label(table: &str, key: &str) -> String {
    if table.is_empty() { key.to_string() } else { format!("[{table}] {key}") }
}

/// The value of `key` in `table` of `t` (the top level when `table` is empty).
fn get<'a>(t: &'a toml::Table, table: &str, key: &str) -> Option<&'a toml::Value> {
    if table.is_empty() { t.get(key) } else { t.get(table)?.as_table()?.get(key) }
}

/// `key` of `table`, when present, must be a whole number in `lo..=hi`.
pub(crate) fn whole(
    t: &toml::Table,
    file: &str,
    table: &str,
    key: &str,
    (lo, hi): (i64, i64),
    what: &str,
) -> Result<(), DriveError> {
    let Some(v) = get(t, table, key) else { return Ok(()) };
    match v.as_integer() {
        Some(n) if (lo..=hi).contains(&n) => Ok(()),
        _ => Err(DriveError::config(
            at(file, &label(table, key)),
            format!("{v}; expected {what}, a whole number from {lo} to {hi}"),
        )),
    }
}

/// `key` of `table`, when present, must be a number or the name of a scalar of the record.
pub(crate) fn number_or_name(
    t: &toml::Table,
    file: &str,
    table: &str,
    key: &str,
    what: &str,
) -> Result<(), DriveError> {
    match get(t, table, key) {
        None | Some(toml::Value::Integer(_) | toml::Value::Float(_) | toml::Value::String(_)) => {
            Ok(())
        }
        Some(v) => Err(DriveError::config(
            at(file, &label(table, key)),
            format!("{v}; expected {what} (a number, or the name of a scalar in the first record)"),
        )),
    }
}

/// `[controller] delay` and `delays`: whole numbers of samples, or `"auto"`.
pub(crate) fn delays(t: &toml::Table, file: &str) -> Result<(), DriveError> {
    let max = MAX_DELAY as i64;
    match get(t, "controller", "delay") {
        None | Some(toml::Value::String(_)) => {}
        Some(v) => {
            if !v.as_integer().is_some_and(|n| (0..=max).contains(&n)) {
                return Err(DriveError::config(
                    at(file, "[controller] delay"),
                    format!(
                        "{v}; expected a number of samples from 0 to {MAX_DELAY} (the controller's computation delay), or \"auto\""
                    ),
                ));
            }
        }
    }
    if let Some(v) = get(t, "controller", "delays") {
        let ok = v.as_array().is_some_and(|a| {
            !a.is_empty()
                && a.iter().all(|d| d.as_integer().is_some_and(|n| (0..=max).contains(&n)))
        });
        if !ok {
            return Err(DriveError::config(
                at(file, "[controller] delays"),
                format!("{v}; expected a non-empty list of delays from 0 to {MAX_DELAY} [samples]"),
            ));
        }
    }
    Ok(())
}

/// Checks of a rigid configuration's TOML table before it is deserialised.
pub fn raw(t: &toml::Table, file: &str) -> Result<(), DriveError> {
    number_or_name(t, file, "", "gain", "the drive gain [N/V or N·m/V]")?;
    number_or_name(t, file, "controller", "kp", "the position-loop gain [1/s]")?;
    number_or_name(t, file, "controller", "kv", "the speed-loop gain")?;
    delays(t, file)?;
    whole(t, file, "start", "order", (1, MAX_ORDER as i64), "the filter's order")?;
    whole(t, file, "start", "decimate", (1, 1_000_000), "the decimation factor")?;
    whole(t, file, "fit", "max_iterations", (0, MAX_ITERATIONS as i64), "an iteration budget")?;
    Ok(())
}

/// Widest factor a unit conversion or a gain may have, either way [–]: 1e12 spans pico to
/// tera; beyond it the scaled signal overflows or vanishes in the fit's arithmetic (a
/// `gain = 1e300` gave NaN parameters and exit 0).
pub const SCALE_RANGE: f64 = 1e12;

/// Largest magnitude of a start value [its unit]: no parameter of a drive in SI units comes
/// near it, and 1e300 overflows the simulation (the fit then never moved and exit 0).
pub const MAX_START: f64 = 1e30;

/// A finite scale factor ≠ 0 within ×[`SCALE_RANGE`] of 1 (negative flips the signal's sign).
pub(crate) fn scale(file: &str, key: &str, v: f64) -> Result<(), DriveError> {
    if v.is_finite() && v != 0.0 && (1.0 / SCALE_RANGE..=SCALE_RANGE).contains(&v.abs()) {
        return Ok(());
    }
    Err(DriveError::config(
        at(file, key),
        format!(
            "{}; expected a finite factor ≠ 0 between {:e} and {SCALE_RANGE:e} in magnitude (the file's unit to the fit's; negative flips the sign)",
            hd_model::error::num(v),
            1.0 / SCALE_RANGE
        ),
    ))
}

/// Smallest noise level an output may be given, as a share of its signal's RMS [–]: below
/// it the weights overflow (a noise of 1e-300 gave an infinite BIC and no standard error).
pub const MIN_NOISE_SHARE: f64 = 1e-12;

/// A given noise level `level` of output `name` against its signal's RMS `rms` (same unit).
pub fn noise_floor(file: &str, name: &str, level: f64, rms: f64) -> Result<(), DriveError> {
    if !(rms.is_finite() && rms > 0.0) || level >= MIN_NOISE_SHARE * rms {
        return Ok(());
    }
    Err(DriveError::config(
        at(file, &format!("[fit] noise.{name}")),
        format!(
            "{level:e}; expected the sensor's noise level, at least {MIN_NOISE_SHARE:e} of the signal's RMS ({rms:.4e})"
        ),
    ))
}

/// A start value's magnitude at most [`MAX_START`].
pub(crate) fn start_magnitude(file: &str, key: &str, v: f64) -> Result<(), DriveError> {
    if v.abs() <= MAX_START {
        return Ok(());
    }
    Err(DriveError::config(
        at(file, key),
        format!(
            "{v:e}; expected a start of at most {MAX_START:e} in magnitude (check the unit: no drive parameter comes near it)"
        ),
    ))
}

/// A finite value > 0 (a gain, a frequency).
pub fn positive(file: &str, key: &str, v: f64, what: &str) -> Result<(), DriveError> {
    if v.is_finite() && v > 0.0 {
        return Ok(());
    }
    Err(DriveError::config(at(file, key), format!("{v}; expected {what}, a finite value > 0")))
}

/// A gain > 0 within ×[`SCALE_RANGE`] of 1 (the drive gain, a controller's gain).
fn bounded_gain(file: &str, key: &str, v: f64, what: &str) -> Result<(), DriveError> {
    positive(file, key, v, what)?;
    if (1.0 / SCALE_RANGE..=SCALE_RANGE).contains(&v) {
        return Ok(());
    }
    Err(DriveError::config(
        at(file, key),
        format!(
            "{v:e}; expected {what} between {:e} and {SCALE_RANGE:e} (check its unit)",
            1.0 / SCALE_RANGE
        ),
    ))
}

/// Every experiment's name non-empty and its own.
pub(crate) fn names<'a>(
    file: &str,
    names: impl Iterator<Item = &'a str>,
) -> Result<(), DriveError> {
    let mut seen = BTreeSet::new();
    for n in names {
        if n.trim().is_empty() {
            return Err(DriveError::config(
                at(file, "[[experiment]] name"),
                "empty; expected a name for the reports",
            ));
        }
        if !seen.insert(n) {
            return Err(DriveError::config(
                at(file, &format!("[[experiment]] name '{n}'")),
                "used twice; expected each experiment to have its own name (the reports and plots are by name)",
            ));
        }
    }
    Ok(())
}

/// The gains of a discrete controller: finite and > 0 (a negative gain is positive
/// feedback; a record logged with the opposite sign convention is flipped by its scale).
pub fn gain(file: &str, key: &str, v: f64) -> Result<(), DriveError> {
    if v.is_finite() && v > 0.0 {
        return bounded_gain(file, key, v, "a controller gain");
    }
    Err(DriveError::config(
        at(file, key),
        format!(
            "{v}; expected a finite gain > 0 (a sign convention of the record is flipped by a negative position or command scale, not by the gain)"
        ),
    ))
}

/// `[controller] saturation` and `speed_filter`.
pub(crate) fn saturation_and_filter(
    file: &str,
    saturation: Option<f64>,
    filter: Option<&[f64]>,
) -> Result<(), DriveError> {
    if let Some(s) = saturation
        && (s.is_nan() || s <= 0.0)
    {
        return Err(DriveError::config(
            at(file, "[controller] saturation"),
            format!("{s}; expected an output limit > 0 (leave it out for none)"),
        ));
    }
    if let Some(f) = filter {
        if f.is_empty() || f.len() > MAX_FILTER_TAPS || f.iter().any(|c| !c.is_finite()) {
            return Err(DriveError::config(
                at(file, "[controller] speed_filter"),
                format!("{f:?}; expected 1 to {MAX_FILTER_TAPS} finite coefficients summing to 1"),
            ));
        }
        let sum: f64 = f.iter().sum();
        if (sum - 1.0).abs() > 1e-9 {
            return Err(DriveError::config(
                at(file, "[controller] speed_filter"),
                format!("coefficients sum to {sum}; expected 1 (a filter of unit DC gain)"),
            ));
        }
    }
    Ok(())
}

/// Physical range of a rigid drive's parameter: (lowest value, whether it is allowed,
/// what the parameter is).
fn range(name: &str) -> (f64, bool, &'static str) {
    match name {
        "M" => (0.0, false, "the moving mass or inertia"),
        "gain" => (0.0, false, "the drive gain"),
        "vs" => (0.0, false, "the Stribeck speed"),
        "sigma0" => (0.0, false, "the bristle stiffness"),
        "sigma1" => (0.0, true, "the bristle damping"),
        "offset" => (f64::NEG_INFINITY, false, "the force offset"),
        n if n.starts_with("Fv") => (0.0, true, "a viscous friction coefficient"),
        n if n.starts_with("Fs") => (0.0, true, "a static friction level"),
        _ => (0.0, true, "a Coulomb friction level"),
    }
}

/// Text of a lower limit: "> 0", "≥ 0" or "finite".
fn limit_text(lo: f64, inclusive: bool) -> String {
    match (lo.is_finite(), inclusive) {
        (false, _) => "finite".into(),
        (true, true) => format!("≥ {lo}"),
        (true, false) => format!("> {lo}"),
    }
}

/// The laws (of `all`) that have parameter `name`, by name.
fn laws_with(name: &str) -> Vec<&'static str> {
    FrictionLaw::ALL.iter().filter(|l| l.names().contains(&name)).map(|l| l.name()).collect()
}

/// Parameter `name` of `key` must belong to one of the configured `laws`.
fn of_laws(file: &str, key: &str, name: &str, laws: &[FrictionLaw]) -> Result<(), DriveError> {
    if laws.iter().any(|l| l.names().contains(&name)) {
        return Ok(());
    }
    let owners = laws_with(name);
    let asked: Vec<&str> = laws.iter().map(|l| l.name()).collect();
    Err(DriveError::config(
        at(file, &format!("{key} {name}")),
        format!(
            "{name} belongs to the {} law{}, not to {} configured here (friction = \"{}\"); remove it, or fit a law that has it",
            owners.join(" and "),
            if owners.len() > 1 { "s" } else { "" },
            if asked.len() == 1 { "the one" } else { "those" },
            asked.join("\", \"")
        ),
    ))
}

/// Checks of a parsed rigid configuration, before any record is read.
pub fn rigid(
    c: &DriveConfig,
    file: &str,
    laws: &[FrictionLaw],
    axis: Axis,
) -> Result<(), DriveError> {
    if let NumberOrVariable::Number(g) = c.gain {
        bounded_gain(file, "gain", g, &format!("the drive gain [{}]", axis.unit_of("gain")))?;
    }
    names(file, c.experiment.iter().map(|e| e.name.as_str()))?;
    for e in &c.experiment {
        let key = |k: &str| format!("[[experiment]] '{}' {k}", e.name);
        if e.file.trim().is_empty() {
            return Err(DriveError::config(
                at(file, &key("file")),
                "empty; expected a record's path",
            ));
        }
        scale(file, &key("position_scale"), e.position_scale)?;
        scale(file, &key("command_scale"), e.command_scale)?;
    }
    if let Some(ctl) = &c.controller {
        for (k, v) in [("kp", &ctl.kp), ("kv", &ctl.kv)] {
            if let NumberOrVariable::Number(x) = v {
                gain(file, &format!("[controller] {k}"), *x)?;
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
    let s = &c.start;
    for (k, v) in [("cutoff_hz", s.cutoff_hz), ("decimate_cutoff_hz", s.decimate_cutoff_hz)] {
        if let Some(v) = v {
            positive(file, &format!("[start] {k}"), v, "a filter corner [Hz]")?;
        }
    }
    for (name, &v) in &c.params {
        of_laws(file, "[params]", name, laws)?;
        let (lo, incl, what) = range(name);
        let below = if incl { v < lo } else { v <= lo };
        if !v.is_finite() || below {
            return Err(DriveError::config(
                at(file, &format!("[params] {name}")),
                format!(
                    "{v}; expected a finite value {} [{}] ({what})",
                    limit_text(lo, incl),
                    axis.unit_of(name)
                ),
            ));
        }
        start_magnitude(file, &format!("[params] {name}"), v)?;
    }
    for (name, &[lo, hi]) in &c.bounds {
        of_laws(file, "[bounds]", name, laws)?;
        bounds(file, name, lo, hi, range(name), axis.unit_of(name))?;
        if let Some(&v) = c.params.get(name) {
            inside(file, name, v, lo, hi, "[params]")?;
        }
    }
    for name in c.fit.fix.iter().flatten() {
        of_laws(file, "[fit] fix", name, laws)?;
    }
    Ok(())
}

/// A `[bounds]` pair: each end a number or ±inf, lower < upper, and inside the parameter's
/// physical range `(lowest, allowed, what)`.
pub(crate) fn bounds(
    file: &str,
    name: &str,
    lo: f64,
    hi: f64,
    (min, incl, what): (f64, bool, &str),
    unit: &str,
) -> Result<(), DriveError> {
    let key = at(file, &format!("[bounds] {name}"));
    if lo.is_nan() || hi.is_nan() || lo == f64::INFINITY || hi == f64::NEG_INFINITY || lo >= hi {
        return Err(DriveError::config(
            key,
            format!(
                "[{}, {}]; expected [lower, upper] with lower < upper (either may be -inf or inf)",
                hd_model::error::num(lo),
                hd_model::error::num(hi)
            ),
        ));
    }
    let below = if incl { lo < min } else { lo <= min };
    if min.is_finite() && below {
        return Err(DriveError::config(
            key,
            format!(
                "[{}, {}]; {name} ({what}) must stay {} [{unit}]: expected a lower bound {}",
                hd_model::error::num(lo),
                hd_model::error::num(hi),
                limit_text(min, incl),
                limit_text(min, incl)
            ),
        ));
    }
    Ok(())
}

/// The start `v` of `name` (from `source`) inside its bounds `[lo, hi]`.
pub fn inside(
    file: &str,
    name: &str,
    v: f64,
    lo: f64,
    hi: f64,
    source: &str,
) -> Result<(), DriveError> {
    if v >= lo && v <= hi {
        return Ok(());
    }
    Err(DriveError::config(
        at(file, &format!("[bounds] {name}")),
        format!(
            "[{}, {}] excludes the start {name} = {} ({source}); widen the bounds or start inside them",
            hd_model::error::num(lo),
            hd_model::error::num(hi),
            hd_model::error::num(v)
        ),
    ))
}

/// Checks that need the records: `h` the sample period [s], `rows` the shortest record's
/// length [samples].
pub fn with_records(c: &DriveConfig, file: &str, h: f64, rows: usize) -> Result<(), DriveError> {
    let (first, last) = (c.score.skip_first.unwrap_or(0), c.score.skip_last.unwrap_or(0));
    if first.saturating_add(last).saturating_add(MIN_SCORED) > rows {
        return Err(DriveError::config(
            at(file, "[score] skip_first, skip_last"),
            format!(
                "{first} and {last} samples; expected to leave at least {MIN_SCORED} of the shortest record's {rows} samples to score"
            ),
        ));
    }
    let nyquist = 0.5 / h;
    let s = &c.start;
    for (k, v) in [("cutoff_hz", s.cutoff_hz), ("decimate_cutoff_hz", s.decimate_cutoff_hz)] {
        if let Some(v) = v
            && v >= nyquist
        {
            return Err(DriveError::config(
                at(file, &format!("[start] {k}")),
                format!(
                    "{v} Hz; expected a corner below the records' Nyquist frequency {nyquist} Hz"
                ),
            ));
        }
    }
    if let Some(ctl) = &c.controller {
        let mut asked: Vec<usize> = ctl.delays.clone().unwrap_or_default();
        if let Some(DelayChoice::Samples(d)) = ctl.delay {
            asked.push(d);
        }
        let taps = ctl.speed_filter.as_ref().map_or(1, Vec::len);
        if let Some(d) = asked.into_iter().find(|&d| d + taps + 1 >= rows) {
            return Err(DriveError::config(
                at(file, "[controller] delay"),
                format!(
                    "{d} samples; expected fewer than the shortest record's {rows} samples (with this delay the loop would never act on it)"
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
#[path = "validate_tests.rs"]
mod tests;
