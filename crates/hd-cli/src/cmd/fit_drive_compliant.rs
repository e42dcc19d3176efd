//! `hdw fit drive` with `transmission = "compliant"`: the simulator's compliant drive fitted
//! to voltage tests (motor and load encoders, current) by output error (docs/fit-drive.md,
//! "The compliant drive"). Everything is computed before anything is written.

use super::common::ensure_dir;
use super::fit_drive::DriveArgs;
use super::fit_drive_compliant_out::{Outcome, write_outputs};
use anyhow::{Context, Result};
use hd_ident::drive::compliant::accuracy::{
    ACCURACY_COST, accurate_substeps, first_substeps, integration_error, raised_substeps,
};
use hd_ident::drive::compliant::config::VoltageExperimentConfig;
use hd_ident::drive::compliant::fit::{CompliantSpec, score_records};
use hd_ident::drive::compliant::model::{P, has_load_law, on_law};
use hd_ident::drive::compliant::scale_check::{check_command, check_current};
use hd_ident::drive::compliant::supported::load_law_problem;
use hd_ident::drive::compliant::{
    Amplifier, CompliantConfig, NAMES, Signal, VoltageRecord, fit_compliant,
};
use hd_ident::drive::fit::noise_level;
use hd_ident::lm::LmOptions;
use hd_model::HystLaw;
use std::path::Path;
use std::time::Instant;

/// A pass stops when an accepted step lowers the cost by less than this share (for a
/// cost of 4000, a noise-weighted change of 4e-5). Measured before the geodesic steps:
/// 1e-6 stopped the worked example of docs/fit-drive.md early and left its validation
/// record's load residual at 2.3 times the noise instead of 1.4.
const COST_TOLERANCE: f64 = 1e-8;

/// Iteration budget of each pass, unless `[fit] max_iterations` says otherwise. The valleys
/// of a gear the record barely sees take many small steps. With geodesic steps
/// ([`LmOptions::geodesic`]) a full fit of a 2–200 Hz multisine converges in about 150
/// iterations (260 without).
const MAX_ITERATIONS: usize = 300;

/// Read one record with `ec`'s mapping from `path`: a voltage test, or a closed-loop record
/// (its `u` the recorded command) with its reference [rad].
pub(crate) fn load(
    ec: &VoltageExperimentConfig,
    name: &str,
    path: &Path,
) -> Result<(VoltageRecord, Option<Vec<f64>>)> {
    let (input, input_scale) = match (&ec.voltage, &ec.command) {
        (Some(v), _) => (v.as_str(), ec.voltage_scale),
        (None, Some(c)) => (c.as_str(), ec.command_scale),
        (None, None) => anyhow::bail!("[[experiment]] '{name}': no voltage or command column"),
    };
    let names = [ec.time.as_str(), input, &ec.motor, &ec.load];
    let cols = hd_io::read_columns(path, &names)?;
    let column = |c: &Option<String>| -> Result<Option<Vec<f64>>> {
        Ok(match c {
            None => None,
            Some(c) => Some(hd_io::read_columns(path, &[c.as_str()])?.remove(0)),
        })
    };
    let current = column(&ec.current)?;
    let reference = column(&ec.reference)?;
    let scale = |v: &[f64], s: f64| v.iter().map(|x| x * s).collect::<Vec<f64>>();
    let rec = VoltageRecord::new(
        name,
        &path.display().to_string(),
        cols[0].clone(),
        scale(&cols[1], input_scale),
        scale(&cols[2], ec.motor_scale),
        scale(&cols[3], ec.load_scale),
        current.map(|i| scale(&i, ec.current_scale)),
    )?;
    Ok((rec, reference.map(|r| scale(&r, ec.reference_scale))))
}

/// Noise level of a recorded signal [its unit]: from its third differences, and no less
/// than the quantisation noise q/√12 of its smallest step q (an encoder that moves less
/// than a count per sample hides its quantisation from the differences).
pub fn estimated_noise(y: &[f64]) -> f64 {
    let q = y
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let floor = if q.is_finite() { q / 12f64.sqrt() } else { 0.0 };
    noise_level(y).max(floor).max(f64::MIN_POSITIVE)
}

/// Samples at the start of a record over which the drive should still be at rest.
const REST_SAMPLES: usize = 3;

/// A sentence when the motor encoder of `r` already moves over its first samples by more
/// than two of its smallest steps: the fit starts each record at rest, so a record that
/// begins in motion starts with a model error.
fn moving_at_start(r: &VoltageRecord) -> Option<String> {
    let m = &r.theta_m;
    let step = m
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let moved = (m[REST_SAMPLES.min(m.len() - 1)] - m[0]).abs();
    (step.is_finite() && moved > 2.0 * step).then(|| {
        format!(
            "{}: the motor encoder moves {moved:.3e} rad over the first {REST_SAMPLES} samples; the fit starts each record at rest, so trim it to begin at rest",
            r.source
        )
    })
}

