//! The study report: `report.md` with the key tables, and SVG plots beside it (a heatmap
//! per metric for 2-D grids, lines for 1-D axes, a Bode figure where `freq` is swept with
//! `gain_db` and `phase_deg` kept, overlaid traces where traces were kept),
//! plus the paper-versus-model table when the study states the paper's claims.

mod bode;
mod compare;
mod markdown;
mod part_data;
mod plots;
pub mod sensitivity;

use anyhow::Result;
use hd_sweep::Study;
use part_data::PartData;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Everything a study writes once its runs are in one table: `report.md` with its plots
/// and, when a part has a sobol or morris design, the sensitivity analysis. `hdw study`
/// (one machine) and `hdw report` (merged shards) both end here, so their reports agree.
/// `note` (markdown, e.g. the list of missing runs) is placed under the run counts.
/// Returns the report's path.
pub fn write_study_outputs(
    dir: &Path,
    study: &Study,
    runs: &Path,
    traces: &Path,
    note: Option<&str>,
) -> Result<PathBuf> {
    let path = write_report(dir, study, runs, traces, note)?;
    eprintln!("report: {}", path.display());
    if study.has_sensitivity_design() {
        sensitivity::after_study(dir)?;
    }
    Ok(path)
}

/// The columns of `runs.parquet` the report reads (a scan decodes only these): identity,
/// input, the swept names, the kept metrics and the compared quantities.
fn report_columns(study: &Study) -> Vec<&str> {
    let mut cols: Vec<&str> =
        vec!["run_id", "run_index", "part", "variant", "status", "error", "voltage", "freq"];
    cols.extend(study.swept_names());
    cols.extend(study.keep_metrics.iter().copied());
    for c in &study.compare {
        cols.extend([c.axis.as_str(), c.metric.as_str()]);
    }
    cols.sort_unstable();
    cols.dedup();
    cols
}

/// Runs of a part whose load angle the report overlays.
pub const OVERLAID_RUNS: usize = 12;

/// Write `DIR/report.md` and its plots; returns the report's path.
fn write_report(
    dir: &Path,
    study: &Study,
    runs: &Path,
    traces: &Path,
    note: Option<&str>,
) -> Result<PathBuf> {
    let table = hd_io::table::read_table_columns(runs, &report_columns(study))?;
    // Only the runs the overlays draw (the first 12 of each part), and only the columns they
    // use: memory follows those runs, not the length of the whole traces table.
    let trace_table = if traces.exists() {
        let ids = table.text("run_id").unwrap_or(&[]);
        let parts = table.text("part").unwrap_or(&[]);
        let mut shown: Vec<String> = Vec::new();
        for part in &study.parts {
            let of_part = (0..table.height)
                .filter(|&i| parts.get(i).and_then(|p| p.as_deref()) == Some(part.name.as_str()))
                .filter_map(|i| ids.get(i).cloned().flatten())
                .take(OVERLAID_RUNS);
            shown.extend(of_part);
        }
        Some(hd_io::table::read_rows_with(traces, &["run_id", "t", "theta_z"], "run_id", &shown)?)
    } else {
        None
    };
    let mut md = String::new();
    writeln!(md, "# Study `{}`\n", study.name)?;
    if !study.description.is_empty() {
        writeln!(md, "{}\n", study.description)?;
    }
    let total = table.height;
    let failed =
        table.text("status").map_or(0, |s| s.iter().filter(|v| v.as_deref() != Some("ok")).count());
    writeln!(
        md,
        "{total} runs, {failed} failed. Study file: `{}`. Full results: `runs.parquet`.\n",
        study.file.display()
    )?;
    if let Some(note) = note {
        writeln!(md, "{}\n", note.trim_end())?;
    }
    if !study.compare.is_empty() {
        writeln!(md, "## The seed paper's claims against the model\n")?;
        md.push_str(&compare::section(study, &table));
    }
    let mut progress = crate::stages::Stages::new(study.parts.len(), "report");
    for part in &study.parts {
        progress.stage(&format!("part {}: tables and plots", part.name));
        let data = PartData::new(part, &table, &study.keep_metrics);
        writeln!(
            md,
            "## Part `{}` ({} runs, {} failed)\n",
            part.name,
            data.rows.len(),
            data.failed
        )?;
        writeln!(md, "{}\n", markdown::describe_part(part))?;
        md.push_str(&plots::part_plots(dir, &study.name, &data, trace_table.as_ref())?);
        md.push_str(&markdown::part_table(&data));
        md.push_str(&markdown::failures(&data));
        progress.done();
    }
    progress.finish();
    let path = dir.join("report.md");
    hd_io::atomic::write_atomically(&path, |f| {
        use std::io::Write;
        f.write_all(md.as_bytes()).map_err(|e| hd_io::IoError::fs(&path, e))
    })?;
    Ok(path)
}
