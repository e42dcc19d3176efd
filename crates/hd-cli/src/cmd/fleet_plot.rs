//! Pictures of a fleet's drift: per unit and parameter the estimates against time with
//! ±2 SE bands, the normalised series and the alarm; an overview of units × parameters
//! coloured by the change at the end of the record. Drawn one unit at a time as the drift
//! stage streams.

use hd_ident::fleet::UnitDrift;
use hd_plot::{Series, heatmap, line_plot};
use std::path::Path;

fn file_safe(s: &str) -> String {
    s.chars().map(|c| if c.is_alphanumeric() || c == '-' || c == '_' { c } else { '-' }).collect()
}

/// One unit's series of one parameter, in any order (sorted by day here).
pub struct UnitPlot<'a> {
    /// Unit id.
    pub unit: &'a str,
    /// Parameter name.
    pub parameter: &'a str,
    /// Its unit.
    pub param_unit: &'a str,
    /// Label of the time axis.
    pub x_label: &'a str,
    /// Day the time axis starts [days].
    pub t0: f64,
    /// Days of the estimates [days].
    pub day: &'a [f64],
    /// Estimates (NaN: left out) [parameter unit].
    pub value: &'a [f64],
    /// Their standard errors [parameter unit].
    pub se: &'a [f64],
    /// Normalised estimates [parameter unit].
    pub normalised: &'a [f64],
    /// The unit's verdict.
    pub verdict: &'a UnitDrift,
}

/// Write plots/UNIT-PARAM.svg (a failure is a warning).
pub fn unit_plot(dir: &Path, p: &UnitPlot<'_>) {
    let mut idx: Vec<usize> = (0..p.day.len()).collect();
    idx.sort_by(|&a, &b| p.day[a].total_cmp(&p.day[b]));
    let x: Vec<f64> = idx.iter().map(|&k| p.day[k] - p.t0).collect();
    let v = |f: &dyn Fn(usize) -> f64| idx.iter().map(|&k| f(k)).collect::<Vec<f64>>();
    let val = |k: usize| p.value[k];
    let se = |k: usize| if p.se[k].is_finite() { p.se[k] } else { 0.0 };
    let mut series = vec![
        Series::new("estimate", x.clone(), v(&val)),
        Series::new("+2 SE", x.clone(), v(&|k| val(k) + 2.0 * se(k))),
        Series::new("−2 SE", x.clone(), v(&|k| val(k) - 2.0 * se(k))),
        Series::new("normalised", x.clone(), v(&|k| p.normalised[k])),
    ];
    let ud = p.verdict;
    if let Some(f) = ud.first_flagged {
        let ys: Vec<f64> =
            series.iter().flat_map(|s| s.y.iter().copied()).filter(|y| y.is_finite()).collect();
        let (lo, hi) =
            ys.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| (a.min(*y), b.max(*y)));
        series.push(Series::new(
            format!("alarm ({:+.1} %)", ud.change_pct),
            vec![f - p.t0, f - p.t0],
            vec![lo, hi],
        ));
    }
    let title = format!(
        "{} {}: {}",
        p.unit,
        p.parameter,
        match ud.first_flagged {
            Some(_) => format!(
                "alarm, change {:+.1} % [{:+.1}, {:+.1}]",
                ud.change_pct, ud.ci95[0], ud.ci95[1]
            ),
            None => format!("no alarm, change {:+.1} %", ud.change_pct),
        }
    );
    let path =
        dir.join("plots").join(format!("{}-{}.svg", file_safe(p.unit), file_safe(p.parameter)));
    if let Err(e) = line_plot(
        &path,
        &title,
        p.x_label,
        &format!("{} [{}]", p.parameter, p.param_unit),
        &series,
        false,
    ) {
        eprintln!("warning: {e}");
    }
}

/// Write plots/overview.svg: x = parameter (1…), y = unit (1…), colour = `change`
/// [%] (unit-major: `change[unit · parameters + parameter]`).
pub fn overview(dir: &Path, units: &[String], names: &[String], change: &[f64]) {
    let xs: Vec<f64> = (1..=names.len()).map(|k| k as f64).collect();
    let ys: Vec<f64> = (1..=units.len()).map(|k| k as f64).collect();
    let labels: Vec<String> =
        names.iter().enumerate().map(|(k, a)| format!("{}={a}", k + 1)).collect();
    let unit_names: Vec<String> =
        units.iter().enumerate().take(12).map(|(k, u)| format!("{}={u}", k + 1)).collect();
    if let Err(e) = heatmap(
        &dir.join("plots").join("overview.svg"),
        "fleet: normalised change at the end of the record",
        &format!("parameter ({})", labels.join(", ")),
        &format!("unit ({}{})", unit_names.join(", "), if units.len() > 12 { ", …" } else { "" }),
        &xs,
        &ys,
        change,
        "change [%]",
        false,
        false,
    ) {
        eprintln!("warning: {e}");
    }
}
