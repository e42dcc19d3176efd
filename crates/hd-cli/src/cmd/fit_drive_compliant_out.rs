//! The outputs of a compliant-drive fit: fit.json, params.toml (a params file `hdw simulate
//! --params` runs), report.md with plots, series.parquet with the residual analysis, and
//! the summary printed to the terminal. All of them land together or not at all. Scores
//! count every sample (a compliant configuration has no `[score]` table).

use super::fit_drive_compliant_loop::LoopInfo;
use super::fit_drive_out::pair_plots;
use super::fit_drive_out::resid::{self, OutputPair, RecordRun};
use anyhow::Result;
use hd_ident::drive::compliant::fit::{CompliantSpec, RecordScore, Signal, simulate_on_zeros};
use hd_ident::drive::compliant::model::ix::{TC_NEG, TC_NEG_L, TS_NEG, TS_NEG_L};
use hd_ident::drive::compliant::model::{gear_law, in_drive};
use hd_ident::drive::compliant::units::{parameter_unit, signal_unit};
use hd_ident::drive::compliant::{CompliantFit, NAMES, VoltageRecord};
use hd_ident::drive::model::Axis;
use hd_ident::drive::score_rule::ScoreRule;
use serde_json::{Map, Value, json};
use std::fmt::Write as _;
use std::path::Path;

/// Everything the compliant fit computed.
pub struct Outcome {
    /// The configuration file.
    pub config: String,
    /// What was fitted (start, bounds, outputs with their noise levels, substeps).
    pub spec: CompliantSpec,
    /// The fitted records.
    pub records: Vec<VoltageRecord>,
    /// The validation record.
    pub validation: Option<VoltageRecord>,
    /// The fit.
    pub fit: CompliantFit,
    /// Wall time of the fit [s].
    pub secs: f64,
    /// Scores of the start values on the fitted records.
    pub start_scores: Vec<RecordScore>,
    /// Scores of the fitted drive on the validation record.
    pub validation_scores: Option<RecordScore>,
    /// The loop of closed-loop records (None for voltage tests).
    pub controller: Option<LoopInfo>,
    /// The axis, whose units the outputs carry.
    pub axis: Axis,
    /// Whether the configuration named `voltage_between` (else the default, `hold`).
    pub between_given: bool,
}

/// The unit of output `o` on `axis`: the command's is the amplifier's (V or A).
fn unit_of(o: Signal, ctl: Option<&LoopInfo>, axis: Axis) -> &'static str {
    match (o, ctl) {
        (Signal::Command, Some(c)) => c.amplifier.unit(),
        _ => signal_unit(o, axis),
    }
}

fn scores_json(s: &RecordScore, ctl: Option<&LoopInfo>, axis: Axis) -> Value {
    let mut m = Map::new();
    for (o, sc, noise, ratio) in &s.outputs {
        let mut v = json!({"rel_error": sc.rel_error, "rmse": sc.rmse,
                           "fit_percent": sc.fit_percent, "noise": noise,
                           "rmse_over_noise": ratio, "unit": unit_of(*o, ctl, axis)});
        let offset = match o {
            Signal::Motor => Some(s.encoder_offsets[0]),
            Signal::Load => Some(s.encoder_offsets[1]),
            Signal::Current | Signal::Command => None,
        };
        if let Some(x) = offset {
            v["encoder_offset"] = json!(x);
        }
        if let (Signal::Current, Some(x)) = (o, s.current_offset) {
            v["sensor_offset"] = json!(x);
        }
        m.insert(o.name().into(), v);
    }
    Value::Object(m)
}

/// `{record name: {output: scores}}`, as the rigid fit's fit.json has them.
fn records_json(v: &[RecordScore], ctl: Option<&LoopInfo>, axis: Axis) -> Value {
    Value::Object(v.iter().map(|s| (s.name.clone(), scores_json(s, ctl, axis))).collect())
}

