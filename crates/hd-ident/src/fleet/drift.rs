//! Drift of one parameter across a fleet: the normalised residuals of each unit in time
//! order, standardised by their standard deviations (the estimates' standard errors with
//! the unexplained scatter and the normalisation's own uncertainty, so each estimate
//! weighs by its precision), Page's two-sided CUSUM on them, and the change at the end
//! of the record with its 95 % interval.

use super::cusum::{cusum, threshold_estimated};
use super::normalise::{Normalisation, Normalise, Sample, normalise};
use std::collections::HashMap;

/// Settings of the drift analysis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriftOptions {
    /// Baseline: each unit's first days [days].
    pub baseline_days: f64,
    /// Probability of at least one false alarm over the whole fleet (all units and
    /// parameters tested) over the record [–].
    pub false_alarm: f64,
    /// CUSUM reference k [standard deviations].
    pub k: f64,
    /// Estimates averaged for the change at the end of the record.
    pub last: usize,
    /// Normalisation mode.
    pub normalise: Normalise,
}

impl Default for DriftOptions {
    fn default() -> Self {
        Self { baseline_days: 20.0, false_alarm: 0.05, k: 0.5, last: 5, normalise: Normalise::Auto }
    }
}

/// Per estimate: where it stands in its unit's test.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DriftRow {
    /// Standardised residual.
    pub z: f64,
    /// Upper CUSUM after this estimate.
    pub upper: f64,
    /// Lower CUSUM after this estimate.
    pub lower: f64,
    /// Whether the unit's test has alarmed at or before this estimate.
    pub flagged: bool,
}

/// One unit's verdict on the parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitDrift {
    /// Unit (0-based).
    pub unit: usize,
    /// Estimates tested.
    pub tested: usize,
    /// Day of the first alarm.
    pub first_flagged: Option<f64>,
    /// Page's estimate of the day the change began.
    pub onset: Option<f64>,
    /// +1 rise, −1 fall, 0 no alarm.
    pub direction: i8,
    /// Change at the end of the record (mean of the last estimates' residuals) [%].
    pub change_pct: f64,
    /// Its 95 % interval [%].
    pub ci95: [f64; 2],
}

/// The drift analysis of one parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterDrift {
    /// The normalisation (with per-sample residuals and normalised values).
    pub normalisation: Normalisation,
    /// Per sample, in input order.
    pub rows: Vec<DriftRow>,
    /// Per unit.
    pub units: Vec<UnitDrift>,
    /// The CUSUM threshold used for a series of the median length [standard deviations].
    pub threshold: f64,
}

/// One unit's estimates of a parameter for its test, in any order: per estimate the day
/// [days], the normalised residual, its variance (with the unit's own scale) and the
/// unit's level [parameter unit].
pub struct UnitSeries<'a> {
    /// Unit (0-based).
    pub unit: usize,
    /// Days of the estimates [days].
    pub day: &'a [f64],
    /// Residuals on the y scale (NaN: not tested).
    pub residual: &'a [f64],
    /// Their variances.
    pub variance: &'a [f64],
    /// The unit's baseline level at the reference covariates [parameter unit].
    pub level: &'a [f64],
}

/// A unit's verdict with its series' baseline and total lengths `(m, n)`.
pub type Verdict = (UnitDrift, (usize, usize));

/// Page's test on one unit's series: per estimate its row (input order), and the verdict
/// with the series' baseline and total lengths `(m, n)` (`None` when no estimate has a
/// residual). `alpha` is the series' false-alarm probability; `thresholds` caches h per
/// `(m, n)` ([`threshold_estimated`] is deterministic).
pub fn test_unit(
    s: &UnitSeries<'_>,
    log_scale: bool,
    alpha: f64,
    o: &DriftOptions,
    thresholds: &mut HashMap<(usize, usize), f64>,
) -> (Vec<DriftRow>, Option<Verdict>) {
    let mut rows = vec![DriftRow { z: f64::NAN, ..Default::default() }; s.day.len()];
    let mut idx: Vec<usize> = (0..s.day.len()).filter(|&i| s.residual[i].is_finite()).collect();
    if idx.is_empty() {
        return (rows, None);
    }
    idx.sort_by(|&a, &b| s.day[a].total_cmp(&s.day[b]));
    let z: Vec<f64> = idx.iter().map(|&i| s.residual[i] / s.variance[i].sqrt()).collect();
    let first = s.day[idx[0]];
    let m = idx.iter().filter(|&&i| s.day[i] < first + o.baseline_days).count();
    let h = *thresholds
        .entry((m, z.len()))
        .or_insert_with(|| threshold_estimated(alpha, m, z.len(), o.k));
    let path = cusum(&z, o.k, h);
    for (p, &i) in idx.iter().enumerate() {
        rows[i] = DriftRow {
            z: z[p],
            upper: path.upper[p],
            lower: path.lower[p],
            flagged: path.alarm.is_some_and(|a| p >= a),
        };
    }
    let lengths = (m, z.len());
    let m = o.last.max(1).min(idx.len());
    let tail = &idx[idx.len() - m..];
    let mean = tail.iter().map(|&i| s.residual[i]).sum::<f64>() / m as f64;
    let se = (tail.iter().map(|&i| s.variance[i]).sum::<f64>()).sqrt() / m as f64;
    let pct = |r: f64| {
        if log_scale {
            100.0 * r.exp_m1()
        } else {
            let level = s.level[tail[m - 1]].abs();
            100.0 * r / level
        }
    };
    let verdict = UnitDrift {
        unit: s.unit,
        tested: idx.len(),
        first_flagged: path.alarm.map(|a| s.day[idx[a]]),
        onset: path.onset.map(|a| s.day[idx[a.min(idx.len() - 1)]]),
        direction: path.direction,
        change_pct: pct(mean),
        ci95: [pct(mean - 1.96 * se), pct(mean + 1.96 * se)],
    };
    (rows, Some((verdict, lengths)))
}

