//! The outputs of `hdw fit drive`: fit.json, params.toml, report.md with plots,
//! series.parquet with the residual analysis, and the summary printed to the terminal.
//! Everything is computed before the first file is written. Scores follow the
//! configuration's `[score]` rule, with the all-samples score beside each.

#[path = "fit_drive_resid.rs"]
pub mod resid;
#[path = "fit_drive_stream.rs"]
pub mod stream;

use super::common::{staged_plot, write_json};
use super::fit_drive::progress::Progress;
use anyhow::Result;
use hd_ident::drive::score_rule::{RuledScore, ScoreRule};
use hd_ident::drive::{
    Axis, Controller, DisturbanceCheck, DriveConfig, DriveFit, Experiment, ExperimentScore,
    IdimFit, OutputKind, Reproduction,
};
use hd_plot::{Series, ThinnedCurve, line_plot};
use serde_json::{Map, Value, json};
use std::fmt::Write as _;
use std::path::Path;
use stream::{Feed, OutputTrace};

/// Everything `hdw fit drive` computed.
pub struct Outcome {
    /// The configuration file.
    pub config: String,
    /// The axis.
    pub axis: Axis,
    /// Nominal drive gain [N/V].
    pub gain: f64,
    /// The controller (with the delay used).
    pub controller: Controller,
    /// Reproduction of the recorded command per delay.
    pub checks: Vec<Reproduction>,
    /// Why the fit is in doubt (a controller check that fails), said first; empty when not.
    pub doubt: Vec<String>,
    /// The units found for each record's disturbance column.
    pub disturbance: Vec<DisturbanceCheck>,
    /// Outputs and noise levels.
    pub outputs: Vec<(OutputKind, f64)>,
    /// The fitted experiments.
    pub experiments: Vec<Experiment>,
    /// The validation record.
    pub validation: Option<Experiment>,
    /// Per law: the inverse-model start (none for a LuGre law, which starts from its base
    /// law's fit), the closed-loop scores of the start, and the start values.
    pub starts: Vec<(Option<IdimFit>, Vec<ExperimentScore>, Vec<f64>)>,
    /// Per law: the fit, its time [s], its validation scores.
    pub fitted: Vec<(DriveFit, f64, Option<ExperimentScore>)>,
}

fn unit_of(axis: Axis, o: OutputKind) -> &'static str {
    match o {
        OutputKind::Force => axis.force_unit(),
        OutputKind::Position => axis.position_unit(),
    }
}

/// One record's scores by the rule: (record name, per output its kind and scores).
type Ruled = (String, Vec<(OutputKind, RuledScore)>);

/// `{output: {rel_error, rmse, fit_percent (by the rule), rule, samples, all_samples}}`.
pub fn scores_json(s: &Ruled, rule: &ScoreRule) -> Value {
    let mut m = Map::new();
    for (o, sc) in &s.1 {
        let (r, a) = (sc.rule, sc.all);
        m.insert(
            o.name().into(),
            json!({"rel_error": r.rel_error, "rmse": r.rmse, "fit_percent": r.fit_percent,
                   "rule": rule.name, "samples": sc.samples,
                   "all_samples": {"rel_error": a.rel_error, "rmse": a.rmse, "fit_percent": a.fit_percent}}),
        );
    }
    Value::Object(m)
}

fn experiments_json(v: &[Ruled], rule: &ScoreRule) -> Value {
    Value::Object(v.iter().map(|s| (s.0.clone(), scores_json(s, rule))).collect())
}

/// The `[score]` rule of the configuration file `config` (every sample if it cannot be
/// read again).
fn rule_of(config: &str) -> ScoreRule {
    std::fs::read_to_string(config)
        .ok()
        .and_then(|t| DriveConfig::parse(&t, config).ok())
        .map(|c| c.score.rule())
        .unwrap_or_default()
}

