//! The drift stage of `hdw fleet`: fits.parquet → covariate normalisation, Page's CUSUM
//! per unit and parameter → drift.parquet, alarms.csv, drift.json and the plots.

use super::fleet_plan::Source;
use anyhow::{Context, Result, bail};
use clap::Args;
use hd_ident::fleet::{DriftOptions, Normalise, ParameterDrift, Sample, drift};
use hd_io::fleet::{FleetCells, FleetColumn, format_day, write_fleet_table};
use hd_io::table::Table;
use serde_json::json;
use std::collections::BTreeMap;
use std::path::Path;

/// Settings of the drift analysis.
#[derive(Args, Debug, Clone)]
pub struct DriftArgs {
    /// Baseline: each unit's first days, over which the covariate model is fitted [days].
    #[arg(long, value_name = "DAYS", default_value_t = 20.0)]
    pub baseline_days: f64,
    /// Probability of at least one false alarm over the whole fleet and record.
    #[arg(long, value_name = "P", default_value_t = 0.05)]
    pub false_alarm: f64,
    /// Covariate normalisation: auto (the model of least BIC) or none.
    #[arg(long, value_name = "MODE", default_value = "auto", value_parser = ["auto", "none"])]
    pub normalise: String,
    /// Parameters to test, comma-separated (default: every parameter the fits determine).
    #[arg(long = "params", value_name = "NAMES", value_delimiter = ',')]
    pub params: Vec<String>,
    /// Estimates averaged for the change at the end of the record.
    #[arg(long, value_name = "N", default_value_t = 5)]
    pub last: usize,
    /// Skip the plots.
    #[arg(long)]
    pub no_plots: bool,
}

/// Refuse settings out of range before any work.
pub fn check(a: &DriftArgs) -> Result<()> {
    if !(a.baseline_days > 0.0 && a.baseline_days.is_finite()) {
        bail!("--baseline-days {}: expected a positive number of days", a.baseline_days);
    }
    if !(a.false_alarm > 0.0 && a.false_alarm < 1.0) {
        bail!("--false-alarm {}: expected a probability in (0, 1), e.g. 0.05", a.false_alarm);
    }
    if a.last == 0 {
        bail!("--last 0: expected at least 1 estimate");
    }
    Ok(())
}

/// One parameter's analysis with the rows it came from.
pub struct Analysed {
    /// Parameter name.
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// Rows of fits.parquet (indices), parallel to the samples.
    pub rows: Vec<usize>,
    /// The samples.
    pub samples: Vec<Sample>,
    /// Why a row was left out before normalisation (other units).
    pub excluded: Vec<Option<String>>,
    /// The analysis.
    pub drift: ParameterDrift,
}

/// The number of a text or numeric cell.
fn num_at(t: &Table, name: &str, row: usize) -> f64 {
    if let Some(v) = t.num(name) {
        return v[row];
    }
    t.text(name)
        .and_then(|v| v[row].as_deref())
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(f64::NAN)
}

