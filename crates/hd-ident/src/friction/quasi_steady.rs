//! Quasi-steady samples picked out of a friction time series, to start the static
//! parameters of the joint fit without a separate steady-state sweep.
//!
//! A sample counts as quasi-steady when the contact has slid well past the last reversal
//! (at least [`MIN_STROKE_SHARE`] of that half-cycle's stroke, so the bristles have
//! saturated) and the speed changes slowly there (|ω̇|/|ω| among the calmer half of such
//! samples). Those samples are binned by log |ω| on each side, and each bin gives one
//! point: the median speed and the median torque. The result is a small steady-state
//! table in the sense of [`SteadyData`]; it only starts the search, the joint fit then
//! uses every sample.

use crate::data::{SteadyData, TransientData};

/// Share of a half-cycle's stroke that must lie behind a sample since the last reversal.
pub const MIN_STROKE_SHARE: f64 = 0.3;
/// Bins per decade of |ω| on each side.
pub const BINS_PER_DECADE: f64 = 8.0;
/// Samples a bin needs to give a point.
pub const MIN_PER_BIN: usize = 3;

/// The quasi-steady table of `data`, or `None` when fewer than 4 points come out.
pub fn quasi_steady(data: &TransientData) -> Option<SteadyData> {
    let (t, w, y) = (data.t(), data.omega(), data.torque());
    let n = t.len();
    if n < 8 {
        return None;
    }
    // Half-cycles: maximal runs of one sign of ω; stroke = ∫|ω|dt over the run.
    let sign = |v: f64| {
        if v > 0.0 {
            1
        } else if v < 0.0 {
            -1
        } else {
            0
        }
    };
    let mut travelled = vec![0.0; n]; // since the start of the run
    let mut run_of = vec![0usize; n];
    let mut strokes = vec![0.0];
    for k in 1..n {
        let same = sign(w[k]) == sign(w[k - 1]) && sign(w[k]) != 0;
        if !same {
            strokes.push(0.0);
        }
        let r = strokes.len() - 1;
        let dx = 0.5 * (w[k].abs() + w[k - 1].abs()) * (t[k] - t[k - 1]);
        travelled[k] = if same { travelled[k - 1] + dx } else { 0.0 };
        strokes[r] += if same { dx } else { 0.0 };
        run_of[k] = r;
    }
    // Relative rate of change of the speed, central differences.
    let rate = |k: usize| -> f64 {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
        ((w[b] - w[a]) / (t[b] - t[a]) / w[k]).abs()
    };
    let mut candidates: Vec<(usize, f64)> = (1..n - 1)
        .filter(|&k| w[k] != 0.0 && travelled[k] >= MIN_STROKE_SHARE * strokes[run_of[k]])
        .map(|k| (k, rate(k)))
        .filter(|(_, r)| r.is_finite())
        .collect();
    if candidates.len() < 8 {
        return None;
    }
    let mut rates: Vec<f64> = candidates.iter().map(|c| c.1).collect();
    rates.sort_by(f64::total_cmp);
    let calm = rates[rates.len() / 2];
    candidates.retain(|c| c.1 <= calm);

    let mut bins: std::collections::BTreeMap<(i8, i64), Vec<usize>> = Default::default();
    for (k, _) in candidates {
        let key = (sign(w[k]) as i8, (w[k].abs().log10() * BINS_PER_DECADE).floor() as i64);
        bins.entry(key).or_default().push(k);
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (mut omega, mut torque) = (Vec::new(), Vec::new());
    for members in bins.values().filter(|m| m.len() >= MIN_PER_BIN) {
        omega.push(median(members.iter().map(|&k| w[k]).collect()));
        torque.push(median(members.iter().map(|&k| y[k]).collect()));
    }
    if omega.len() < 4 {
        return None;
    }
    SteadyData::new(omega, torque).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plateaus_give_their_levels() {
        // Speed plateaus at ±0.01, ±0.1, ±1 joined by short ramps; torque = sign·(0.2 + 0.1·|ω|).
        let mut t = Vec::new();
        let mut w = Vec::new();
        let levels = [0.01, -0.01, 0.1, -0.1, 1.0, -1.0];
        let mut time = 0.0;
        for &l in &levels {
            for k in 0..200 {
                let ramp = (k as f64 / 20.0).min(1.0);
                t.push(time);
                w.push(l * ramp.max(0.01));
                time += 0.01;
            }
        }
        let y: Vec<f64> = w.iter().map(|&v: &f64| v.signum() * (0.2 + 0.1 * v.abs())).collect();
        let d = TransientData::new(t, w, y).unwrap();
        let s = quasi_steady(&d).unwrap();
        assert!(s.len() >= 6, "{s:?}");
        for (&v, &f) in s.omega().iter().zip(s.torque()) {
            assert!((f - v.signum() * (0.2 + 0.1 * v.abs())).abs() < 1e-9, "{v} {f}");
        }
    }
}
