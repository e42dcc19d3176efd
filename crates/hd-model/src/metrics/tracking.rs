//! Closed-loop metrics: tracking error, reversal peaks, command effort, saturation,
//! torque-estimate error, and for regulation the steady error and hunting
//! (docs/model.md §6.7). Computed from uniform samples over the run.

use super::limit_cycle;

/// Uniform samples of the closed-loop signals.
#[derive(Clone, Debug, Default)]
pub struct TrackingSamples {
    /// Time [s].
    pub t: Vec<f64>,
    /// Tracking error θz_ref − θz [rad].
    pub error: Vec<f64>,
    /// Reference speed [rad/s].
    pub ref_speed: Vec<f64>,
    /// Command after saturation [V].
    pub u: Vec<f64>,
    /// Whether the command was clipped.
    pub saturated: Vec<bool>,
    /// Transmitted-torque estimate minus the true Tb, with the friction model [N·m].
    pub tb_err: Vec<f64>,
    /// The same without the friction model [N·m].
    pub tb_err_nofric: Vec<f64>,
}

/// Where the metrics look.
#[derive(Clone, Copy, Debug)]
pub struct Windows {
    /// Start of the tracking window [s] (after the first reference period, or after the
    /// move).
    pub settled_from: f64,
    /// Length of the window after each reference-speed reversal [s].
    pub reversal_window: f64,
    /// Start of the final window for steady error and hunting [s].
    pub final_from: f64,
    /// Whether the reference ends at rest (regulation).
    pub regulation: bool,
}

/// The closed-loop metric values, in the order
/// `[track_rms, track_max, reversal_peak, u_rms, saturation_fraction, torque_est_rms,
/// torque_est_rms_nofric, steady_error, hunting, hunt_amplitude, hunt_period]`.
pub fn tracking_metrics(s: &TrackingSamples, w: &Windows) -> [f64; 11] {
    let nan = f64::NAN;
    let k0 = s.t.partition_point(|&t| t < w.settled_from);
    let rms = |x: &[f64]| {
        if x.is_empty() {
            nan
        } else {
            (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
        }
    };
    let max_abs = |x: &[f64]| {
        x.iter().fold(nan, |m: f64, v| if m.is_nan() { v.abs() } else { m.max(v.abs()) })
    };
    let e = &s.error[k0..];
    let mut reversal_peak = nan;
    for k in (k0.max(1))..s.t.len() {
        let (a, b) = (s.ref_speed[k - 1], s.ref_speed[k]);
        if a * b < 0.0
            || (a != 0.0 && b == 0.0 && s.ref_speed.get(k + 1).is_some_and(|c| c * a < 0.0))
        {
            let end = s.t[k] + w.reversal_window;
            let k1 = s.t.partition_point(|&t| t <= end);
            let peak = max_abs(&s.error[k..k1]);
            reversal_peak = if reversal_peak.is_nan() { peak } else { reversal_peak.max(peak) };
        }
    }
    let sat = &s.saturated[k0..];
    let saturation_fraction = if sat.is_empty() {
        nan
    } else {
        sat.iter().filter(|&&b| b).count() as f64 / sat.len() as f64
    };
    let mut out = [
        rms(e),
        max_abs(e),
        reversal_peak,
        rms(&s.u[k0..]),
        saturation_fraction,
        rms(&s.tb_err[k0..]),
        rms(&s.tb_err_nofric[k0..]),
        nan,
        nan,
        nan,
        nan,
    ];
    if w.regulation {
        let kf = s.t.partition_point(|&t| t < w.final_from);
        let tail = &s.error[kf..];
        if !tail.is_empty() {
            out[7] = tail.iter().sum::<f64>() / tail.len() as f64;
            let [flag, amp, period] = limit_cycle::detect(&s.t[kf..], tail);
            out[8] = flag;
            out[9] = amp;
            out[10] = period;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// A sine error of known amplitude gives RMS A/√2 and max A; a bump after the
    /// reference's reversal is found as the reversal peak.
    #[test]
    fn rms_max_and_reversal_peak_of_known_signals() {
        let n = 10_001;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let mut error: Vec<f64> = t.iter().map(|&t| 1e-4 * (TAU * 7.0 * t).sin()).collect();
        // Reference speed cos(2π·0.5·t) reverses at t = 0.5, 1.5, …; put a bump at 1.52 s.
        error[1520] = 5e-4;
        let s = TrackingSamples {
            ref_speed: t.iter().map(|&t| (TAU * 0.5 * t).cos()).collect(),
            u: vec![2.0; n],
            saturated: (0..n).map(|k| k % 4 == 0).collect(),
            tb_err: vec![0.1; n],
            tb_err_nofric: vec![-0.3; n],
            error,
            t,
        };
        let w =
            Windows { settled_from: 1.0, reversal_window: 0.1, final_from: 8.0, regulation: false };
        let m = tracking_metrics(&s, &w);
        assert!((m[0] - 1e-4 / 2f64.sqrt()).abs() < 2e-6, "{}", m[0]);
        assert_eq!(m[1], 5e-4);
        assert_eq!(m[2], 5e-4);
        assert!((m[3] - 2.0).abs() < 1e-12 && (m[4] - 0.25).abs() < 1e-3);
        assert!((m[5] - 0.1).abs() < 1e-12 && (m[6] - 0.3).abs() < 1e-12);
        assert!(m[7].is_nan());
    }
}