/// What the params file named in the configuration (or the seed's) gives the fit.
struct Base {
    /// Start values in [`NAMES`] order; the other gear laws' hysteretic parameters zero.
    values: [f64; P],
    /// Gear ratio N [–].
    n: f64,
    /// The gear law (the file's `stiffness`, default the memory).
    law: HystLaw,
    /// Whether the file sets direction-dependent friction levels (Tc_neg or Ts_neg).
    sets_negative: bool,
    /// Whether it sets the load-side law's (Tc_neg_load or Ts_neg_load).
    sets_negative_load: bool,
    /// The file's `friction_velocity`, if it names one.
    friction_velocity: Option<hd_model::FrictionVelocity>,
}

/// The params file named in the configuration, read (the seed's without one).
fn base_params(cfg: &CompliantConfig, base: &Path) -> Result<Base> {
    let mut p = hd_model::Params::default();
    let mut law = HystLaw::Memory;
    let mut friction_velocity = None;
    if let Some(f) = &cfg.params_file {
        let path = base.join(f);
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read params_file {}", path.display()))?;
        let name = path.display().to_string();
        hd_model::params_file::apply_params_toml(&mut p, &text, &name)?;
        let found = hd_model::params_file::stiffness_from_toml(&text, &name)?;
        if let Some(why) = hd_ident::drive::compliant::supported::unsupported(&p, found).first() {
            anyhow::bail!("{name}: {why}");
        }
        law = found.unwrap_or(HystLaw::Memory);
        friction_velocity = hd_model::params_file::friction_velocity_from_toml(&text, &name)?;
    }
    let mut out = [0.0; P];
    let source = cfg.params_file.as_ref().map(|f| base.join(f).display().to_string());
    for (k, n) in NAMES.iter().enumerate() {
        out[k] = p.get(n)?;
        // A start no drive has (1e300) overflows the simulation; [params] are checked when
        // parsed, the params file's values here.
        if let Some(src) = &source
            && out[k].abs() > hd_ident::drive::config::validate::MAX_START
        {
            anyhow::bail!(
                "params file {src}: {n} = {}; expected a start of at most {:e} in magnitude (check the unit: no drive parameter comes near it)",
                hd_model::error::num(out[k]),
                hd_ident::drive::config::validate::MAX_START
            );
        }
    }
    on_law(&mut out, law);
    let sets_negative = p.tc_neg.is_some() || p.ts_neg.is_some();
    let sets_negative_load = p.tc_neg_load.is_some() || p.ts_neg_load.is_some();
    Ok(Base { values: out, n: p.n, law, sets_negative, sets_negative_load, friction_velocity })
}

