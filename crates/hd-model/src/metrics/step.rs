//! Step-response metrics from uniformly sampled signals.

/// Step metrics: `(rise_time, overshoot, settling_time, final_value)` of `x` (the load
/// speed) after a step at `t_step`, with `final_value` the mean over the samples at or after
/// `t_final`. NaN where a metric is undefined: the final value is below 1e-3 of the peak
/// (the load ends at rest), or the run ends outside the band (settling).
pub fn step_metrics(t: &[f64], x: &[f64], t_step: f64, t_final: f64, band: f64) -> [f64; 4] {
    let nan = f64::NAN;
    let tail: Vec<f64> =
        t.iter().zip(x).filter(|(tk, _)| **tk >= t_final).map(|(_, v)| *v).collect();
    if tail.is_empty() {
        return [nan; 4];
    }
    let fin = tail.iter().sum::<f64>() / tail.len() as f64;
    // A load that ends (nearly) at rest — stuck in pre-sliding — has no final value to
    // measure rise, overshoot and settling against.
    let peak = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !fin.is_finite() || fin.abs() <= 1e-3 * peak {
        return [nan, nan, nan, fin];
    }
    let after: Vec<(f64, f64)> =
        t.iter().zip(x).filter(|(tk, _)| **tk >= t_step).map(|(a, b)| (*a, *b / fin)).collect();
    let cross = |level: f64| -> f64 {
        for w in after.windows(2) {
            let ((t0, y0), (t1, y1)) = (w[0], w[1]);
            if y0 < level && y1 >= level {
                return t0 + (level - y0) / (y1 - y0) * (t1 - t0);
            }
        }
        nan
    };
    let rise = cross(0.9) - cross(0.1);
    let peak = after.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    let overshoot = (peak - 1.0).max(0.0);
    // Settling: the last sample outside the band; undefined if the run ends outside it.
    let last_out = after.iter().rposition(|p| (p.1 - 1.0).abs() > band);
    let settling = match last_out {
        None => after.first().map_or(nan, |p| p.0 - t_step),
        Some(k) if k + 1 < after.len() => after[k + 1].0 - t_step,
        Some(_) => nan,
    };
    [rise, overshoot, settling, fin]
}

/// Damping ratio from the logarithmic decrement of the successive maxima of `x` about its
/// final value `x_final`, using peaks above 1 % of the first one. NaN with fewer than two
/// such peaks.
pub fn damping_from_decrement(x: &[f64], x_final: f64) -> f64 {
    let d: Vec<f64> = x.iter().map(|v| v - x_final).collect();
    let mut peaks = Vec::new();
    for k in 1..d.len().saturating_sub(1) {
        if d[k] > 0.0 && d[k] > d[k - 1] && d[k] >= d[k + 1] {
            peaks.push(d[k]);
        }
    }
    let Some(&first) = peaks.first() else {
        return f64::NAN;
    };
    let used: Vec<f64> = peaks.into_iter().take_while(|&p| p > 0.01 * first).collect();
    if used.len() < 2 {
        return f64::NAN;
    }
    let delta = (used[0] / used[used.len() - 1]).ln() / (used.len() - 1) as f64;
    delta / (4.0 * std::f64::consts::PI.powi(2) + delta * delta).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn log_decrement_recovers_the_damping_ratio_of_a_damped_oscillation() {
        let zeta: f64 = 0.05;
        let wn = TAU * 10.0;
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        let x: Vec<f64> = (0..20000)
            .map(|k| k as f64 * 1e-4)
            .map(|t| 1.0 + (-zeta * wn * t).exp() * (wd * t).cos())
            .collect();
        let z = damping_from_decrement(&x, 1.0);
        assert!((z - zeta).abs() < 1e-3, "{z}");
    }

    #[test]
    fn first_order_step_has_the_textbook_rise_and_settling_times() {
        let tau = 0.1;
        let t: Vec<f64> = (0..100_001).map(|k| k as f64 * 2e-5).collect();
        let x: Vec<f64> = t.iter().map(|&t| 1.0 - (-t / tau).exp()).collect();
        let [rise, over, settle, fin] = step_metrics(&t, &x, 0.0, 1.9, 0.02);
        assert!((fin - 1.0).abs() < 1e-6);
        assert!((rise - tau * 9f64.ln()).abs() < 1e-4, "{rise}");
        assert!(over < 1e-6);
        assert!((settle - tau * 50f64.ln()).abs() < 1e-3, "{settle}");
    }

    #[test]
    fn a_load_that_ends_at_rest_has_no_step_metrics() {
        let t: Vec<f64> = (0..1000).map(|k| k as f64 * 1e-3).collect();
        // A pre-sliding twitch: up and back to rest.
        let x: Vec<f64> = t.iter().map(|&t| 1e-5 * t * (-50.0 * t).exp()).collect();
        let [rise, over, settle, _] = step_metrics(&t, &x, 0.0, 0.8, 0.02);
        assert!(rise.is_nan() && over.is_nan() && settle.is_nan());
    }
}
