//! The Bode figure of a part that sweeps `freq` and kept `gain_db` and `phase_deg`: one
//! curve per combination of the other axes (and variant), phase unwrapped along frequency,
//! with a table row per curve giving its peak and its −3 dB frequency.

use super::markdown::fmt;
use super::part_data::PartData;
use anyhow::Result;
use hd_plot::BodeCurve;
use std::fmt::Write as _;
use std::path::Path;

/// The curves of the part: `(name, freq [Hz], gain [dB], unwrapped phase [°])`, sorted by
/// frequency; empty if the part has no `freq` axis or lacks the two metrics.
pub fn curves(d: &PartData) -> Vec<BodeCurve> {
    let has = |m: &str| d.metrics.contains(&m);
    if !has("gain_db") || !has("phase_deg") || !d.part.axes.iter().any(|a| a.knob.name() == "freq")
    {
        return Vec::new();
    }
    let others: Vec<&str> =
        d.part.axes.iter().map(|a| a.knob.name()).filter(|&n| n != "freq").collect();
    let key = |i: usize| {
        let mut k = if d.variant_swept { d.text("variant", i) } else { String::new() };
        for n in &others {
            let v = if d.table.num(n).is_some() { fmt(d.num(n, i)) } else { d.text(n, i) };
            let sep = if k.is_empty() { "" } else { ", " };
            let _ = write!(k, "{sep}{n} = {v}");
        }
        if k.is_empty() { d.text("variant", i) } else { k }
    };
    let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
    for &i in &d.rows {
        let k = key(i);
        match groups.iter_mut().find(|g| g.0 == k) {
            Some(g) => g.1.push(i),
            None => groups.push((k, vec![i])),
        }
    }
    groups
        .into_iter()
        .map(|(name, mut rows)| {
            rows.sort_by(|&a, &b| d.num("freq", a).total_cmp(&d.num("freq", b)));
            let phase: Vec<f64> = rows.iter().map(|&i| d.num("phase_deg", i)).collect();
            BodeCurve {
                name,
                freq: rows.iter().map(|&i| d.num("freq", i)).collect(),
                mag_db: rows.iter().map(|&i| d.num("gain_db", i)).collect(),
                phase_deg: hd_model::metrics::unwrap_deg(&phase),
            }
        })
        .collect()
}

/// The −3 dB frequency [Hz]: the first crossing of the level 3 dB under the lowest-
/// frequency gain or under 0 dB, whichever is lower (0 dB is the reference of a closed
/// loop θz/θz_ref), interpolated in log frequency; NaN if none.
pub fn bandwidth(c: &BodeCurve) -> f64 {
    let Some(&g0) = c.mag_db.first() else { return f64::NAN };
    let level = g0.min(0.0) - 3.0;
    for k in 1..c.freq.len() {
        let (a, b) = (c.mag_db[k - 1], c.mag_db[k]);
        if a >= level && b < level {
            let w = (a - level) / (a - b);
            return (c.freq[k - 1].ln() + w * (c.freq[k].ln() - c.freq[k - 1].ln())).exp();
        }
    }
    f64::NAN
}

/// Draw the part's Bode figure into `dir` and return its markdown (figure and a summary
/// line per curve); empty when the part has no Bode data.
pub fn section(dir: &Path, file: &str, d: &PartData) -> Result<String> {
    let curves = curves(d);
    if curves.is_empty() {
        return Ok(String::new());
    }
    let title = format!("Bode plot of θz over the drive ({})", d.part.name);
    hd_plot::bode_plot(&dir.join(file), &title, &curves)?;
    let mut md = format!(
        "![Bode plot]({file})\n\n| curve | peak [dB] | at [Hz] | −3 dB [Hz] | phase at the top frequency [°] |\n|---|---|---|---|---|\n"
    );
    for c in &curves {
        let peak = (0..c.freq.len())
            .filter(|&k| c.mag_db[k].is_finite())
            .max_by(|&a, &b| c.mag_db[a].total_cmp(&c.mag_db[b]));
        let (p, at) = peak.map_or((f64::NAN, f64::NAN), |k| (c.mag_db[k], c.freq[k]));
        let last = c.phase_deg.last().copied().unwrap_or(f64::NAN);
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} |",
            c.name,
            fmt(p),
            fmt(at),
            fmt(bandwidth(c)),
            fmt(last)
        );
    }
    md.push('\n');
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bandwidth_interpolates_in_log_frequency() {
        let c = BodeCurve {
            name: "x".into(),
            freq: vec![1.0, 10.0, 100.0],
            mag_db: vec![0.5, -2.0, -4.0],
            phase_deg: vec![0.0; 3],
        };
        assert!((bandwidth(&c) - 10f64.powf(1.5)).abs() < 1e-9, "{}", bandwidth(&c));
    }
}