fn fmt_score(s: &RecordScore, ctl: Option<&LoopInfo>, axis: Axis) -> String {
    s.outputs
        .iter()
        .map(|(o, sc, noise, ratio)| {
            format!(
                "{} rmse {:.3e} {} ({ratio:.2}× the noise {noise:.2e}), fit {:.2} %",
                o.name(),
                sc.rmse,
                unit_of(*o, ctl, axis),
                sc.fit_percent
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The fitted drive simulated on `r`: every compared output, measured and simulated, and
/// the input that drives it (the reference in a loop, else the voltage).
fn run_of(o: &Outcome, r: &VoltageRecord, set: &'static str) -> RecordRun {
    let (sim, _, _) = simulate_on_zeros(&o.spec, &o.spec.drive(o.fit.values), r);
    let outputs = o
        .spec
        .outputs
        .iter()
        .filter_map(|(s, _)| {
            let meas = s.measured(r)?;
            Some(OutputPair {
                name: s.name().to_string(),
                unit: unit_of(*s, o.controller.as_ref(), o.axis).to_string(),
                measured: meas.to_vec(),
                simulated: s.simulated(&sim).to_vec(),
            })
        })
        .collect();
    let (input_name, input_unit, input) = match (&r.closed, &o.controller) {
        (Some(c), Some(l)) => ("reference", l.position_unit, c.reference.clone()),
        _ => ("voltage", "V", r.u.clone()),
    };
    RecordRun {
        experiment: r.name.clone(),
        set,
        model: "compliant".into(),
        t: r.t.clone(),
        h: r.h,
        input_name: input_name.into(),
        input_unit: input_unit.into(),
        input,
        outputs,
    }
}

/// Measured against simulated, and the residuals, of every compared output of `run`, as
/// `prefix<output>.svg` and `prefix residuals-<output>.svg`.
fn plots(dir: &Path, run: &RecordRun, prefix: &str) -> Result<Vec<String>> {
    let mut files = Vec::new();
    for p in &run.outputs {
        let what = (run.experiment.as_str(), p.name.as_str(), p.unit.as_str(), "compliant drive");
        files.extend(pair_plots(dir, prefix, what, &run.t, &p.measured, &p.simulated)?);
    }
    Ok(files)
}

/// Write fit.json, params.toml, report.md and the plots, renamed into place together at the
/// end (or none, on an error); print the report.
pub fn write_outputs(dir: &Path, o: &Outcome) -> Result<()> {
    hd_io::atomic::group(|| write_all(dir, o))
}

fn write_all(dir: &Path, o: &Outcome) -> Result<()> {
    let f = &o.fit;
    let sp = &o.spec;
    let ctl = o.controller.as_ref();
    let law = gear_law(&f.values);
    // The gear law's parameters (and the load-side law's where the drive has one); the
    // negative-side friction levels only where they are the drive's own (a symmetric fit's
    // follow Tc and Ts).
    let shown = |k: usize| {
        in_drive(k, &f.values)
            && !(sp.symmetric_friction && [TC_NEG, TS_NEG].contains(&k))
            && !(sp.symmetric_load_friction && [TC_NEG_L, TS_NEG_L].contains(&k))
    };
    // A fit in doubt (it does not reach the noise, a scale or the controller check fails):
    // what the records would determine is "in_doubt", and nothing "determined".
    let doubt = !f.doubt.is_empty();
    let parameters: Map<String, Value> = NAMES
        .iter()
        .enumerate()
        .filter(|(k, _)| shown(*k))
        .map(|(k, n)| {
            (
                n.to_string(),
                json!({"value": f.values[k], "std_error": f.std_errors[k], "free": f.free[k],
                       "held": f.held.contains(&k), "determined": f.determined[k] && !doubt,
                       "in_doubt": f.determined[k] && doubt,
                       "start": sp.start[k], "unit": parameter_unit(n, o.axis)}),
            )
        })
        .collect();
    // Where the configuration is wherever one reads fit.json from (hdw design re-reads it).
    let config_absolute = std::fs::canonicalize(&o.config).ok().map(|p| p.display().to_string());
    let doc = json!({
        "config": o.config,
        "config_absolute": config_absolute,
        "transmission": "compliant",
        "stiffness": law.name(),
        "N": sp.n,
        "axis": o.axis.name(),
        "voltage_between": if ctl.is_some() { "hold" } else { sp.between.name() },
        "voltage_between_from": if ctl.is_some() { "loop" } else if o.between_given { "configuration" } else { "default" },
        "current_sampled": o.records.first().map_or("after", |r| r.current_sampled.name()),
        "in_doubt": doubt,
        "doubt": f.doubt,
        "substeps": sp.substeps,
        "km_equals_ke": sp.km_is_ke,
        "directional_friction": !sp.symmetric_friction,
        "directional_load_friction": !sp.symmetric_load_friction,
        "friction_velocity": sp.friction_velocity.name(),
        "wall_time_s": o.secs,
        "stage_seconds": f.stage_seconds.iter().map(|(stage, s)| serde_json::json!({ "stage": stage, "seconds": s })).collect::<Vec<_>>(),
        "starts": f.starts,
        "iterations": f.iterations,
        "failed_trials": f.failed_trials,
        "termination": f.termination,
        "cost": f.cost,
        "residuals": f.n,
        "parameters": parameters,
        "determination": f.determination.sentences,
        "best": "compliant",
        "experiments": records_json(&f.scores, ctl, o.axis),
        "start_scores": records_json(&o.start_scores, ctl, o.axis),
        "validation": o.validation_scores.as_ref().map(|s| scores_json(s, ctl, o.axis)),
        "controller": o.controller.as_ref().map(|c| c.json()),
    });

    // params.toml: a params file of `hdw simulate` (variant full, the fitted gear law).
    let mut params = format!(
        "# Compliant drive fitted by `hdw fit drive --config {}`.\n# A params file for `hdw simulate --params` (variant full, stiffness law {}).\n# Parameters the records do not determine are listed in fit.json and report.md.\n\nstiffness = \"{}\"\nfriction_velocity = \"{}\"\nN = {:e}\n",
        o.config,
        law.name(),
        law.name(),
        sp.friction_velocity.name(),
        sp.n
    );
    if o.axis == Axis::Linear {
        params.insert_str(
            params.find("\n\n").unwrap_or(0),
            "\n# A linear axis: past the gear, positions in m, forces in N, the load's mass in kg and\n# N in rad/m (the simulator's own labels, rad and N·m, stand for them).",
        );
    }
    for (k, n) in NAMES.iter().enumerate().filter(|(k, _)| shown(*k)) {
        let _ = writeln!(params, "{n} = {:e}", f.values[k]);
    }

    // Every record simulated: the series, the plots (first record and validation) and
    // the residual analysis of each.
    let rule = ScoreRule::default();
    let mut series = hd_io::FitSeries::default();
    let (mut figs, mut verdicts, mut analysis) = (Vec::new(), Vec::new(), Map::new());
    let sets = o.records.iter().map(|r| (r, "estimation"));
    for (j, (rec, set)) in sets.chain(o.validation.iter().map(|v| (v, "validation"))).enumerate() {
        let run = run_of(o, rec, set);
        resid::add_series(&mut series, &run, &rule);
        let prefix = match (set, j) {
            ("validation", _) => "validation-".to_string(),
            (_, 0) => String::new(),
            _ => format!("{}-", rec.name),
        };
        if j == 0 || set == "validation" {
            figs.extend(plots(dir, &run, &prefix)?);
        }
        let a = resid::analyse_record(dir, &prefix, &run, &rule)?;
        figs.extend(a.figs);
        verdicts.extend(a.lines);
        analysis.insert(rec.name.clone(), a.json);
    }
    hd_io::write_fit_series(&dir.join("series.parquet"), &series)?;
    let mut doc = doc;
    doc["residual_analysis"] = json!({"law": "compliant", "records": analysis});
    doc["score_rule"] = json!({"name": rule.name, "skip_first": 0, "skip_last": 0,
        "metric": rule.metric, "description": rule.describe()});

    let mut r = String::new();
    let _ = writeln!(r, "# Compliant drive fit: {}\n", o.config);
    let _ = writeln!(
        r,
        "{} record(s), {} residuals; {}, {} Runge–Kutta substeps per sample; {} start(s) of the full fit, {} iterations in {:.2} s; {}.\n",
        o.records.len(),
        f.n,
        if ctl.is_some() {
            "closed loop, the command held over each sample".to_string()
        } else {
            format!(
                "voltage read `{}` between samples{}, current read {} the new voltage",
                sp.between.name(),
                if o.between_given { "" } else { " (the default)" },
                o.records.first().map_or("after", |r| r.current_sampled.name())
            )
        },
        sp.substeps,
        f.starts,
        f.iterations,
        o.secs,
        f.termination
    );
    if !f.stage_seconds.is_empty() {
        let stages: Vec<String> =
            f.stage_seconds.iter().map(|(stage, s)| format!("{stage} {s:.2} s")).collect();
        let _ = writeln!(r, "Time by stage: {}.\n", stages.join("; "));
    }
    if let Some(c) = &o.controller {
        let _ = writeln!(r, "## The loop\n");
        for l in c.lines() {
            let _ = writeln!(r, "- {l}");
        }
        let _ = writeln!(r);
    }
    if o.axis == Axis::Linear {
        let _ = writeln!(
            r,
            "A linear axis: the load's position in m, forces past the gear in N, its mass in kg, N = {:e} rad/m.\n",
            sp.n
        );
    }
    if doubt {
        let _ = writeln!(r, "**The fit is in doubt.**\n");
        for d in &f.doubt {
            let _ = writeln!(r, "- {d}");
        }
        let _ = writeln!(r);
    }
    let _ = writeln!(r, "| parameter | start | value | std. error | determined | unit |");
    let _ = writeln!(r, "|---|---:|---:|---:|---|---|");
    for (k, n) in NAMES.iter().enumerate().filter(|(k, _)| shown(*k)) {
        let se = match (f.free[k], f.held.contains(&k), f.std_errors[k]) {
            (false, _, _) => "fixed".to_string(),
            (true, true, _) => "held".to_string(),
            (true, false, Some(s)) => format!("{s:.3e}"),
            (true, false, None) => "—".to_string(),
        };
        let det = match (f.free[k], f.determined[k], doubt) {
            (false, _, _) => "",
            (true, true, true) => "in doubt",
            (true, true, false) => "yes",
            (true, false, _) => "no",
        };
        let _ = writeln!(
            r,
            "| {n} | {:.4e} | {:.4e} | {se} | {det} | {} |",
            sp.start[k],
            f.values[k],
            parameter_unit(n, o.axis)
        );
    }
    let _ = writeln!(r, "\n## What the records determine\n");
    for s in &f.determination.sentences {
        let _ = writeln!(r, "- {s}");
    }
    let _ = writeln!(r, "\n## Scores\n");
    for (s, s0) in f.scores.iter().zip(&o.start_scores) {
        let _ = writeln!(r, "- {} (fitted): {}", s.name, fmt_score(s, ctl, o.axis));
        let _ = writeln!(r, "- {} (start): {}", s0.name, fmt_score(s0, ctl, o.axis));
    }
    if let Some(v) = &o.validation_scores {
        let _ = writeln!(r, "- validation: {}", fmt_score(v, ctl, o.axis));
    }
    let _ = writeln!(r, "\nScores count every sample (score rule {}).", rule.describe());
    let _ = writeln!(r, "\n## Residual analysis\n");
    let _ = writeln!(
        r,
        "Per output: the residuals' autocorrelation and their cross-correlation with the input against the 99 % bounds of white noise, and the frequency response from the input, measured and simulated (docs/fit-drive.md). The measured and simulated outputs are in series.parquet.\n"
    );
    for v in &verdicts {
        let _ = writeln!(r, "- {v}");
    }
    let _ = writeln!(r, "\n## Plots\n");
    for fig in &figs {
        let _ = writeln!(r, "![{fig}]({fig})");
    }

    super::fit_drive_out::finish(dir, &doc, &params, &r)
}