/// Run the drift analysis on `dir/fits.parquet`.
pub fn run(dir: &Path, src: &Source, a: &DriftArgs) -> Result<()> {
    check(a)?;
    let fits_path = dir.join("fits.parquet");
    // Only the columns the analysis reads: memory per log stays a few hundred bytes.
    let mut wanted: Vec<&str> = vec![
        "log_index",
        "file",
        "status",
        "parameter",
        "unit_id",
        "param_unit",
        "day",
        "value",
        "std_error",
        "determined",
    ];
    wanted.extend(src.covariates.iter().map(String::as_str));
    let t = hd_io::table::read_table_columns(&fits_path, &wanted)?;
    for c in &src.covariates {
        if !t.names.contains(c) {
            bail!("{}: no covariate column '{c}'", fits_path.display());
        }
    }
    let text = |name: &str| {
        t.text(name).with_context(|| format!("{}: no text column '{name}'", fits_path.display()))
    };
    let (status, param, unit_id, punit) =
        (text("status")?, text("parameter")?, text("unit_id")?, text("param_unit")?);
    let (day, value, se) = (
        t.num("day").context("fits.parquet: no day column")?,
        t.num("value").context("fits.parquet: no value column")?,
        t.num("std_error").context("fits.parquet: no std_error column")?,
    );
    let determined = t.num("determined").context("fits.parquet: no determined column")?;
    let ok = |r: usize| status[r].as_deref() == Some("ok");
    let mut units: Vec<String> = (0..t.height).filter_map(|r| unit_id[r].clone()).collect();
    units.sort();
    units.dedup();
    let unit_of: BTreeMap<&str, usize> =
        units.iter().enumerate().map(|(i, u)| (u.as_str(), i)).collect();
    // Parameters: those asked, else those determined in at least half their logs.
    let mut counts: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    for r in (0..t.height).filter(|&r| ok(r)) {
        if let Some(p) = &param[r] {
            let c = counts.entry(p.clone()).or_default();
            c.0 += 1;
            c.1 += usize::from(determined[r] > 0.5);
        }
    }
    let names: Vec<String> = if a.params.is_empty() {
        counts.iter().filter(|(_, c)| 2 * c.1 >= c.0 && c.0 > 0).map(|(n, _)| n.clone()).collect()
    } else {
        for p in &a.params {
            if !counts.contains_key(p) {
                bail!(
                    "--params {p}: no estimates of '{p}' in {} (parameters: {})",
                    fits_path.display(),
                    counts.keys().cloned().collect::<Vec<_>>().join(", ")
                );
            }
        }
        a.params.clone()
    };
    if names.is_empty() {
        bail!(
            "{}: no parameter is determined in most logs; nothing to test for drift",
            fits_path.display()
        );
    }
    let opts = DriftOptions {
        baseline_days: a.baseline_days,
        false_alarm: a.false_alarm,
        last: a.last,
        normalise: if a.normalise == "none" { Normalise::None } else { Normalise::Auto },
        ..Default::default()
    };
    let series = units.len() * names.len();
    let mut analysed = Vec::new();
    for name in &names {
        let rows: Vec<usize> =
            (0..t.height).filter(|&r| ok(r) && param[r].as_deref() == Some(name)).collect();
        let mut samples: Vec<Sample> = rows
            .iter()
            .map(|&r| Sample {
                unit: unit_of[unit_id[r].as_deref().unwrap_or("")],
                day: day[r],
                value: value[r],
                se: se[r],
                covariates: src.covariates.iter().map(|c| num_at(&t, c, r)).collect(),
            })
            .collect();
        // A value far from its unit's median is not wear: a log in other units.
        let mut excluded = vec![None; samples.len()];
        for u in 0..units.len() {
            let mut v: Vec<f64> = samples
                .iter()
                .filter(|s| s.unit == u && s.value.is_finite())
                .map(|s| s.value.abs())
                .collect();
            if v.is_empty() {
                continue;
            }
            v.sort_by(f64::total_cmp);
            let med = v[v.len() / 2];
            for (s, e) in samples.iter_mut().zip(excluded.iter_mut()) {
                let ratio = s.value.abs() / med;
                if s.unit == u && med > 0.0 && !(0.2..=5.0).contains(&ratio) {
                    *e = Some(format!(
                        "{ratio:.3} × the unit's median: a log in other units, or a failed test?"
                    ));
                    s.value = f64::NAN;
                }
            }
        }
        let d = drift(&samples, &src.covariates, series, &opts);
        let unit = rows.first().and_then(|&r| punit[r].clone()).unwrap_or_default();
        analysed.push(Analysed { name: name.clone(), unit, rows, samples, excluded, drift: d });
    }
    let dated = day.iter().filter(|d| d.is_finite()).fold(f64::INFINITY, |m, d| m.min(*d)) > 3650.0;
    let show = |d: f64| if dated { format_day(d) } else { format!("{d}") };
    write_drift_table(dir, &t, &units, &analysed, &src.covariates)?;
    // Alarms and the summary.
    let mut alarm_lines = vec!["unit_id,parameter,first_flagged,first_flagged_day,onset,onset_day,direction,change_pct,ci95_lo,ci95_hi".to_string()];
    let mut doc_params = Vec::new();
    let mut alarms = 0;
    for an in &analysed {
        let n = &an.drift.normalisation;
        let mut unit_docs = Vec::new();
        for u in &an.drift.units {
            if let (Some(f), Some(o)) = (u.first_flagged, u.onset) {
                alarms += 1;
                alarm_lines.push(format!(
                    "{},{},{},{},{},{},{},{:.3},{:.3},{:.3}",
                    units[u.unit],
                    an.name,
                    show(f),
                    f,
                    show(o),
                    o,
                    if u.direction > 0 { "rise" } else { "fall" },
                    u.change_pct,
                    u.ci95[0],
                    u.ci95[1]
                ));
            }
            unit_docs.push(json!({
                "unit_id": units[u.unit], "tested": u.tested, "first_flagged": u.first_flagged,
                "onset": u.onset, "direction": u.direction, "change_pct": u.change_pct, "ci95": u.ci95,
            }));
        }
        doc_params.push(json!({
            "parameter": an.name,
            "unit": an.unit,
            "scale": if n.log_scale { "log" } else { "linear" },
            "normalisation": n.chosen,
            "candidates": n.candidates.iter().map(|c| json!({"model": c.name, "params": c.params, "rss": c.rss, "bic": c.bic})).collect::<Vec<_>>(),
            "coefficients": n.coefficients.iter().map(|(c, v, s)| json!({"covariate": c, "per_unit_of_covariate": v, "std_error": s, "percent_per_unit": if n.log_scale { Some(100.0 * v) } else { None }})).collect::<Vec<_>>(),
            "tau": n.tau,
            "baseline_estimates": n.baseline_rows,
            "cusum_threshold_median_series": an.drift.threshold,
            "units": unit_docs,
        }));
    }
    let alarms_path = dir.join("alarms.csv");
    hd_io::atomic::write_atomically(&alarms_path, |f| {
        use std::io::Write;
        f.write_all((alarm_lines.join("\n") + "\n").as_bytes())
            .map_err(|e| hd_io::IoError::fs(&alarms_path, e))
    })?;
    let doc = json!({
        "settings": {
            "covariates": src.covariates, "baseline_days": a.baseline_days, "false_alarm": a.false_alarm,
            "false_alarm_per_series": a.false_alarm / series.max(1) as f64, "series": series,
            "normalise": a.normalise, "cusum_k": opts.k, "last": a.last,
            "test": "Page's two-sided CUSUM on residuals standardised by sqrt(se^2 + tau^2 + var(prediction)); threshold from Siegmund's ARL approximation",
        },
        "units": units,
        "parameters": doc_params,
    });
    let json_path = dir.join("drift.json");
    hd_io::atomic::write_atomically(&json_path, |f| {
        use std::io::Write;
        f.write_all(serde_json::to_string_pretty(&doc).unwrap_or_default().as_bytes())
            .map_err(|e| hd_io::IoError::fs(&json_path, e))
    })?;
    eprintln!(
        "drift: {} units × {} parameters ({}), normalisation {}; {alarms} alarm(s) at a fleet-wide false-alarm probability of {}",
        units.len(),
        names.len(),
        names.join(", "),
        analysed
            .iter()
            .map(|a| format!("{}: {}", a.name, a.drift.normalisation.chosen))
            .collect::<Vec<_>>()
            .join(", "),
        a.false_alarm
    );
    for l in alarm_lines.iter().skip(1) {
        eprintln!("  alarm: {l}");
    }
    if !a.no_plots {
        super::fleet_plot::plots(dir, &units, &analysed, dated)?;
    }
    eprintln!(
        "wrote {}, {}, {}",
        dir.join("drift.parquet").display(),
        alarms_path.display(),
        json_path.display()
    );
    Ok(())
}

