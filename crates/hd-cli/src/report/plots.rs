//! The report's figures for one part.

use super::part_data::PartData;
use anyhow::Result;
use hd_plot::Series;
use hd_plot::ThinnedCurve;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

/// Metrics worth a figure of their own: kept, finite somewhere, not bookkeeping, and not
/// gain and phase, which go to the Bode figure.
fn plotted_metrics<'a>(d: &'a PartData) -> impl Iterator<Item = &'static str> + 'a {
    let skip = ["cycles_used", "energy_residual", "limit_cycle", "gain_db", "phase_deg"];
    d.metrics.iter().copied().filter(move |m| !skip.contains(m))
}

fn file_name(study: &str, part: &str, what: &str) -> String {
    let clean = |s: &str| {
        s.chars()
            .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
            .collect::<String>()
    };
    format!("{}-{}-{}.svg", clean(study), clean(part), clean(what))
}

/// Draw the part's figures into `dir` and return the markdown that shows them.
pub fn part_plots(
    dir: &Path,
    study: &str,
    d: &PartData,
    traces: Option<&HashMap<String, ThinnedCurve>>,
) -> Result<String> {
    let mut md = String::new();
    let variants = d.variants();
    let short = |k: usize| d.distinct(&d.numeric_axes[k].0).len() <= 6;
    match d.numeric_axes.len() {
        // A grid with one short axis reads best as one line per value of that axis.
        2 if d.part.sample.is_none() && (short(0) || short(1)) => {
            let (x, group) = if short(0) { (1, 0) } else { (0, 1) };
            md.push_str(&lines(dir, study, d, x, Some(group))?);
        }
        2 if d.part.sample.is_none() => {
            let ((xn, xlog), (yn, ylog)) = (&d.numeric_axes[0], &d.numeric_axes[1]);
            let xs = d.distinct(xn);
            let ys = d.distinct(yn);
            for m in plotted_metrics(d) {
                for v in &variants {
                    let mut values = vec![f64::NAN; xs.len() * ys.len()];
                    for &i in &d.rows {
                        if &d.curve(i) != v {
                            continue;
                        }
                        let (x, y) = (d.num(xn, i), d.num(yn, i));
                        if let (Some(ix), Some(iy)) = (index_of(&xs, x), index_of(&ys, y)) {
                            values[iy * xs.len() + ix] = d.num(m, i);
                        }
                    }
                    if values.iter().all(|x| !x.is_finite()) {
                        continue;
                    }
                    let what = if variants.len() > 1 { format!("{m}-{v}") } else { m.to_string() };
                    let name = file_name(study, &d.part.name, &what);
                    hd_plot::heatmap(
                        &dir.join(&name),
                        &format!("{m} ({v})"),
                        &label(xn),
                        &label(yn),
                        &xs,
                        &ys,
                        &values,
                        &label(m),
                        *xlog,
                        *ylog,
                    )?;
                    let _ = writeln!(md, "![{m} over {xn} × {yn} ({v})]({name})\n");
                }
            }
        }
        1 => md.push_str(&lines(dir, study, d, 0, None)?),
        _ => {}
    }
    md.push_str(&super::bode::section(dir, &file_name(study, &d.part.name, "bode"), d)?);
    if let Some(t) = traces {
        md.push_str(&trace_overlay(dir, study, d, t)?);
    }
    Ok(md)
}

/// One figure per metric against numeric axis `x`, one line per variant (and per value
/// of the `group` axis, when given).
fn lines(dir: &Path, study: &str, d: &PartData, x: usize, group: Option<usize>) -> Result<String> {
    let mut md = String::new();
    let (xn, xlog) = &d.numeric_axes[x];
    let groups: Vec<Option<f64>> = match group {
        Some(g) => d.distinct(&d.numeric_axes[g].0).into_iter().map(Some).collect(),
        None => vec![None],
    };
    let variants = d.variants();
    for m in plotted_metrics(d) {
        let mut series = Vec::new();
        for v in &variants {
            for gv in &groups {
                let mut pts: Vec<(f64, f64)> = d
                    .rows
                    .iter()
                    .filter(|&&i| &d.curve(i) == v)
                    .filter(|&&i| match (group, gv) {
                        (Some(g), Some(val)) => d.num(&d.numeric_axes[g].0, i) == *val,
                        _ => true,
                    })
                    .map(|&i| (d.num(xn, i), d.num(m, i)))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                let mut name = v.clone();
                if let (Some(g), Some(val)) = (group, gv) {
                    let _ =
                        write!(name, ", {} = {}", d.numeric_axes[g].0, super::markdown::fmt(*val));
                }
                let s = Series::new(
                    name,
                    pts.iter().map(|p| p.0).collect(),
                    pts.iter().map(|p| p.1).collect(),
                );
                if s.y.iter().any(|y| y.is_finite()) {
                    series.push(s);
                }
            }
        }
        if series.is_empty() {
            continue;
        }
        let name = file_name(study, &d.part.name, m);
        hd_plot::line_plot(
            &dir.join(&name),
            &format!("{m} against {xn}"),
            &label(xn),
            &label(m),
            &series,
            *xlog,
        )?;
        let _ = writeln!(md, "![{m} against {xn}]({name})\n");
    }
    Ok(md)
}

/// Overlaid load angle θz(t) of up to 12 runs of the part (each thinned as it was read).
fn trace_overlay(
    dir: &Path,
    study: &str,
    d: &PartData,
    curves: &HashMap<String, ThinnedCurve>,
) -> Result<String> {
    let mut series = Vec::new();
    for &i in d.rows.iter().take(super::OVERLAID_RUNS) {
        let Some(curve) = curves.get(&d.text("run_id", i)).filter(|c| !c.is_empty()) else {
            continue;
        };
        let mut name = d.curve(i);
        for (a, _) in &d.numeric_axes {
            let _ = write!(name, " {a}={}", super::markdown::fmt(d.num(a, i)));
        }
        let (t, thz) = curve.points();
        series.push(Series::new(name, t, thz));
    }
    if series.is_empty() {
        return Ok(String::new());
    }
    let name = file_name(study, &d.part.name, "theta_z-traces");
    hd_plot::overlay_plot(&dir.join(&name), "load angle θz(t)", "t [s]", "θz [rad]", &series)?;
    Ok(format!("![load angle traces]({name})\n\n"))
}

fn index_of(grid: &[f64], x: f64) -> Option<usize> {
    // The grid is sorted: look at the two values around x (a 1000 × 1000 grid has a
    // million rows to place).
    let k = grid.partition_point(|g| *g < x);
    [k.checked_sub(1), Some(k)]
        .into_iter()
        .flatten()
        .filter(|&j| j < grid.len())
        .find(|&j| (grid[j] - x).abs() <= 1e-9 * grid[j].abs().max(1e-300))
}

/// Axis label with its unit from the schema (`name [unit]`).
pub fn label(name: &str) -> String {
    hd_io::explore::label(name)
}
