//! A run's configuration from Python values: parameters from a dict of registry names,
//! the input from a dict mirroring a study file's `[input]` table, the controller from a
//! dict mirroring its `[controller]` table (read with the same serde rules as TOML).

use crate::errors::value_error;
use hd_model::laws::load::LoadTorque;
use hd_model::registry::{ParamInfo, lookup};
use hd_model::{
    ControllerConfig, FrictionVelocity, Input, Method, MetricSettings, Params, Profile, SimConfig,
    SolverOptions, Variant,
};
use numpy::PyArrayLike1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::str::FromStr;

/// The registry entry of a parameter name given from Python (`ValueError` naming it, with
/// the nearest valid name, when it is not a parameter).
pub fn param_info(name: &str) -> PyResult<&'static ParamInfo> {
    lookup(name).map_err(|e| value_error(e.to_string()))
}

/// Apply `{name: value}` to `p`. With `checked`, a value outside its range is a
/// `ValueError`; without, it is stored as given and the run that uses it fails (as a
/// sweep's point would).
pub fn apply_params(p: &mut Params, dict: &Bound<'_, PyDict>, checked: bool) -> PyResult<()> {
    for (k, v) in dict.iter() {
        let name: String = k
            .extract()
            .map_err(|_| value_error(format!("parameter names must be text, got {k}")))?;
        let info = param_info(&name)?;
        let value: f64 = v.extract().map_err(|_| {
            value_error(format!("parameter '{name}' = {v}: expected a number [{}]", info.unit))
        })?;
        if checked {
            info.check(value).map_err(|e| value_error(e.to_string()))?;
        }
        info.set_unchecked(p, value);
    }
    Ok(())
}

/// Keys of a dict, checked against `allowed`; `what` names the dict in errors.
fn check_keys(dict: &Bound<'_, PyDict>, allowed: &[&str], what: &str) -> PyResult<()> {
    for k in dict.keys() {
        let key: String =
            k.extract().map_err(|_| value_error(format!("{what}: keys must be text")))?;
        if !allowed.contains(&key.as_str()) {
            let hint = hd_model::registry::nearest_of(&key, allowed.iter().copied())
                .map(|s| format!(" (did you mean '{s}'?)"))
                .unwrap_or_default();
            return Err(value_error(format!(
                "{what}: unknown key '{key}'{hint}: expected one of {}",
                allowed.join(", ")
            )));
        }
    }
    Ok(())
}

fn get_f64(dict: &Bound<'_, PyDict>, key: &str, what: &str) -> PyResult<Option<f64>> {
    match dict.get_item(key)? {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => v
            .extract::<f64>()
            .map(Some)
            .map_err(|_| value_error(format!("{what}.{key} = {v}: expected a number"))),
    }
}

fn array(dict: &Bound<'_, PyDict>, key: &str, what: &str) -> PyResult<Vec<f64>> {
    let v = dict
        .get_item(key)?
        .ok_or_else(|| value_error(format!("{what}: a recorded input needs '{key}' (an array)")))?;
    let a: PyArrayLike1<f64> = v
        .extract()
        .map_err(|_| value_error(format!("{what}.{key}: expected a 1-D array of numbers")))?;
    Ok(a.as_array().to_vec())
}

/// The input of a run from a dict such as `{"kind": "sine", "voltage": 24, "freq": 50}`:
/// the keys of a study file's `[input]` table (kind, voltage, freq, t0, f0, f1, duration,
/// freqs, dwell), with `t` and `u` arrays for `kind = "recorded"`.
pub fn input_from_dict(dict: &Bound<'_, PyDict>) -> PyResult<Input> {
    const WHAT: &str = "input";
    let keys =
        ["kind", "voltage", "freq", "t0", "f0", "f1", "duration", "freqs", "dwell", "t", "u"];
    check_keys(dict, &keys, WHAT)?;
    let kind: String = match dict.get_item("kind")? {
        Some(k) => k.extract().map_err(|_| value_error("input.kind: expected text"))?,
        None => "sine".to_string(),
    };
    let voltage = get_f64(dict, "voltage", WHAT)?.unwrap_or(24.0);
    let need = |key: &str| {
        get_f64(dict, key, WHAT)?
            .ok_or_else(|| value_error(format!("input kind '{kind}' needs '{key}'")))
    };
    let input = match kind.as_str() {
        "sine" => {
            Input::Sine { amplitude: voltage, freq: get_f64(dict, "freq", WHAT)?.unwrap_or(50.0) }
        }
        "step" => Input::Step { amplitude: voltage, t0: get_f64(dict, "t0", WHAT)?.unwrap_or(0.0) },
        "constant" => Input::Constant { amplitude: voltage },
        "chirp" => Input::Chirp {
            amplitude: voltage,
            f0: need("f0")?,
            f1: need("f1")?,
            duration: need("duration")?,
        },
        "stepped_sine" => {
            let freqs = dict
                .get_item("freqs")?
                .ok_or_else(|| value_error("input kind 'stepped_sine' needs 'freqs'"))?;
            let freqs: PyArrayLike1<f64> = freqs
                .extract()
                .map_err(|_| value_error("input.freqs: expected a list of frequencies [Hz]"))?;
            Input::SteppedSine {
                amplitude: voltage,
                freqs: freqs.as_array().to_vec(),
                dwell: need("dwell")?,
            }
        }
        "recorded" => {
            let profile =
                Profile::new(array(dict, "t", WHAT)?, array(dict, "u", WHAT)?, "input (t, u)")
                    .map_err(|e| value_error(e.to_string()))?;
            Input::Recorded(profile)
        }
        other => {
            let kinds = ["sine", "step", "constant", "chirp", "stepped_sine", "recorded"];
            let hint = hd_model::registry::nearest_of(other, kinds.into_iter())
                .map(|s| format!(" (did you mean '{s}'?)"))
                .unwrap_or_default();
            return Err(value_error(format!(
                "input.kind = '{other}'{hint}: expected one of {}",
                kinds.join(", ")
            )));
        }
    };
    input.validate().map_err(|e| value_error(format!("input: {e}")))?;
    Ok(input)
}

