//! Global sensitivity of a finished study: every part with a sobol or morris design is
//! analysed into `sensitivity.parquet`, one bar chart per metric
//! (`sensitivity-<metric>.svg`, or `sensitivity-<part>-<metric>.svg` when several parts
//! have designs) and `sensitivity.md`, whose section is also placed at the end of
//! `report.md` when there is one. `hdw sensitivity DIR` and the end of `hdw study` both
//! call [`analyse_dir`].

mod figures;
mod gather;
mod markdown;

use anyhow::{Context, Result, bail};
use gather::DesignData;
use hd_sweep::sensitivity::{
    MetricColumn, SensitivityMethod, SensitivityRow, SobolOptions, analyse,
};
use std::path::{Path, PathBuf};

/// Settings of the analysis.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Metrics to analyse (`None`: every kept metric with a finite value).
    pub metrics: Option<Vec<String>>,
    /// Sobol' estimator settings (bootstrap resamples and seed).
    pub sobol: SobolOptions,
}

/// The result for one design part.
pub struct PartResult {
    /// Part name.
    pub part: String,
    /// sobol or morris.
    pub method: SensitivityMethod,
    /// Design parameters, in design order.
    pub parameters: Vec<String>,
    /// Metrics analysed, in order.
    pub metrics: Vec<String>,
    /// Base rows or trajectories in the design.
    pub groups: usize,
    /// Runs in the design.
    pub runs: usize,
    /// Runs that failed.
    pub failed: usize,
    /// Runs missing from the runs tables.
    pub missing: usize,
    /// One row per metric × parameter, metric by metric.
    pub rows: Vec<SensitivityRow>,
}

impl PartResult {
    /// The rows of one metric, best-ranked first (by ST for Sobol', μ* for Morris; NaN
    /// last).
    pub fn ranked(&self, metric: &str) -> Vec<&SensitivityRow> {
        let mut rows: Vec<&SensitivityRow> =
            self.rows.iter().filter(|r| r.metric == metric).collect();
        rows.sort_by(|a, b| rank_value(b).total_cmp(&rank_value(a)));
        rows
    }

    /// Base rows or trajectories, as the method calls them.
    pub fn group_word(&self) -> &'static str {
        match self.method {
            SensitivityMethod::Sobol => "base rows",
            SensitivityMethod::Morris => "trajectories",
        }
    }
}

/// The ranking value of a row: ST (Sobol') or μ* (Morris); NaN ranks last.
pub fn rank_value(r: &SensitivityRow) -> f64 {
    let v = match r.method {
        SensitivityMethod::Sobol => r.st,
        SensitivityMethod::Morris => r.mu_star,
    };
    if v.is_finite() { v } else { f64::NEG_INFINITY }
}

/// Everything the analysis produced.
pub struct Analysis {
    /// Study name.
    pub study: String,
    /// Results per design part.
    pub parts: Vec<PartResult>,
    /// `sensitivity.parquet`.
    pub table: PathBuf,
    /// `sensitivity.md`.
    pub markdown: PathBuf,
    /// Bar charts written.
    pub plots: Vec<PathBuf>,
    /// Bar charts that could not be drawn, with the reason (e.g. no finite index).
    pub skipped_plots: Vec<String>,
}

/// Analyse the study in `dir` (its `study.json` and `runs*.parquet`) and write the outputs.
pub fn analyse_dir(dir: &Path, options: &Options) -> Result<Analysis> {
    let json_path = dir.join("study.json");
    let text = std::fs::read_to_string(&json_path).with_context(|| {
        format!("cannot read {} (is DIR a study's output folder?)", json_path.display())
    })?;
    let study: hd_sweep::StudyManifest = serde_json::from_str(&text).with_context(|| {
        format!("{}: not the study.json of a study written by hdw", json_path.display())
    })?;
    let table = hd_io::sensitivity::read_study_runs(dir)?;
    let data = gather::design_parts(&study, &table, options.metrics.as_deref())?;
    if data.is_empty() {
        bail!(
            "{}: the study has no part with a sobol or morris design ([sample] method = \"sobol\" or \"morris\")",
            dir.display()
        );
    }
    let parts =
        data.into_iter().map(|d| analyse_part(d, &options.sobol)).collect::<Result<Vec<_>>>()?;
    let flat: Vec<(String, SensitivityRow)> =
        parts.iter().flat_map(|p| p.rows.iter().map(|r| (p.part.clone(), r.clone()))).collect();
    let table_path = dir.join("sensitivity.parquet");
    hd_io::sensitivity::write_sensitivity(
        &table_path,
        &hd_sweep::tables::sensitivity_table(&flat),
    )?;
    let (plots, skipped_plots) = figures::draw(dir, &parts)?;
    let name = study.name.clone();
    let markdown = markdown::write(dir, &name, &parts, &options.sobol, &plots)?;
    Ok(Analysis { study: name, parts, table: table_path, markdown, plots, skipped_plots })
}

/// The analysis at the end of `hdw study`, with default settings; prints the three
/// top-ranked parameters per metric to stderr.
pub fn after_study(dir: &Path) -> Result<()> {
    let a = analyse_dir(dir, &Options::default())?;
    for p in &a.parts {
        for m in &p.metrics {
            let top: Vec<&str> = p.ranked(m).iter().take(3).map(|r| r.parameter.as_str()).collect();
            eprintln!("sensitivity ({}, {m}): {}", p.method, top.join(" > "));
        }
    }
    eprintln!("sensitivity: {}, {}", a.markdown.display(), a.table.display());
    Ok(())
}

fn analyse_part(d: DesignData, sobol: &SobolOptions) -> Result<PartResult> {
    let columns: Vec<MetricColumn> =
        d.metrics.iter().map(|(name, values)| MetricColumn { name, values }).collect();
    let rows = if columns.is_empty() {
        Vec::new()
    } else {
        analyse(&d.parameters, &d.points, &columns, sobol)
            .with_context(|| format!("part '{}'", d.part))?
    };
    Ok(PartResult {
        metrics: d.metrics.iter().map(|(n, _)| n.clone()).collect(),
        runs: d.points.len(),
        part: d.part,
        method: d.method,
        parameters: d.parameters,
        groups: d.groups,
        failed: d.failed,
        missing: d.missing,
        rows,
    })
}