/// The CUSUM threshold of the series of median length among `lengths` (`(m, n)` per
/// tested unit, in unit order) [standard deviations].
pub fn median_threshold(
    mut lengths: Vec<(usize, usize)>,
    thresholds: &HashMap<(usize, usize), f64>,
) -> f64 {
    lengths.sort_unstable_by_key(|l| l.1);
    let (m, n) = lengths.get(lengths.len() / 2).copied().unwrap_or((1, 1));
    thresholds.get(&(m, n)).copied().unwrap_or(f64::NAN)
}

/// Analyse one parameter: `series` is the number of unit × parameter series tested over
/// the whole fleet (the false-alarm probability is shared among them, Bonferroni).
pub fn drift(
    samples: &[Sample],
    covariates: &[String],
    series: usize,
    o: &DriftOptions,
) -> ParameterDrift {
    let norm = normalise(samples, covariates, o.baseline_days, o.normalise);
    let units = samples.iter().map(|s| s.unit + 1).max().unwrap_or(0);
    let mut rows = vec![DriftRow { z: f64::NAN, ..Default::default() }; samples.len()];
    let mut out = Vec::new();
    let alpha = o.false_alarm / series.max(1) as f64;
    let mut lengths = Vec::new();
    let mut thresholds: HashMap<(usize, usize), f64> = HashMap::new();
    for u in 0..units {
        let idx: Vec<usize> = (0..samples.len()).filter(|&i| samples[i].unit == u).collect();
        let pick = |v: &[f64]| idx.iter().map(|&i| v[i]).collect::<Vec<f64>>();
        let day: Vec<f64> = idx.iter().map(|&i| samples[i].day).collect();
        let (residual, variance, level) =
            (pick(&norm.residual), pick(&norm.variance), pick(&norm.level));
        let s = UnitSeries {
            unit: u,
            day: &day,
            residual: &residual,
            variance: &variance,
            level: &level,
        };
        let (r, verdict) = test_unit(&s, norm.log_scale, alpha, o, &mut thresholds);
        for (&i, r) in idx.iter().zip(r) {
            rows[i] = r;
        }
        if let Some((v, l)) = verdict {
            out.push(v);
            lengths.push(l);
        }
    }
    let threshold = median_threshold(lengths, &thresholds);
    ParameterDrift { normalisation: norm, rows, units: out, threshold }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three units over 60 days with a temperature effect of −2 %/K and a 0.2 % scatter;
    /// unit 1 rises 15 % over 20 days from day 30. Normalised: unit 1 alarms within 10
    /// days of day 30, the others never, and its change at the end is 15 % within its
    /// interval. Without normalisation the temperature swings hide the onset or alarm on
    /// a healthy unit.
    #[test]
    fn a_wear_ramp_is_flagged_only_with_normalisation() {
        let mut samples = Vec::new();
        let mut seed: u64 = 3;
        let mut noise = || {
            let mut s = 0.0;
            for _ in 0..12 {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                s += (seed >> 11) as f64 / (1u64 << 53) as f64;
            }
            s - 6.0
        };
        for u in 0..3 {
            for d in 0..60 {
                let temp = 25.0 + 10.0 * (std::f64::consts::TAU * d as f64 / 15.0 + u as f64).sin();
                let wear = if u == 1 {
                    1.0 + 0.15 * ((d as f64 - 30.0) / 20.0).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                let v = 0.05 * (-0.02 * (temp - 25.0)).exp() * wear * (1.0 + 0.002 * noise());
                samples.push(Sample {
                    unit: u,
                    day: d as f64,
                    value: v,
                    se: 1e-5,
                    covariates: vec![temp],
                });
            }
        }
        let o = DriftOptions::default();
        let d = drift(&samples, &["temperature".into()], 3, &o);
        assert_ne!(d.normalisation.chosen, "none");
        for u in &d.units {
            if u.unit == 1 {
                let day = u.first_flagged.expect("the worn unit alarms");
                assert!((30.0..40.0).contains(&day), "flagged on day {day}");
                assert_eq!(u.direction, 1);
                assert!(u.ci95[0] < 15.0 && 15.0 < u.ci95[1], "{:?}", u);
            } else {
                assert_eq!(u.first_flagged, None, "unit {} alarmed", u.unit);
            }
        }
        let raw = drift(
            &samples,
            &["temperature".into()],
            3,
            &DriftOptions { normalise: Normalise::None, ..o },
        );
        assert_eq!(raw.normalisation.chosen, "none");
        let worn = raw.units.iter().find(|u| u.unit == 1).unwrap();
        let healthy_alarms =
            raw.units.iter().filter(|u| u.unit != 1 && u.first_flagged.is_some()).count();
        assert!(
            healthy_alarms > 0 || worn.first_flagged.is_none_or(|d| d > 40.0),
            "{:?}",
            raw.units
        );
    }
}
