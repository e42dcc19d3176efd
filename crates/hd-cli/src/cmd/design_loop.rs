//! The loop of a closed-loop design: read from a closed-loop fit's fit.json (the controller
//! it fitted with, the delay it chose) or from the `[controller]` table of a TOML file (a
//! fit configuration's own, or a file holding only that table), with the command's noise
//! level (the fit's estimate, else what the encoder's rounding makes through the law).

use anyhow::{Context, Result, bail};
use hd_ident::design::{Loop, command_noise};
use hd_ident::drive::compliant::loop_config::LoopControllerConfig;
use hd_ident::drive::compliant::{Amplifier, Feedback};
use hd_ident::drive::config::{DelayChoice, NumberOrVariable};
use hd_ident::drive::controller::Controller;
use serde::Deserialize;
use serde_json::Value;
use std::path::Path;

/// A TOML file's `[controller]` (its other tables are not read).
#[derive(Deserialize)]
struct WithController {
    controller: Option<LoopControllerConfig>,
}

/// The loop of the `[controller]` in `path`, at sample period `h` [s]; the command's noise
/// is what encoder noise `motor` or `load` [rad] (the fed-back one) makes through the law.
pub fn from_file(path: &Path, h: f64, motor: f64, load: f64) -> Result<Loop> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read the controller file {}", path.display()))?;
    let file = path.display().to_string();
    let w: WithController =
        toml::from_str(&text).map_err(|e| anyhow::anyhow!("{file}: {}", e.message()))?;
    let Some(ctl) = w.controller else {
        bail!("{file}: no [controller] table; expected kp and kv (or p and d), feedback, amplifier")
    };
    let number = |v: Option<NumberOrVariable>, key: &str| -> Result<f64> {
        match v {
            Some(NumberOrVariable::Number(x)) => Ok(x),
            Some(NumberOrVariable::Variable(name)) => bail!(
                "{file}, [controller] {key}: '{name}' names a record's scalar; hdw design has no record, give the number"
            ),
            None => bail!(
                "{file}, [controller] {key}: missing; expected kp and kv (cascade) or p and d (PD)"
            ),
        }
    };
    let (kp, kv) = ctl.gains();
    let (kp, kv) = (number(kp, "kp")?, number(kv, "kv")?);
    let mut controller = ctl.controller(&file, kp, kv, h)?;
    controller.delay = match &ctl.delay {
        None => 0,
        Some(DelayChoice::Samples(d)) => *d,
        Some(DelayChoice::Auto(_)) => bail!(
            "{file}, [controller] delay: \"auto\" is chosen against a record's command; hdw design has none, give the delay in samples"
        ),
    };
    let (feedback, amplifier) = (ctl.feedback(&file)?, ctl.amplifier(&file)?);
    let sigma = if feedback == Feedback::Load { load } else { motor };
    let command_noise = command_noise(&controller, sigma);
    Ok(Loop { controller, feedback, amplifier, command_noise })
}

/// The loop of a closed-loop fit's fit.json `controller` (`file` for messages), at sample
/// period `h` [s], its command noise `noise` [V or A] (the fit's estimate).
pub fn from_fit_json(c: &Value, file: &str, h: f64, noise: f64) -> Result<Loop> {
    let num = |k: &str| -> Result<f64> {
        c[k].as_f64().with_context(|| format!("{file}: controller.{k} missing or not a number"))
    };
    let saturation = c["saturation"].as_f64().unwrap_or(f64::INFINITY);
    let speed_filter: Vec<f64> = match c["speed_filter"].as_array() {
        Some(a) => a.iter().filter_map(Value::as_f64).collect(),
        None => vec![1.0],
    };
    let controller = Controller {
        kp: num("kp")?,
        kv: num("kv")?,
        saturation,
        delay: c["delay"].as_u64().unwrap_or(0) as usize,
        speed_filter,
        h,
        open_loop: None,
    };
    let feedback = match c["feedback"].as_str() {
        None => Feedback::default(),
        Some(s) => Feedback::parse(s).with_context(|| {
            format!("{file}: controller.feedback '{s}' is neither \"motor\" nor \"load\"")
        })?,
    };
    let amplifier = match c["amplifier"].as_str() {
        None => Amplifier::default(),
        Some(s) => Amplifier::parse(s).with_context(|| {
            format!("{file}: controller.amplifier '{s}' is neither \"voltage\" nor \"current\"")
        })?,
    };
    if !(noise.is_finite() && noise > 0.0) {
        bail!("{file}: no positive command noise level for the loop's records");
    }
    Ok(Loop { controller, feedback, amplifier, command_noise: noise })
}
