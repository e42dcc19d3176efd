//! The logs of a fleet: the manifest (or path pattern) read and checked into one
//! [`LogSpec`] per row, with the row's problem when it cannot be fitted (a duplicate, an
//! empty cell, a timestamp that does not parse): such a row becomes a failed row of
//! fits.parquet with its reason, and the others go on.

use anyhow::{Result, bail};
use hd_io::fleet::{expand_pattern, parse_day};
use hd_io::table::{ColumnData, Table};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Columns of fits.parquet that a manifest column may not take the name of.
pub const RESERVED: [&str; 22] = [
    "run_index",
    "run_id",
    "log_index",
    "unit_id",
    "day",
    "status",
    "error",
    "fit",
    "parameter",
    "value",
    "std_error",
    "ci95_lo",
    "ci95_hi",
    "determined",
    "param_unit",
    "resid_over_noise",
    "rms",
    "noise_std",
    "samples",
    "fit_time_s",
    "time_scale_used",
    "torque_scale_used",
];

/// Where the logs are listed and which columns say what.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct Source {
    /// A manifest file (CSV or Parquet), or
    pub manifest: Option<PathBuf>,
    /// a path pattern such as `logs/{robot}/{joint}/{date}.csv`.
    pub pattern: Option<String>,
    /// Column naming each log's file.
    pub file_column: String,
    /// Columns identifying a unit (e.g. robot, joint).
    pub unit: Vec<String>,
    /// Column holding the log's timestamp.
    pub time: String,
    /// Covariate columns (numbers).
    pub covariates: Vec<String>,
}

/// One log to fit.
#[derive(Clone, Debug)]
pub struct LogSpec {
    /// 0-based manifest row.
    pub index: usize,
    /// The file as the manifest names it.
    pub file: String,
    /// The file to open.
    pub path: PathBuf,
    /// The unit's identifiers joined by '/'.
    pub unit: String,
    /// Timestamp [days since 1970-01-01, or the manifest's own day numbers].
    pub day: f64,
    /// Per-row unit factors from the manifest's columns time_scale, speed_scale,
    /// torque_scale (NaN: the template's).
    pub scales: [f64; 3],
    /// Why the row is not fitted.
    pub problem: Option<String>,
}

/// The manifest's table and the logs it lists.
pub struct Plan {
    /// The manifest as read (every column is carried into fits.parquet).
    pub table: Table,
    /// One per row.
    pub logs: Vec<LogSpec>,
}

fn cell_text(t: &Table, k: usize, row: usize) -> Option<String> {
    match &t.columns[k] {
        ColumnData::Text(v) => v[row].clone().filter(|s| !s.trim().is_empty()),
        ColumnData::Num(v) => v[row].is_finite().then(|| {
            let x = v[row];
            if x.fract() == 0.0 && x.abs() < 1e15 {
                format!("{}", x as i64)
            } else {
                format!("{x}")
            }
        }),
    }
}

