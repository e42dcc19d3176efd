//! Parameter files: flat TOML tables of registry names and values, e.g.
//!
//! ```toml
//! c = 60000.0     # [N·m/rad]
//! sigma0 = 2e5    # [N·m/rad]
//! ```
//!
//! Every key must be a registry name and every value a number inside the registry's range;
//! errors name the file, the line and the key. Three keys are not numbers: `stiffness`, the
//! law the file is for (`stiffness = "maxwell-slip"`), `friction_velocity`, where the
//! friction acts (`friction_velocity = "load"`), and the `[controller]` table.

use crate::error::ParamError;
use crate::params::Params;
use crate::registry::lookup;
use std::collections::BTreeMap;
use toml::Spanned;

/// The key of the controller table in a params file.
pub const CONTROLLER_KEY: &str = "controller";
/// The key naming the stiffness law a params file is for (`stiffness = "catalogue"`).
pub const STIFFNESS_KEY: &str = "stiffness";
/// The key naming the speed the friction law sees (`friction_velocity = "load"`).
pub const FRICTION_VELOCITY_KEY: &str = "friction_velocity";

/// The friction speed a params file names with `friction_velocity = "…"`, if it names one.
pub fn friction_velocity_from_toml(
    text: &str,
    file: &str,
) -> Result<Option<crate::FrictionVelocity>, ParamError> {
    let table = spanned_table(text, file)?;
    let Some((key, value)) = table.iter().find(|(k, _)| k.get_ref() == FRICTION_VELOCITY_KEY)
    else {
        return Ok(None);
    };
    let at = |message: String| ParamError::File {
        file: file.to_string(),
        line: line_of(text, key.span().start),
        message: format!("{FRICTION_VELOCITY_KEY} = {message}"),
    };
    match value.get_ref() {
        toml::Value::String(name) => name.parse().map(Some).map_err(at),
        other => Err(at(format!("{other}: expected a name (motor, deflection, load)"))),
    }
}

/// The stiffness law a params file names with `stiffness = "…"`, if it names one.
pub fn stiffness_from_toml(text: &str, file: &str) -> Result<Option<crate::HystLaw>, ParamError> {
    let table = spanned_table(text, file)?;
    let Some((key, value)) = table.iter().find(|(k, _)| k.get_ref() == STIFFNESS_KEY) else {
        return Ok(None);
    };
    let at = |message: String| ParamError::File {
        file: file.to_string(),
        line: line_of(text, key.span().start),
        message,
    };
    match value.get_ref() {
        toml::Value::String(name) => name.parse().map(Some).map_err(at),
        other => Err(at(format!(
            "stiffness = {other}: expected a law name (memory, maxwell-slip, bouc-wen, catalogue)"
        ))),
    }
}

/// The `[controller]` table of a params file's text, if it has one (docs/model.md §6).
/// `file` names the source in error messages.
pub fn controller_from_toml(
    text: &str,
    file: &str,
) -> Result<Option<crate::control::ControllerConfig>, ParamError> {
    #[derive(serde::Deserialize)]
    struct WithController {
        controller: Option<crate::control::ControllerConfig>,
    }
    let parsed: WithController = toml::from_str(text).map_err(|e| ParamError::File {
        file: file.to_string(),
        line: e.span().map_or(1, |s| line_of(text, s.start)),
        message: format!("[controller]: {}", e.message()),
    })?;
    Ok(parsed.controller)
}

/// A params file's text as its top-level keys and values, with their positions for error
/// messages; `file` names the source.
fn spanned_table(
    text: &str,
    file: &str,
) -> Result<BTreeMap<Spanned<String>, Spanned<toml::Value>>, ParamError> {
    toml::from_str(text).map_err(|e| ParamError::File {
        file: file.to_string(),
        line: e.span().map_or(1, |s| line_of(text, s.start)),
        message: format!("malformed TOML: {}", e.message()),
    })
}

/// 1-based line number of byte offset `pos` in `text`.
pub fn line_of(text: &str, pos: usize) -> usize {
    text[..pos.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

/// Apply the assignments of a parameter file's text to `base`. `file` names the source in
/// error messages.
pub fn apply_params_toml(base: &mut Params, text: &str, file: &str) -> Result<(), ParamError> {
    let table = spanned_table(text, file)?;
    // Canonical name → the key that set it: `A` and `mem_A` in one file would leave one
    // of the two values silently unused.
    let mut seen: BTreeMap<&str, &str> = BTreeMap::new();
    for (key, value) in &table {
        if [CONTROLLER_KEY, STIFFNESS_KEY, FRICTION_VELOCITY_KEY].contains(&key.get_ref().as_str())
        {
            continue;
        }
        let at = |message: String| ParamError::File {
            file: file.to_string(),
            line: line_of(text, key.span().start),
            message,
        };
        let info = lookup(key.get_ref()).map_err(|e| at(e.to_string()))?;
        if let Some(first) = seen.insert(info.name, key.get_ref()) {
            return Err(at(format!(
                "'{}' and '{first}' are two names for one parameter ({}): keep one",
                key.get_ref(),
                info.name
            )));
        }
        let v = match value.get_ref() {
            toml::Value::Float(f) => *f,
            toml::Value::Integer(i) => *i as f64,
            other => {
                return Err(at(format!(
                    "parameter '{}' = {other}: expected a number [{}]",
                    info.name, info.unit
                )));
            }
        };
        info.check(v).map_err(|e| at(e.to_string()))?;
        info.set_unchecked(base, v);
    }
    Ok(())
}
