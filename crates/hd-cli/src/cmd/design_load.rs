//! What `hdw design` starts from: a compliant fit's output folder (its params.toml, its
//! fit.json's free parameters and noise levels, and its records re-read through its
//! configuration for the prior information), or a params file with named unknowns.

use anyhow::{Context, Result, bail};
use hd_ident::design::prior_information;
use hd_ident::design::{Limits, Noise, Problem};
use hd_ident::drive::compliant::config::CompliantConfig;
use hd_ident::drive::compliant::fit::CompliantSpec;
use hd_ident::drive::compliant::model::{P, on_law};
use hd_ident::drive::compliant::{Between, NAMES, Signal, VoltageRecord, substeps_for};
use hd_ident::lm::LmOptions;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// What was loaded: the problem, the records already fitted (for the refit check) and the
/// params file of the drive.
pub struct Loaded {
    /// The design problem.
    pub problem: Problem,
    /// The records the fit used (empty from a params file).
    pub records: Vec<VoltageRecord>,
    /// The drive's params file (what the check synthesises from unless told otherwise).
    pub params_file: PathBuf,
    /// The fit's reported values and SEs ([`NAMES`] order), if from a fit.
    pub fitted_se: Option<[Option<f64>; P]>,
}

/// A params file read as the compliant fit reads one: values in [`NAMES`] order with the
/// other gear laws' constants zero, the gear ratio, and whether negative-side friction
/// levels are set.
pub fn read_params(path: &Path) -> Result<([f64; P], f64, bool)> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read params file {}", path.display()))?;
    let name = path.display().to_string();
    let mut p = hd_model::Params::default();
    hd_model::params_file::apply_params_toml(&mut p, &text, &name)?;
    let law = hd_model::params_file::stiffness_from_toml(&text, &name)?;
    if let Some(why) = hd_ident::drive::compliant::supported::unsupported(&p, law).first() {
        bail!("{name}: {why}");
    }
    let mut v = [0.0; P];
    for (k, n) in NAMES.iter().enumerate() {
        v[k] = p.get(n)?;
    }
    on_law(&mut v, law.unwrap_or(hd_model::HystLaw::Memory));
    Ok((v, p.n, p.tc_neg.is_some() || p.ts_neg.is_some()))
}

/// The spec of the fit's settings (noise levels set per record by the caller).
fn spec_for(
    values: [f64; P],
    n: f64,
    free: [bool; P],
    between: Between,
    substeps: usize,
    directional: bool,
) -> CompliantSpec {
    CompliantSpec {
        n,
        between,
        start: values,
        free,
        lower: values.map(|v| v / 1e3),
        upper: values.map(|v| v * 1e3),
        outputs: Vec::new(),
        noise_estimated: Vec::new(),
        km_is_ke: true,
        symmetric_friction: !directional,
        symmetric_load_friction: true,
        current_offset: true,
        friction_velocity: hd_model::FrictionVelocity::Motor,
        substeps,
        settings: LmOptions {
            max_iterations: 300,
            cost_tolerance: 1e-8,
            geodesic: true,
            ..LmOptions::drive()
        },
    }
}

/// The free parameters of `spec` that are optimisation variables (no followers).
fn free_slots(spec: &CompliantSpec) -> Vec<usize> {
    (0..P).filter(|&k| spec.free[k] && !spec.follows(k)).collect()
}

/// A record as read and its reference column (closed loop) [rad].
type Read = (VoltageRecord, Option<Vec<f64>>);

/// Read the records of a compliant configuration `config` (voltage tests, or closed-loop
/// records with their reference, read as the fit reads them).
fn read_records(config: &Path) -> Result<(CompliantConfig, Vec<Read>)> {
    let text = std::fs::read_to_string(config)
        .with_context(|| format!("cannot read the fit's configuration {}", config.display()))?;
    let file = config.display().to_string();
    let cfg = CompliantConfig::parse(&text, &file)?;
    let base = config.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    for ec in &cfg.experiment {
        out.push(super::fit_drive_compliant::load(ec, &ec.name, &base.join(&ec.file))?);
    }
    Ok((cfg, out))
}

