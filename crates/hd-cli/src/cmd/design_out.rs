//! The outputs of `hdw design`: input.csv and input.parquet (t [s], u [V], or a closed
//! loop's reference [rad]), design.json,
//! report.md and its plots (the input, its spectrum, the simulated response against the
//! limits, the predicted standard errors beside the defaults').

use super::common::{ensure_dir, write_json};
use super::design_check::Check;
use super::design_load::Loaded;
use anyhow::Result;
use hd_ident::design::criterion::describe_direction;
use hd_ident::design::{Evaluated, Outcome, Prediction, predict};
use hd_ident::drive::compliant::NAMES;
use hd_ident::drive::identifiability::CORRELATION_LIMIT;
use hd_plot::{BarGroup, Series, bar_chart, line_plot};
use serde_json::{Value, json};
use std::fmt::Write as _;
use std::path::Path;

/// A prediction's per-parameter figures: (relative SE, absolute SE, determined).
fn figures(pred: &Prediction, loaded: &Loaded) -> Vec<(Option<f64>, Option<f64>, bool)> {
    let p = &loaded.problem;
    p.free
        .iter()
        .enumerate()
        .map(|(s, &k)| {
            let rel = pred.relative[s];
            (rel, rel.map(|r| r * p.values[k].abs().max(f64::MIN_POSITIVE)), pred.determined[s])
        })
        .collect()
}

/// Peaks of `e` against the limits as JSON.
fn peaks_json(e: &Evaluated, loaded: &Loaded) -> Value {
    let l = &loaded.problem.limits;
    let rows: Vec<Value> = e
        .scaled
        .peaks
        .against(l)
        .into_iter()
        .map(|(n, pk, lim, unit)| json!({"quantity": n, "peak": pk, "limit": lim, "unit": unit, "ratio": pk / lim}))
        .collect();
    // The scaled amplitude is the input's: a voltage [V], or a loop's reference [rad].
    let amplitude = if loaded.problem.closed.is_some() { "amplitude_rad" } else { "amplitude_V" };
    json!({"peaks": rows, "binds": e.scaled.binds, "within": e.scaled.within, amplitude: e.scaled.amplitude,
           "peak_reference_rad": e.scaled.peaks.reference, "peak_current_A": e.scaled.peaks.current, "peak_speed_rad_s": e.scaled.peaks.speed,
           "peak_load_speed_rad_s": e.scaled.peaks.load_speed,
           "peak_deflection_rad": e.scaled.peaks.deflection, "peak_torque_Nm": e.scaled.peaks.torque,
           "peak_load_angle_rad": e.scaled.peaks.load_angle})
}

/// One input's predictions: alone and with the prior.
struct Judged {
    name: String,
    alone: Vec<(Option<f64>, Option<f64>, bool)>,
    together: Vec<(Option<f64>, Option<f64>, bool)>,
    /// With the prior: per free parameter, its strongest correlation (the other's slot, the
    /// correlation), which the fit's rule calls not separable from 0.99 in magnitude.
    strongest: Vec<Option<(usize, f64)>>,
    weakest_variance: f64,
}

/// Per free parameter of `pred`, the other free parameter it correlates with most.
fn strongest(pred: &Prediction) -> Vec<Option<(usize, f64)>> {
    let k = pred.relative.len();
    (0..k)
        .map(|i| {
            (0..k)
                .filter(|&j| j != i && pred.relative[j].is_some())
                .map(|j| (j, pred.correlation[(i, j)]))
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .filter(|_| pred.relative[i].is_some())
        })
        .collect()
}

fn judge(name: &str, e: &Evaluated, loaded: &Loaded, o: &Outcome) -> Judged {
    let p = &loaded.problem;
    let total = predict(&(&p.prior + &e.info), &p.free);
    Judged {
        name: name.into(),
        alone: figures(&predict(&e.info, &p.free), loaded),
        together: figures(&total, loaded),
        strongest: strongest(&total),
        weakest_variance: o.weakest_variance(&p.prior, &e.info),
    }
}

