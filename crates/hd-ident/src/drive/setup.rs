//! From a checked configuration and the loaded records to what the fit needs: the
//! controller with its delay (chosen by reproducing the recorded command), the noise level
//! of each output, and per friction law the start, the free set and the bounds.

use super::config::{DelayChoice, DriveConfig};
use super::controller::{Controller, Reproduction, reproduce};
use super::error::DriveError;
use super::fit::{FitSpec, OutputKind, noise_level};
use super::idim::{IdimFit, idim_ls};
use super::lm::LmSettings;
use super::model::FrictionLaw;
use super::record::Experiment;

/// The controller of the configuration with the delay it asks for, and the reproduction
/// check of every delay considered on every experiment (averaged in quadrature over the
/// experiments).
pub fn controller(
    cfg: &DriveConfig,
    file: &str,
    kp: f64,
    kv: f64,
    experiments: &[Experiment],
) -> Result<(Controller, Vec<Reproduction>), DriveError> {
    let c = &cfg.controller;
    let h = experiments[0].h;
    if let Some(e) = experiments.iter().find(|e| ((e.h - h) / h).abs() > 1e-3) {
        return Err(DriveError::data(
            &e.source,
            format!(
                "sample period {} s differs from the first experiment's {h} s; one controller runs at one rate",
                e.h
            ),
        ));
    }
    let speed_filter = c.speed_filter.clone().unwrap_or_else(|| vec![1.0]);
    let sum: f64 = speed_filter.iter().sum();
    if speed_filter.is_empty() || (sum - 1.0).abs() > 1e-9 {
        return Err(DriveError::config(
            format!("{file}, [controller] speed_filter"),
            format!("coefficients sum to {sum}; expected 1 (a filter of unit DC gain)"),
        ));
    }
    let saturation = c.saturation.unwrap_or(f64::INFINITY);
    if saturation.is_nan() || saturation <= 0.0 {
        return Err(DriveError::config(
            format!("{file}, [controller] saturation"),
            "expected a positive limit",
        ));
    }
    let mut ctl = Controller { kp, kv, saturation, delay: 0, speed_filter, h };
    let delays = c.delays.clone().unwrap_or_else(|| vec![0, 1]);
    let mut checks: Vec<Reproduction> =
        delays.iter().map(|&d| Reproduction { delay: d, rms: 0.0, percent: 0.0 }).collect();
    for e in experiments {
        let r = reproduce(&ctl, &e.position, &e.reference, &e.disturbance, &e.command, &delays);
        for (acc, r) in checks.iter_mut().zip(r) {
            acc.rms += r.rms * r.rms / experiments.len() as f64;
            acc.percent += r.percent * r.percent / experiments.len() as f64;
        }
    }
    for r in &mut checks {
        r.rms = r.rms.sqrt();
        r.percent = r.percent.sqrt();
    }
    ctl.delay = match &c.delay {
        Some(DelayChoice::Samples(d)) => *d,
        _ => checks.iter().min_by(|a, b| a.rms.total_cmp(&b.rms)).map(|r| r.delay).unwrap_or(0),
    };
    Ok((ctl, checks))
}

/// The noise level of each configured output: given, or estimated from the records
/// ([`noise_level`], pooled in quadrature over the experiments).
pub fn noise(
    cfg: &DriveConfig,
    file: &str,
    gain: f64,
    experiments: &[Experiment],
) -> Result<Vec<(OutputKind, f64)>, DriveError> {
    cfg.outputs(file)?
        .into_iter()
        .map(|o| {
            let given = cfg.fit.noise.get(o.name()).copied();
            let level = given.unwrap_or_else(|| {
                let ms: f64 = experiments
                    .iter()
                    .map(|e| noise_level(&o.measured(e, gain)).powi(2))
                    .sum::<f64>()
                    / experiments.len() as f64;
                ms.sqrt()
            });
            if level.is_nan() || level <= 0.0 {
                return Err(DriveError::config(
                    format!("{file}, [fit] noise.{}", o.name()),
                    "the record's noise level estimates to zero (a constant or piecewise-quadratic signal); give it",
                ));
            }
            Ok((o, level))
        })
        .collect()
}

/// The inverse-model start of `law`, when the configuration asks for it.
pub fn start(
    cfg: &DriveConfig,
    law: FrictionLaw,
    gain: f64,
    experiments: &[Experiment],
) -> Result<Option<IdimFit>, DriveError> {
    match cfg.start.method.as_deref().unwrap_or("idim") {
        "idim" => idim_ls(law, experiments, gain, &cfg.idim()).map(Some),
        _ => Ok(None),
    }
}

/// The fit of `law`: start (inverse model, then `[params]`), free set, bounds.
pub fn spec(
    cfg: &DriveConfig,
    file: &str,
    law: FrictionLaw,
    controller: &Controller,
    gain: f64,
    outputs: &[(OutputKind, f64)],
    idim: Option<&IdimFit>,
) -> Result<FitSpec, DriveError> {
    let names = law.names();
    let fix = cfg.fix();
    let mut start = Vec::with_capacity(names.len());
    for &n in names {
        let from_idim =
            idim.and_then(|f| f.names.iter().position(|m| *m == n).map(|k| f.values[k]));
        let v = match (cfg.params.get(n), n) {
            (Some(&v), _) => v,
            (None, "gain") => gain,
            (None, _) => from_idim.ok_or_else(|| {
                DriveError::config(
                    format!("{file}, [params] {n}"),
                    format!("no start value for {n} ({} friction); give it in [params] or use [start] method = \"idim\"", law.name()),
                )
            })?,
        };
        start.push(v);
    }
    let (mut lower, mut upper) = (Vec::new(), Vec::new());
    for (k, &n) in names.iter().enumerate() {
        let (lo, hi) = match cfg.bounds.get(n) {
            Some(&[lo, hi]) => (lo, hi),
            None if n == "offset" => (f64::NEG_INFINITY, f64::INFINITY),
            None if n == "M" || n == "gain" => (1e-12, f64::INFINITY),
            None => (0.0, f64::INFINITY),
        };
        // A start outside the bounds is moved inside.
        start[k] = start[k].clamp(lo, hi);
        lower.push(lo);
        upper.push(hi);
    }
    let free = names.iter().map(|n| !fix.iter().any(|f| f == n)).collect();
    Ok(FitSpec {
        law,
        controller: controller.clone(),
        gain,
        outputs: outputs.to_vec(),
        start,
        free,
        lower,
        upper,
        settings: LmSettings {
            max_iterations: cfg.fit.max_iterations.unwrap_or(LmSettings::default().max_iterations),
            ..LmSettings::default()
        },
    })
}
