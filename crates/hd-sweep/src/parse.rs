//! Reading and checking a study file completely before any run starts. Every error names
//! the file, the line and the key, and suggests the nearest valid name where one is close.

use crate::axis::{Knob, Value, linspace, logspace};
use crate::design::{Axis, Bound, Sample, SampleMethod};
use crate::error::{Source, StudyError};
use crate::sensitivity::{morris_design, saltelli_design};
use crate::spec::*;
use crate::study::{Part, Study, TraceSettings};
use hd_model::params_file::apply_params_toml;
use hd_model::registry::nearest_of;
use hd_model::{FrictionVelocity, Input, Metrics, Profile, SimConfig, Variant};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Loads a recorded input profile (the I/O layer provides it).
pub type ProfileLoader<'a> = &'a dyn Fn(&Path) -> Result<Profile, String>;

/// Read and check the study file at `path`.
pub fn load_study(path: &Path, loader: ProfileLoader) -> Result<Study, StudyError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| StudyError {
        file: file.clone(),
        line: 1,
        key: "file".into(),
        message: format!("cannot read: {e}"),
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
        let mut base = SimConfig { solver: spec.solver, ..SimConfig::default() };
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
        if let Some(f) = &b.params_file {
            let p = self.dir.join(f.get_ref());
            let text = std::fs::read_to_string(&p).map_err(|e| {
                self.err(
                    f.span().start,
                    "base.params_file",
                    format!("cannot read {}: {e}", p.display()),
                )
            })?;
            apply_params_toml(&mut cfg.params, &text, &p.display().to_string())
                .map_err(|e| self.err(f.span().start, "base.params_file", e.to_string()))?;
        }
        self.apply_set(&b.set, cfg, "base.set")?;
        if let Some(t) = &b.t_end {
            cfg.t_end = *t.get_ref();
        }
        if let Some(fv) = &b.friction_velocity {
            cfg.friction_velocity = match fv.get_ref().as_str() {
                "motor" => FrictionVelocity::Motor,
                "deflection" => FrictionVelocity::Deflection,
                other => {
                    return Err(self.err(
                        fv.span().start,
                        "base.friction_velocity",
                        format!("'{other}': expected motor or deflection"),
                    ));
                }
            };
        }
        Ok(())
    }

    fn apply_set(
        &self,
        set: &BTreeMap<Spanned<String>, Spanned<f64>>,
        cfg: &mut SimConfig,
        key: &str,
    ) -> Result<(), StudyError> {
        for (k, v) in set {
            let at = k.span().start;
            let info = hd_model::registry::lookup(k.get_ref())
                .map_err(|e| self.err(at, &format!("{key}.{}", k.get_ref()), e.to_string()))?;
            info.check(*v.get_ref())
                .map_err(|e| self.err(at, &format!("{key}.{}", info.name), e.to_string()))?;
            info.set_unchecked(&mut cfg.params, *v.get_ref());
        }
        Ok(())
    }

    fn variant(&self, v: &Spanned<String>) -> Result<Variant, StudyError> {
        v.get_ref().parse().map_err(|e: String| self.err(v.span().start, "variant", e))
    }

    fn input(&self, s: &Spanned<InputSpec>) -> Result<Input, StudyError> {
        let at = s.span().start;
        let i = s.get_ref();
        let voltage = i.voltage.unwrap_or(24.0);
        let need = |v: Option<f64>, field: &str| {
            v.ok_or_else(|| {
                self.err(
                    at,
                    &format!("input.{field}"),
                    format!("input kind '{}' needs '{field}'", i.kind.get_ref()),
                )
            })
        };
        let input = match i.kind.get_ref().as_str() {
            "sine" => Input::Sine { amplitude: voltage, freq: i.freq.unwrap_or(50.0) },
            "step" => Input::Step { amplitude: voltage, t0: i.t0.unwrap_or(0.0) },
            "constant" => Input::Constant { amplitude: voltage },
            "chirp" => Input::Chirp {
                amplitude: voltage,
                f0: need(i.f0, "f0")?,
                f1: need(i.f1, "f1")?,
                duration: need(i.duration, "duration")?,
            },
            "stepped_sine" => Input::SteppedSine {
                amplitude: voltage,
                freqs: i
                    .freqs
                    .clone()
                    .ok_or_else(|| self.err(at, "input.freqs", "stepped_sine needs 'freqs'"))?,
                dwell: need(i.dwell, "dwell")?,
            },
            "recorded" => {
                let f = i
                    .file
                    .as_ref()
                    .ok_or_else(|| self.err(at, "input.file", "recorded input needs 'file'"))?;
                let p = self.dir.join(f);
                Input::Recorded((self.loader)(&p).map_err(|e| self.err(at, "input.file", e))?)
            }
            other => {
                let kinds = ["sine", "step", "constant", "chirp", "stepped_sine", "recorded"];
                let hint = nearest_of(other, kinds.into_iter())
                    .map(|s| format!(" (did you mean '{s}'?)"))
                    .unwrap_or_default();
                return Err(self.err(
                    i.kind.span().start,
                    "input.kind",
                    format!(
                        "unknown input kind '{other}'{hint}: expected one of {}",
                        kinds.join(", ")
                    ),
                ));
            }
        };
        input.validate().map_err(|e| self.err(at, "input", e.to_string()))?;
        Ok(input)
    }

    fn keep_metrics(&self, m: &MetricsSpec) -> Result<Vec<&'static str>, StudyError> {
        let all: Vec<&'static str> = Metrics::UNITS.iter().map(|(n, _)| *n).collect();
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

    fn axis(&self, s: &Spanned<AxisSpec>, input: &Input) -> Result<Axis, StudyError> {
        let a = s.get_ref();
        let at = a.name.span().start;
        let key = format!("axis '{}'", a.name.get_ref());
        let knob = self.knob(&a.name, "axis.name", input)?;
        let given = [a.values.is_some(), a.linspace.is_some(), a.logspace.is_some()]
            .iter()
            .filter(|b| **b)
            .count();
        if given != 1 {
            return Err(self.err(at, &key, "expected exactly one of values, linspace, logspace"));
        }
        let values: Vec<Value> = if let Some(vals) = &a.values {
            vals.iter().map(|v| self.value(knob, v, at, &key)).collect::<Result<_, _>>()?
        } else {
            let (r, log) = a
                .linspace
                .map(|r| (r, false))
                .or(a.logspace.map(|r| (r, true)))
                .expect("one range");
            if log && !(r.start > 0.0 && r.stop > 0.0) {
                return Err(self.err(
                    at,
                    &key,
                    format!(
                        "logspace needs start > 0 and stop > 0, got {} and {}",
                        r.start, r.stop
                    ),
                ));
            }
            let xs = if log {
                logspace(r.start, r.stop, r.num)
            } else {
                linspace(r.start, r.stop, r.num)
            };
            xs.into_iter()
                .map(|x| knob.check(x).map(|_| Value::Num(x)).map_err(|e| self.err(at, &key, e)))
                .collect::<Result<_, _>>()?
        };
        if values.is_empty() {
            return Err(self.err(at, &key, "empty axis: expected at least one value"));
        }
        Ok(Axis { knob, values, zip: a.zip.clone() })
    }

    fn value(
        &self,
        knob: Knob,
        v: &toml::Value,
        at: usize,
        key: &str,
    ) -> Result<Value, StudyError> {
        match (knob, v) {
            (Knob::Variant, toml::Value::String(s)) => {
                s.parse().map(Value::Variant).map_err(|e: String| self.err(at, key, e))
            }
            (Knob::Variant, other) => Err(self.err(
                at,
                key,
                format!("{other}: expected a variant name (linear, damped, full)"),
            )),
            (_, toml::Value::Float(x)) => {
                knob.check(*x).map(|_| Value::Num(*x)).map_err(|e| self.err(at, key, e))
            }
            (_, toml::Value::Integer(i)) => knob
                .check(*i as f64)
                .map(|_| Value::Num(*i as f64))
                .map_err(|e| self.err(at, key, e)),
            (_, other) => Err(self.err(at, key, format!("{other}: expected a number"))),
        }
    }

    fn sample(&self, s: &Spanned<SampleSpec>, input: &Input) -> Result<Sample, StudyError> {
        let at = s.span().start;
        let sp = s.get_ref();
        let methods = ["lhs", "random", "sobol", "morris"];
        let method = match sp.method.get_ref().as_str() {
            "lhs" => SampleMethod::Lhs,
            "random" => SampleMethod::Random,
            "sobol" => SampleMethod::Sobol,
            "morris" => SampleMethod::Morris,
            other => {
                let hint = nearest_of(other, methods.into_iter())
                    .map(|m| format!(" (did you mean '{m}'?)"))
                    .unwrap_or_default();
                return Err(self.err(
                    sp.method.span().start,
                    "sample.method",
                    format!(
                        "unknown sampling method '{other}'{hint}: expected {}",
                        methods.join(", ")
                    ),
                ));
            }
        };
        let n = self.sample_count(sp, method, at)?;
        if sp.param.is_empty() {
            return Err(self.err(at, "sample.param", "expected at least one [[sample.param]]"));
        }
        let bounds =
            sp.param.iter().map(|b| self.bound(b, input)).collect::<Result<Vec<_>, _>>()?;
        let seed = sp.seed.as_ref().map(|s| *s.get_ref());
        let design = match method {
            SampleMethod::Lhs | SampleMethod::Random => None,
            SampleMethod::Sobol => Some(saltelli_design(bounds.len(), n, seed)),
            SampleMethod::Morris => {
                let levels = sp.levels.as_ref().map_or(4, |l| *l.get_ref());
                Some(morris_design(bounds.len(), n, levels, seed.unwrap_or(0)))
            }
        };
        let design = design
            .transpose()
            .map_err(|e| self.err(at, &format!("sample ({})", method.name()), e.to_string()))?;
        Ok(Sample { method, n, seed, bounds, design })
    }

    /// The count of a sample: `n` (lhs, random, sobol) or `trajectories` (morris); fields
    /// that do not apply to the method are errors, so a typo cannot pass silently.
    fn sample_count(
        &self,
        sp: &SampleSpec,
        method: SampleMethod,
        at: usize,
    ) -> Result<usize, StudyError> {
        let m = method.name();
        let (wanted, stray) = match method {
            SampleMethod::Morris => (&sp.trajectories, [("n", &sp.n), ("levels", &None)]),
            _ => (&sp.n, [("trajectories", &sp.trajectories), ("levels", &sp.levels)]),
        };
        if let Some((field, v)) = stray.iter().find_map(|(f, v)| v.as_ref().map(|v| (f, v))) {
            let instead = match method {
                SampleMethod::Morris => "trajectories",
                _ => "n",
            };
            return Err(self.err(
                v.span().start,
                &format!("sample.{field}"),
                format!("'{field}' does not apply to method '{m}' (it takes '{instead}')"),
            ));
        }
        let field = if method == SampleMethod::Morris { "trajectories" } else { "n" };
        let Some(count) = wanted else {
            return Err(self.err(
                at,
                &format!("sample.{field}"),
                format!("method '{m}' needs '{field}'"),
            ));
        };
        if *count.get_ref() == 0 {
            return Err(self.err(
                count.span().start,
                &format!("sample.{field}"),
                "expected at least 1",
            ));
        }
        Ok(*count.get_ref())
    }

    /// One `[[sample.param]]`: a known, sampleable name and bounds inside its valid range.
    fn bound(&self, b: &Spanned<BoundSpec>, input: &Input) -> Result<Bound, StudyError> {
        let bp = b.get_ref();
        let key = format!("sample.param '{}'", bp.name.get_ref());
        let knob = self.knob(&bp.name, "sample.param.name", input)?;
        if matches!(knob, Knob::Variant) {
            return Err(self.err(
                bp.name.span().start,
                &key,
                "variant cannot be sampled; use an axis",
            ));
        }
        let (lo, hi) = (*bp.lo.get_ref(), *bp.hi.get_ref());
        knob.check(lo).map_err(|e| self.err(bp.lo.span().start, &key, format!("lo: {e}")))?;
        knob.check(hi).map_err(|e| self.err(bp.hi.span().start, &key, format!("hi: {e}")))?;
        if lo >= hi {
            return Err(self.err(
                bp.lo.span().start,
                &key,
                format!("expected lo < hi, got lo = {lo}, hi = {hi}"),
            ));
        }
        if bp.log && lo <= 0.0 {
            return Err(self.err(bp.lo.span().start, &key, "log sampling needs lo > 0"));
        }
        Ok(Bound { knob, lo, hi, log: bp.log })
    }

    fn compare(&self, c: &Spanned<CompareSpec>, study: &Study) -> Result<CompareSpec, StudyError> {
        let at = c.span().start;
        let spec = c.get_ref().clone();
        let part = study.parts.iter().find(|p| p.name == spec.part).ok_or_else(|| {
            self.err(at, "compare.part", format!("no part named '{}'", spec.part))
        })?;
        if !part.swept_names().contains(&spec.axis.as_str()) {
            return Err(self.err(
                at,
                "compare.axis",
                format!("part '{}' does not sweep '{}'", spec.part, spec.axis),
            ));
        }
        let sweeps_variant = part.axes.iter().any(|a| matches!(a.knob, Knob::Variant));
        match &spec.variant {
            None if sweeps_variant => {
                return Err(self.err(
                    at,
                    "compare.variant",
                    format!("part '{}' sweeps variants: say which one to compare", spec.part),
                ));
            }
            Some(v) => {
                v.parse::<Variant>().map_err(|e| self.err(at, "compare.variant", e))?;
            }
            None => {}
        }
        if !study.keep_metrics.contains(&spec.metric.as_str()) {
            return Err(self.err(
                at,
                "compare.metric",
                format!("metric '{}' is not kept by this study", spec.metric),
            ));
        }
        if !["increase", "decrease"].contains(&spec.direction.as_str()) {
            return Err(self.err(
                at,
                "compare.direction",
                format!("'{}': expected increase or decrease", spec.direction),
            ));
        }
        if !["up", "down", "flat", "up_or_flat", "down_or_flat"].contains(&spec.expect.as_str()) {
            return Err(self.err(
                at,
                "compare.expect",
                format!("'{}': expected up, down, flat, up_or_flat or down_or_flat", spec.expect),
            ));
        }
        Ok(spec)
    }
}
