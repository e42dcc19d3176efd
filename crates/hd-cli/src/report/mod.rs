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
use hd_plot::ThinnedCurve;
use hd_sweep::Study;
use part_data::PartData;
use std::collections::HashMap;
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

/// Buckets of first/lowest/highest/last points kept per overlaid trace (at most four
/// points each; the plot's own decimation then works on these) [–].
const OVERLAY_BUCKETS: usize = 2048;

/// Rows of traces.parquet read at a time [–].
const TRACE_CHUNK_ROWS: usize = 1 << 19;

/// θz(t) of the runs `shown`, read from `traces` chunk by chunk and thinned as it arrives,
/// so memory is bounded whatever the traces' length.
fn read_overlays(traces: &Path, shown: &[String]) -> Result<HashMap<String, ThinnedCurve>> {
    let mut curves: HashMap<String, ThinnedCurve> =
        shown.iter().map(|id| (id.clone(), ThinnedCurve::new(OVERLAY_BUCKETS))).collect();
    hd_io::table::for_each_chunk(traces, &["run_id", "t", "theta_z"], TRACE_CHUNK_ROWS, |t| {
        let (Some(ids), Some(time), Some(thz)) = (t.text("run_id"), t.num("t"), t.num("theta_z"))
        else {
            return Ok(());
        };
        for ((id, &x), &y) in ids.iter().zip(time).zip(thz) {
            if let Some(c) = id.as_deref().and_then(|id| curves.get_mut(id)) {
                c.push(x, y);
            }
        }
        Ok(())
    })?;
    Ok(curves)
}

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
    // use, thinned while read: memory does not follow the traces' length.
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
        Some(read_overlays(traces, &shown)?)
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