fn col(name: &str, cells: FleetCells, unit: &str, doc: &str) -> FleetColumn {
    FleetColumn { name: name.into(), cells, unit: unit.into(), doc: doc.into() }
}

fn write_drift_table(
    dir: &Path,
    t: &Table,
    units: &[String],
    analysed: &[Analysed],
    covs: &[String],
) -> Result<()> {
    let li = t.num("log_index").context("fits.parquet: no log_index")?;
    let files = t.text("file").context("fits.parquet: no file")?;
    let mut c: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
    let (mut log_index, mut file, mut unit, mut param, mut note, mut flagged) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut cov_vals: Vec<Vec<f64>> = vec![Vec::new(); covs.len()];
    for an in analysed {
        let n = &an.drift.normalisation;
        for (k, &r) in an.rows.iter().enumerate() {
            let s = &an.samples[k];
            let d = &an.drift.rows[k];
            log_index.push(li[r] as u64);
            file.push(files[r].clone());
            unit.push(Some(units[s.unit].clone()));
            param.push(Some(an.name.clone()));
            let res = n.residual[k];
            let pct =
                if n.log_scale { 100.0 * res.exp_m1() } else { 100.0 * res / n.level[k].abs() };
            for (key, v) in [
                ("day", s.day),
                ("value", t.num("value").map_or(f64::NAN, |v| v[r])),
                ("std_error", s.se),
                ("normalised", n.normalised[k]),
                ("level", n.level[k]),
                ("change_pct", pct),
                ("z", d.z),
                ("cusum_upper", d.upper),
                ("cusum_lower", d.lower),
            ] {
                c.entry(key).or_default().push(v);
            }
            flagged.push(d.flagged);
            note.push(an.excluded[k].clone().or_else(|| n.reason[k].clone()));
            for (j, v) in s.covariates.iter().enumerate() {
                cov_vals[j].push(*v);
            }
        }
    }
    let mut take = |k: &str| FleetCells::F64(c.remove(k).unwrap_or_default());
    let mut cols = vec![
        col("log_index", FleetCells::U64(log_index), "-", "0-based row of the manifest"),
        col("file", FleetCells::Text(file), "text", "the log file"),
        col("unit_id", FleetCells::Text(unit), "text", "the unit's identifiers joined by '/'"),
        col("parameter", FleetCells::Text(param), "text", "registry name of the parameter"),
        col("day", take("day"), "d", "timestamp in days"),
        col("value", take("value"), "param_unit", "the estimate (fits.parquet)"),
        col("std_error", take("std_error"), "param_unit", "its standard error"),
        col(
            "normalised",
            take("normalised"),
            "param_unit",
            "the estimate moved to the reference covariates (the baseline's mean)",
        ),
        col(
            "level",
            take("level"),
            "param_unit",
            "the unit's baseline level at the reference covariates",
        ),
        col(
            "change_pct",
            take("change_pct"),
            "%",
            "normalised residual: change from the unit's baseline level",
        ),
        col(
            "z",
            take("z"),
            "-",
            "residual over its standard deviation (se, unexplained scatter, normalisation)",
        ),
        col("cusum_upper", take("cusum_upper"), "-", "Page's upper CUSUM after this log"),
        col("cusum_lower", take("cusum_lower"), "-", "Page's lower CUSUM after this log"),
        col(
            "flagged",
            FleetCells::Bool(flagged),
            "-",
            "whether the unit's test has alarmed at or before this log",
        ),
        col(
            "note",
            FleetCells::Text(note),
            "text",
            "why the log has no residual (covariate missing, other units, no baseline)",
        ),
    ];
    for (name, v) in covs.iter().zip(cov_vals) {
        cols.push(col(name, FleetCells::F64(v), "-", "covariate (manifest column)"));
    }
    write_fleet_table(&dir.join("drift.parquet"), &cols, &[])?;
    Ok(())
}
