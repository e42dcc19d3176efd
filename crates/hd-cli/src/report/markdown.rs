//! Markdown pieces of the report.

use super::part_data::PartData;
use hd_sweep::design::SampleMethod;
use hd_sweep::study::Part;
use std::fmt::Write as _;

/// One paragraph describing the part's base and axes.
pub fn describe_part(part: &Part) -> String {
    let b = &part.base;
    let axes: Vec<String> = part
        .axes
        .iter()
        .map(|a| {
            let first = serde_json::to_string(&a.values[0]).unwrap_or_default();
            let last = serde_json::to_string(&a.values[a.values.len() - 1]).unwrap_or_default();
            format!("`{}` ({} values, {first} … {last})", a.knob.name(), a.values.len())
        })
        .collect();
    let sample = part.sample.as_ref().map(|s| {
        let d = s.bounds.len();
        let size = match s.method {
            SampleMethod::Lhs => format!("{} Latin-hypercube points", s.n),
            SampleMethod::Random => format!("{} random points", s.n),
            SampleMethod::Sobol => {
                format!("a Saltelli design of {} base samples ({} runs)", s.n, s.n * (d + 2))
            }
            SampleMethod::Morris => format!("{} Morris trajectories ({} runs)", s.n, s.n * (d + 1)),
        };
        format!(
            "; {size} over {}",
            s.bounds
                .iter()
                .map(|b| format!(
                    "`{}` in [{}, {}]{}",
                    b.knob.name(),
                    b.lo,
                    b.hi,
                    if b.log { " (log)" } else { "" }
                ))
                .collect::<Vec<_>>()
                .join(", ")
        )
    });
    format!(
        "Variant `{}`, input `{}`, {} s simulated, rtol {:e}. Axes: {}{}.",
        b.variant,
        serde_json::to_string(&b.input).unwrap_or_default(),
        b.t_end,
        b.solver.rtol,
        if axes.is_empty() { "none".to_string() } else { axes.join(" × ") },
        sample.unwrap_or_default()
    )
}

/// A full table for small parts, min/median/max for large ones.
pub fn part_table(d: &PartData) -> String {
    let mut md = String::new();
    let metrics: Vec<&str> = d.metrics.iter().copied().filter(|m| *m != "cycles_used").collect();
    if d.rows.len() <= 40 {
        let mut head: Vec<String> = Vec::new();
        if d.variant_swept {
            head.push("variant".into());
        }
        head.extend(d.text_axes.iter().cloned());
        head.extend(d.numeric_axes.iter().map(|a| a.0.clone()));
        head.extend(metrics.iter().map(|m| m.to_string()));
        head.push("status".into());
        let _ = writeln!(md, "| {} |", head.join(" | "));
        let _ = writeln!(md, "|{}|", vec!["---"; head.len()].join("|"));
        for &i in &d.rows {
            let mut cells: Vec<String> = Vec::new();
            if d.variant_swept {
                cells.push(d.text("variant", i));
            }
            cells.extend(d.text_axes.iter().map(|a| d.text(a, i)));
            cells.extend(d.numeric_axes.iter().map(|a| fmt(d.num(&a.0, i))));
            cells.extend(metrics.iter().map(|m| fmt(d.num(m, i))));
            cells.push(d.text("status", i));
            let _ = writeln!(md, "| {} |", cells.join(" | "));
        }
    } else {
        let _ =
            writeln!(md, "| metric | min | median | max | finite runs |\n|---|---|---|---|---|");
        for m in &metrics {
            let mut v: Vec<f64> =
                d.rows.iter().map(|&i| d.num(m, i)).filter(|x| x.is_finite()).collect();
            v.sort_by(f64::total_cmp);
            if v.is_empty() {
                continue;
            }
            let _ = writeln!(
                md,
                "| {m} | {} | {} | {} | {} |",
                fmt(v[0]),
                fmt(v[v.len() / 2]),
                fmt(v[v.len() - 1]),
                v.len()
            );
        }
    }
    md.push('\n');
    md
}

/// The failed runs and their errors (first ten).
pub fn failures(d: &PartData) -> String {
    let failed: Vec<usize> =
        d.rows.iter().copied().filter(|&i| d.text("status", i) != "ok").collect();
    if failed.is_empty() {
        return String::new();
    }
    let mut md = format!("Failed runs ({}):\n\n", failed.len());
    for &i in failed.iter().take(10) {
        let _ = writeln!(md, "- `{}`: {}", d.text("run_id", i), d.text("error", i));
    }
    md.push('\n');
    md
}

/// A number in a report table: [`hd_text::number`], the one format of every table hdw
/// prints; `> run` for a time past the end of the run (infinite), `–` for undefined.
pub fn fmt(x: f64) -> String {
    if x == f64::INFINITY {
        return "> run".into();
    }
    if !x.is_finite() {
        return "–".into();
    }
    hd_text::number(x)
}
