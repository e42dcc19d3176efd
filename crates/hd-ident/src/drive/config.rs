//! The fit configuration (`fit.toml`) of `hdw fit drive`, as written by a user; the format is
//! documented in docs/fit-drive.md. Unknown keys are errors (a misspelt key would otherwise
//! be silently ignored); every check names the file and the key.

use super::error::DriveError;
use super::fit::OutputKind;
use super::idim::IdimOptions;
use super::model::{Axis, FrictionLaw};
use serde::Deserialize;
use std::collections::BTreeMap;

#[path = "validate.rs"]
pub mod validate;
#[path = "validate_compliant.rs"]
pub mod validate_compliant;

/// A number, or the name of a scalar variable (column of length 1) of the first
/// experiment's file, e.g. `kp = "kp"` in a MAT file that stores its gains.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum NumberOrVariable {
    /// A literal value.
    Number(f64),
    /// The name of a scalar in the record.
    Variable(String),
}

/// The computation delay: a number of samples, or `"auto"` (the one among `delays` whose
/// controller best reproduces the recorded command).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum DelayChoice {
    /// A fixed delay [samples].
    Samples(usize),
    /// `"auto"`.
    Auto(String),
}

/// One recorded experiment: its file and the column (or MAT variable) of each signal.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentConfig {
    /// Name in reports.
    pub name: String,
    /// CSV, Parquet or MAT v5 file, relative to the configuration file.
    pub file: String,
    /// Time column [s].
    pub time: String,
    /// Measured position column.
    pub position: String,
    /// Controller reference column (closed loop only).
    pub reference: Option<String>,
    /// Recorded command (controller output) column.
    pub command: String,
    /// Optional column added to the controller's output (zeros where the file lacks it).
    pub disturbance: Option<String>,
    /// Factor to the axis unit of position and reference (e.g. 1e-3 for mm → m); default 1.
    #[serde(default = "one")]
    pub position_scale: f64,
    /// Factor applied to the command and the disturbance; default 1.
    #[serde(default = "one")]
    pub command_scale: f64,
}

fn one() -> f64 {
    1.0
}

/// `[controller]`: the discrete cascade P–P position controller of the logged loop.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerConfig {
    /// Position-loop gain [1/s].
    pub kp: NumberOrVariable,
    /// Speed-loop gain [command unit per (m/s)].
    pub kv: NumberOrVariable,
    /// Output limit [command unit]; none when absent.
    pub saturation: Option<f64>,
    /// Computation delay: samples or "auto"; default "auto".
    pub delay: Option<DelayChoice>,
    /// Delays compared by the reproduction check; default [0, 1].
    pub delays: Option<Vec<usize>>,
    /// FIR coefficients of the position filter before the speed difference; default [1].
    pub speed_filter: Option<Vec<f64>>,
}

/// `[start]`: where the fit starts.
#[derive(Clone, Debug, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct StartConfig {
    /// `"idim"` (inverse model, default) or `"values"` (the `[params]` table only).
    pub method: Option<String>,
    /// Position filter corner [Hz].
    pub cutoff_hz: Option<f64>,
    /// Butterworth order.
    pub order: Option<usize>,
    /// Decimation factor.
    pub decimate: Option<usize>,
    /// Parallel filter corner [Hz].
    pub decimate_cutoff_hz: Option<f64>,
}

/// `[fit]`: outputs, noise levels, fixed parameters, optimiser budget.
#[derive(Clone, Debug, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct FitConfig {
    /// Outputs compared: `force`, `position`; default both.
    pub outputs: Option<Vec<String>>,
    /// Noise level per output [its unit]; estimated from the record where absent.
    #[serde(default)]
    pub noise: BTreeMap<String, f64>,
    /// Parameters held at their start values; default ["gain"].
    pub fix: Option<Vec<String>>,
    /// Iteration budget; default 100.
    pub max_iterations: Option<usize>,
    /// Open loop only: length of the multiple-shooting segments [s]; default 0.2.
    pub segment: Option<f64>,
}