/// Noise options of the command line.
pub struct NoiseArgs {
    /// Motor encoder counts per revolution.
    pub motor_counts: Option<u64>,
    /// Load encoder counts per revolution.
    pub load_counts: Option<u64>,
    /// Current noise [A].
    pub current_noise: Option<f64>,
}

/// An encoder's quantisation noise, a count/√12 [rad].
fn count_noise(counts: u64) -> f64 {
    std::f64::consts::TAU / counts as f64 / 12f64.sqrt()
}

/// Load from a fit's output folder `dir` (only the free parameters `only` if any; at the
/// values of params file `at` if given).
pub fn from_fit(
    dir: &Path,
    only: &[String],
    at: Option<&Path>,
    limits: Limits,
    noise: &NoiseArgs,
) -> Result<Loaded> {
    let json_path = dir.join("fit.json");
    let text = std::fs::read_to_string(&json_path)
        .with_context(|| format!("cannot read {}", json_path.display()))?;
    let doc: Value = serde_json::from_str(&text)
        .with_context(|| format!("{}: not JSON", json_path.display()))?;
    if doc["transmission"].as_str() != Some("compliant") {
        bail!(
            "{}: not a compliant-drive fit (transmission = \"compliant\"); hdw design plans the compliant drive's voltage tests",
            json_path.display()
        );
    }
    let params_file = dir.join("params.toml");
    let (mut values, n, _) = read_params(&params_file)?;
    if let Some(at) = at {
        values = read_params(at)?.0;
    }
    let pars = &doc["parameters"];
    let mut free = [false; P];
    let mut fitted_se = [None; P];
    for (k, name) in NAMES.iter().enumerate() {
        free[k] = pars[name]["free"].as_bool().unwrap_or(false);
        fitted_se[k] = pars[name]["std_error"].as_f64();
    }
    let between = doc["voltage_between"].as_str().and_then(Between::parse).unwrap_or(Between::Hold);
    let substeps = doc["substeps"].as_u64().unwrap_or(20) as usize;
    let mut spec = spec_for(
        values,
        n,
        free,
        between,
        substeps,
        doc["directional_friction"].as_bool().unwrap_or(false),
    );
    spec.km_is_ke = doc["km_equals_ke"].as_bool().unwrap_or(true);
    spec.symmetric_load_friction = !doc["directional_load_friction"].as_bool().unwrap_or(false);
    if let Some(fv) = doc["friction_velocity"].as_str() {
        spec.friction_velocity = match fv {
            "load" => hd_model::FrictionVelocity::Load,
            "deflection" => hd_model::FrictionVelocity::Deflection,
            _ => hd_model::FrictionVelocity::Motor,
        };
    }
    // The configuration as the fit was given it (relative to where it ran), else where it
    // was then (fit.json's absolute path), else beside the output folder's parent.
    let given = PathBuf::from(doc["config"].as_str().unwrap_or(""));
    let tried: Vec<PathBuf> = [
        Some(given.clone()),
        doc["config_absolute"].as_str().map(PathBuf::from),
        Some(dir.join("..").join(given.file_name().unwrap_or_default())),
    ]
    .into_iter()
    .flatten()
    .collect();
    let Some(config) = tried.iter().find(|p| p.is_file()).cloned() else {
        let list: Vec<String> = tried.iter().map(|p| p.display().to_string()).collect();
        bail!(
            "{}: the fit's configuration '{}' is not found (tried {}); run hdw design from the folder the fit ran in, or keep the configuration and its records where they were",
            dir.join("fit.json").display(),
            given.display(),
            list.join(", ")
        )
    };
    let (cfg, read) = read_records(&config)?;
    spec.current_offset = cfg.fit.current_offset.unwrap_or(true);
    let exps = &doc["experiments"];
    let level = |rec: &str, o: &str| exps[rec][o]["noise"].as_f64();
    // A fit of a closed loop: its controller, with the delay it chose, on every record.
    let closed = match (doc["controller"].is_null(), read.first()) {
        (false, Some((first, _))) => {
            let noise = level(&first.name, Signal::Command.name()).unwrap_or(f64::NAN);
            let file = json_path.display().to_string();
            Some(super::design_loop::from_fit_json(&doc["controller"], &file, first.h, noise)?)
        }
        _ => None,
    };
    let mut records = Vec::with_capacity(read.len());
    for (rec, reference) in read {
        records.push(match (&closed, reference) {
            (Some(l), Some(r)) => rec.in_loop(l.closed(&r))?,
            (Some(_), None) => bail!("{}: no reference column for the closed loop", rec.source),
            (None, _) => rec,
        });
    }
    let mut outputs: Vec<(Signal, Vec<f64>)> = Vec::new();
    for o in [Signal::Motor, Signal::Load, Signal::Current, Signal::Command] {
        let levels: Option<Vec<f64>> = records.iter().map(|r| level(&r.name, o.name())).collect();
        if let Some(l) = levels {
            outputs.push((o, l));
        }
    }
    spec.noise_estimated = vec![false; outputs.len()];
    let first = |o: Signal| outputs.iter().find(|x| x.0 == o).map(|x| x.1[0]);
    let new_noise = Noise {
        motor: noise
            .motor_counts
            .map(count_noise)
            .or(first(Signal::Motor))
            .unwrap_or(count_noise(4096)),
        load: noise
            .load_counts
            .map(count_noise)
            .or(first(Signal::Load))
            .unwrap_or(count_noise(1 << 20)),
        current: noise.current_noise.or(first(Signal::Current)),
    };
    spec.outputs = outputs;
    if !only.is_empty() {
        let mut keep = [false; P];
        for name in only {
            let k = NAMES
                .iter()
                .position(|x| x.eq_ignore_ascii_case(name))
                .filter(|&k| spec.free[k])
                .with_context(|| {
                    format!("--free {name}: not a free parameter of the fit in {}", dir.display())
                })?;
            keep[k] = true;
        }
        spec.free = keep;
    }
    let free_idx = free_slots(&spec);
    let prior = prior_information(&spec, &values, &free_idx, &records);
    Ok(Loaded {
        problem: Problem { spec, values, free: free_idx, noise: new_noise, prior, limits, closed },
        records,
        params_file,
        fitted_se: Some(fitted_se),
    })
}