/// The controller from its `[controller]` table, given as JSON text by the Python side.
pub fn controller_from_json(text: &str) -> PyResult<ControllerConfig> {
    serde_json::from_str(text).map_err(|e| value_error(format!("controller: {e}")))
}

fn text_option(dict: &Bound<'_, PyDict>, key: &str, default: &str) -> PyResult<String> {
    match dict.get_item(key)? {
        Some(v) if !v.is_none() => v
            .cast::<PyString>()
            .map_err(|_| value_error(format!("{key}: expected text")))
            .map(|s| s.to_string()),
        _ => Ok(default.to_string()),
    }
}

/// A run's configuration from the options dict the Python wrappers build (keys: variant,
/// stiffness,
/// input, t_end, rtol, atol, dt_out, method, friction_velocity, cycles, max_steps,
/// controller (JSON text), load_torque) and the parameters (checked).
pub fn config_from_options(
    opts: &Bound<'_, PyDict>,
    params: Option<&Bound<'_, PyDict>>,
    record_trace: bool,
) -> PyResult<SimConfig> {
    let keys = [
        "variant",
        "stiffness",
        "input",
        "t_end",
        "rtol",
        "atol",
        "dt_out",
        "method",
        "friction_velocity",
        "cycles",
        "max_steps",
        "controller",
        "load_torque",
    ];
    check_keys(opts, &keys, "options")?;
    let mut p = Params::default();
    if let Some(d) = params {
        apply_params(&mut p, d, true)?;
    }
    let variant_text = text_option(opts, "variant", "full")?;
    let variant = Variant::from_str(&variant_text).map_err(|_| {
        value_error(format!("variant = '{variant_text}': expected linear, damped or full"))
    })?;
    let stiffness_text = text_option(opts, "stiffness", "memory")?;
    let stiffness = hd_model::HystLaw::from_str(&stiffness_text).map_err(value_error)?;
    let input = match opts.get_item("input")? {
        Some(d) if !d.is_none() => {
            input_from_dict(d.cast::<PyDict>().map_err(|_| value_error("input: expected a dict"))?)?
        }
        _ => Input::default(),
    };
    let method = match text_option(opts, "method", "auto")?.as_str() {
        "auto" => Method::Auto,
        "dopri5" => Method::Dopri5,
        "dop853" => Method::Dop853,
        "rodas4" => Method::Rodas4,
        "imex" => Method::Imex,
        "imex5" => Method::Imex5,
        other => {
            return Err(value_error(format!(
                "method = '{other}': expected auto, dopri5, dop853, rodas4, imex or imex5"
            )));
        }
    };
    let friction_velocity = text_option(opts, "friction_velocity", "motor")?
        .parse::<FrictionVelocity>()
        .map_err(|e| value_error(format!("friction_velocity = {e}")))?;
    let defaults = SolverOptions::default();
    let cycles = match opts.get_item("cycles")? {
        Some(v) if !v.is_none() => v
            .extract::<usize>()
            .map_err(|_| value_error(format!("cycles = {v}: expected a whole number >= 1")))?,
        _ => MetricSettings::default().cycles,
    };
    let max_steps = match opts.get_item("max_steps")? {
        Some(v) if !v.is_none() => v
            .extract::<u64>()
            .map_err(|_| value_error(format!("max_steps = {v}: expected a whole number >= 1")))?,
        _ => defaults.max_steps,
    };
    let controller = match opts.get_item("controller")? {
        Some(v) if !v.is_none() => Some(controller_from_json(&v.extract::<String>()?)?),
        _ => None,
    };
    let load_torque = match get_f64(opts, "load_torque", "options")? {
        Some(tl) => LoadTorque::new(Input::Constant { amplitude: tl }),
        None => LoadTorque::default(),
    };
    let cfg = SimConfig {
        params: p,
        variant,
        stiffness,
        input,
        t_end: get_f64(opts, "t_end", "options")?.unwrap_or(0.2),
        dt_out: get_f64(opts, "dt_out", "options")?.unwrap_or(0.0),
        solver: SolverOptions {
            method,
            rtol: get_f64(opts, "rtol", "options")?.unwrap_or(defaults.rtol),
            atol: get_f64(opts, "atol", "options")?.unwrap_or(defaults.atol),
            max_steps,
            ..defaults
        },
        friction_velocity,
        metrics: MetricSettings { cycles, ..Default::default() },
        record_trace,
        load_torque,
        controller,
    };
    // Everything but the parameters is checked here; the parameters were checked above
    // (simulate) or are left to each run (batches, where a bad point is a failed row).
    let mut probe = cfg.clone();
    probe.params = Params::default();
    probe.validate().map_err(|e| value_error(e.to_string()))?;
    Ok(cfg)
}