fn law_json(
    o: &Outcome,
    fit: &DriveFit,
    secs: f64,
    (scores, val, rule): (&[Ruled], Option<&Ruled>, &ScoreRule),
    rank: usize,
) -> Value {
    let mut params = Map::new();
    for (k, n) in fit.names.iter().enumerate() {
        params.insert(
            n.to_string(),
            json!({"value": fit.values[k], "std_error": fit.std_errors[k], "free": fit.free[k], "unit": o.axis.unit_of(n),
                   "in_doubt": fit.free[k] && !o.doubt.is_empty()}),
        );
    }
    let free: Vec<&str> = fit.names.iter().zip(&fit.free).filter(|x| *x.1).map(|x| *x.0).collect();
    json!({
        "law": fit.law.name(),
        "rank": rank,
        "bic": fit.bic,
        "cost": fit.cost,
        "residuals": fit.n,
        "parameters": params,
        "correlation": {"parameters": free, "matrix": fit.correlation},
        "experiments": experiments_json(scores, rule),
        "validation": val.map(|v| scores_json(v, rule)),
        "determination": fit.determination.sentences,
        "iterations": fit.iterations,
        "failed_trials": fit.failed_trials,
        "termination": fit.termination,
        "seconds": secs,
    })
}

/// One record's scores in words: each by the rule, the all-samples value beside it.
fn fmt_score(s: &Ruled, axis: Axis, rule: &ScoreRule) -> String {
    let tag = if rule.is_all() { "all samples".to_string() } else { format!("{} rule", rule.name) };
    s.1.iter()
        .map(|(o, sc)| {
            let (r, a) = (sc.rule, sc.all);
            let beside = if rule.is_all() {
                String::new()
            } else {
                format!(
                    "; all samples {:.3} %, {:.4e}, {:.2} %",
                    a.rel_error, a.rmse, a.fit_percent
                )
            };
            format!(
                "{} {:.3} % (RMSE {:.4e} {}, fit {:.2} %; {tag}{beside})",
                o.name(),
                r.rel_error,
                r.rmse,
                unit_of(axis, *o),
                r.fit_percent
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// Measured against simulated, and the residuals, of every output of the best law on one
/// record (`traces`, in the order of the outcome's outputs), as SVG files `prefix*.svg`.
fn plots(
    dir: &Path,
    o: &Outcome,
    (record, model): (&str, &str),
    traces: &[OutputTrace],
    prefix: &str,
) -> Result<Vec<String>> {
    let mut files = Vec::new();
    for (&(kind, _), tr) in o.outputs.iter().zip(traces) {
        let Some(curves) = &tr.curves else { continue };
        let what = (record, kind.name(), unit_of(o.axis, kind), model);
        files.extend(thinned_pair_plots(dir, prefix, what, curves)?);
    }
    Ok(files)
}

/// Measured against simulated (`prefix<output>.svg`) and the residual
/// (`prefix residuals-<output>.svg`) of one output; `what` is (record, output, unit, model).
/// Long records are drawn from their min/max envelope ([`hd_plot::ThinnedCurve`] of
/// [`stream::PLOT_BUCKETS`] buckets). Returns the two file names.
pub fn pair_plots(
    dir: &Path,
    prefix: &str,
    what: (&str, &str, &str, &str),
    t: &[f64],
    meas: &[f64],
    sim: &[f64],
) -> Result<Vec<String>> {
    let mut curves = [(); 3].map(|_| ThinnedCurve::new(stream::PLOT_BUCKETS));
    for ((t, a), b) in t.iter().zip(meas).zip(sim) {
        curves[0].push(*t, *a);
        curves[1].push(*t, *b);
        curves[2].push(*t, a - b);
    }
    thinned_pair_plots(dir, prefix, what, &curves)
}

/// [`pair_plots`] of thinned curves: measured, simulated, residual.
fn thinned_pair_plots(
    dir: &Path,
    prefix: &str,
    what: (&str, &str, &str, &str),
    [meas, sim, res]: &[ThinnedCurve; 3],
) -> Result<Vec<String>> {
    let (record, output, unit, model) = what;
    let name = format!("{prefix}{output}.svg");
    let title = format!("{record}: {output} measured and simulated ({model})");
    let series = |name: &str, c: &ThinnedCurve| {
        let (x, y) = c.points();
        Series::new(name, x, y)
    };
    let curves = [series("measured", meas), series("simulated", sim)];
    let y_label = format!("{output} [{unit}]");
    staged_plot(&dir.join(&name), |p| line_plot(p, &title, "t [s]", &y_label, &curves, false))?;
    let residual_name = format!("{prefix}residuals-{output}.svg");
    let title = format!("{record}: {output} residual, measured − simulated");
    let curve = [series("residual", res)];
    let y_label = format!("residual [{unit}]");
    staged_plot(&dir.join(&residual_name), |p| {
        line_plot(p, &title, "t [s]", &y_label, &curve, false)
    })?;
    Ok(vec![name, residual_name])
}

/// Write fit.json, params.toml, report.md and the plots, all renamed into place together
/// at the end (or none, on an error: an earlier fit's files stay whole); print the summary.
pub fn write_outputs(dir: &Path, o: &Outcome, progress: &Progress) -> Result<()> {
    hd_io::atomic::group(|| write_all(dir, o, progress))
}

fn write_all(dir: &Path, o: &Outcome, progress: &Progress) -> Result<()> {
    let mut order: Vec<usize> = (0..o.fitted.len()).collect();
    order.sort_by(|&a, &b| o.fitted[a].0.bic.total_cmp(&o.fitted[b].0.bic));
    let best = &o.fitted[order[0]].0;
    let mut rank = vec![0; order.len()];
    for (r, &k) in order.iter().enumerate() {
        rank[k] = r + 1;
    }

    // Every law on every record and the validation record, one pass per output: the
    // series (streamed into series.parquet) and the scores by the configuration's rule;
    // the best law's thinned curves and residual sums kept for the plots and the analysis.
    let rule = rule_of(&o.config);
    let units: Vec<String> =
        o.outputs.iter().map(|(k, _)| format!("{}: {}", k.name(), unit_of(o.axis, *k))).collect();
    let mut scored: Vec<(Vec<Ruled>, Option<Ruled>)> = Vec::new();
    // (index among the records, record, set, traces)
    let mut best_traces: Vec<(usize, &Experiment, &'static str, Vec<OutputTrace>)> = Vec::new();
    let series_path = dir.join("series.parquet");
    hd_io::fit_series::stream_fit_series(&series_path, &units.join(", "), |st| {
        for (k, (fit, _, _)) in o.fitted.iter().enumerate() {
            let sets = o.experiments.iter().map(|e| (e, "estimation"));
            let sets = sets.chain(o.validation.iter().map(|v| (v, "validation")));
            let (mut scores, mut val) = (Vec::new(), None);
            for (j, (e, set)) in sets.enumerate() {
                let best = k == order[0];
                let plotted = j == 0 || set == "validation";
                let (mut outs, mut traces) = (Vec::new(), Vec::new());
                for &(kind, _) in &o.outputs {
                    progress.set_message(format!(
                        "series.parquet: {} on {}, {}",
                        fit.law.name(),
                        e.name,
                        kind.name()
                    ));
                    let key = hd_io::fit_series::SeriesKey {
                        experiment: e.name.clone(),
                        set: set.to_string(),
                        model: fit.law.name().to_string(),
                        output: kind.name().to_string(),
                        unit: unit_of(o.axis, kind).to_string(),
                    };
                    let feed = Feed { series: st, key, trace: best.then_some(plotted) };
                    let (sc, tr) =
                        stream::output_pass(o, &rule, (fit.law, &fit.values), e, kind, feed);
                    outs.push((kind, sc));
                    traces.extend(tr);
                }
                let sc = (e.name.clone(), outs);
                if set == "validation" {
                    val = Some(sc)
                } else {
                    scores.push(sc)
                }
                if best {
                    best_traces.push((j, e, set, traces));
                }
            }
            scored.push((scores, val));
        }
    })?;
    let mut start_scores: Vec<Vec<Ruled>> = Vec::new();
    for (k, (fit, _, _)) in o.fitted.iter().enumerate() {
        progress.set_message(format!("scores of the {} start", fit.law.name()));
        let start = (fit.law, o.starts[k].2.as_slice());
        start_scores.push(
            o.experiments
                .iter()
                .map(|e| (e.name.clone(), stream::scores(o, &rule, start, e)))
                .collect(),
        );
    }

    // fit.json
    let laws: Vec<Value> = order
        .iter()
        .map(|&k| {
            let with = (scored[k].0.as_slice(), scored[k].1.as_ref(), &rule);
            law_json(o, &o.fitted[k].0, o.fitted[k].1, with, rank[k])
        })
        .collect();
    let starts: Vec<Value> = o
        .starts
        .iter()
        .zip(&o.fitted)
        .zip(&start_scores)
        .map(|(((idim, _, values), (fit, _, _)), sc)| {
            json!({
                "law": fit.law.name(),
                "from": if fit.law.is_lugre() {
                    Value::from(format!("{} fit", fit.law.base().name()))
                } else {
                    Value::from("idim")
                },
                "values": fit.names.iter().zip(values)
                    .map(|(n, v)| (n.to_string(), json!(v)))
                    .collect::<Map<_, _>>(),
                "idim": idim.as_ref().map(|f| json!({
                    "parameters": f.names.iter().zip(&f.values).zip(&f.std_errors)
                        .map(|((n, v), s)| (n.to_string(), json!({"value": v, "std_error": s})))
                        .collect::<Map<_, _>>(),
                    "rel_error_percent": f.rel_error_percent,
                    "condition": f.condition,
                    "rows": f.rows,
                })),
                "closed_loop": experiments_json(sc, &rule),
            })
        })
        .collect();
    let best_json = &laws[0];
    let mut doc = json!({
        "config": o.config,
        "axis": o.axis.name(),
        "gain": o.gain,
        "controller": {
            "kp": o.controller.kp, "kv": o.controller.kv, "saturation": o.controller.saturation,
            "speed_filter": o.controller.speed_filter, "sample_period": o.controller.h,
            "delay": o.controller.delay,
            "open_loop_segment": o.controller.open_loop,
            "check": o.checks.iter().map(|c| json!({"delay": c.delay, "rms": c.rms, "percent": c.percent})).collect::<Vec<_>>(),
        },
        "disturbance": o.disturbance.iter().map(|d| json!({
            "record": d.record,
            "scale": d.scale,
            "readings": d.readings.iter().map(|r| json!({"reading": r.name, "scale": r.scale, "rms": r.rms, "percent": r.percent})).collect::<Vec<_>>(),
            "sentence": d.sentence,
        })).collect::<Vec<_>>(),
        "noise": o.outputs.iter().map(|(k, s)| (k.name().to_string(), json!(s))).collect::<Map<_, _>>(),
        "in_doubt": !o.doubt.is_empty(),
        "doubt": o.doubt,
        "best": best.law.name(),
        "parameters": best_json["parameters"],
        "experiments": best_json["experiments"],
        "validation": best_json["validation"],
        "start": starts,
        "laws": laws,
    });

    // params.toml
    let mut params = format!(
        "# {} rigid drive fitted by `hdw fit drive --config {}` (lowest BIC).\n# Units: {}.\nfriction = \"{}\"\n\n[params]\n",
        best.law.name(),
        o.config,
        best.names
            .iter()
            .map(|n| format!("{n} [{}]", o.axis.unit_of(n)))
            .collect::<Vec<_>>()
            .join(", "),
        best.law.name()
    );
    for (n, v) in best.names.iter().zip(&best.values) {
        let _ = writeln!(params, "{n} = {v:e}");
    }

    // plots of the best law (the first record's and the validation's), its residual
    // analysis on every record, the series of every law
    let mut figs = Vec::new();
    let mut analysis = Map::new();
    let mut verdicts = Vec::new();
    for (j, e, set, traces) in &best_traces {
        let prefix = match (*set, j) {
            ("validation", _) => "validation-".to_string(),
            (_, 0) => String::new(),
            _ => format!("{}-", e.name),
        };
        progress.set_message(format!("plots and residual analysis of {}", e.name));
        if *j == 0 || *set == "validation" {
            figs.extend(plots(dir, o, (&e.name, best.law.name()), traces, &prefix)?);
        }
        let mut a = resid::Analysis {
            figs: Vec::new(),
            lines: Vec::new(),
            json: Value::Object(Map::new()),
        };
        let best_law = (best.law, best.values.as_slice());
        stream::analyse_pass(&mut a, dir, &prefix, o, &rule, best_law, e, traces)?;
        figs.extend(a.figs);
        verdicts.extend(a.lines);
        analysis.insert(e.name.clone(), a.json);
    }
    doc["residual_analysis"] = json!({"law": best.law.name(), "records": analysis});
    doc["score_rule"] = json!({"name": rule.name, "skip_first": rule.skip_first,
        "skip_last": rule.skip_last, "metric": rule.metric, "description": rule.describe()});

    // report.md and the terminal summary
    let mut r = String::new();
    let _ = writeln!(r, "# Drive fit: {}\n", o.config);
    if !o.doubt.is_empty() {
        let _ = writeln!(r, "**The fit is in doubt.**\n");
        for d in &o.doubt {
            let _ = writeln!(r, "- {d}");
        }
        let _ = writeln!(r);
    }
    if let Some(segment) = o.controller.open_loop {
        let _ = writeln!(r, "## Open loop\n");
        let _ = writeln!(
            r,
            "No controller: the recorded command drives the model. Multiple shooting: the simulation restarts at the measured position and its low-passed speed every {segment} samples ({:.4} s).\n",
            segment as f64 * o.controller.h
        );
    } else {
        let _ = writeln!(r, "## Controller check\n");
        let _ = writeln!(
            r,
            "The controller (kp {} 1/s, kv {}, saturation ±{}, speed filter {:?}) applied to the recorded position reproduces the recorded command with:\n",
            o.controller.kp, o.controller.kv, o.controller.saturation, o.controller.speed_filter
        );
        let _ = writeln!(
            r,
            "| delay [samples] | residual RMS [command unit] | residual [% of command RMS] |\n|---|---|---|"
        );
        for c in &o.checks {
            let _ = writeln!(r, "| {} | {:.5} | {:.3} |", c.delay, c.rms, c.percent);
        }
        let _ = writeln!(r, "\nDelay used: {} sample(s).\n", o.controller.delay);
    }
    for d in &o.disturbance {
        let _ = writeln!(r, "Disturbance column, {}.\n", d.sentence);
    }
    let _ = writeln!(
        r,
        "Noise levels: {}.\n",
        o.outputs
            .iter()
            .map(|(k, s)| format!("{} {s:.4e} {}", k.name(), unit_of(o.axis, *k)))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        r,
        "Scores: relative error ‖y − ŷ‖/‖y‖, RMSE and fit 100·(1 − ‖y − ŷ‖/‖y − ȳ‖), by the rule {}{}.\n",
        rule.describe(),
        if rule.is_all() { "" } else { ", each followed by the same three over all samples" }
    );
    let _ = writeln!(r, "## Inverse-model start (IDIM-LS)\n");
    for (((idim, _, values), (fit, _, _)), sc) in o.starts.iter().zip(&o.fitted).zip(&start_scores)
    {
        if let Some(f) = idim {
            let vals: Vec<String> = f
                .names
                .iter()
                .zip(&f.values)
                .zip(&f.std_errors)
                .map(|((n, v), s)| format!("{n} = {v:.4} ± {s:.4} {}", o.axis.unit_of(n)))
                .collect();
            let _ = writeln!(
                r,
                "- {}: {} (relative error of the filtered force {:.3} %, {} rows)",
                fit.law.name(),
                vals.join(", "),
                f.rel_error_percent,
                f.rows
            );
        } else if fit.law.is_lugre() {
            let start: Vec<String> =
                fit.names.iter().zip(values).map(|(n, v)| format!("{n} = {v:.5}")).collect();
            let _ = writeln!(
                r,
                "- {}: from the {} output-error fit and the LuGre start values (docs/fit-drive.md): {} (a second start puts Fs 20 % below Fc)",
                fit.law.name(),
                fit.law.base().name(),
                start.join(", ")
            );
        }
        for s in sc {
            let _ = writeln!(
                r,
                "  - closed loop with these values on {}: {}",
                s.0,
                fmt_score(s, o.axis, &rule)
            );
        }
    }
    let _ = writeln!(r, "\n## Output-error fits, ranked by BIC\n");
    for &k in &order {
        let (fit, secs, _) = &o.fitted[k];
        let _ = writeln!(
            r,
            "### {}. {} (BIC {:.1}, {} iterations, {:.2} s)\n",
            rank[k],
            fit.law.name(),
            fit.bic,
            fit.iterations,
            secs
        );
        let _ = writeln!(r, "| parameter | value | std. error | unit |\n|---|---|---|---|");
        for (j, n) in fit.names.iter().enumerate() {
            let se = match (fit.free[j], fit.std_errors[j]) {
                (false, _) => "fixed".to_string(),
                (true, Some(s)) if !o.doubt.is_empty() => format!("{s:.4} (in doubt)"),
                (true, Some(s)) => format!("{s:.4}"),
                (true, None) => "not determined".to_string(),
            };
            let _ = writeln!(r, "| {n} | {:.4} | {se} | {} |", fit.values[j], o.axis.unit_of(n));
        }
        let _ = writeln!(r);
        for s in &scored[k].0 {
            let _ = writeln!(r, "- {}: {}", s.0, fmt_score(s, o.axis, &rule));
        }
        if let Some(v) = &scored[k].1 {
            let _ = writeln!(r, "- validation ({}): {}", v.0, fmt_score(v, o.axis, &rule));
        }
        for s in &fit.determination.sentences {
            let _ = writeln!(r, "- {s}");
        }
        let _ = writeln!(r);
    }
    let _ = writeln!(r, "## Residual analysis ({})\n", best.law.name());
    let _ = writeln!(
        r,
        "Per output: the residuals' autocorrelation (lags 1–{l}) and their cross-correlation with the input (lags −{l}–{l}) against the 99 % bounds of white noise, ±2.58/√N, over the samples scored; and the frequency response from the input to the output (Welch H1), measured and simulated, over the band where the input has power (docs/fit-drive.md). Every law's measured and simulated outputs are in series.parquet.\n",
        l = resid_lags()
    );
    for v in &verdicts {
        let _ = writeln!(r, "- {v}");
    }
    let _ = writeln!(r);
    let _ = writeln!(r, "## Plots ({})\n", best.law.name());
    for f in &figs {
        let _ = writeln!(r, "![{f}]({f})");
    }

    progress.finish_and_clear();
    finish(dir, &doc, &params, &r)
}

/// Lags of the residual analysis [samples].
fn resid_lags() -> usize {
    hd_ident::drive::residual_analysis::DEFAULT_LAGS
}

/// Write fit.json, params.toml and report.md into `dir` (atomically, with the rest of the
/// command's group) and print the report.
pub fn finish(dir: &Path, doc: &Value, params: &str, report: &str) -> Result<()> {
    write_json(&dir.join("fit.json"), doc)?;
    for (name, text) in [("params.toml", params), ("report.md", report)] {
        let path = dir.join(name);
        hd_io::atomic::write_atomically(&path, |f| {
            use std::io::Write;
            f.write_all(text.as_bytes()).map_err(|e| hd_io::IoError::fs(&path, e))
        })?;
    }
    use std::io::Write;
    let _ = writeln!(std::io::stdout().lock(), "{report}");
    Ok(())
}
