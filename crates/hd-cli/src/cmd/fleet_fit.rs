//! One log of a fleet fitted with the fleet's template, in-process (the hd-ident fit
//! functions `hdw fit friction` calls), and the rows it gives in fits.parquet: one per
//! parameter, or one failed row with the reason.

use super::fleet_plan::{LogSpec, Plan};
use hd_ident::fleet::{PlateauOptions, fit_plateaus};
use hd_ident::stiffness::{Law, LawOptions, fit_law};
use hd_ident::{
    Estimate, Fixed, FrictionOptions, HysteresisData, SteadyData, TransientData, fit_friction_with,
};
use hd_io::fleet::{FleetCells, FleetColumn};
use hd_io::table::ColumnData;
use std::time::Instant;

/// Which fit every log gets.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum FitKind {
    /// The static law (Tc, Ts, ws, sigma2) from the speed plateaus of a joint test.
    Plateaus,
    /// Every LuGre parameter from the time series (`hdw fit friction --transient`).
    Transient,
    /// The static law from a steady-state table (`hdw fit friction --steady`).
    Steady,
    /// A stiffness law from a torque–deflection record (`hdw fit hysteresis`: `--law`,
    /// `--elements`, `--theta-unit`, `--offset`, `--fix`).
    Hysteresis,
    /// A rigid drive from its logged closed loop (`hdw fit drive`): the configuration of
    /// `--drive-config` with its one record's `file` replaced by each log.
    Drive,
}

/// The fit template: the same settings for every log.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct Template {
    /// Fit kind.
    pub kind: FitKind,
    /// Column names: t, omega, torque (steady: omega, torque).
    pub columns: Vec<String>,
    /// Factors to s, rad/s, N·m.
    pub time_scale: f64,
    /// Speed factor.
    pub speed_scale: f64,
    /// Torque factor.
    pub torque_scale: f64,
    /// Direction-dependent levels.
    pub asymmetric: bool,
    /// Torque offset.
    pub offset: bool,
    /// `NAME=VALUE` held parameters.
    pub fix: Vec<String>,
    /// Plateaus: relative speed tolerance.
    pub plateau_tolerance: f64,
    /// Plateaus: settling share dropped.
    pub settle: f64,
    /// Plateaus: shortest plateau [s].
    pub min_dwell: f64,
    /// Hysteresis: the stiffness law (memory, maxwell-slip, bouc-wen).
    #[serde(default = "default_law")]
    pub law: String,
    /// Hysteresis: Maxwell-slip elements.
    #[serde(default = "default_elements")]
    pub elements: usize,
    /// Hysteresis: unit of the deflection column (rad, mrad, urad, deg, arcmin, arcsec).
    #[serde(default = "default_theta_unit")]
    pub theta_unit: String,
    /// Drive: the text of the fit-drive configuration (its `file` replaced per log).
    #[serde(default)]
    pub drive_config: String,
}

fn default_law() -> String {
    "memory".into()
}

fn default_elements() -> usize {
    hd_ident::stiffness::maxwell_slip::DEFAULT_ELEMENTS
}

fn default_theta_unit() -> String {
    "rad".into()
}

impl Template {
    /// The name of the fit in fits.parquet: `friction-plateaus`, `hysteresis-memory` …
    pub fn fit_name(&self) -> String {
        match self.kind {
            FitKind::Hysteresis => format!("hysteresis-{}", self.law),
            FitKind::Drive => "drive".into(),
            k => format!(
                "friction-{}",
                serde_json::to_value(k)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_string))
                    .unwrap_or_default()
            ),
        }
    }
}

/// What one log gave.
pub struct LogFit {
    /// Parameters with their estimates, or the reason the log failed.
    pub outcome: Result<Vec<(String, Estimate)>, String>,
    /// Fit name.
    pub fit: String,
    /// RMS residual over the noise [–].
    pub resid_over_noise: f64,
    /// RMS residual [N·m].
    pub rms: f64,
    /// Noise estimate [N·m].
    pub noise_std: f64,
    /// Points fitted.
    pub samples: u64,
    /// Wall time [s].
    pub time_s: f64,
}

