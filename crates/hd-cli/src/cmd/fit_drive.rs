//! `hdw fit drive`: identify a rigid drive from its logged closed loop (docs/fit-drive.md).
//! Reads the configuration and records, checks the controller against the recorded command,
//! starts from the inverse model, fits each friction law by output error, ranks them by BIC,
//! optionally scores a validation record, and writes fit.json, params.toml and report.md with
//! plots — all computed before anything is written.

use super::common::{EarlierOutputs, MAX_CONFIG_BYTES, check_data_file, ensure_dir};
use super::fit_drive_out::{Outcome, write_outputs};
use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use hd_ident::drive::compliant::scale_check::{Recorded, command_check};
use hd_ident::drive::config::{ExperimentConfig, NumberOrVariable};
use hd_ident::drive::controller::{Controller, Reproduction};
use hd_ident::drive::{
    DisturbanceCheck, DriveConfig, DriveFit, Experiment, FitSpec, FrictionLaw, IdimFit, fit_drive,
    score_all, settle_units, setup,
};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[path = "fit_drive_abort.rs"]
mod abort;
#[path = "fit_drive_files.rs"]
mod files;
#[path = "fit_drive_progress.rs"]
pub mod progress;

/// `hdw fit drive`.
#[derive(Args, Debug)]
#[command(
    after_help = "The configuration names the records (CSV, Parquet or MAT v5) and their columns, the drive gain, the\n\
controller (cascade P position / P speed loop, sample delay, saturation, speed filter), the friction\n\
law(s), the outputs compared and the fixed parameters (docs/fit-drive.md). Outputs in --out DIR:\n\
  fit.json     controller check per delay, inverse-model start, per law: parameters (value, std_error),\n\
               correlations, BIC, per experiment and output rel_error, rmse, fit_percent, what the\n\
               record does not determine; the validation scores with --validate\n\
  params.toml  the best law's parameters, as a [params] table a configuration can start from\n\
  report.md    the same in words, with force.svg, position.svg, residuals.svg (and validation-*.svg)\n\
With transmission = \"compliant\" the configuration fits the simulator's compliant drive to voltage tests\n\
(motor and load encoders, current), or, with a [controller] and reference and command columns, to records\n\
of its own position loop (the command is then an output too). Its gear is the params file's stiffness\n\
law (memory, bouc-wen, maxwell-slip or catalogue); its friction levels differ by direction where the file sets\n\
Tc_neg or Ts_neg; its friction acts on the load with friction_velocity = \"load\" (across the gear\n\
with \"deflection\"), or a second law acts on the load beside it where the file sets Tc_load and\n\
Ts_load; TL is a constant load torque;\n\
axis = \"linear\" gives a ball screw's or a belt's units (m, N, kg past the gear, N in rad/m).\n\
params.toml is then a params file hdw simulate runs, and the plots are motor.svg,\n\
load.svg, current.svg (command.svg) with their residuals.\n\n\
Example:\n  hdw fit drive --config data/emps/fit.toml --out out/emps"
)]
pub struct DriveArgs {
    /// Fit configuration (TOML).
    #[arg(long, value_name = "FIT.toml")]
    pub config: PathBuf,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/fit-drive")]
    pub out: PathBuf,
    /// A validation record read with the first experiment's column mapping (its optional
    /// disturbance column is zero where absent), simulated with every fitted law.
    #[arg(long, value_name = "FILE")]
    pub validate: Option<PathBuf>,
}

/// Read one experiment with `ec`'s mapping from `path`.
fn load(ec: &ExperimentConfig, name: &str, path: &Path) -> Result<Experiment> {
    check_data_file(path, &format!("record of [[experiment]] '{}'", ec.name))?;
    let mut names = vec![ec.time.as_str(), &ec.position, &ec.command];
    if let Some(r) = &ec.reference {
        names.push(r);
    }
    let mut cols = hd_io::read_columns(path, &names)?;
    // An open-loop record has no reference: the position stands in (no law reads it).
    let reference: Vec<f64> = if ec.reference.is_some() {
        cols.pop().unwrap_or_default().iter().map(|x| x * ec.position_scale).collect()
    } else {
        cols[1].iter().map(|x| x * ec.position_scale).collect()
    };
    let disturbance = match &ec.disturbance {
        None => Vec::new(),
        Some(col) => match hd_io::read_columns(path, &[col.as_str()]) {
            Ok(mut v) => v.pop().unwrap_or_default(),
            Err(hd_io::IoError::Format { message, .. }) if message.starts_with("missing") => {
                Vec::new()
            }
            Err(e) => return Err(e.into()),
        },
    };
    let command: Vec<f64> =
        cols.pop().unwrap_or_default().iter().map(|u| u * ec.command_scale).collect();
    let position: Vec<f64> =
        cols.pop().unwrap_or_default().iter().map(|x| x * ec.position_scale).collect();
    let t = cols.pop().unwrap_or_default();
    let disturbance = disturbance.iter().map(|u| u * ec.command_scale).collect();
    let e = Experiment::new(
        name,
        &path.display().to_string(),
        t,
        position,
        reference,
        command,
        disturbance,
    )?;
    // A dead encoder or an amplifier that was off: nothing to fit.
    files::refuse_dead(path, &[(&ec.position, &e.position), (&ec.command, &e.command)])?;
    Ok(e)
}

