//! The drift stage of `hdw fleet`: fits.parquet → covariate normalisation, Page's CUSUM
//! per unit and parameter → drift.parquet, alarms.csv, drift.json and the plots.

use super::fleet_drift_table::write_drift_table;
use super::fleet_plan::Source;
use super::fleet_spill::Spill;
use anyhow::{Result, bail};
use clap::Args;
use hd_ident::fleet::{
    DriftOptions, Normalise, Normalised, Reason, Sample, UnitSeries, baseline_flags,
    fit_normalisation, median_threshold, test_unit,
};
use hd_io::fleet::format_day;
use hd_io::table::Table;
use serde_json::json;
use std::collections::{BTreeMap, HashMap};
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

/// Rows of fits.parquet read at a time, at least (whole row groups; each pass streams the
/// table in such pieces).
pub(super) const CHUNK_ROWS: usize = 2048;

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

/// What a first pass over fits.parquet finds: per-unit and per-parameter state only.
#[derive(Default)]
struct Census {
    /// Unit ids (every row's), sorted.
    units: Vec<String>,
    /// Per parameter (ok rows): estimates, determined ones.
    counts: BTreeMap<String, (usize, usize)>,
    /// Per parameter: the first row's unit.
    punit: BTreeMap<String, String>,
    /// Per parameter: unit id → ok rows.
    per_unit: HashMap<String, HashMap<String, usize>>,
    /// Per parameter: the earliest day of an ok row [days].
    first_day: BTreeMap<String, f64>,
    /// The earliest day of any row [days].
    min_day: f64,
}

fn census(fits: &Path, covariates: &[String]) -> Result<Census> {
    let mut c = Census { min_day: f64::INFINITY, ..Default::default() };
    let mut units = std::collections::BTreeSet::new();
    let mut checked = false;
    let cols = ["status", "parameter", "unit_id", "param_unit", "day", "determined"];
    let mut wanted: Vec<&str> = cols.to_vec();
    wanted.extend(covariates.iter().map(String::as_str));
    let mut missing = None;
    hd_io::fleet::for_each_piece(fits, &wanted, CHUNK_ROWS, |t| {
        if !checked {
            checked = true;
            missing = covariates.iter().find(|c| !t.names.contains(c)).cloned();
        }
        let (Some(status), Some(param), Some(unit_id), Some(punit)) =
            (t.text("status"), t.text("parameter"), t.text("unit_id"), t.text("param_unit"))
        else {
            return Err(hd_io::IoError::format(
                fits,
                "expected text columns status, parameter, unit_id, param_unit",
            ));
        };
        let (Some(day), Some(det)) = (t.num("day"), t.num("determined")) else {
            return Err(hd_io::IoError::format(fits, "expected columns day and determined"));
        };
        for r in 0..t.height {
            if day[r].is_finite() {
                c.min_day = c.min_day.min(day[r]);
            }
            if let Some(u) = &unit_id[r]
                && !units.contains(u)
            {
                units.insert(u.clone());
            }
            let (Some("ok"), Some(p)) = (status[r].as_deref(), &param[r]) else { continue };
            if !c.counts.contains_key(p) {
                c.counts.insert(p.clone(), (0, 0));
                c.punit.insert(p.clone(), punit[r].clone().unwrap_or_default());
                c.per_unit.insert(p.clone(), HashMap::new());
                c.first_day.insert(p.clone(), f64::INFINITY);
            }
            if let Some(n) = c.counts.get_mut(p) {
                n.0 += 1;
                n.1 += usize::from(det[r] > 0.5);
            }
            if let Some(d) = c.first_day.get_mut(p)
                && day[r].is_finite()
            {
                *d = d.min(day[r]);
            }
            if let (Some(m), Some(u)) = (c.per_unit.get_mut(p), &unit_id[r]) {
                match m.get_mut(u) {
                    Some(n) => *n += 1,
                    None => {
                        m.insert(u.clone(), 1);
                    }
                }
            }
        }
        Ok(())
    })?;
    if let Some(m) = missing {
        bail!("{}: no covariate column '{m}'", fits.display());
    }
    c.units = units.into_iter().collect();
    Ok(c)
}

