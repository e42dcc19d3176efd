//! The paper-versus-model table: for each of the paper's statements, the change the model
//! computes when the axis moves from its base value to the end of the grid.

use super::markdown::fmt;
use super::part_data::PartData;
use hd_io::Table;
use hd_sweep::Study;
use hd_sweep::axis::Knob;
use hd_sweep::spec::CompareSpec;
use std::fmt::Write as _;

/// Relative changes smaller than this count as "near constant".
const FLAT: f64 = 0.02;

/// Markdown table of every comparison in the study.
pub fn section(study: &Study, table: &Table) -> String {
    let mut md = String::from(
        "| parameter change | metric | paper says | model: from → to | change | model says | agrees |\n|---|---|---|---|---|---|---|\n",
    );
    let mut disagreements = Vec::new();
    for c in &study.compare {
        let Some(part) = study.parts.iter().find(|p| p.name == c.part) else { continue };
        let d = PartData::new(part, table, &study.keep_metrics);
        match judge(&d, c) {
            Some(j) => {
                let _ = writeln!(
                    md,
                    "| {} `{}` ({} → {}){} | {} | {} ({}) | {} → {} | {:+.1} % | {} | {} |",
                    c.direction,
                    c.axis,
                    fmt(j.x_ref),
                    fmt(j.x_to),
                    c.variant.as_ref().map(|v| format!(", {v}")).unwrap_or_default(),
                    c.metric,
                    c.paper,
                    c.expect,
                    fmt(j.m_ref),
                    fmt(j.m_to),
                    100.0 * j.change,
                    j.verdict,
                    if j.agrees { "yes" } else { "**no**" }
                );
                if !j.agrees {
                    disagreements.push(format!(
                        "- {} `{}`: the paper says {} ({}); the model gives {} ({:+.1} % in `{}`).",
                        c.direction,
                        c.axis,
                        c.paper.to_lowercase(),
                        c.expect,
                        j.verdict,
                        100.0 * j.change,
                        c.metric
                    ));
                }
            }
            None => {
                let _ = writeln!(
                    md,
                    "| {} `{}` | {} | {} | – | – | not computable (no finite values) | – |",
                    c.direction, c.axis, c.metric, c.paper
                );
            }
        }
    }
    md.push('\n');
    if disagreements.is_empty() {
        md.push_str("The model agrees with every statement above.\n\n");
    } else {
        md.push_str("Where the model disagrees with the paper:\n\n");
        md.push_str(&disagreements.join("\n"));
        md.push_str("\n\n");
    }
    md
}

/// One comparison's numbers.
struct Judgement {
    x_ref: f64,
    x_to: f64,
    m_ref: f64,
    m_to: f64,
    change: f64,
    verdict: &'static str,
    agrees: bool,
}

/// Base value of a swept quantity in the part's base configuration.
fn base_value(d: &PartData, name: &str) -> f64 {
    match Knob::from_name(name) {
        Ok(Knob::Param(p)) => p.get(&d.part.base.params),
        Ok(Knob::FrictionScale) => 1.0,
        Ok(Knob::Voltage) => {
            d.part
                .base
                .input
                .value_and_rate(0.25 / d.part.base.input.drive_frequency().unwrap_or(1.0))
                .0
        }
        Ok(Knob::Freq) => d.part.base.input.drive_frequency().unwrap_or(f64::NAN),
        _ => f64::NAN,
    }
}

/// The grid value nearest to `target` (log distance for positive grids).
fn nearest(grid: &[f64], target: f64) -> Option<f64> {
    let dist =
        |g: f64| if g > 0.0 && target > 0.0 { (g / target).ln().abs() } else { (g - target).abs() };
    grid.iter().copied().min_by(|a, b| dist(*a).total_cmp(&dist(*b)))
}

fn judge(d: &PartData, c: &CompareSpec) -> Option<Judgement> {
    // Hold every other numeric axis at the grid value nearest its base value.
    let held: Vec<(String, f64)> = d
        .numeric_axes
        .iter()
        .filter(|(n, _)| n != &c.axis)
        .filter_map(|(n, _)| nearest(&d.distinct(n), base_value(d, n)).map(|v| (n.clone(), v)))
        .collect();
    let line: Vec<usize> = d
        .rows
        .iter()
        .copied()
        .filter(|&i| d.text("status", i) == "ok")
        .filter(|&i| c.variant.as_ref().is_none_or(|v| &d.text("variant", i) == v))
        .filter(|&i| {
            held.iter().all(|(n, v)| (d.num(n, i) - v).abs() <= 1e-9 * v.abs().max(1e-300))
        })
        .collect();
    let grid = d.distinct(&c.axis);
    let x_ref = nearest(&grid, base_value(d, &c.axis))?;
    let x_to = if c.direction == "increase" { *grid.last()? } else { *grid.first()? };
    let at = |x: f64| {
        line.iter()
            .find(|&&i| (d.num(&c.axis, i) - x).abs() <= 1e-9 * x.abs().max(1e-300))
            .map(|&i| d.num(&c.metric, i))
    };
    let (m_ref, m_to) = (at(x_ref)?, at(x_to)?);
    // A settling time is undefined when the run ends before the response settles: that
    // is a settling time longer than the run, not a missing value.
    let censored =
        |m: f64| if c.metric == "settling_time" && m.is_nan() { f64::INFINITY } else { m };
    let (m_ref, m_to) = (censored(m_ref), censored(m_to));
    if m_ref.is_nan() || m_to.is_nan() || m_ref == 0.0 || m_ref.is_infinite() {
        return None;
    }
    let change = (m_to - m_ref) / m_ref.abs();
    let verdict = if change.abs() < FLAT {
        "near constant"
    } else if change > 0.0 {
        "increases"
    } else {
        "decreases"
    };
    let agrees = match c.expect.as_str() {
        "up" => verdict == "increases",
        "down" => verdict == "decreases",
        "flat" => verdict == "near constant",
        "up_or_flat" => verdict != "decreases",
        "down_or_flat" => verdict != "increases",
        _ => false,
    };
    Some(Judgement { x_ref, x_to, m_ref, m_to, change, verdict, agrees })
}
