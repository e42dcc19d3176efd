//! The sensitivity section: `sensitivity.md`, and the same section at the end of
//! `report.md` (replaced, not repeated, when the analysis runs again).

use super::{PartResult, figures, rank_value};
use anyhow::Result;
use hd_sweep::sensitivity::{SensitivityMethod, SobolOptions};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Marks the start of the section in `report.md`; everything after it is replaced.
const MARKER: &str = "<!-- hdw sensitivity: this section is rewritten by each analysis -->";

/// Write `sensitivity.md` and the section of `report.md` (if that exists); returns the
/// path of `sensitivity.md`.
pub fn write(
    dir: &Path,
    study: &str,
    parts: &[PartResult],
    sobol: &SobolOptions,
    plots: &[PathBuf],
) -> Result<PathBuf> {
    let body = section(parts, sobol, plots);
    let path = dir.join("sensitivity.md");
    write_text(&path, &format!("# Global sensitivity of study `{study}`\n\n{body}"))?;
    let report = dir.join("report.md");
    if let Ok(old) = std::fs::read_to_string(&report) {
        let kept = old.split(MARKER).next().unwrap_or_default().trim_end();
        write_text(&report, &format!("{kept}\n\n{MARKER}\n## Global sensitivity\n\n{body}"))?;
    }
    Ok(path)
}

fn write_text(path: &Path, text: &str) -> Result<()> {
    hd_io::atomic::write_atomically(path, |f| {
        use std::io::Write;
        f.write_all(text.as_bytes()).map_err(|e| hd_io::IoError::fs(path, e))
    })?;
    Ok(())
}

/// The section body: per part, what was run, then per metric the ranking, a table and
/// the chart.
fn section(parts: &[PartResult], sobol: &SobolOptions, plots: &[PathBuf]) -> String {
    let mut md = String::new();
    for p in parts {
        let d = p.parameters.len();
        let _ = match p.method {
            SensitivityMethod::Sobol => writeln!(
                md,
                "### Part `{}`: Sobol' indices\n\nSaltelli design over {d} parameters: {} base \
                 rows × {} = {} runs ({} failed, {} missing from the tables). S1 is the share \
                 of a metric's variance explained by the parameter alone; ST adds every \
                 interaction the parameter takes part in, so ST − S1 measures interaction. \
                 Intervals: {:.0} % percentile bootstrap over base rows ({} resamples). A \
                 base row with any failed or missing run is dropped whole, never filled in.\n",
                p.part,
                p.groups,
                d + 2,
                p.runs,
                p.failed,
                p.missing,
                100.0 * sobol.confidence,
                sobol.bootstrap
            ),
            SensitivityMethod::Morris => writeln!(
                md,
                "### Part `{}`: Morris screening\n\n{} trajectories over {d} parameters: {} runs \
                 ({} failed, {} missing from the tables). μ* is the mean absolute elementary \
                 effect, in the metric's unit per full parameter range; μ its signed mean; a \
                 large σ flags interactions or a nonlinear effect. A trajectory with any \
                 failed or missing run is dropped whole.\n",
                p.part, p.groups, p.runs, p.failed, p.missing
            ),
        };
        for m in &p.metrics {
            metric_section(&mut md, parts, p, m, plots);
        }
    }
    md.push_str("Full table: `sensitivity.parquet` (one row per part, metric and parameter).\n");
    md
}

fn metric_section(
    md: &mut String,
    parts: &[PartResult],
    p: &PartResult,
    metric: &str,
    plots: &[PathBuf],
) {
    let rows = p.ranked(metric);
    let Some(first) = rows.first() else { return };
    let by = if p.method == SensitivityMethod::Sobol { "ST" } else { "μ*" };
    let _ = writeln!(
        md,
        "#### `{metric}`: {} of {} {} used, {} dropped\n",
        first.n_used,
        p.groups,
        p.group_word(),
        first.n_dropped
    );
    if let Some(note) = &first.note {
        let _ = writeln!(md, "Note: {note}\n");
    }
    let order: Vec<String> = rows
        .iter()
        .filter(|r| rank_value(r).is_finite())
        .map(|r| format!("`{}`", r.parameter))
        .collect();
    if order.is_empty() {
        let _ = writeln!(md, "No ranking: every {by} is undefined.\n");
    } else {
        let _ = writeln!(md, "Ranking by {by}: {}.\n", order.join(", "));
    }
    let ci = |lo: f64, hi: f64| format!("[{}, {}]", num(lo), num(hi));
    match p.method {
        SensitivityMethod::Sobol => {
            md.push_str(
                "| parameter | S1 | S1 interval | ST | ST interval |\n|---|---|---|---|---|\n",
            );
            for r in &rows {
                let _ = writeln!(
                    md,
                    "| `{}` | {} | {} | {} | {} |",
                    r.parameter,
                    num(r.s1),
                    ci(r.s1_lo, r.s1_hi),
                    num(r.st),
                    ci(r.st_lo, r.st_hi)
                );
            }
        }
        SensitivityMethod::Morris => {
            md.push_str("| parameter | μ* | μ | σ |\n|---|---|---|---|\n");
            for r in &rows {
                let _ = writeln!(
                    md,
                    "| `{}` | {} | {} | {} |",
                    r.parameter,
                    num(r.mu_star),
                    num(r.mu),
                    num(r.sigma)
                );
            }
        }
    }
    md.push('\n');
    let chart = figures::file_name(parts, &p.part, metric);
    if plots.iter().any(|f| f.file_name().is_some_and(|n| n == chart.as_str())) {
        let _ = writeln!(md, "![{metric}]({chart})\n");
    }
}

/// Three significant figures; – for NaN.
fn num(x: f64) -> String {
    if !x.is_finite() {
        "–".into()
    } else if x != 0.0 && (x.abs() < 1e-2 || x.abs() >= 1e4) {
        format!("{x:.2e}")
    } else {
        format!("{x:.3}")
    }
}