/// The whole configuration.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveConfig {
    /// `rigid` (default; `compliant` configurations have their own format,
    /// [`super::compliant::CompliantConfig`]).
    pub transmission: Option<String>,
    /// `linear` (default) or `rotary`.
    pub axis: Option<String>,
    /// `coulomb-viscous` (default), `directional`, `lugre`, `directional-lugre` or `all`.
    pub friction: Option<String>,
    /// Force (or torque) per unit command [N/V or N·m/V].
    pub gain: NumberOrVariable,
    /// The experiments fitted jointly.
    pub experiment: Vec<ExperimentConfig>,
    /// The controller; absent for an open-loop record (the recorded command drives the
    /// model, fitted by multiple shooting).
    pub controller: Option<ControllerConfig>,
    /// The start.
    #[serde(default)]
    pub start: StartConfig,
    /// The fit.
    #[serde(default)]
    pub fit: FitConfig,
    /// Start values by parameter name (override the inverse-model start).
    #[serde(default)]
    pub params: BTreeMap<String, f64>,
    /// Bounds `[lower, upper]` by parameter name.
    #[serde(default)]
    pub bounds: BTreeMap<String, [f64; 2]>,
    /// `[score]`: the samples the scores count ([`super::score_rule`]).
    #[serde(default)]
    pub score: super::score_rule::ScoreConfig,
}

/// The `transmission` key of a configuration's text, if it parses and has one.
pub fn transmission_of(text: &str) -> Option<String> {
    let t: toml::Table = toml::from_str(text).ok()?;
    t.get("transmission")?.as_str().map(String::from)
}

/// A TOML or serde error of `file` on one line.
pub fn toml_error(file: &str, e: &toml::de::Error) -> DriveError {
    let text = e.to_string();
    let lines: Vec<&str> = text.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    // toml's message: "TOML parse error at line L, column C", the quoted line ("L | text"),
    // a caret, then what is wrong; keep the position, what is wrong and, where that does
    // not name the key (e.g. "duplicate key"), the line itself.
    let quoted = lines.iter().find_map(|l| {
        let (number, rest) = l.split_once('|')?;
        let text = rest.trim();
        (number.trim().parse::<usize>().is_ok() && !text.is_empty()).then_some(text)
    });
    let message = match (lines.first(), lines.last()) {
        (Some(first), Some(last)) if lines.len() > 1 && first.starts_with("TOML parse error") => {
            let at = first.trim_start_matches("TOML parse error at ").trim();
            match quoted {
                Some(q) if !last.contains('`') && !last.contains('\'') => {
                    format!("{at}: {last} (the line reads `{q}`)")
                }
                _ => format!("{at}: {last}"),
            }
        }
        _ => lines.join(" "),
    };
    DriveError::config(file, message)
}

/// Default length of an open-loop record's multiple-shooting segments [s].
pub const DEFAULT_SEGMENT: f64 = 0.2;

/// Parsed and checked pieces of a configuration.
impl DriveConfig {
    /// Parse `text` of file `file`.
    pub fn parse(text: &str, file: &str) -> Result<DriveConfig, DriveError> {
        let table: toml::Table = toml::from_str(text).map_err(|e| toml_error(file, &e))?;
        validate::raw(&table, file)?;
        let c: DriveConfig = toml::from_str(text).map_err(|e| toml_error(file, &e))?;
        c.check(file)?;
        validate::rigid(&c, file, &c.laws(file)?, c.axis(file)?)?;
        Ok(c)
    }

    fn check(&self, file: &str) -> Result<(), DriveError> {
        let at = |k: &str| format!("{file}, {k}");
        if let Some(t) = &self.transmission
            && t != "rigid"
        {
            return Err(DriveError::config(
                at("transmission"),
                format!("'{t}'; expected \"rigid\" or \"compliant\""),
            ));
        }
        self.axis(file)?;
        self.score.check(file)?;
        self.laws(file)?;
        self.outputs(file)?;
        if self.experiment.is_empty() {
            return Err(DriveError::config(file, "no [[experiment]]; expected at least one"));
        }
        for law in self.laws(file)? {
            let names = law.names();
            for key in self.params.keys().chain(self.bounds.keys()).chain(self.fix().iter()) {
                let known = FrictionLaw::ALL.iter().any(|l| l.names().contains(&key.as_str()));
                if !known {
                    return Err(DriveError::config(
                        at(&format!("parameter '{key}'")),
                        format!("unknown parameter; expected one of {}", all_names().join(", ")),
                    ));
                }
                let _ = names;
            }
        }
        for (k, [lo, hi]) in &self.bounds {
            if lo.partial_cmp(hi) != Some(std::cmp::Ordering::Less) {
                return Err(DriveError::config(
                    at(&format!("[bounds] {k}")),
                    format!("[{lo}, {hi}]; expected lower < upper"),
                ));
            }
        }
        for (k, v) in &self.fit.noise {
            if OutputKind::parse(k).is_none() || !(*v > 0.0 && v.is_finite()) {
                return Err(DriveError::config(
                    at(&format!("[fit] noise.{k}")),
                    "expected a positive noise level for `force` or `position`",
                ));
            }
        }
        match &self.controller {
            Some(_) => {
                if let Some(e) = self.experiment.iter().find(|e| e.reference.is_none()) {
                    return Err(DriveError::config(
                        at(&format!("[[experiment]] '{}' reference", e.name)),
                        "missing; a closed-loop record needs the controller's reference column",
                    ));
                }
                if self.fit.segment.is_some() {
                    return Err(DriveError::config(
                        at("[fit] segment"),
                        "multiple shooting is for open-loop records; this one has a [controller]",
                    ));
                }
            }
            None => {
                if self.outputs(file)?.contains(&OutputKind::Force) {
                    return Err(DriveError::config(
                        at("[fit] outputs"),
                        "'force' in an open-loop record (no [controller]): the force is the recorded command itself; compare `position`",
                    ));
                }
                if let Some(seg) = self.fit.segment
                    && !(seg.is_finite() && seg > 0.0)
                {
                    return Err(DriveError::config(
                        at("[fit] segment"),
                        format!("{seg}; expected a segment length > 0 [s]"),
                    ));
                }
            }
        }
        if let Some(DelayChoice::Auto(s)) = self.controller.as_ref().and_then(|c| c.delay.as_ref())
            && s != "auto"
        {
            return Err(DriveError::config(
                at("[controller] delay"),
                format!("'{s}'; expected a number of samples or \"auto\""),
            ));
        }
        if let Some(m) = &self.start.method
            && m != "idim"
            && m != "values"
        {
            return Err(DriveError::config(
                at("[start] method"),
                format!("'{m}'; expected \"idim\" or \"values\""),
            ));
        }
        Ok(())
    }

