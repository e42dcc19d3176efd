//! Whether a recorded signal repeats, and with what period.
//!
//! A recorded voltage that is a sampled sine (or any repeating wave) drives the model as the
//! built-in sine does, so its runs get the periodic metrics (amplitude, ripple, gain and
//! phase, losses per cycle) over whole periods, and its forced response is never mistaken for
//! a limit cycle. A record is periodic when its upward crossings of the mean are evenly
//! spaced and the record shifted by that spacing matches itself.

use crate::interp::linear_at;

/// Largest spread of the crossing intervals about their mean, relative [–].
const INTERVAL_SPREAD: f64 = 0.02;
/// Largest RMS of `u(t + P) − u(t)` relative to the RMS of `u` about its mean [–]; a sine
/// sampled 20 times a cycle and joined by straight lines stays under 1 %.
const SHIFT_MISMATCH: f64 = 0.03;

/// The period [s] of the samples `(t, u)` if they repeat over at least three whole periods,
/// else `None` (constant, aperiodic, noisy or too short records).
pub fn period_of(t: &[f64], u: &[f64]) -> Option<f64> {
    let n = t.len().min(u.len());
    if n < 16 {
        return None;
    }
    let mean = u[..n].iter().sum::<f64>() / n as f64;
    let rms = (u[..n].iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
    let scale = u[..n].iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if rms.is_nan() || rms <= 1e-9 * scale.max(f64::MIN_POSITIVE) {
        return None;
    }
    // Upward crossings of the mean, re-armed only after dipping a band below it (noise).
    let band = 0.3 * rms;
    let mut armed = false;
    let mut ups: Vec<f64> = Vec::new();
    for k in 1..n {
        if u[k] < mean - band {
            armed = true;
        }
        if armed && u[k - 1] < mean && u[k] >= mean {
            let f = (mean - u[k - 1]) / (u[k] - u[k - 1]);
            ups.push(t[k - 1] + f * (t[k] - t[k - 1]));
            armed = false;
        }
    }
    if ups.len() < 4 {
        return None;
    }
    let cycles = (ups.len() - 1) as f64;
    let period = (ups[ups.len() - 1] - ups[0]) / cycles;
    if period.is_nan()
        || period <= 0.0
        || ups.windows(2).any(|w| ((w[1] - w[0]) / period - 1.0).abs() > INTERVAL_SPREAD)
    {
        return None;
    }
    // The record shifted by one period matches itself (rules out waves whose crossings are
    // evenly spaced but whose shape changes, such as a chirp of small sweep).
    let end = t[n - 1] - period;
    let (mut ss, mut count) = (0.0, 0usize);
    for k in 0..n {
        if t[k] > end {
            break;
        }
        let (shifted, _) = linear_at(&t[..n], &u[..n], t[k] + period);
        ss += (shifted - u[k]).powi(2);
        count += 1;
    }
    let mismatch = (ss / count.max(1) as f64).sqrt();
    (count > 0 && mismatch <= SHIFT_MISMATCH * rms).then_some(period)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    fn sampled(f: impl Fn(f64) -> f64, dt: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let u = t.iter().map(|&t| f(t)).collect();
        (t, u)
    }

    #[test]
    fn a_sampled_sine_has_its_period() {
        // 50 Hz at 20 samples a cycle (coarse) and at 1e-5 s (fine).
        for dt in [1e-3, 1e-5] {
            let (t, u) = sampled(|t| 24.0 * (TAU * 50.0 * t).sin(), dt, (0.2 / dt) as usize + 1);
            let p = period_of(&t, &u).expect("periodic");
            assert!((p - 0.02).abs() < 1e-3 * 0.02, "dt {dt}: period {p}");
        }
        // A square wave with an offset.
        let (t, u) =
            sampled(|t| 3.0 + if (t * 10.0).fract() < 0.5 { 1.0 } else { -1.0 }, 1e-3, 1000);
        let p = period_of(&t, &u).expect("periodic");
        assert!((p - 0.1).abs() < 2e-3, "{p}");
    }

    #[test]
    fn steps_chirps_constants_and_short_records_are_not_periodic() {
        let (t, u) = sampled(|t| if t > 0.05 { 12.0 } else { 0.0 }, 1e-4, 2000);
        assert_eq!(period_of(&t, &u), None);
        let (t, u) = sampled(|_| 5.0, 1e-4, 2000);
        assert_eq!(period_of(&t, &u), None);
        let (t, u) = sampled(|t| (TAU * (10.0 * t + 40.0 * t * t)).sin(), 1e-4, 20_000);
        assert_eq!(period_of(&t, &u), None);
        let (t, u) = sampled(|t| (TAU * 50.0 * t).sin(), 1e-4, 500); // 2.5 cycles
        assert_eq!(period_of(&t, &u), None);
    }
}
