//! Detection of a persistent oscillation in the final window of a run.

/// `(flag, amplitude, period)` for uniformly sampled `x` over the final window: the flag is
/// 1 when the oscillation about the mean is larger than `1e-4` of the mean level (and than
/// `1e-9` absolutely) and does not decay (the second half's peak-to-peak is at least 97 %
/// of the first half's). Period from the mean spacing of upward mean crossings.
pub fn detect(t: &[f64], x: &[f64]) -> [f64; 3] {
    let n = x.len();
    if n < 8 {
        return [f64::NAN; 3];
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let ptp = |s: &[f64]| {
        let (lo, hi) =
            s.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        hi - lo
    };
    let amp = 0.5 * ptp(x);
    let (first, second) = x.split_at(n / 2);
    let sustained = ptp(second) >= 0.97 * ptp(first);
    // Upward crossings of the mean, with a 10 % hysteresis band against noise.
    let band = 0.1 * amp;
    let mut armed = false;
    let mut ups = Vec::new();
    for k in 1..n {
        if x[k] < mean - band {
            armed = true;
        }
        if armed && x[k - 1] < mean && x[k] >= mean {
            let f = (mean - x[k - 1]) / (x[k] - x[k - 1]);
            ups.push(t[k - 1] + f * (t[k] - t[k - 1]));
            armed = false;
        }
    }
    let period = if ups.len() >= 2 {
        (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64
    } else {
        f64::NAN
    };
    let flag = amp > 1e-9 && amp > 1e-4 * mean.abs() && sustained && ups.len() >= 2;
    if flag { [1.0, amp, period] } else { [0.0, amp, f64::NAN] }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn flags_a_sustained_oscillation_and_not_a_decaying_one() {
        let t: Vec<f64> = (0..4000).map(|k| k as f64 * 1e-4).collect();
        let steady: Vec<f64> = t.iter().map(|&t| 2.0 + 0.1 * (TAU * 25.0 * t).sin()).collect();
        let [flag, amp, period] = detect(&t, &steady);
        assert_eq!(flag, 1.0);
        assert!((amp - 0.1).abs() < 1e-4 && (period - 0.04).abs() < 1e-4, "{amp} {period}");
        let decaying: Vec<f64> =
            t.iter().map(|&t| 2.0 + 0.1 * (-20.0 * t).exp() * (TAU * 25.0 * t).sin()).collect();
        assert_eq!(detect(&t, &decaying)[0], 0.0);
    }
}
