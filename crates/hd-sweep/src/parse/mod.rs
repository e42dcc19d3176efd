//! Reading and checking a study file completely before any run starts. Every error names
//! the file, the line and the key, and suggests the nearest valid name where one is close.
//!
//! One checker, split by section: this file (the study, base, parts), `input.rs`,
//! `axes.rs`, `sample.rs` and `compare.rs`.

mod axes;
mod compare;
mod input;
mod sample;

use crate::axis::Knob;
use crate::error::{Source, StudyError};
use crate::spec::*;
use crate::study::{Part, Study, TraceSettings};
use hd_model::params_file::apply_params_toml;
use hd_model::registry::nearest_of;
use hd_model::text_file::{MAX_SETTINGS_BYTES, read_text};
use hd_model::{FrictionVelocity, Input, Profile, SimConfig, Variant};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Loads a recorded input profile (the I/O layer provides it).
pub type ProfileLoader<'a> = &'a dyn Fn(&Path) -> Result<Profile, String>;

/// Read and check the study file at `path`.
pub fn load_study(path: &Path, loader: ProfileLoader) -> Result<Study, StudyError> {
    let file = path.display().to_string();
    let text = read_text(path, "study file", MAX_SETTINGS_BYTES).map_err(|message| StudyError {
        file: file.clone(),
        line: 1,
        key: "file".into(),
        message,
    })?;
    parse_study(&text, path, loader)
}

/// Check a study from its text; `path` locates relative files and names the file.
pub fn parse_study(text: &str, path: &Path, loader: ProfileLoader) -> Result<Study, StudyError> {
    let file = path.display().to_string();
    let src = Source { file: &file, text };
    let spec: StudySpec = toml::from_str(text).map_err(|e| toml_error(&src, &e))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    Checker { src, dir, loader }.study(spec, path)
}

/// Turn a TOML/serde error into a located error, with a suggestion for unknown keys.
fn toml_error(src: &Source, e: &toml::de::Error) -> StudyError {
    let pos = e.span().map_or(0, |s| s.start);
    let msg = e.message().to_string();
    let mut key = "toml".to_string();
    let mut message = format!("malformed study file: {msg}");
    if let Some(rest) = msg.strip_prefix("unknown field `")
        && let Some((name, tail)) = rest.split_once('`')
    {
        {
            key = name.to_string();
            let expected: Vec<&str> = tail.split('`').skip(1).step_by(2).collect();
            message = match nearest_of(name, expected.iter().copied()) {
                Some(s) => format!("unknown key '{name}' (did you mean '{s}'?)"),
                None => format!("unknown key '{name}': expected one of {}", expected.join(", ")),
            };
        }
    }
    src.error(pos, key, message)
}

struct Checker<'a> {
    src: Source<'a>,
    dir: PathBuf,
    loader: ProfileLoader<'a>,
}