/// Noise of a smooth signal from its first differences, σ ≈ RMS(Δy)/√2 [signal unit].
fn diff_noise(y: &[f64]) -> f64 {
    if y.len() < 3 {
        return f64::NAN;
    }
    let mut d: Vec<f64> = y.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    // Median absolute difference: jumps at speed changes do not count.
    let mid = d.len() / 2;
    let m = *d.select_nth_unstable_by(mid, f64::total_cmp).1;
    m / (std::f64::consts::SQRT_2 * 0.674_489_75)
}

/// An error with its sources, on one line: `file: no such file (os error 2)`.
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut src = e.source();
    while let Some(c) = src {
        let t = c.to_string();
        if !s.contains(&t) {
            s.push_str(": ");
            s.push_str(&t);
        }
        src = c.source();
    }
    s.replace('\n', " ")
}

/// Fit one log.
pub fn fit_log(log: &LogSpec, t: &Template, fixed: &Fixed) -> LogFit {
    let start = Instant::now();
    let mut out = LogFit {
        outcome: Err(String::new()),
        fit: t.fit_name(),
        resid_over_noise: f64::NAN,
        rms: f64::NAN,
        noise_std: f64::NAN,
        samples: 0,
        time_s: 0.0,
    };
    if let Some(p) = &log.problem {
        out.outcome = Err(p.clone());
        return out;
    }
    if t.kind == FitKind::Drive {
        out.outcome = super::fleet_drive::fit_drive_log(log, &t.drive_config, &mut out);
        out.time_s = start.elapsed().as_secs_f64();
        return out;
    }
    let res = (|| -> Result<Vec<(String, Estimate)>, String> {
        let names: Vec<&str> = t.columns.iter().map(String::as_str).collect();
        // A folder, a device or a pipe is named as such (read_columns would wait on a pipe
        // or read /dev/zero without end).
        if log.path.exists() {
            super::common::check_data_file(&log.path, "log").map_err(|e| format!("{e:#}"))?;
        }
        let cols = hd_io::read_columns(&log.path, &names).map_err(|e| chain(&e))?;
        let pick = |own: f64, tpl: f64| if own.is_finite() { own } else { tpl };
        let (ts, ws, qs) = (
            pick(log.scales[0], t.time_scale),
            pick(log.scales[1], t.speed_scale),
            pick(log.scales[2], t.torque_scale),
        );
        let scaled = |v: &Vec<f64>, k: f64| v.iter().map(|x| x * k).collect::<Vec<f64>>();
        let at = |e: String| format!("{}: {e}", log.path.display());
        match t.kind {
            FitKind::Plateaus | FitKind::Transient => {
                let (tt, w, q) = (scaled(&cols[0], ts), scaled(&cols[1], ws), scaled(&cols[2], qs));
                out.noise_std = diff_noise(&q);
                if t.kind == FitKind::Plateaus {
                    let o = PlateauOptions {
                        tolerance: t.plateau_tolerance,
                        min_duration: t.min_dwell,
                        settle: t.settle,
                        asymmetric: t.asymmetric,
                        offset: t.offset,
                        ..Default::default()
                    };
                    let f = fit_plateaus(&tt, &w, &q, &o, fixed).map_err(|e| at(e.to_string()))?;
                    out.resid_over_noise = f.resid_over_noise;
                    out.rms = f.report.rms;
                    out.samples = f.plateaus.len() as u64;
                    Ok(f.report.parameters.0)
                } else {
                    let d = TransientData::new(tt, w, q).map_err(|e| at(e.to_string()))?;
                    #[allow(clippy::needless_update)]
                    let o = FrictionOptions {
                        asymmetric: t.asymmetric,
                        offset: t.offset,
                        ..Default::default()
                    };
                    let f = fit_friction_with(None, Some(&d), fixed, o)
                        .map_err(|e| at(e.to_string()))?;
                    out.rms = f.report.rms;
                    out.resid_over_noise = f.report.rms / out.noise_std;
                    out.samples = f.report.samples as u64;
                    Ok(f.report.parameters.0)
                }
            }
            FitKind::Hysteresis => {
                let to_rad = super::fit_input::angle_factor(&t.theta_unit)
                    .map_err(|e| format!("--theta-unit: {e}"))?;
                let (tt, th, q) =
                    (scaled(&cols[0], ts), scaled(&cols[1], to_rad), scaled(&cols[2], qs));
                let d = HysteresisData::new(tt, th, q).map_err(|e| at(e.to_string()))?;
                let law = Law::parse(&t.law).map_err(|e| format!("--law: {e}"))?;
                let o = LawOptions { offset: t.offset, elements: t.elements, fixed: fixed.clone() };
                let f = fit_law(&d, law, &o).map_err(|e| at(e.to_string()))?;
                out.rms = f.report.rms;
                out.noise_std = f.report.noise_std;
                out.resid_over_noise = f.report.rms / f.report.noise_std;
                out.samples = f.report.samples as u64;
                Ok(f.report.parameters.0)
            }
            FitKind::Drive => Err("internal error: a drive log read as columns".into()),
            FitKind::Steady => {
                let (w, q) = (scaled(&cols[0], ws), scaled(&cols[1], qs));
                let d = SteadyData::new(w, q).map_err(|e| at(e.to_string()))?;
                #[allow(clippy::needless_update)]
                let o = FrictionOptions {
                    asymmetric: t.asymmetric,
                    offset: t.offset,
                    ..Default::default()
                };
                let f =
                    fit_friction_with(Some(&d), None, fixed, o).map_err(|e| at(e.to_string()))?;
                out.rms = f.report.rms;
                out.noise_std = f.report.noise_std;
                out.resid_over_noise = 1.0;
                out.samples = f.report.samples as u64;
                Ok(f.report.parameters.0)
            }
        }
    })();
    out.outcome = res;
    out.time_s = start.elapsed().as_secs_f64();
    out
}

