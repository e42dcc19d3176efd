//! Start values of the joint fit's static parameters, from the series itself.

use super::super::quasi_steady::quasi_steady;
use super::super::steady::{SteadyOptions, SteadyProblem};
use super::FrictionOptions;
use crate::data::TransientData;
use crate::fix::Fixed;
use crate::separable::fit_separable;

pub(super) fn speed_range(omega: &[f64]) -> (f64, f64) {
    omega
        .iter()
        .map(|w| w.abs())
        .filter(|w| *w > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(l, h), w| (l.min(w), h.max(w)))
}

/// Median of |x| over the samples where `keep` holds.
fn median_abs(x: &[f64], keep: impl Fn(usize) -> bool) -> Option<f64> {
    let mut v: Vec<f64> = (0..x.len()).filter(|&k| keep(k)).map(|k| x[k].abs()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// Start values of the static parameters (Tc, Ts, ωs, σ2, Tc_neg, Ts_neg) and how they
/// were found.
pub(super) fn static_start(
    data: &TransientData,
    fixed: &Fixed,
    opts: FrictionOptions,
) -> (Vec<(&'static str, f64)>, String) {
    let statics = ["Tc", "Ts", "ws", "sigma2", "Tc_neg", "Ts_neg"];
    if let Some(table) = quasi_steady(data) {
        let steady_opts = SteadyOptions { asymmetric: opts.asymmetric, offset: false };
        let held = fixed.restricted_to(&statics);
        let problem = SteadyProblem::with_options(&table, steady_opts);
        if let Ok(fit) = fit_separable(&problem, &held) {
            let start: Vec<(&'static str, f64)> =
                fit.values.iter().copied().filter(|(_, v)| v.is_finite() && *v > 0.0).collect();
            // A level the table could not separate (at its bound 0) falls back below.
            let has = |name: &str| start.iter().any(|(n, _)| *n == name);
            if has("Tc") && has("Ts") {
                return (
                    start,
                    format!(
                        "static start from {} quasi-steady points picked from the series (sliding past {:.0} % of each stroke, calm speed)",
                        table.len(),
                        100.0 * super::super::quasi_steady::MIN_STROKE_SHARE
                    ),
                );
            }
        }
    }
    let (t, w, y) = (data.t(), data.omega(), data.torque());
    let _ = t;
    let pos = median_abs(y, |k| w[k] > 0.0).unwrap_or(1.0).max(f64::MIN_POSITIVE);
    let neg = median_abs(y, |k| w[k] < 0.0).unwrap_or(pos).max(f64::MIN_POSITIVE);
    let speed = median_abs(w, |k| w[k] != 0.0).unwrap_or(1.0);
    let mut start = vec![("Tc", pos), ("Ts", 1.2 * pos), ("ws", 0.1 * speed)];
    if opts.asymmetric {
        start.push(("Tc_neg", neg));
        start.push(("Ts_neg", 1.2 * neg));
    }
    (start, "static start from the median torque on each side (too few quasi-steady samples for a static fit)".into())
}
