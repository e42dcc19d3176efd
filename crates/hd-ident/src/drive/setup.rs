//! From a checked configuration and the loaded records to what the fit needs: the
//! controller with its delay (chosen by reproducing the recorded command), the noise level
//! of each output, and per friction law the start, the free set and the bounds.

use super::config::{DelayChoice, DriveConfig};
use super::controller::{Controller, Reproduction, reproduce};
use super::error::DriveError;
use super::fit::{DriveFit, FitSpec, OutputKind, noise_level};
use super::idim::{IdimFit, idim_ls};
use super::model::FrictionLaw;
use super::record::Experiment;
use crate::lm::LmOptions;

/// Relative cost change below which a LuGre fit stops.
pub const LUGRE_COST_TOLERANCE: f64 = 1e-7;

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
    let Some(c) = &cfg.controller else {
        // Open loop: nothing to check against the recorded command.
        let segment = cfg.segment_samples(h).unwrap_or(2);
        return Ok((Controller::open(segment, h), Vec::new()));
    };
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
    let mut ctl = Controller { kp, kv, saturation, delay: 0, speed_filter, h, open_loop: None };
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
            if given.is_some() {
                let ms: f64 = experiments
                    .iter()
                    .map(|e| {
                        let y = o.measured(e, gain);
                        y.iter().map(|v| v * v).sum::<f64>() / y.len().max(1) as f64
                    })
                    .sum::<f64>()
                    / experiments.len() as f64;
                super::config::validate::noise_floor(file, o.name(), level, ms.sqrt())?;
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

/// The fit of `law`: start, free set, bounds. Start values come from `[params]`, else
/// (LuGre laws) the fitted base law `base`, else the inverse model, else (the LuGre
/// parameters) [`lugre_start`].
#[allow(clippy::too_many_arguments)]
pub fn spec(
    cfg: &DriveConfig,
    file: &str,
    law: FrictionLaw,
    controller: &Controller,
    gain: f64,
    outputs: &[(OutputKind, f64)],
    idim: Option<&IdimFit>,
    base: Option<&DriveFit>,
    experiments: &[Experiment],
) -> Result<FitSpec, DriveError> {
    let names = law.names();
    let fix = cfg.fix();
    let mut start = Vec::with_capacity(names.len());
    for &n in names {
        let from_idim =
            idim.and_then(|f| f.names.iter().position(|m| *m == n).map(|k| f.values[k]));
        let from_base =
            base.and_then(|f| f.names.iter().position(|m| *m == n).map(|k| f.values[k]));
        let v = match (cfg.params.get(n), n) {
            (Some(&v), _) => v,
            (None, "gain") => gain,
            (None, n) if law.is_lugre() && !law.base().names().contains(&n) => f64::NAN,
            (None, _) => from_base.or(from_idim).ok_or_else(|| {
                DriveError::config(
                    format!("{file}, [params] {n}"),
                    format!("no start value for {n} ({} friction); give it in [params] or use [start] method = \"idim\"", law.name()),
                )
            })?,
        };
        start.push(v);
    }
    if law.is_lugre() {
        for (k, v) in lugre_start(law, &start, experiments) {
            if !cfg.params.contains_key(names[k]) {
                start[k] = v;
            }
        }
    }
    // A bristle–mass oscillation above the Nyquist frequency is not seen by the record:
    // σ0 ≤ M·(π/h)², σ1 at most twice the critical damping there.
    let m = names.iter().position(|n| *n == "M").map(|k| start[k]).unwrap_or(f64::NAN);
    let sigma0_max = m * (std::f64::consts::PI / experiments[0].h).powi(2);
    let (mut lower, mut upper) = (Vec::new(), Vec::new());
    for (k, &n) in names.iter().enumerate() {
        let (lo, hi) = match cfg.bounds.get(n) {
            Some(&[lo, hi]) => (lo, hi),
            None if n == "offset" => (f64::NEG_INFINITY, f64::INFINITY),
            None if n == "sigma0" => (1e-12, sigma0_max),
            None if n == "sigma1" => (0.0, 4.0 * (sigma0_max * m).sqrt()),
            None if ["M", "gain", "sigma0", "vs"].contains(&n) => (1e-12, f64::INFINITY),
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
        settings: LmOptions {
            max_iterations: cfg.fit.max_iterations.unwrap_or(LmOptions::drive().max_iterations),
            // LuGre's σ0–σ1 valley is long and flat: stop once an iteration gains less than a
            // ten-millionth of the cost (for EMPS, 0.04 in the noise-weighted sum of squares,
            // far below a significant change).
            cost_tolerance: if law.is_lugre() {
                LUGRE_COST_TOLERANCE
            } else {
                LmOptions::drive().cost_tolerance
            },
            ..LmOptions::drive()
        },
    })
}

/// Start values of a LuGre law's own parameters (index in [`FrictionLaw::names`], value),
/// from the start of its Coulomb–viscous levels `start` (the base law's fit) and the record:
/// static levels Fs± 20 % above the Coulomb levels ([`stribeck_variants`] adds the start
/// 20 % below); the Stribeck speed vs a tenth of the record's RMS speed (from differences of
/// the measured position); the bristle stiffness σ0 such that the bristle–mass oscillation
/// √(σ0/M) sits at a fortieth of the sample rate (a pre-sliding spring well resolved by the
/// samples; the bounds let it rise to the Nyquist frequency); the bristle damping
/// σ1 = 0.2·√(σ0·M), a tenth of the critical damping of that oscillation.
pub fn lugre_start(
    law: FrictionLaw,
    start: &[f64],
    experiments: &[Experiment],
) -> Vec<(usize, f64)> {
    let names = law.names();
    let at = |n: &str| names.iter().position(|m| *m == n);
    let value = |n: &str| at(n).map(|k| start[k]).unwrap_or(f64::NAN);
    let m = value("M");
    let h = experiments[0].h;
    let (mut ss, mut count) = (0.0, 0usize);
    for e in experiments {
        for w in e.position.windows(2) {
            ss += ((w[1] - w[0]) / e.h).powi(2);
            count += 1;
        }
    }
    let rms_speed = (ss / count.max(1) as f64).sqrt();
    let omega = std::f64::consts::TAU / (40.0 * h);
    let sigma0 = m * omega * omega;
    let mut out = Vec::new();
    for (fs, fc) in [("Fs", "Fc"), ("Fs_pos", "Fc_pos"), ("Fs_neg", "Fc_neg")] {
        if let Some(k) = at(fs) {
            out.push((k, 1.2 * value(fc)));
        }
    }
    for (n, v) in
        [("vs", 0.1 * rms_speed), ("sigma0", sigma0), ("sigma1", 0.2 * (sigma0 * m).sqrt())]
    {
        if let Some(k) = at(n) {
            out.push((k, v));
        }
    }
    out
}

/// The starts a LuGre fit runs from: `spec` itself and, unless `[params]` sets them, the
/// same with the static levels Fs± 20 % below the Coulomb levels instead of above (a record
/// may favour friction that falls, or rises, towards rest; from the wrong side the Stribeck
/// hump can collapse, vs → 0, before the levels move). The fit keeps the lower cost.
pub fn stribeck_variants(cfg: &DriveConfig, spec: &FitSpec) -> Vec<FitSpec> {
    let names = spec.law.names();
    let mut below = spec.clone();
    let mut changed = false;
    for (fs, fc) in [("Fs", "Fc"), ("Fs_pos", "Fc_pos"), ("Fs_neg", "Fc_neg")] {
        let (Some(i), Some(j)) =
            (names.iter().position(|n| *n == fs), names.iter().position(|n| *n == fc))
        else {
            continue;
        };
        if !cfg.params.contains_key(fs) {
            below.start[i] = (0.8 * spec.start[j]).clamp(spec.lower[i], spec.upper[i]);
            changed = true;
        }
    }
    if changed { vec![spec.clone(), below] } else { vec![spec.clone()] }
}