/// Rows per log in `run_index` (log_index · ROW_SLOTS + the parameter's position).
pub const ROW_SLOTS: u64 = 64;

fn col(name: &str, cells: FleetCells, unit: &str, doc: &str) -> FleetColumn {
    FleetColumn { name: name.into(), cells, unit: unit.into(), doc: doc.into() }
}

/// The fits.parquet rows of `fits` (logs of `plan` in the same order).
pub fn rows(plan: &Plan, logs: &[&LogSpec], fits: &[LogFit]) -> Vec<FleetColumn> {
    let mut run_index = Vec::new();
    let mut run_id = Vec::new();
    let mut log_index = Vec::new();
    let mut file = Vec::new();
    let mut unit = Vec::new();
    let mut day = Vec::new();
    let mut status = Vec::new();
    let mut error = Vec::new();
    let mut fit = Vec::new();
    let mut parameter = Vec::new();
    let (mut value, mut se, mut lo, mut hi) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut determined = Vec::new();
    let mut punit = Vec::new();
    let (mut ron, mut rms, mut noise, mut samples, mut time) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut manifest_rows = Vec::new();
    for (log, f) in logs.iter().zip(fits) {
        let list: Vec<(Option<String>, Option<&Estimate>)> = match &f.outcome {
            Ok(p) => p.iter().map(|(n, e)| (Some(n.clone()), Some(e))).collect(),
            Err(_) => vec![(None, None)],
        };
        for (slot, (name, est)) in list.into_iter().enumerate() {
            run_index.push(log.index as u64 * ROW_SLOTS + slot as u64);
            run_id.push(Some(format!(
                "{}#{}#{}",
                log.index,
                log.file,
                name.as_deref().unwrap_or("-")
            )));
            log_index.push(log.index as u64);
            file.push(Some(log.file.clone()));
            unit.push(Some(log.unit.clone()));
            day.push(log.day);
            status.push(Some(if f.outcome.is_ok() { "ok" } else { "failed" }.to_string()));
            error.push(f.outcome.as_ref().err().cloned());
            fit.push(Some(f.fit.clone()));
            parameter.push(name);
            value.push(est.map_or(f64::NAN, |e| e.value));
            se.push(est.and_then(|e| e.std_error).unwrap_or(f64::NAN));
            lo.push(est.and_then(|e| e.ci95).map_or(f64::NAN, |c| c[0]));
            hi.push(est.and_then(|e| e.ci95).map_or(f64::NAN, |c| c[1]));
            determined.push(est.is_some_and(|e| e.determined));
            punit.push(est.map(|e| e.unit.to_string()));
            ron.push(f.resid_over_noise);
            rms.push(f.rms);
            noise.push(f.noise_std);
            samples.push(f.samples);
            time.push(f.time_s);
            manifest_rows.push(log.index);
        }
    }
    let mut cols = vec![
        col(
            "run_index",
            FleetCells::U64(run_index),
            "-",
            "row key: log_index × 64 + the parameter's position (the table is sorted by it)",
        ),
        col("run_id", FleetCells::Text(run_id), "text", "row key: log_index#file#parameter"),
        col("log_index", FleetCells::U64(log_index), "-", "0-based row of the manifest"),
        col("file", FleetCells::Text(file), "text", "the log file, as the manifest names it"),
        col("unit_id", FleetCells::Text(unit), "text", "the unit's identifiers joined by '/'"),
        col(
            "day",
            FleetCells::F64(day),
            "d",
            "the log's timestamp in days since 1970-01-01 (or the manifest's day numbers)",
        ),
    ];
    for (k, name) in plan.table.names.iter().enumerate() {
        if name == "file" {
            continue; // the manifest's file column is `file` above
        }
        let cells = match &plan.table.columns[k] {
            ColumnData::Num(v) => FleetCells::F64(manifest_rows.iter().map(|&r| v[r]).collect()),
            ColumnData::Text(v) => {
                FleetCells::Text(manifest_rows.iter().map(|&r| v[r].clone()).collect())
            }
        };
        let unit = if matches!(cells, FleetCells::Text(_)) { "text" } else { "-" };
        cols.push(col(name, cells, unit, "manifest column"));
    }
    cols.extend([
        col("status", FleetCells::Text(status), "text", "ok, or failed (see error)"),
        col("error", FleetCells::Text(error), "text", "why the log was not fitted: file, column or fit, and what was expected"),
        col("fit", FleetCells::Text(fit), "text", "fit kind: friction-plateaus, friction-transient, friction-steady, hysteresis-LAW or drive"),
        col("parameter", FleetCells::Text(parameter), "text", "registry name of the parameter (null on a failed row)"),
        col("value", FleetCells::F64(value), "param_unit", "estimate, in the unit of param_unit"),
        col("std_error", FleetCells::F64(se), "param_unit", "standard error (null when fixed or singular)"),
        col("ci95_lo", FleetCells::F64(lo), "param_unit", "95 % interval, lower end"),
        col("ci95_hi", FleetCells::F64(hi), "param_unit", "95 % interval, upper end"),
        col("determined", FleetCells::Bool(determined), "-", "whether the log determines the parameter"),
        col("param_unit", FleetCells::Text(punit), "text", "the parameter's unit (registry)"),
        col("resid_over_noise", FleetCells::F64(ron), "-", "RMS residual over the noise (plateaus: of the plateau means over their standard errors; transient: over the noise from first differences; hysteresis: over the fit's noise estimate)"),
        col("rms", FleetCells::F64(rms), "N·m", "RMS residual of the fit"),
        col("noise_std", FleetCells::F64(noise), "N·m", "noise of the torque estimated from first differences"),
        col("samples", FleetCells::U64(samples), "-", "points fitted (plateaus: plateau means)"),
        col("fit_time_s", FleetCells::F64(time), "s", "wall time of reading and fitting the log"),
    ]);
    cols
}

/// The parameters' units as one JSON document (`hdw.parameter_units` in the metadata).
pub fn parameter_units() -> String {
    let m: serde_json::Map<String, serde_json::Value> = hd_model::registry::REGISTRY
        .iter()
        .map(|p| (p.name.to_string(), serde_json::Value::String(p.unit.to_string())))
        .collect();
    serde_json::Value::Object(m).to_string()
}