/// Read and check the manifest: a missing named column is one line (naming the manifest
/// and listing its columns); problems of single rows stay with their rows.
pub fn plan(src: &Source) -> Result<Plan> {
    let (table, base, what) = match (&src.manifest, &src.pattern) {
        (Some(m), None) => {
            super::common::check_data_file(m, "manifest")?;
            let t = hd_io::read_table(m)?;
            let base = m.parent().map(Path::to_path_buf).unwrap_or_default();
            (t, base, format!("manifest {}", m.display()))
        }
        (None, Some(p)) => {
            let t = expand_pattern(p)?;
            if t.height == 0 {
                bail!("--pattern {p}: no file matches");
            }
            (t, PathBuf::new(), format!("--pattern {p}"))
        }
        _ => bail!(
            "give the logs as --manifest FILE or --pattern 'logs/{{robot}}/{{joint}}/{{date}}.csv' (one of them)"
        ),
    };
    let col = |name: &str, role: &str| -> Result<usize> {
        match table.names.iter().position(|n| n == name) {
            Some(k) => Ok(k),
            None => bail!(
                "{what}: no column '{name}' ({role}); its columns: {}",
                table.names.join(", ")
            ),
        }
    };
    let taken =
        |n: &String| RESERVED.contains(&n.as_str()) || (n == "file" && src.file_column != "file");
    if let Some(n) = table.names.iter().find(|n| taken(n)) {
        bail!("{what}: column '{n}' has the name of a column of fits.parquet: rename it");
    }
    let kf = col(&src.file_column, "the log files, --file-column")?;
    let ku: Vec<usize> =
        src.unit.iter().map(|u| col(u, "a unit identifier, --unit")).collect::<Result<_>>()?;
    let kt = col(&src.time, "the timestamp, --time")?;
    if table.height == 0 {
        bail!("{what}: no logs (a header and no rows): expected one row per log");
    }
    for c in &src.covariates {
        let k = col(c, "a covariate, --covariates")?;
        if let ColumnData::Text(v) = &table.columns[k] {
            // A covariate is a number (temperature, payload); a text cell that is not one
            // means the wrong column (a date, a name) and would leave nothing to normalise.
            if let Some((row, cell)) = v.iter().enumerate().find_map(|(r, x)| {
                x.as_deref().filter(|x| x.trim().parse::<f64>().is_err()).map(|x| (r, x))
            }) {
                bail!(
                    "{what}: covariate column '{c}' is not numeric (row {}: '{cell}'): expected a number per log (a temperature, a payload), or leave it out of --covariates",
                    row + 1
                );
            }
        }
    }
    let scale_cols: Vec<Option<usize>> = ["time_scale", "speed_scale", "torque_scale"]
        .iter()
        .map(|n| table.names.iter().position(|m| m == n))
        .collect();
    let mut by_file: HashMap<String, usize> = HashMap::new();
    let mut by_key: HashMap<(String, u64), usize> = HashMap::new();
    let mut logs = Vec::with_capacity(table.height);
    for row in 0..table.height {
        let mut problem = None;
        let file = cell_text(&table, kf, row).unwrap_or_default();
        if file.is_empty() {
            problem =
                Some(format!("manifest row {}: column '{}' is empty", row + 1, src.file_column));
        }
        let mut parts = Vec::new();
        for (k, name) in ku.iter().zip(&src.unit) {
            match cell_text(&table, *k, row) {
                Some(v) => parts.push(v),
                None => {
                    problem.get_or_insert(format!(
                        "manifest row {}: column '{name}' is empty",
                        row + 1
                    ));
                    parts.push(String::new());
                }
            }
        }
        let unit = parts.join("/");
        let day = match &table.columns[kt] {
            ColumnData::Num(v) if v[row].is_finite() => v[row],
            _ => match cell_text(&table, kt, row).map(|s| parse_day(&s)) {
                Some(Ok(d)) => d,
                Some(Err(e)) => {
                    problem.get_or_insert(format!(
                        "manifest row {}: column '{}': {e}",
                        row + 1,
                        src.time
                    ));
                    f64::NAN
                }
                None => {
                    problem.get_or_insert(format!(
                        "manifest row {}: column '{}' is empty",
                        row + 1,
                        src.time
                    ));
                    f64::NAN
                }
            },
        };
        if problem.is_none() {
            if let Some(first) = by_file.get(&file) {
                problem = Some(format!(
                    "manifest row {}: duplicate of row {} (same file {file})",
                    row + 1,
                    first + 1
                ));
            } else if let Some(first) = by_key.get(&(unit.clone(), day.to_bits())) {
                problem = Some(format!(
                    "manifest row {}: duplicate of row {} (same unit {unit} and time)",
                    row + 1,
                    first + 1
                ));
            }
        }
        if problem.is_none() {
            by_file.insert(file.clone(), row);
            by_key.insert((unit.clone(), day.to_bits()), row);
        }
        let mut scales = [f64::NAN; 3];
        for ((s, k), name) in
            scales.iter_mut().zip(&scale_cols).zip(["time_scale", "speed_scale", "torque_scale"])
        {
            let Some(k) = k else { continue };
            // An empty cell keeps the template's factor; anything else must be one.
            let cell = cell_text(&table, *k, row);
            let Some(text) = cell else { continue };
            match text.trim().parse::<f64>() {
                Ok(v) if super::fit_input::usable_factor(v) => *s = v,
                _ => {
                    problem.get_or_insert(format!(
                        "manifest row {}: column '{name}' is '{text}': expected a finite, non-zero unit factor between 1e-12 and 1e12 in magnitude (or an empty cell for the template's)",
                        row + 1
                    ));
                }
            }
        }
        let path =
            if Path::new(&file).is_absolute() { PathBuf::from(&file) } else { base.join(&file) };
        logs.push(LogSpec { index: row, file, path, unit, day, scales, problem });
    }
    Ok(Plan { table, logs })
}