/// Where each parameter × unit's estimates sit in the spill (first record, count).
pub(super) struct Regions {
    pub(super) start: Vec<Vec<usize>>,
    count: Vec<Vec<usize>>,
}

impl Regions {
    fn new(c: &Census, names: &[String]) -> Self {
        let (mut start, mut count, mut total) = (Vec::new(), Vec::new(), 0);
        for name in names {
            let m = c.per_unit.get(name);
            let n: Vec<usize> =
                c.units.iter().map(|u| m.and_then(|m| m.get(u)).copied().unwrap_or(0)).collect();
            let mut s = Vec::with_capacity(n.len());
            for k in &n {
                s.push(total);
                total += k;
            }
            start.push(s);
            count.push(n);
        }
        Regions { start, count }
    }
}

/// Result record per estimate: normalised, level, change_pct, z, cusum_upper,
/// cusum_lower, flagged, note code, note argument.
const RESULT_WIDTH: usize = 9;

/// A note as (code, argument) in the result spill, and back in words.
fn note_code(excluded: Option<f64>, reason: Option<Reason>) -> (f64, f64) {
    match (excluded, reason) {
        (Some(ratio), _) => (1.0, ratio),
        (None, Some(Reason::NoEstimate)) => (2.0, 0.0),
        (None, Some(Reason::CovariateMissing(c))) => (3.0, c as f64),
        (None, Some(Reason::NoBaseline)) => (4.0, 0.0),
        (None, Some(Reason::TooFew(nb))) => (5.0, nb as f64),
        (None, None) => (0.0, 0.0),
    }
}

pub(super) fn note_text(code: f64, arg: f64, covariates: &[String]) -> Option<String> {
    let reason = match code as u8 {
        1 => {
            return Some(format!(
                "{arg:.3} × the unit's median: a log in other units, or a failed test?"
            ));
        }
        2 => Reason::NoEstimate,
        3 => Reason::CovariateMissing(arg as usize),
        4 => Reason::NoBaseline,
        5 => Reason::TooFew(arg as usize),
        _ => return None,
    };
    Some(reason.text(covariates))
}

/// One unit's estimates of one parameter from the spill (in fits.parquet's order), with
/// their positions in the parameter's sequence.
fn read_unit(
    spill: &Spill,
    start: usize,
    n: usize,
    unit: usize,
) -> Result<(Vec<f64>, Vec<Sample>)> {
    let w = spill.width();
    let v = spill.get(start, n)?;
    let mut seq = Vec::with_capacity(n);
    let samples = v
        .chunks_exact(w)
        .map(|r| {
            seq.push(r[0]);
            Sample { unit, day: r[1], value: r[2], se: r[3], covariates: r[4..].to_vec() }
        })
        .collect();
    Ok((seq, samples))
}

/// A value far from its unit's median is not wear: a log in other units. Such samples
/// lose their value; the ratio to the median is returned for the note.
fn exclude(samples: &mut [Sample]) -> Vec<Option<f64>> {
    let mut out = vec![None; samples.len()];
    let mut v: Vec<f64> =
        samples.iter().filter(|s| s.value.is_finite()).map(|s| s.value.abs()).collect();
    if v.is_empty() {
        return out;
    }
    v.sort_by(f64::total_cmp);
    let med = v[v.len() / 2];
    for (s, e) in samples.iter_mut().zip(out.iter_mut()) {
        let ratio = s.value.abs() / med;
        if med > 0.0 && !(0.2..=5.0).contains(&ratio) {
            *e = Some(ratio);
            s.value = f64::NAN;
        }
    }
    out
}