/// Magnitude of the input's spectrum [dB re 1 V] at log-spaced frequencies up to Nyquist.
fn spectrum(u: &[f64], rate: f64) -> (Vec<f64>, Vec<f64>) {
    let n = u.len() as f64;
    let (f0, f1) = (rate / n, 0.5 * rate);
    let m = 300;
    let mut fs = Vec::with_capacity(m);
    let mut db = Vec::with_capacity(m);
    for j in 0..m {
        let f = f0 * (f1 / f0).powf(j as f64 / (m - 1) as f64);
        let w = std::f64::consts::TAU * f / rate;
        let (mut re, mut im) = (0.0, 0.0);
        for (k, v) in u.iter().enumerate() {
            let (s, c) = (w * k as f64).sin_cos();
            re += v * c;
            im -= v * s;
        }
        fs.push(f);
        db.push(20.0 * ((2.0 * (re * re + im * im).sqrt() / n).max(1e-12)).log10());
    }
    (fs, db)
}

fn fmt(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:.3e}"))
}

/// Write every output of `hdw design` into `dir`.
pub fn write(
    dir: &Path,
    loaded: &Loaded,
    o: &Outcome,
    secs: f64,
    check: Option<&Check>,
) -> Result<()> {
    let dir = ensure_dir(dir)?;
    let p = &loaded.problem;
    let best = o.best();
    let rate = p.limits.rate;
    let t: Vec<f64> = (0..best.scaled.u.len()).map(|k| k as f64 / rate).collect();
    // A closed loop's input is its position reference [rad]; a voltage test's, u [V].
    let (column, unit) = if p.closed.is_some() { ("reference", "rad") } else { ("u", "V") };
    for f in ["input.csv", "input.parquet"] {
        hd_io::write_columns(&dir.join(f), &["t", column], &[t.clone(), best.scaled.u.clone()])?;
    }
    let mut judged = vec![judge("design", best, loaded, o)];
    for (name, e) in &o.defaults {
        judged.push(judge(name, e, loaded, o));
    }
    let k = p.free.len();
    let prior_pred = figures(&predict(&p.prior, &p.free), loaded);
    let has_prior = p.prior.iter().any(|v| *v != 0.0);
    let names: Vec<&str> = p.free.iter().map(|&i| NAMES[i]).collect();
    let ratio_of = |j: &Judged| j.weakest_variance;
    let ratios: Vec<(String, f64)> =
        judged[1..].iter().map(|j| (j.name.clone(), ratio_of(j) / ratio_of(&judged[0]))).collect();
    // Verdicts.
    let mut verdicts = Vec::new();
    for (s, n) in names.iter().enumerate() {
        let (before, with) = (has_prior && prior_pred[s].2, judged[0].together[s].2);
        let by_default: Vec<&str> =
            judged[1..].iter().filter(|j| j.together[s].2).map(|j| j.name.as_str()).collect();
        let corr = match judged[0].strongest[s] {
            Some((j, r)) if r.abs() >= CORRELATION_LIMIT => {
                format!("; correlation {r:.4} with {}", names[j])
            }
            _ => String::new(),
        };
        let what = match (before, with) {
            (true, true) => format!("{n} is determined already"),
            // More information can still raise a correlation past the fit's limit.
            (true, false) => format!(
                "{n} is determined by the fitted records, but not together with the designed record (relative SE {}{corr})",
                fmt(judged[0].together[s].0)
            ),
            (false, true) => format!(
                "{n} becomes determined with the designed record (relative SE {:.2e})",
                judged[0].together[s].0.unwrap_or(f64::NAN)
            ),
            (false, false) => format!(
                "{n} stays undetermined (relative SE {}{corr})",
                fmt(judged[0].together[s].0)
            ),
        };
        let dflt = if by_default.is_empty() {
            "no default input determines it".to_string()
        } else {
            format!("determined with the {} too", by_default.join(" and the "))
        };
        verdicts.push(format!("{what}; {dflt}."));
    }
    // The figures are linear: a refit may wander along what stays undetermined and carry
    // the newly determined parameters with it (measured on the docs' worked example).
    let loose: Vec<&str> = (0..k).filter(|&s| !judged[0].together[s].2).map(|s| names[s]).collect();
    let gained = (0..k).any(|s| judged[0].together[s].2 && !(has_prior && prior_pred[s].2));
    if check.is_none() && gained && !loose.is_empty() {
        verdicts.push(format!(
            "These figures linearise the fit at one point; {} stay undetermined, and a refit may wander along them and carry the parameters the design determines with it: run --check 20 to measure the spread and coverage the refits reach.",
            loose.join(", ")
        ));
    }
    for (name, r) in ratios.iter().filter(|_| has_prior) {
        verdicts.push(format!("Along the prior's weakest direction the designed record leaves {r:.3} times less variance than the {name}."));
    }
    if !best.scaled.within {
        verdicts.push(format!(
            "The design cannot meet the limits: {} binds at {:.3} times its limit.",
            best.scaled.binds,
            best.scaled.peaks.worst(&p.limits).1
        ));
    }
    let params: Value = p
        .free
        .iter()
        .enumerate()
        .map(|(s, &i)| {
            let mut v = json!({
                "value": p.values[i],
                "fitted_std_error": loaded.fitted_se.and_then(|se| se[i]),
                "prior_std_error": prior_pred[s].1,
                "prior_determined": has_prior && prior_pred[s].2,
            });
            for j in &judged {
                let key = j.name.replace(' ', "_");
                v[format!("{key}_alone_std_error")] = json!(j.alone[s].1);
                v[format!("{key}_alone_determined")] = json!(j.alone[s].2);
                v[format!("{key}_with_fitted_std_error")] = json!(j.together[s].1);
                v[format!("{key}_with_fitted_determined")] = json!(j.together[s].2);
                v[format!("{key}_with_fitted_strongest_correlation")] =
                    json!(j.strongest[s].map(|(o, r)| json!({"with": names[o], "correlation": r})));
            }
            (NAMES[i].to_string(), v)
        })
        .collect::<serde_json::Map<_, _>>()
        .into();
    let w = &o.weakest.0;
    // Every weak direction of the prior: its variance with each input and the ratios.
    let (dirs, eigs) = hd_ident::design::weakest(&p.prior);
    let mut weak_md = String::new();
    let weak_json: Vec<Value> = (0..dirs.ncols())
        .filter(|_| has_prior)
        .map(|c| {
            let v = dirs.column(c).into_owned();
            let var: Vec<(String, f64)> = std::iter::once(("design", best))
                .chain(o.defaults.iter().map(|(n, e)| (*n, e)))
                .map(|(n, e)| (n.to_string(), hd_ident::design::direction_variance(&(&p.prior + &e.info), &v)))
                .collect();
            let combo = describe_direction(&v, &p.free);
            let _ = write!(weak_md, "| {combo} | {:.3e} |", eigs[c]);
            for (_, x) in &var {
                let _ = write!(weak_md, " {x:.3e} |");
            }
            for (_, x) in &var[1..] {
                let _ = write!(weak_md, " {:.2} |", x / var[0].1);
            }
            weak_md.push('\n');
            json!({"combination": combo, "prior_eigenvalue": eigs[c],
                   "variance": var.iter().map(|(n, x)| (n.clone(), json!(x))).collect::<serde_json::Map<_, _>>(),
                   "variance_ratio": var[1..].iter().map(|(n, x)| (n.clone(), json!(x / var[0].1))).collect::<serde_json::Map<_, _>>()})
        })
        .collect();
    let searched: Vec<Value> = o
        .searched
        .iter()
        .map(|s| json!({"family": s.family.name(), "x": s.x, "criterion": s.best.cost, "evaluations": s.evaluations, "input": s.best.design.describe()}))
        .collect();
    let mut doc = json!({
        "criterion": o.criterion.name(),
        "input_column": column,
        "input_unit": unit,
        "controller": p.closed.as_ref().map(|l| json!({"kp": l.controller.kp, "kv": l.controller.kv,
            "saturation": l.controller.saturation, "delay": l.controller.delay,
            "speed_filter": l.controller.speed_filter, "feedback": l.feedback.name(),
            "amplifier": l.amplifier.name(), "command_noise": l.command_noise})),
        "limits": {"reference_rad": p.limits.reference, "voltage_V": p.limits.voltage, "current_A": p.limits.current, "speed_rad_s": p.limits.speed,
                   "load_speed_rad_s": p.limits.load_speed,
                   "deflection_rad": p.limits.deflection, "torque_Nm": p.limits.torque,
                   "load_angle_rad": p.limits.load_angle, "duration_s": p.limits.duration, "rate_Hz": rate},
        "noise": {"motor_rad": p.noise.motor, "load_rad": p.noise.load, "current_A": p.noise.current},
        "free": names,
        "input": best.design.describe(),
        "family": o.searched[0].family.name(),
        "criterion_value": best.cost,
        "searched": searched,
        "design": peaks_json(best, loaded),
        "defaults": o.defaults.iter().map(|(n, e)| json!({"name": n, "input": e.design.describe(), "criterion_value": e.cost, "limits": peaks_json(e, loaded)})).collect::<Vec<_>>(),
        "parameters": params,
        "weakest_direction": {
            "combination": describe_direction(w, &p.free),
            "weights": names.iter().zip(w.iter()).map(|(n, x)| ((*n).to_string(), json!(x))).collect::<serde_json::Map<_,_>>(),
            "prior_eigenvalue": o.weakest.1,
            "variance_prior": hd_ident::design::direction_variance(&p.prior, w),
            "variance": judged.iter().map(|j| (j.name.clone(), json!(j.weakest_variance))).collect::<serde_json::Map<_,_>>(),
            "variance_ratio": ratios.iter().map(|(n, r)| (n.clone(), json!(r))).collect::<serde_json::Map<_,_>>(),
        },
        "weak_directions": weak_json,
        "verdicts": verdicts,
        "wall_time_s": secs,
    });
    // The check.
    let mut check_md = String::new();
    if let Some(c) = check {
        let mut rows = serde_json::Map::new();
        let _ = writeln!(
            check_md,
            "\n## Refit check\n\n{} refits ({} failed) of the designed record together with the fitted records' voltages, synthesised with fresh noise, in {:.1} s.\n\n| parameter | truth | mean | spread (SD) | predicted SE | spread / predicted | 95 % coverage, fit's SE (a refit without one misses) | where it gave one | where determined | 95 % coverage (predicted SE) | determined | no SE (held) |\n|---|---|---|---|---|---|---|---|---|---|---|---|",
            c.fits.len(),
            c.failed.len(),
            c.secs
        );
        for (s, &i) in p.free.iter().enumerate() {
            let est: Vec<f64> = c.fits.iter().map(|f| f.0[i]).collect();
            let m = est.len().max(1) as f64;
            let mean = est.iter().sum::<f64>() / m;
            let sd =
                (est.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (m - 1.0).max(1.0)).sqrt();
            let pred = judged[0].together[s].1;
            // A refit without a standard error (the parameter held, or in a null direction)
            // counts as not covering; the coverage among the refits that call the parameter
            // determined is the one the fit's verdict promises.
            let covers = |f: &super::design_check::Refit| {
                f.1[i].is_some_and(|se| (f.0[i] - c.truth[i]).abs() <= 1.96 * se)
            };
            let cov_fit = c.fits.iter().filter(|f| covers(f)).count() as f64 / m;
            let determined: Vec<_> = c.fits.iter().filter(|f| f.2[i]).collect();
            let cov_det = (!determined.is_empty()).then(|| {
                determined.iter().filter(|f| covers(f)).count() as f64 / determined.len() as f64
            });
            let no_se = c.fits.iter().filter(|f| f.1[i].is_none()).count();
            let cov_given = (no_se < c.fits.len()).then(|| {
                c.fits.iter().filter(|f| covers(f)).count() as f64 / (c.fits.len() - no_se) as f64
            });
            let cov_pred = pred.map(|se| {
                est.iter().filter(|v| (*v - c.truth[i]).abs() <= 1.96 * se).count() as f64 / m
            });
            let det = determined.len();
            let ratio = pred.map(|se| sd / se);
            rows.insert(NAMES[i].into(), json!({"truth": c.truth[i], "mean": mean, "spread": sd, "predicted_std_error": pred,
                "spread_over_predicted": ratio, "coverage_fit_se": cov_fit, "coverage_fit_se_given": cov_given, "coverage_fit_se_determined": cov_det,
                "coverage_predicted_se": cov_pred, "determined_in": det, "without_std_error_in": no_se,
                "estimates": est, "std_errors": c.fits.iter().map(|f| f.1[i]).collect::<Vec<_>>(),
                "determined": c.fits.iter().map(|f| f.2[i]).collect::<Vec<_>>()}));
            let pct = |x: Option<f64>| x.map_or("—".into(), |c| format!("{:.0} %", 100.0 * c));
            let _ = writeln!(
                check_md,
                "| {} | {:.4e} | {:.4e} | {:.3e} | {} | {} | {:.0} % | {} | {} | {} | {det}/{n} | {no_se}/{n} |",
                NAMES[i],
                c.truth[i],
                mean,
                sd,
                fmt(pred),
                ratio.map_or("—".into(), |r| format!("{r:.2}")),
                100.0 * cov_fit,
                pct(cov_given),
                pct(cov_det),
                pct(cov_pred),
                n = c.fits.len()
            );
        }
        // Refits that stopped above the truth's cost: local optima of the fit.
        let short: Vec<f64> = c
            .above_truth
            .iter()
            .flatten()
            .copied()
            .filter(|d| *d > super::design_check::SHORT_OF_OPTIMUM)
            .collect();
        if !short.is_empty() {
            let worst = short.iter().fold(0.0f64, |a, &b| a.max(b));
            let line = format!(
                "{} of {} refits stopped at a cost above the truth's on their own records (by up to {worst:.3} in Σ(r/σ)²): local optima of the fit, so their distance from the truth is the optimiser's, not the information's, and the spread above counts it.",
                short.len(),
                c.fits.len()
            );
            eprintln!("  {line}");
            let _ = writeln!(check_md, "\n{line}");
        }
        doc["check"] = json!({"refits": c.fits.len(), "failed": c.failed, "wall_time_s": c.secs, "parameters": rows,
            "verdicts": c.sentences, "cost_above_truth": c.above_truth, "short_of_optimum": short.len()});
    }
    write_json(&dir.join("design.json"), &doc)?;
    // Plots.
    line_plot(
        &dir.join("input.svg"),
        "Designed input",
        "t [s]",
        &format!("{column} [{unit}]"),
        &[Series::new(column, t.clone(), best.scaled.u.clone())],
        false,
    )?;
    let (fs, db) = spectrum(&best.scaled.u, rate);
    let mut spec = vec![Series::new("design", fs, db)];
    for (n, e) in &o.defaults {
        let (f, d) = spectrum(&e.scaled.u, rate);
        spec.push(Series::new(*n, f, d));
    }
    line_plot(
        &dir.join("spectrum.svg"),
        "Input spectra",
        "f [Hz]",
        &format!("|{column}| [dB re 1 {unit}]"),
        &spec,
        true,
    )?;
    let r = &best.scaled.response;
    let l = &p.limits;
    let mut resp = vec![Series::new(
        "u / limit",
        t.clone(),
        r.voltage.iter().map(|v| v / l.voltage).collect(),
    )];
    if let Some(lim) = l.reference {
        resp.insert(
            0,
            Series::new(
                "reference / limit",
                t.clone(),
                best.scaled.u.iter().map(|v| v / lim).collect(),
            ),
        );
    }
    let norm = |x: &[f64], lim: Option<f64>| -> Vec<f64> {
        let s = lim
            .unwrap_or_else(|| x.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE));
        x.iter().map(|v| v / s).collect()
    };
    let lab = |n: &str, lim: Option<f64>| {
        if lim.is_some() { format!("{n} / limit") } else { format!("{n} / its peak (no limit)") }
    };
    resp.push(Series::new(lab("current", l.current), t.clone(), norm(&r.current, l.current)));
    resp.push(Series::new(lab("motor speed", l.speed), t.clone(), norm(&r.speed, l.speed)));
    resp.push(Series::new(
        lab("deflection", l.deflection),
        t.clone(),
        norm(&r.deflection, l.deflection),
    ));
    // The load speed, the transmitted torque and the load's travel are drawn where limited.
    if l.load_speed.is_some() {
        resp.push(Series::new(
            lab("load speed", l.load_speed),
            t.clone(),
            norm(&r.load_speed, l.load_speed),
        ));
    }
    if l.torque.is_some() {
        resp.push(Series::new(lab("torque", l.torque), t.clone(), norm(&r.torque, l.torque)));
    }
    if l.load_angle.is_some() {
        resp.push(Series::new(
            lab("load angle", l.load_angle),
            t.clone(),
            norm(&r.load, l.load_angle),
        ));
    }
    line_plot(
        &dir.join("response.svg"),
        "Simulated response against the limits",
        "t [s]",
        "value / limit [–]",
        &resp,
        false,
    )?;
    let cats: Vec<String> = names.iter().map(|s| s.to_string()).collect();
    let bar = |name: &str, xs: &[(Option<f64>, Option<f64>, bool)]| BarGroup {
        name: name.into(),
        values: xs.iter().map(|x| x.0.map_or(f64::NAN, |r| r.log10())).collect(),
        intervals: None,
    };
    let mut groups = Vec::new();
    if has_prior {
        groups.push(bar("fitted records", &prior_pred));
    }
    for j in &judged {
        groups.push(bar(
            &format!("{}{}", j.name, if has_prior { " + fitted" } else { "" }),
            &j.together,
        ));
    }
    bar_chart(
        &dir.join("se.svg"),
        "Predicted relative standard errors",
        "log10 (SE / |value|)",
        &cats,
        &groups,
    )?;
    // report.md
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Designed test\n\nCriterion: {} over {} free parameters ({}). Input: {} ({} s at {} Hz; family {}; {} candidates searched in {:.1} s).\n",
        o.criterion.name(),
        k,
        names.join(", "),
        best.design.describe(),
        l.duration,
        rate,
        o.searched[0].family.name(),
        o.searched.iter().map(|s| s.evaluations).sum::<usize>(),
        secs
    );
    let _ = writeln!(
        md,
        "![input](input.svg)\n\n![spectrum](spectrum.svg)\n\n## Limits\n\n| input | quantity | peak | limit | peak / limit |\n|---|---|---|---|---|"
    );
    for (n, e) in std::iter::once(("design", best)).chain(o.defaults.iter().map(|(n, e)| (*n, e))) {
        for (q, pk, lim, unit) in e.scaled.peaks.against(l) {
            let _ = writeln!(
                md,
                "| {n} | {q} [{unit}] | {pk:.4e} | {lim:.4e} | {:.3}{} |",
                pk / lim,
                if q == e.scaled.binds { " (binds)" } else { "" }
            );
        }
    }
    let _ = writeln!(
        md,
        "\n![response](response.svg)\n\n## Predicted standard errors\n\nRelative SE (SE / |value|); — where the information does not see the parameter; * where the fit would call it determined.\n"
    );
    let mut head = "| parameter | value |".to_string();
    if has_prior {
        head.push_str(" fitted records |");
    }
    for j in &judged {
        let _ = write!(
            head,
            " {} alone | {}{} |",
            j.name,
            j.name,
            if has_prior { " + fitted" } else { "" }
        );
    }
    let _ = writeln!(md, "{head}\n|{}", "---|".repeat(2 + has_prior as usize + 2 * judged.len()));
    let cell = |x: &(Option<f64>, Option<f64>, bool)| {
        format!("{}{}", fmt(x.0), if x.2 { " *" } else { "" })
    };
    for (s, n) in names.iter().enumerate() {
        let mut row = format!("| {n} | {:.4e} |", p.values[p.free[s]]);
        if has_prior {
            let _ = write!(row, " {} |", cell(&prior_pred[s]));
        }
        for j in &judged {
            let _ = write!(row, " {} | {} |", cell(&j.alone[s]), cell(&j.together[s]));
        }
        let _ = writeln!(md, "{row}");
    }
    let _ = writeln!(
        md,
        "\n![standard errors](se.svg)\n\n## The weakest direction\n\nThe prior's weakest direction is {} (eigenvalue {:.3e}).\n",
        describe_direction(w, &p.free),
        o.weakest.1
    );
    for j in &judged {
        let _ = writeln!(md, "- variance along it with the {}: {:.4e}", j.name, j.weakest_variance);
    }
    if has_prior {
        let _ = writeln!(
            md,
            "\nEvery weak direction of the prior (eigenvalue below 100, at most 6): variance with the design, with each default, and default / design.\n\n| direction | prior eigenvalue | design |{} {} |\n|{}",
            o.defaults.iter().map(|(n, _)| format!(" {n} |")).collect::<String>(),
            o.defaults.iter().map(|(n, _)| format!("{n} / design")).collect::<Vec<_>>().join(" | "),
            "---|".repeat(3 + 2 * o.defaults.len())
        );
        md.push_str(&weak_md);
    }
    let _ = writeln!(md, "\n## Verdicts\n");
    for v in &verdicts {
        let _ = writeln!(md, "- {v}");
    }
    md.push_str(&check_md);
    std::fs::write(dir.join("report.md"), md)?;
    eprintln!(
        "{} ({}); wrote input.csv, input.parquet, design.json, report.md to {}",
        best.design.describe(),
        o.criterion.name(),
        dir.display()
    );
    for v in &verdicts {
        eprintln!("  {v}");
    }
    Ok(())
}