/// A number of the configuration, or a scalar variable of `file`.
pub fn resolve(v: &NumberOrVariable, key: &str, file: &Path) -> Result<f64> {
    match v {
        NumberOrVariable::Number(x) => Ok(*x),
        NumberOrVariable::Variable(name) => {
            let col = hd_io::read_columns(file, &[name.as_str()])
                .with_context(|| format!("{key} = \"{name}\""))?;
            match col[0].as_slice() {
                [x] => Ok(*x),
                other => Err(anyhow!(
                    "{}: {key} = \"{name}\" names a column of {} values; expected a scalar",
                    file.display(),
                    other.len()
                )),
            }
        }
    }
}

/// A spinner with the elapsed time and `message`, ticking on its own; plain lines on
/// stderr when it is not a terminal and the run takes more than 2 s ([`progress`]).
pub fn spinner(message: String) -> progress::Progress {
    progress::Progress::start(message)
}

/// Run `hdw fit drive`: every file it reads and every number of the configuration checked
/// first; then, with the output folder locked against a second fit, the fit; then the
/// plots an earlier fit left in the folder that this one did not replace are removed.
pub fn run(args: DriveArgs) -> Result<()> {
    let file = args.config.display().to_string();
    let text = hd_model::text_file::read_text(&args.config, "configuration", MAX_CONFIG_BYTES)
        .map_err(anyhow::Error::msg)?;
    // `transmission = "compliant"`: the compliant drive under voltage tests.
    let transmission = hd_ident::drive::config::transmission_of(&text);
    // Named first: a value of another spelling would have the file read as the other kind
    // and refused for a key of the kind it meant ("unknown field 'current'").
    if let Some(t) = transmission.as_deref().filter(|t| !matches!(*t, "rigid" | "compliant")) {
        bail!("{file}, transmission: '{t}'; expected \"rigid\" or \"compliant\" (lower case)");
    }
    let compliant = transmission.as_deref() == Some("compliant");
    let cfg = if compliant {
        files::check_compliant(&args, &text)?;
        None
    } else {
        let cfg = DriveConfig::parse(&text, &file)?;
        let base = args.config.parent().unwrap_or(Path::new("."));
        for e in &cfg.experiment {
            check_data_file(
                &base.join(&e.file),
                &format!("record of [[experiment]] '{}'", e.name),
            )?;
        }
        Some(cfg)
    };
    if let Some(v) = &args.validate {
        check_data_file(v, "--validate record")?;
    }
    let created = abort::missing_folders(&args.out);
    let dir = ensure_dir(&args.out)?;
    let lock = dir.join(".hdw-fit.lock");
    let _lock = hd_io::lock::lock_folder(&lock, "a fit")?;
    // An abort (a failed allocation, kill -ABRT) leaves neither the lock nor a folder made here.
    abort::arm(&lock, &created);
    let earlier = EarlierOutputs::scan(&dir, files::is_fit_output);
    match cfg {
        None => super::fit_drive_compliant::run(&args, &text)?,
        Some(cfg) => rigid(&args, cfg, file)?,
    }
    earlier.remove_stale();
    Ok(())
}