/// Run the drift analysis on `dir/fits.parquet`, streamed: a census of units and
/// parameters, every estimate spilled into its unit's region, then per parameter the
/// normalisation fitted on the baseline estimates and each unit tested on its own; the
/// tables are written as fits.parquet streams by once more. Memory holds per-unit state,
/// one unit's estimates and one chunk of rows, whatever the number of logs.
pub fn run(dir: &Path, src: &Source, a: &DriftArgs) -> Result<()> {
    check(a)?;
    let fits_path = dir.join("fits.parquet");
    let covs = &src.covariates;
    let c = census(&fits_path, covs)?;
    let units = &c.units;
    let unit_of: BTreeMap<&str, usize> =
        units.iter().enumerate().map(|(i, u)| (u.as_str(), i)).collect();
    // Parameters: those asked, else those determined in at least half their logs.
    let names: Vec<String> = if a.params.is_empty() {
        c.counts.iter().filter(|(_, n)| 2 * n.1 >= n.0 && n.0 > 0).map(|(n, _)| n.clone()).collect()
    } else {
        for p in &a.params {
            if !c.counts.contains_key(p) {
                bail!(
                    "--params {p}: no estimates of '{p}' in {} (parameters: {})",
                    fits_path.display(),
                    c.counts.keys().cloned().collect::<Vec<_>>().join(", ")
                );
            }
        }
        a.params.clone()
    };
    if c.counts.is_empty() {
        bail!(
            "{}: no log was fitted (every row failed; its `error` column says why, e.g. a template that does not fit these logs); nothing to test for drift",
            fits_path.display()
        );
    }
    if names.is_empty() {
        bail!(
            "{}: no parameter is determined in most logs; nothing to test for drift",
            fits_path.display()
        );
    }
    let param_of: HashMap<&str, usize> =
        names.iter().enumerate().map(|(i, n)| (n.as_str(), i)).collect();
    let opts = DriftOptions {
        baseline_days: a.baseline_days,
        false_alarm: a.false_alarm,
        last: a.last,
        normalise: if a.normalise == "none" { Normalise::None } else { Normalise::Auto },
        ..Default::default()
    };
    let series = units.len() * names.len();
    let alpha = opts.false_alarm / series.max(1) as f64;
    // Every estimate into its parameter × unit region: (sequence, day, value, se, covariates).
    let regions = Regions::new(&c, &names);
    let data = Spill::new(&dir.join("drift-estimates.bin"), 4 + covs.len())?;
    let results = Spill::new(&dir.join("drift-results.bin"), RESULT_WIDTH)?;
    {
        let mut cursor: Vec<Vec<usize>> = regions.count.iter().map(|n| vec![0; n.len()]).collect();
        let mut seq = vec![0usize; names.len()];
        let mut wanted = vec!["status", "parameter", "unit_id", "day", "value", "std_error"];
        wanted.extend(covs.iter().map(String::as_str));
        let mut failure = None;
        hd_io::fleet::for_each_piece(&fits_path, &wanted, CHUNK_ROWS, |t| {
            let (status, param, unit_id) = (
                t.text("status").unwrap_or_default(),
                t.text("parameter").unwrap_or_default(),
                t.text("unit_id").unwrap_or_default(),
            );
            let (day, value, se) = (
                t.num("day").unwrap_or_default(),
                t.num("value").unwrap_or_default(),
                t.num("std_error").unwrap_or_default(),
            );
            let mut recs = Vec::new();
            for r in 0..t.height {
                if status[r].as_deref() != Some("ok") {
                    continue;
                }
                let Some(&p) = param[r].as_deref().and_then(|n| param_of.get(n)) else { continue };
                let Some(&u) = unit_id[r].as_deref().and_then(|n| unit_of.get(n)) else {
                    continue;
                };
                let pos = regions.start[p][u] + cursor[p][u];
                cursor[p][u] += 1;
                let mut rec = vec![seq[p] as f64, day[r], value[r], se[r]];
                seq[p] += 1;
                rec.extend(covs.iter().map(|c| num_at(t, c, r)));
                recs.push((pos, rec));
            }
            if let Err(e) = data.put_all(&mut recs) {
                failure = Some(e);
                return Err(hd_io::IoError::format(&fits_path, "spill failed"));
            }
            Ok(())
        })
        .map_err(|e| failure.take().unwrap_or_else(|| e.into()))?;
    }
    let dated = c.min_day > 3650.0;
    let show = |d: f64| if dated { format_day(d) } else { format!("{d}") };
    let t0 = names.iter().filter_map(|n| c.first_day.get(n)).fold(f64::INFINITY, |m, d| m.min(*d));
    let x_label =
        if dated { format!("days since {}", format_day(t0)) } else { format!("day − {t0}") };
    let mut alarm_lines = vec!["unit_id,parameter,first_flagged,first_flagged_day,onset,onset_day,direction,change_pct,ci95_lo,ci95_hi".to_string()];
    let mut doc_params = Vec::new();
    let mut alarms = 0;
    let mut chosen = Vec::new();
    let mut overview = vec![f64::NAN; names.len() * units.len()];
    for (p, name) in names.iter().enumerate() {
        let punit = c.punit.get(name).cloned().unwrap_or_default();
        // The baseline of every unit, in fits.parquet's order, and the scale.
        let mut base: Vec<(f64, Sample)> = Vec::new();
        let mut log_scale = true;
        for u in 0..units.len() {
            let n = regions.count[p][u];
            if n == 0 {
                continue;
            }
            let (seq, mut samples) = read_unit(&data, regions.start[p][u], n, u)?;
            exclude(&mut samples);
            log_scale &= samples.iter().filter(|s| s.value.is_finite()).all(|s| s.value > 0.0);
            let flags = baseline_flags(&samples, opts.baseline_days);
            for ((s, q), f) in samples.into_iter().zip(seq).zip(flags) {
                if f {
                    base.push((q, s));
                }
            }
        }
        base.sort_by(|x, y| x.0.total_cmp(&y.0));
        let base: Vec<Sample> = base.into_iter().map(|(_, s)| s).collect();
        let nb = base.len();
        let (norm, model) = fit_normalisation(&base, units.len(), log_scale, covs, opts.normalise);
        drop(base);
        // Each unit on its own.
        let mut thresholds = HashMap::new();
        let mut lengths = Vec::new();
        let mut unit_docs = Vec::new();
        for u in 0..units.len() {
            let n = regions.count[p][u];
            if n == 0 {
                continue;
            }
            let (_, mut samples) = read_unit(&data, regions.start[p][u], n, u)?;
            let excluded = exclude(&mut samples);
            let flags = baseline_flags(&samples, opts.baseline_days);
            let rows: Vec<Normalised> = match &model {
                Some(m) => samples.iter().map(|s| m.apply(s)).collect(),
                None => vec![Normalised::missing(Reason::TooFew(nb)); n],
            };
            let mut variance: Vec<f64> = rows.iter().map(|r| r.variance).collect();
            if let Some(phi) = model.as_ref().and_then(|m| {
                m.unit_scale(rows.iter().zip(&flags).filter(|(_, f)| **f).map(|(r, _)| r))
            }) {
                variance.iter_mut().filter(|v| v.is_finite()).for_each(|v| *v *= phi);
            }
            let day: Vec<f64> = samples.iter().map(|s| s.day).collect();
            let residual: Vec<f64> = rows.iter().map(|r| r.residual).collect();
            let level: Vec<f64> = rows.iter().map(|r| r.level).collect();
            let series = UnitSeries {
                unit: u,
                day: &day,
                residual: &residual,
                variance: &variance,
                level: &level,
            };
            let (drows, verdict) = test_unit(&series, log_scale, alpha, &opts, &mut thresholds);
            let mut out = Vec::with_capacity(n * RESULT_WIDTH);
            for k in 0..n {
                let res = residual[k];
                let pct =
                    if log_scale { 100.0 * res.exp_m1() } else { 100.0 * res / level[k].abs() };
                let (code, arg) = note_code(excluded[k], rows[k].reason);
                let d = &drows[k];
                out.extend([
                    rows[k].normalised,
                    level[k],
                    pct,
                    d.z,
                    d.upper,
                    d.lower,
                    if d.flagged { 1.0 } else { 0.0 },
                    code,
                    arg,
                ]);
            }
            results.put(regions.start[p][u], &out)?;
            let Some((ud, len)) = verdict else { continue };
            lengths.push(len);
            overview[u * names.len() + p] = ud.change_pct;
            if let (Some(f), Some(o)) = (ud.first_flagged, ud.onset) {
                alarms += 1;
                alarm_lines.push(format!(
                    "{},{},{},{},{},{},{},{:.3},{:.3},{:.3}",
                    units[u],
                    name,
                    show(f),
                    f,
                    show(o),
                    o,
                    if ud.direction > 0 { "rise" } else { "fall" },
                    ud.change_pct,
                    ud.ci95[0],
                    ud.ci95[1]
                ));
            }
            unit_docs.push(json!({
                "unit_id": units[u], "tested": ud.tested, "first_flagged": ud.first_flagged,
                "onset": ud.onset, "direction": ud.direction, "change_pct": ud.change_pct, "ci95": ud.ci95,
            }));
            if !a.no_plots {
                let value: Vec<f64> = samples.iter().map(|s| s.value).collect();
                let se: Vec<f64> = samples.iter().map(|s| s.se).collect();
                let normalised: Vec<f64> = rows.iter().map(|r| r.normalised).collect();
                let what = super::fleet_plot::UnitPlot {
                    unit: &units[u],
                    parameter: name,
                    param_unit: &punit,
                    x_label: &x_label,
                    t0,
                    day: &day,
                    value: &value,
                    se: &se,
                    normalised: &normalised,
                    verdict: &ud,
                };
                super::fleet_plot::unit_plot(dir, &what);
            }
        }
        let threshold = median_threshold(lengths, &thresholds);
        let n = &norm;
        chosen.push(format!("{name}: {}", n.chosen));
        doc_params.push(json!({
            "parameter": name,
            "unit": punit,
            "scale": if n.log_scale { "log" } else { "linear" },
            "normalisation": n.chosen,
            "candidates": n.candidates.iter().map(|c| json!({"model": c.name, "params": c.params, "rss": c.rss, "bic": c.bic})).collect::<Vec<_>>(),
            "coefficients": n.coefficients.iter().map(|(c, v, s)| json!({"covariate": c, "per_unit_of_covariate": v, "std_error": s, "percent_per_unit": if n.log_scale { Some(100.0 * v) } else { None }})).collect::<Vec<_>>(),
            "tau": n.tau,
            "baseline_estimates": n.baseline_rows,
            "cusum_threshold_median_series": threshold,
            "units": unit_docs,
        }));
    }
    write_drift_table(dir, &fits_path, units, &names, &regions, &data, &results, covs)?;
    let alarms_path = dir.join("alarms.csv");
    hd_io::atomic::write_atomically(&alarms_path, |f| {
        use std::io::Write;
        f.write_all((alarm_lines.join("\n") + "\n").as_bytes())
            .map_err(|e| hd_io::IoError::fs(&alarms_path, e))
    })?;
    let doc = json!({
        "settings": {
            "covariates": covs, "baseline_days": a.baseline_days, "false_alarm": a.false_alarm,
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
        chosen.join(", "),
        a.false_alarm
    );
    for l in alarm_lines.iter().skip(1) {
        eprintln!("  alarm: {l}");
    }
    if !a.no_plots {
        super::fleet_plot::overview(dir, units, &names, &overview);
    }
    eprintln!(
        "wrote {}, {}, {}",
        dir.join("drift.parquet").display(),
        alarms_path.display(),
        json_path.display()
    );
    Ok(())
}