/// Load from a params file `path` with unknowns `free` (registry names), in the loop of
/// the `[controller]` of `controller` if given.
pub fn from_params(
    path: &Path,
    free: &[String],
    limits: Limits,
    noise: &NoiseArgs,
    controller: Option<&Path>,
) -> Result<Loaded> {
    let (values, n, directional) = read_params(path)?;
    let mut f = [false; P];
    for name in free {
        let k = NAMES
            .iter()
            .position(|x| {
                x.eq_ignore_ascii_case(name)
                    || (*x == "mem_A" && name == "A")
                    || (*x == "mem_B" && name == "B")
            })
            .with_context(|| {
                format!(
                    "--free {name}: not a parameter of the compliant drive (expected one of {})",
                    NAMES.join(", ")
                )
            })?;
        f[k] = true;
    }
    if !f.iter().any(|&x| x) {
        bail!("--free: name at least one parameter");
    }
    let substeps = substeps_for(&values, n, 1.0 / limits.rate);
    let spec = spec_for(values, n, f, Between::Hold, substeps, directional);
    let free_idx = free_slots(&spec);
    let prior = prior_information(&spec, &values, &free_idx, &[]);
    let new_noise = Noise {
        motor: count_noise(noise.motor_counts.unwrap_or(4096)),
        load: count_noise(noise.load_counts.unwrap_or(1 << 20)),
        current: Some(noise.current_noise.unwrap_or(0.01)),
    };
    let closed = match controller {
        Some(c) => Some(super::design_loop::from_file(
            c,
            1.0 / limits.rate,
            new_noise.motor,
            new_noise.load,
        )?),
        None => None,
    };
    Ok(Loaded {
        problem: Problem { spec, values, free: free_idx, noise: new_noise, prior, limits, closed },
        records: Vec::new(),
        params_file: path.to_path_buf(),
        fitted_se: None,
    })
}