/// The fit of a rigid drive (`cfg`, checked, read from `file`).
fn rigid(args: &DriveArgs, cfg: DriveConfig, file: String) -> Result<()> {
    use hd_ident::drive::config::validate;
    let base = args.config.parent().unwrap_or(Path::new("."));
    let axis = cfg.axis(&file)?;
    let mut experiments: Vec<Experiment> = cfg
        .experiment
        .iter()
        .map(|ec| load(ec, &ec.name, &base.join(&ec.file)))
        .collect::<Result<_>>()?;
    let first = base.join(&cfg.experiment[0].file);
    let gain = resolve(&cfg.gain, "gain", &first)?;
    validate::positive(&file, "gain", gain, "the drive gain")?;
    let (kp, kv) = match &cfg.controller {
        Some(c) => {
            let kp = resolve(&c.kp, "[controller] kp", &first)?;
            let kv = resolve(&c.kv, "[controller] kv", &first)?;
            validate::gain(&file, "[controller] kp", kp)?;
            validate::gain(&file, "[controller] kv", kv)?;
            (kp, kv)
        }
        None => (0.0, 0.0),
    };
    let rows = experiments.iter().map(Experiment::len).min().unwrap_or(0);
    validate::with_records(&cfg, &file, experiments[0].h, rows)?;
    let mut validation = match &args.validate {
        Some(p) => Some(load(&cfg.experiment[0], "validation", p)?),
        None => None,
    };
    let (controller, checks) = setup::controller(&cfg, &file, kp, kv, &experiments)?;
    // A controller that does not reproduce the recorded command is said first: the fit
    // simulates it, so a wrong gain, scale or sign bends every parameter (or stops the fit).
    let doubt = controller_doubt(&controller, &checks, &experiments);
    for d in &doubt {
        eprintln!("warning: {d}");
    }
    // A law that cannot be fitted names the failed check before its own error.
    let failed = |law: FrictionLaw, e: anyhow::Error| -> anyhow::Error {
        if doubt.is_empty() {
            e.context(format!("{} friction", law.name()))
        } else {
            e.context(format!("{} {} friction", doubt.join(" "), law.name()))
        }
    };
    if controller.open_loop.is_some() {
        // Where an open-loop fit restarts its segments: the start's own filter.
        let o = cfg.idim();
        for e in experiments.iter_mut().chain(validation.as_mut()) {
            e.estimate_speed(o.order, o.cutoff_hz);
        }
    }
    // A disturbance column's units, as each record's own command shows them.
    let disturbance: Vec<DisturbanceCheck> = experiments
        .iter_mut()
        .chain(validation.as_mut())
        .filter(|_| controller.open_loop.is_none())
        .filter_map(|e| settle_units(&controller, e, gain))
        .collect();
    for d in &disturbance {
        eprintln!("{}", d.sentence);
    }
    let outputs = setup::noise(&cfg, &file, gain, &experiments)?;
    let laws = cfg.laws(&file)?;
    let out_kinds: Vec<_> = outputs.iter().map(|o| o.0).collect();

    let dir = args.out.clone();

    let bar = spinner(format!("fitting {} law(s)", laws.len()));
    let fit_all = |specs: &[FitSpec]| -> Vec<(Result<DriveFit, _>, f64)> {
        specs
            .par_iter()
            .map(|spec| {
                let t0 = Instant::now();
                let progress = |it: usize, cost: f64| {
                    bar.set_message(format!(
                        "{}: iteration {it}, cost {cost:.6e}",
                        spec.law.name()
                    ));
                };
                let fit = fit_drive(spec, &experiments, &progress);
                (fit, t0.elapsed().as_secs_f64())
            })
            .collect()
    };
    // Stage 1: the Coulomb–viscous laws (those asked for, and the bases of the LuGre laws,
    // which start from them); stage 2: the LuGre laws from their bases' fits.
    let mut bases: Vec<FrictionLaw> = Vec::new();
    for law in laws.iter().map(|l| l.base()) {
        if !bases.contains(&law) {
            bases.push(law);
        }
    }
    // One law's fit set-up: its start from the inverse model, or from its base law's fit.
    let spec = |law: FrictionLaw, idim: Option<&IdimFit>, base: Option<&DriveFit>| {
        setup::spec(&cfg, &file, law, &controller, gain, &outputs, idim, base, &experiments)
    };
    let mut idims = Vec::new();
    let mut base_specs = Vec::new();
    for &law in &bases {
        let idim = setup::start(&cfg, law, gain, &experiments)?;
        files::idim_in_bounds(&cfg, &file, idim.as_ref())?;
        base_specs.push(spec(law, idim.as_ref(), None)?);
        idims.push(idim);
    }
    let mut base_fits = Vec::new();
    for ((fit, secs), spec) in fit_all(&base_specs).into_iter().zip(&base_specs) {
        base_fits.push((fit.map_err(|e| failed(spec.law, e.into()))?, secs));
    }
    let lugre: Vec<FrictionLaw> = laws.iter().copied().filter(|l| l.is_lugre()).collect();
    let mut lugre_specs = Vec::new();
    for &law in &lugre {
        let b = bases.iter().position(|&l| l == law.base()).unwrap_or(0);
        lugre_specs.push(spec(law, idims[b].as_ref(), Some(&base_fits[b].0))?);
    }
    // Each LuGre law from its Stribeck starts (setup::stribeck_variants), all in parallel;
    // the lower cost is kept, a start that fails is dropped while another succeeds.
    let variants: Vec<(usize, FitSpec)> = lugre_specs
        .iter()
        .enumerate()
        .flat_map(|(k, s)| setup::stribeck_variants(&cfg, s).into_iter().map(move |v| (k, v)))
        .collect();
    let variant_specs: Vec<FitSpec> = variants.iter().map(|v| v.1.clone()).collect();
    let mut best: Vec<Option<(Result<DriveFit, _>, f64)>> =
        (0..lugre_specs.len()).map(|_| None).collect();
    for ((k, _), (fit, secs)) in variants.iter().zip(fit_all(&variant_specs)) {
        let keep = match (&best[*k], &fit) {
            (None, _) | (Some((Err(_), _)), Ok(_)) => true,
            (Some((Ok(b), _)), Ok(f)) => f.cost < b.cost,
            _ => false,
        };
        // The starts run side by side: the law's time is the longest.
        let total = secs.max(best[*k].as_ref().map(|b| b.1).unwrap_or(0.0));
        if keep {
            best[*k] = Some((fit, total));
        } else if let Some(b) = best[*k].as_mut() {
            b.1 = total;
        }
    }
    let mut lugre_fits = Vec::new();
    for (b, spec) in best.into_iter().zip(&lugre_specs) {
        let (fit, secs) = b.ok_or_else(|| anyhow!("{}: no start", spec.law.name()))?;
        lugre_fits.push((fit.map_err(|e| failed(spec.law, e.into()))?, secs));
    }
    {
        use super::fit_drive_nested::{Stage, keep_nested};
        let (b, l) = (&mut base_fits, &mut lugre_fits);
        let mut stages = [
            Stage { laws: &bases, specs: &base_specs, fits: b },
            Stage { laws: &lugre, specs: &lugre_specs, fits: l },
        ];
        keep_nested(&mut stages, fit_all);
    }
    bar.set_message("scoring and writing the outputs".into());

    let mut starts = Vec::new();
    let mut fitted = Vec::new();
    for &law in &laws {
        let b = bases.iter().position(|&l| l == law.base()).unwrap_or(0);
        let (spec, (fit, secs)) = if law.is_lugre() {
            let k = lugre.iter().position(|&l| l == law).unwrap_or(0);
            (&lugre_specs[k], lugre_fits[k].clone())
        } else {
            (&base_specs[b], base_fits[b].clone())
        };
        let start_scores = score_all(law, &spec.start, &controller, gain, &experiments, &out_kinds);
        // A LuGre law starts from its base's fit, not from an inverse model of its own.
        let idim = if law.is_lugre() { None } else { idims[b].clone() };
        starts.push((idim, start_scores, spec.start.clone()));
        let val = validation.as_ref().map(|v| {
            score_all(law, &fit.values, &controller, gain, std::slice::from_ref(v), &out_kinds)
                .remove(0)
        });
        fitted.push((fit, secs, val));
    }
    let outcome = Outcome {
        config: file,
        axis,
        gain,
        controller,
        checks,
        doubt,
        disturbance,
        outputs,
        experiments,
        validation,
        starts,
        fitted,
    };
    write_outputs(&dir, &outcome, &bar)
}

/// The controller check judged: for each closed-loop record whose recorded command the
/// configured controller (at its delay) leaves more than the limit of, one sentence naming
/// the likely gain, scale or sign (hd-ident `command_check`).
fn controller_doubt(
    controller: &Controller,
    checks: &[Reproduction],
    experiments: &[Experiment],
) -> Vec<String> {
    if controller.open_loop.is_some() {
        return Vec::new();
    }
    let percent = checks.iter().find(|c| c.delay == controller.delay).map_or(0.0, |c| c.percent);
    experiments
        .iter()
        .filter_map(|e| {
            let recorded = Recorded {
                source: &e.source,
                command: &e.command,
                disturbance: Some(&e.disturbance),
                scales: "position_scale and command_scale",
            };
            command_check(controller, &recorded, &e.position, &e.reference, percent, "position")
        })
        .collect()
}