/// Run `hdw fit drive` on a compliant-drive configuration `text` of `args.config`.
pub fn run(args: &DriveArgs, text: &str) -> Result<()> {
    let file = args.config.display().to_string();
    let cfg = CompliantConfig::parse(text, &file)?;
    let base = args.config.parent().unwrap_or(Path::new("."));
    let loaded: Vec<(VoltageRecord, Option<Vec<f64>>)> = cfg
        .experiment
        .iter()
        .map(|ec| load(ec, &ec.name, &base.join(&ec.file)))
        .collect::<Result<_>>()?;
    let validation = match &args.validate {
        Some(p) => Some(load(&cfg.experiment[0], "validation", p)?),
        None => None,
    };
    let first_file = base.join(&cfg.experiment[0].file);
    let (records, validation, controller) =
        super::fit_drive_compliant_loop::attach(&cfg, &file, &first_file, loaded, validation)?;
    // The validation record is simulated from rest too, so it gets the same note.
    for r in records.iter().chain(&validation) {
        if let Some(note) = moving_at_start(r) {
            eprintln!("note: {note}");
        }
    }
    let between = cfg.between(&file)?;
    // Which instant the logged current refers to ([`CurrentSampled`]).
    let sampled = hd_ident::drive::compliant::sampling::current_sampled(&cfg, &file)?;
    let records: Vec<VoltageRecord> =
        records.into_iter().map(|r| r.with_current_sampled(sampled)).collect();
    let validation = validation.map(|r| r.with_current_sampled(sampled));
    // The controller check, judged: a configured controller that does not reproduce the
    // recorded command puts every value in doubt (said first).
    let mut doubt: Vec<String> = Vec::new();
    if let Some(info) = &controller {
        let percent = info
            .checks
            .iter()
            .find(|c| c.delay == info.controller.delay)
            .map_or(0.0, |c| c.percent);
        for r in &records {
            let Some(cl) = &r.closed else { continue };
            let q = cl.measured_feedback(r);
            doubt.extend(check_command(&info.controller, r, q, &cl.reference, percent));
        }
    }
    let Base { values: params, n, law, sets_negative, sets_negative_load, friction_velocity } =
        base_params(&cfg, base)?;
    // A negative side's level set in [params] counts as set, as one in the params file.
    let in_params = |names: [&str; 2]| names.iter().any(|n| cfg.params.contains_key(*n));
    let directional =
        cfg.directional_friction.unwrap_or(sets_negative || in_params(["Tc_neg", "Ts_neg"]));
    let directional_load = cfg
        .directional_load_friction
        .unwrap_or(sets_negative_load || in_params(["Tc_neg_load", "Ts_neg_load"]));
    let friction_velocity = cfg.friction_velocity(&file, friction_velocity)?;
    let axis = cfg.axis(&file)?;
    let (start, lower, upper) = cfg.start_and_bounds(&params);
    // A load-side friction law (Tc_load, Ts_load) from the params file or [params].
    let load_law = has_load_law(&start);
    if let Some(why) = load_law_problem(&start, friction_velocity) {
        anyhow::bail!("{file}: the load-side friction law: {why}");
    }
    let free = cfg.free(&file, Some(law), directional, load_law, directional_load)?;
    cfg.check_law(&file, law)?;
    for r in records.iter().chain(&validation) {
        use hd_ident::drive::compliant::ratio_check::{check_length, check_ratio};
        if let Some(why) = check_length(r).or_else(|| check_ratio(r, n)) {
            anyhow::bail!("{why}");
        }
    }
    let has_current = records.iter().all(|r| r.current.is_some());
    let current_amplifier = controller.as_ref().is_some_and(|c| c.amplifier == Amplifier::Current);
    let mut free = free;
    if current_amplifier {
        super::fit_drive_compliant_loop::unfree_for_current(
            &mut free,
            cfg.km_equals_ke.unwrap_or(true),
        );
    }
    let wanted = cfg.outputs(&file)?.unwrap_or_else(|| {
        // An ideal current amplifier's current is its command: compared once, as `command`.
        Signal::ALL
            .into_iter()
            .filter(|s| *s != Signal::Current || (has_current && !current_amplifier))
            .filter(|s| *s != Signal::Command || controller.is_some())
            .collect()
    });
    let mut outputs = Vec::new();
    for o in wanted {
        let mut levels = Vec::new();
        for r in &records {
            let meas = o.measured(r).ok_or_else(|| {
                anyhow::anyhow!(
                    "{file}, [fit] outputs: '{}' but {} logs no {}",
                    o.name(),
                    r.source,
                    o.name()
                )
            })?;
            let given = cfg.fit.noise.get(o.name()).copied();
            if let Some(level) = given {
                let rms =
                    (meas.iter().map(|v| v * v).sum::<f64>() / meas.len().max(1) as f64).sqrt();
                hd_ident::drive::config::validate::noise_floor(&file, o.name(), level, rms)?;
            }
            levels.push(given.unwrap_or_else(|| estimated_noise(meas)));
        }
        outputs.push((o, levels));
    }
    let h = records[0].h;
    let floor = cfg.substeps.unwrap_or_else(|| {
        let d = hd_ident::drive::compliant::Compliant::new(start, n)
            .with_friction_velocity(friction_velocity);
        first_substeps(&d, h)
    });
    let noise_estimated =
        outputs.iter().map(|(o, _)| !cfg.fit.noise.contains_key(o.name())).collect();
    let spec = CompliantSpec {
        noise_estimated,
        n,
        between,
        start,
        free,
        lower,
        upper,
        outputs,
        km_is_ke: cfg.km_equals_ke.unwrap_or(true),
        symmetric_friction: !directional,
        symmetric_load_friction: !directional_load,
        friction_velocity,
        current_offset: cfg.fit.current_offset.unwrap_or(true),
        substeps: floor,
        settings: LmOptions {
            max_iterations: cfg.fit.max_iterations.unwrap_or(MAX_ITERATIONS),
            cost_tolerance: COST_TOLERANCE,
            geodesic: true,
            ..LmOptions::drive()
        },
    };
    // Followers start at their leaders' values (as the fit holds them).
    let spec = CompliantSpec { start: spec.tied(spec.start), ..spec };
    // A count given in the configuration is used as given; otherwise it is raised until
    // the integration error is below the noise (hd_ident::drive::compliant::accuracy).
    let t_accuracy = Instant::now();
    let spec = if cfg.substeps.is_some() {
        spec
    } else {
        let (substeps, _) = accurate_substeps(&spec, &records);
        CompliantSpec { substeps, ..spec }
    };
    let accuracy_secs = cfg.substeps.is_none().then(|| t_accuracy.elapsed().as_secs_f64());
    // The current's scale against what the start values drive from the voltage.
    doubt.extend(records.iter().filter_map(|r| check_current(&spec, r)));
    for d in &doubt {
        eprintln!("warning: {d}");
    }
    let dir = ensure_dir(&args.out)?;
    let bar = super::fit_drive::spinner("fitting the compliant drive".into());
    let t0 = Instant::now();
    let progress = |stage: &str, it: usize, cost: f64| {
        bar.set_message(super::fit_drive::progress::step_message(stage, it, cost));
    };
    let mut fit = fit_compliant(&spec, &records, &progress)
        .map_err(|e| anyhow::anyhow!("{file}: the compliant fit failed: {e}"))?;
    // The count was chosen at the start values (or given), and a fit may end at a stiffer
    // drive (on a 2 s multisine of the seed drive the gear's stiffness doubles from its
    // start). At the fitted values the integration error is measured again against the same
    // budget ([`ACCURACY_COST`]). Over it, a chosen count is raised and the fit runs again
    // from its end; a given count is kept, and the report says what it costs.
    let t_check = Instant::now();
    let at_fit = CompliantSpec { start: fit.values, ..spec.clone() };
    let err = integration_error(&at_fit, &records);
    // Over the budget, or not measurable (a run that fails at the fitted values).
    let over = err.partial_cmp(&ACCURACY_COST) != Some(std::cmp::Ordering::Less);
    let spec = if over && cfg.substeps.is_none() {
        // The error at the first count is the one just measured.
        let (m, raised) = raised_substeps(&at_fit, &records, Some(err));
        let before = spec.substeps;
        let again = CompliantSpec { substeps: m, ..at_fit };
        let mut refit = fit_compliant(&again, &records, &progress)
            .map_err(|e| anyhow::anyhow!("{file}: the compliant fit failed: {e}"))?;
        refit.determination.sentences.insert(0, format!(
            "At the values first fitted, {before} Runge–Kutta substeps per sample left an integration error costing {err:.3e} noise-weighted squares (the budget is {ACCURACY_COST}); the fit was run again from there at {m} substeps (error cost {raised:.3e})."
        ));
        refit.stage_seconds.splice(0..0, fit.stage_seconds.iter().copied());
        fit = refit;
        CompliantSpec { substeps: m, ..spec }
    } else {
        if over {
            fit.determination.sentences.insert(0, format!(
                "At the fitted values the configuration's {} Runge–Kutta substeps per sample leave an integration error costing {err:.3e} noise-weighted squares (the budget is {ACCURACY_COST}): the parameters follow that error as well as the records; raise `substeps` or leave it out to have it chosen.",
                spec.substeps
            ));
            fit.determination.all_determined = false;
        }
        spec
    };
    fit.stage_seconds
        .push(("integration accuracy at the fitted values", t_check.elapsed().as_secs_f64()));
    if let Some(secs) = accuracy_secs {
        fit.stage_seconds.insert(0, ("substeps chosen (integration accuracy check)", secs));
    }
    hd_ident::drive::compliant::determined::put_in_doubt(&mut fit, doubt);
    let secs = t0.elapsed().as_secs_f64();
    bar.finish_and_clear();
    // The noise levels the fit ended with (estimated ones replaced by the residuals' RMS).
    let spec = CompliantSpec { outputs: fit.noise.clone(), ..spec };
    let start_scores = score_records(&spec, &spec.start, &records, &|o, k| {
        spec.outputs.iter().find(|x| x.0 == o).map_or(f64::NAN, |x| x.1[k])
    });
    // The validation record is scored against its own noise levels: a level the
    // configuration gives, else the one the validation record itself shows (its third
    // differences, as the fitted records' were estimated before the fit). A current's noise
    // scales with its RMS, so the estimation record's level would misstate it (1.86× where
    // the truth is 1.00).
    let validation_scores = validation.as_ref().map(|v| {
        score_records(&spec, &fit.values, std::slice::from_ref(v), &|o, _| {
            cfg.fit
                .noise
                .get(o.name())
                .copied()
                .unwrap_or_else(|| o.measured(v).map_or(f64::NAN, estimated_noise))
        })
        .remove(0)
    });
    if let Some(v) = &validation_scores {
        hd_ident::drive::compliant::determined::doubt_from_validation(&mut fit, v);
    }
    let outcome = Outcome {
        config: file,
        spec,
        records,
        validation,
        fit,
        secs,
        start_scores,
        validation_scores,
        controller,
        axis,
        between_given: cfg.voltage_between.is_some(),
    };
    write_outputs(&dir, &outcome)
}
