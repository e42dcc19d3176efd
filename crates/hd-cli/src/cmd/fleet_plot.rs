//! Pictures of a fleet's drift: per unit and parameter the estimates against time with
//! ±2 SE bands, the normalised series and the alarm; an overview of units × parameters
//! coloured by the change at the end of the record.

use super::fleet_drift::Analysed;
use anyhow::Result;
use hd_plot::{Series, heatmap, line_plot};
use std::path::Path;

fn file_safe(s: &str) -> String {
    s.chars().map(|c| if c.is_alphanumeric() || c == '-' || c == '_' { c } else { '-' }).collect()
}

/// Write plots/UNIT-PARAM.svg for every unit and parameter, and plots/overview.svg.
pub fn plots(dir: &Path, units: &[String], analysed: &[Analysed], dated: bool) -> Result<()> {
    let pd = dir.join("plots");
    let t0 = analysed
        .iter()
        .flat_map(|a| a.samples.iter().map(|s| s.day))
        .filter(|d| d.is_finite())
        .fold(f64::INFINITY, f64::min);
    let x_label = if dated {
        format!("days since {}", hd_io::fleet::format_day(t0))
    } else {
        format!("day − {t0}")
    };
    for an in analysed {
        for ud in &an.drift.units {
            let mut idx: Vec<usize> =
                (0..an.samples.len()).filter(|&k| an.samples[k].unit == ud.unit).collect();
            idx.sort_by(|&a, &b| an.samples[a].day.total_cmp(&an.samples[b].day));
            let x: Vec<f64> = idx.iter().map(|&k| an.samples[k].day - t0).collect();
            let v = |f: &dyn Fn(usize) -> f64| idx.iter().map(|&k| f(k)).collect::<Vec<f64>>();
            let val =
                |k: usize| if an.excluded[k].is_some() { f64::NAN } else { an.samples[k].value };
            let se = |k: usize| if an.samples[k].se.is_finite() { an.samples[k].se } else { 0.0 };
            let mut series = vec![
                Series::new("estimate", x.clone(), v(&val)),
                Series::new("+2 SE", x.clone(), v(&|k| val(k) + 2.0 * se(k))),
                Series::new("−2 SE", x.clone(), v(&|k| val(k) - 2.0 * se(k))),
                Series::new("normalised", x.clone(), v(&|k| an.drift.normalisation.normalised[k])),
            ];
            if let Some(f) = ud.first_flagged {
                let ys: Vec<f64> = series
                    .iter()
                    .flat_map(|s| s.y.iter().copied())
                    .filter(|y| y.is_finite())
                    .collect();
                let (lo, hi) = ys
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| (a.min(*y), b.max(*y)));
                series.push(Series::new(
                    format!("alarm ({:+.1} %)", ud.change_pct),
                    vec![f - t0, f - t0],
                    vec![lo, hi],
                ));
            }
            let title = format!(
                "{} {}: {}",
                units[ud.unit],
                an.name,
                match ud.first_flagged {
                    Some(_) => format!(
                        "alarm, change {:+.1} % [{:+.1}, {:+.1}]",
                        ud.change_pct, ud.ci95[0], ud.ci95[1]
                    ),
                    None => format!("no alarm, change {:+.1} %", ud.change_pct),
                }
            );
            let path =
                pd.join(format!("{}-{}.svg", file_safe(&units[ud.unit]), file_safe(&an.name)));
            if let Err(e) = line_plot(
                &path,
                &title,
                &x_label,
                &format!("{} [{}]", an.name, an.unit),
                &series,
                false,
            ) {
                eprintln!("warning: {e}");
            }
        }
    }
    // Overview: x = parameter (1…), y = unit (1…), colour = change at the end [%].
    let xs: Vec<f64> = (1..=analysed.len()).map(|k| k as f64).collect();
    let ys: Vec<f64> = (1..=units.len()).map(|k| k as f64).collect();
    let mut values = vec![f64::NAN; xs.len() * ys.len()];
    for (ix, an) in analysed.iter().enumerate() {
        for ud in &an.drift.units {
            values[ud.unit * xs.len() + ix] = ud.change_pct;
        }
    }
    let names: Vec<String> =
        analysed.iter().enumerate().map(|(k, a)| format!("{}={}", k + 1, a.name)).collect();
    let unit_names: Vec<String> =
        units.iter().enumerate().take(12).map(|(k, u)| format!("{}={u}", k + 1)).collect();
    if let Err(e) = heatmap(
        &pd.join("overview.svg"),
        "fleet: normalised change at the end of the record",
        &format!("parameter ({})", names.join(", ")),
        &format!("unit ({}{})", unit_names.join(", "), if units.len() > 12 { ", …" } else { "" }),
        &xs,
        &ys,
        &values,
        "change [%]",
        false,
        false,
    ) {
        eprintln!("warning: {e}");
    }
    Ok(())
}
