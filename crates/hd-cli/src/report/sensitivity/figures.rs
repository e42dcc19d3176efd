//! One bar chart per analysed metric: S1 and ST with their bootstrap intervals (Sobol'),
//! or μ* and σ (Morris), parameters in ranking order.

use super::PartResult;
use anyhow::Result;
use hd_plot::BarGroup;
use hd_sweep::sensitivity::{SensitivityMethod, SensitivityRow};
use std::path::{Path, PathBuf};

/// File name of a metric's chart: `sensitivity-<metric>.svg`, with the part name in the
/// middle when several parts have designs.
pub fn file_name(parts: &[PartResult], part: &str, metric: &str) -> String {
    let clean = |s: &str| -> String {
        s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' }).collect()
    };
    if parts.len() > 1 {
        format!("sensitivity-{}-{}.svg", clean(part), clean(metric))
    } else {
        format!("sensitivity-{}.svg", clean(metric))
    }
}

/// Draw every chart into `dir`; returns the files written and, for charts that could not
/// be drawn (no finite value, …), why.
pub fn draw(dir: &Path, parts: &[PartResult]) -> Result<(Vec<PathBuf>, Vec<String>)> {
    let (mut written, mut skipped) = (Vec::new(), Vec::new());
    for p in parts {
        for metric in &p.metrics {
            let rows = p.ranked(metric);
            let path = dir.join(file_name(parts, &p.part, metric));
            let categories: Vec<String> = rows.iter().map(|r| r.parameter.clone()).collect();
            let (title, y_label, groups) = chart(p, metric, &rows);
            match hd_plot::bar_chart(&path, &title, &y_label, &categories, &groups) {
                Ok(()) => written.push(path),
                Err(e) => skipped.push(format!("{}: {e}", path.display())),
            }
        }
    }
    Ok((written, skipped))
}

/// Title, y label and bar groups of one metric's chart.
fn chart(
    p: &PartResult,
    metric: &str,
    rows: &[&SensitivityRow],
) -> (String, String, Vec<BarGroup>) {
    let pick = |f: fn(&SensitivityRow) -> f64| rows.iter().map(|r| f(r)).collect::<Vec<f64>>();
    let interval = |lo: fn(&SensitivityRow) -> f64, hi: fn(&SensitivityRow) -> f64| {
        Some(rows.iter().map(|r| (lo(r), hi(r))).collect::<Vec<_>>())
    };
    let used = rows.first().map_or(0, |r| r.n_used);
    match p.method {
        SensitivityMethod::Sobol => (
            format!("{metric}: Sobol' indices ({used} of {} base rows)", p.groups),
            "index [-]".to_string(),
            vec![
                BarGroup {
                    name: "S1 (first order)".into(),
                    values: pick(|r| r.s1),
                    intervals: interval(|r| r.s1_lo, |r| r.s1_hi),
                },
                BarGroup {
                    name: "ST (total)".into(),
                    values: pick(|r| r.st),
                    intervals: interval(|r| r.st_lo, |r| r.st_hi),
                },
            ],
        ),
        SensitivityMethod::Morris => {
            let unit = hd_model::metrics::METRICS
                .iter()
                .find(|m| m.name == metric)
                .map_or("metric unit", |m| m.unit);
            (
                format!("{metric}: Morris screening ({used} of {} trajectories)", p.groups),
                format!("effect [{unit} per range]"),
                vec![
                    BarGroup { name: "μ*".into(), values: pick(|r| r.mu_star), intervals: None },
                    BarGroup { name: "σ".into(), values: pick(|r| r.sigma), intervals: None },
                ],
            )
        }
    }
}