impl Checker<'_> {
    fn err(&self, pos: usize, key: &str, message: impl Into<String>) -> StudyError {
        self.src.error(pos, key, message)
    }

    fn study(&self, spec: StudySpec, path: &Path) -> Result<Study, StudyError> {
        let name = spec.name.get_ref().trim().to_string();
        if name.is_empty() {
            return Err(self.err(
                spec.name.span().start,
                "name",
                "expected a non-empty study name",
            ));
        }
        // The name is the default output folder (out/<name>): it must stay one folder
        // inside out/.
        if name.contains(['/', '\\', '\0']) || name == "." || name == ".." {
            return Err(self.err(
                spec.name.span().start,
                "name",
                format!(
                    "'{name}' is not a folder name (it would write outside out/): use letters, digits, '-', '_' or '.', no '/'"
                ),
            ));
        }
        let mut base = SimConfig {
            solver: spec.solver,
            controller: spec.controller.clone(),
            ..SimConfig::default()
        };
        let base_cycles = spec.base.t_end_cycles.as_ref();
        base.metrics = spec.metrics.settings.resolve();
        self.apply_base(&spec.base, &mut base)?;
        if let Some(input) = &spec.input {
            base.input = self.input(input)?;
        }
        if let Some(dt) = spec.traces.dt_out {
            base.dt_out = dt;
        }
        let keep_metrics = self.keep_metrics(&spec.metrics)?;
        let traces = TraceSettings {
            keep: spec.traces.keep,
            decimate: spec.traces.decimate.unwrap_or(1).max(1),
        };

        let parts = if spec.part.is_empty() {
            vec![self.part_body(
                &name,
                base.clone(),
                &spec.axis,
                spec.sample.as_ref(),
                base_cycles,
                0,
            )?]
        } else {
            if let Some(a) = spec.axis.first() {
                return Err(self.err(a.span().start, "axis", "top-level axes cannot be combined with [[part]] sections: put the axes inside the parts"));
            }
            if let Some(s) = &spec.sample {
                return Err(self.err(
                    s.span().start,
                    "sample",
                    "a top-level [sample] cannot be combined with [[part]] sections",
                ));
            }
            let mut parts: Vec<Part> = Vec::new();
            for p in &spec.part {
                let pos = p.span().start;
                let p = p.get_ref();
                let pname = p.name.get_ref().trim().to_string();
                if pname.is_empty() || parts.iter().any(|q| q.name == pname) {
                    return Err(self.err(
                        p.name.span().start,
                        "part.name",
                        format!("part name '{pname}' must be non-empty and unique"),
                    ));
                }
                let mut cfg = base.clone();
                if let Some(v) = &p.variant {
                    cfg.variant = self.variant(v)?;
                }
                if let Some(v) = &p.stiffness {
                    cfg.stiffness = self.stiffness(v)?;
                }
                self.apply_set(&p.set, &mut cfg, "part.set")?;
                if let Some(i) = &p.input {
                    cfg.input = self.input(i)?;
                }
                if let Some(t) = &p.t_end {
                    cfg.t_end = *t.get_ref();
                }
                let cycles =
                    p.t_end_cycles.as_ref().or(if p.t_end.is_some() { None } else { base_cycles });
                parts.push(self.part_body(&pname, cfg, &p.axis, p.sample.as_ref(), cycles, pos)?);
            }
            parts
        };
        let study = Study {
            name,
            description: spec.description.trim().to_string(),
            file: path.to_path_buf(),
            parts,
            keep_metrics,
            traces,
            compare: Vec::new(),
        };
        let compare =
            spec.compare.iter().map(|c| self.compare(c, &study)).collect::<Result<_, _>>()?;
        Ok(Study { compare, ..study })
    }

    fn apply_base(&self, b: &BaseSpec, cfg: &mut SimConfig) -> Result<(), StudyError> {
        if let Some(v) = &b.variant {
            cfg.variant = self.variant(v)?;
        }
        if let Some(v) = &b.stiffness {
            cfg.stiffness = self.stiffness(v)?;
        }
        if let Some(f) = &b.params_file {
            let p = self.dir.join(f.get_ref());
            let text = read_text(&p, "params file", MAX_SETTINGS_BYTES)
                .map_err(|e| self.err(f.span().start, "base.params_file", e))?;
            apply_params_toml(&mut cfg.params, &text, &p.display().to_string())
                .map_err(|e| self.err(f.span().start, "base.params_file", e.to_string()))?;
        }
        self.apply_set(&b.set, cfg, "base.set")?;
        if let Some(t) = &b.t_end {
            cfg.t_end = *t.get_ref();
        }
        if let Some(fv) = &b.friction_velocity {
            cfg.friction_velocity = fv
                .get_ref()
                .parse::<FrictionVelocity>()
                .map_err(|e| self.err(fv.span().start, "base.friction_velocity", e))?;
        }
        Ok(())
    }

    fn apply_set(
        &self,
        set: &BTreeMap<Spanned<String>, Spanned<f64>>,
        cfg: &mut SimConfig,
        key: &str,
    ) -> Result<(), StudyError> {
        let mut seen: BTreeMap<&str, &str> = BTreeMap::new();
        for (k, v) in set {
            let at = k.span().start;
            let info = hd_model::registry::lookup(k.get_ref())
                .map_err(|e| self.err(at, &format!("{key}.{}", k.get_ref()), e.to_string()))?;
            if let Some(first) = seen.insert(info.name, k.get_ref()) {
                return Err(self.err(
                    at,
                    &format!("{key}.{}", k.get_ref()),
                    format!(
                        "'{}' and '{first}' are two names for one parameter ({}): keep one",
                        k.get_ref(),
                        info.name
                    ),
                ));
            }
            info.check(*v.get_ref())
                .map_err(|e| self.err(at, &format!("{key}.{}", info.name), e.to_string()))?;
            info.set_unchecked(&mut cfg.params, *v.get_ref());
        }
        Ok(())
    }

    fn stiffness(&self, v: &Spanned<String>) -> Result<hd_model::HystLaw, StudyError> {
        v.get_ref().parse().map_err(|e: String| self.err(v.span().start, "stiffness", e))
    }

    fn variant(&self, v: &Spanned<String>) -> Result<Variant, StudyError> {
        v.get_ref().parse().map_err(|e: String| self.err(v.span().start, "variant", e))
    }
    fn keep_metrics(&self, m: &MetricsSpec) -> Result<Vec<&'static str>, StudyError> {
        let all: Vec<&'static str> = hd_model::METRICS.iter().map(|m| m.name).collect();
        let Some(keep) = &m.keep else { return Ok(all) };
        let mut out = Vec::new();
        for k in keep {
            let name = k.get_ref();
            let found = all.iter().find(|n| **n == name.as_str()).ok_or_else(|| {
                let hint = nearest_of(name, all.iter().copied())
                    .map(|s| format!(" (did you mean '{s}'?)"))
                    .unwrap_or_default();
                self.err(k.span().start, "metrics.keep", format!("unknown metric '{name}'{hint}"))
            })?;
            out.push(*found);
        }
        if out.is_empty() {
            return Err(self.err(0, "metrics.keep", "expected at least one metric"));
        }
        Ok(out)
    }

    fn part_body(
        &self,
        name: &str,
        base: SimConfig,
        axes: &[Spanned<AxisSpec>],
        sample: Option<&Spanned<SampleSpec>>,
        cycles: Option<&Spanned<f64>>,
        pos: usize,
    ) -> Result<Part, StudyError> {
        base.validate().map_err(|e| self.err(pos, &format!("part '{name}'"), e.to_string()))?;
        let t_end_cycles = match cycles {
            None => None,
            Some(c) => {
                let n = *c.get_ref();
                if !(n.is_finite() && n > 0.0) {
                    return Err(self.err(
                        c.span().start,
                        "t_end_cycles",
                        format!("{n}: expected a number of cycles > 0"),
                    ));
                }
                if base.input.drive_frequency().is_none() {
                    return Err(self.err(
                        c.span().start,
                        "t_end_cycles",
                        "needs a sine input (a drive frequency)",
                    ));
                }
                Some(n)
            }
        };
        let axes = axes.iter().map(|a| self.axis(a, &base.input)).collect::<Result<Vec<_>, _>>()?;
        if base.controller.is_none()
            && let Some(a) = axes.iter().find(|a| a.knob.is_controller())
        {
            return Err(self.err(
                pos,
                "axis.name",
                format!("'{}' needs a [controller] table in the study file", a.knob.name()),
            ));
        }
        // Zipped axes must have equal lengths.
        for (k, a) in axes.iter().enumerate() {
            if let Some(z) = &a.zip
                && let Some(b) = axes[..k].iter().find(|b| b.zip.as_ref() == Some(z))
                && b.values.len() != a.values.len()
            {
                return Err(self.err(pos, "axis.zip", format!(
                    "zipped axes '{}' ({} values) and '{}' ({} values) must have the same length",
                    b.knob.name(), b.values.len(), a.knob.name(), a.values.len()
                )));
            }
        }
        let sample = match sample {
            None => None,
            Some(s) => {
                let checked = self.sample(s, &base.input)?;
                if checked.design.is_some()
                    && let Some(a) = axes.first()
                {
                    return Err(self.err(
                        s.span().start,
                        "sample.method",
                        format!(
                            "a {} design cannot be combined with grid axes in the same part \
                             (part '{name}' also sweeps '{}'): make one part per setting of \
                             the axes, each with the design",
                            checked.method.name(),
                            a.knob.name()
                        ),
                    ));
                }
                Some(checked)
            }
        };
        let mut seen: Vec<&str> = Vec::new();
        for n in axes
            .iter()
            .map(|a| a.knob.name())
            .chain(sample.iter().flat_map(|s| s.bounds.iter().map(|b| b.knob.name())))
        {
            if seen.contains(&n) {
                return Err(self.err(pos, n, format!("'{n}' is swept twice in part '{name}'")));
            }
            seen.push(n);
        }
        Ok(Part { name: name.to_string(), base, axes, sample, t_end_cycles })
    }

    fn knob(&self, name: &Spanned<String>, key: &str, input: &Input) -> Result<Knob, StudyError> {
        let at = name.span().start;
        let knob = Knob::from_name(name.get_ref()).map_err(|e| self.err(at, key, e))?;
        knob.applies_to(input).map_err(|e| self.err(at, key, e))?;
        Ok(knob)
    }
}