    /// The axis.
    pub fn axis(&self, file: &str) -> Result<Axis, DriveError> {
        let s = self.axis.as_deref().unwrap_or("linear");
        Axis::parse(s).ok_or_else(|| {
            DriveError::config(
                format!("{file}, axis"),
                format!("'{s}'; expected \"linear\" or \"rotary\""),
            )
        })
    }

    /// The friction laws to fit.
    pub fn laws(&self, file: &str) -> Result<Vec<FrictionLaw>, DriveError> {
        let s = self.friction.as_deref().unwrap_or("coulomb-viscous");
        if s == "all" {
            return Ok(FrictionLaw::ALL.to_vec());
        }
        FrictionLaw::parse(s).map(|l| vec![l]).ok_or_else(|| {
            DriveError::config(
                format!("{file}, friction"),
                format!(
                    "'{s}'; expected \"coulomb-viscous\", \"directional\", \"lugre\", \"directional-lugre\" or \"all\""
                ),
            )
        })
    }

    /// The outputs compared.
    pub fn outputs(&self, file: &str) -> Result<Vec<OutputKind>, DriveError> {
        let default: Vec<String> = if self.controller.is_some() {
            vec!["force".into(), "position".into()]
        } else {
            vec!["position".into()]
        };
        let names = self.fit.outputs.clone().unwrap_or(default);
        if names.is_empty() {
            return Err(DriveError::config(
                format!("{file}, [fit] outputs"),
                "empty; expected force and/or position",
            ));
        }
        names
            .iter()
            .map(|n| {
                OutputKind::parse(n).ok_or_else(|| {
                    DriveError::config(
                        format!("{file}, [fit] outputs"),
                        format!("'{n}'; expected \"force\" or \"position\""),
                    )
                })
            })
            .collect()
    }

    /// Open loop: samples per multiple-shooting segment at sample period `h` [s] (at least
    /// 2); None in closed loop.
    pub fn segment_samples(&self, h: f64) -> Option<usize> {
        if self.controller.is_some() {
            return None;
        }
        Some(((self.fit.segment.unwrap_or(DEFAULT_SEGMENT) / h).round() as usize).max(2))
    }

    /// Names of the fixed parameters.
    pub fn fix(&self) -> Vec<String> {
        self.fit.fix.clone().unwrap_or_else(|| vec!["gain".into()])
    }

    /// The inverse-model options.
    pub fn idim(&self) -> IdimOptions {
        let d = IdimOptions::default();
        IdimOptions {
            cutoff_hz: self.start.cutoff_hz.unwrap_or(d.cutoff_hz),
            order: self.start.order.unwrap_or(d.order),
            decimate: self.start.decimate.unwrap_or(d.decimate),
            decimate_cutoff_hz: self.start.decimate_cutoff_hz.unwrap_or(d.decimate_cutoff_hz),
        }
    }
}

/// Every parameter name of every law.
pub fn all_names() -> Vec<&'static str> {
    let mut v: Vec<&'static str> = Vec::new();
    for l in FrictionLaw::ALL {
        for n in l.names() {
            if !v.contains(n) {
                v.push(n);
            }
        }
    }
    v
}
