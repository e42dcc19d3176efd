//! Page's two-sided CUSUM test on standardised residuals, with its threshold chosen for
//! a false-alarm probability the user sets.
//!
//! For residuals z₁, z₂, … (in control: independent, mean 0, variance 1) the upper and
//! lower sums
//!
//! ```text
//! S⁺ᵢ = max(0, S⁺ᵢ₋₁ + zᵢ − k),   S⁻ᵢ = max(0, S⁻ᵢ₋₁ − zᵢ − k),   S₀ = 0
//! ```
//!
//! alarm when either exceeds h. Siegmund's approximation gives the in-control average run
//! length of one side, `ARL(h) = (e^{2kb} − 2kb − 1)/(2k²)` with `b = h + 1.166`. A series
//! of N residuals tested on both sides then alarms falsely with probability about
//! `1 − exp(−2N/ARL)`; [`threshold`] solves that for h. The reference k = 0.5 is the
//! classical choice, tuned to a shift of one standard deviation.

/// The one-sided in-control average run length at threshold `h` and reference `k`
/// (Siegmund's approximation) [samples].
pub fn arl0(h: f64, k: f64) -> f64 {
    let b = h + 1.166;
    let x = 2.0 * k * b;
    (x.exp() - x - 1.0) / (2.0 * k * k)
}

/// The threshold h for which a two-sided test over `n` in-control samples alarms with
/// probability `alpha` (bisection on [`arl0`]).
pub fn threshold(alpha: f64, n: usize, k: f64) -> f64 {
    let alpha = alpha.clamp(1e-12, 0.999_999);
    let target = -2.0 * n.max(1) as f64 / (1.0 - alpha).ln();
    let (mut lo, mut hi) = (0.0, 1.0);
    while arl0(hi, k) < target {
        hi *= 2.0;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if arl0(mid, k) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The threshold h for a series of `n` residuals whose first `m` (the baseline) also
/// estimated the level they are measured from: that estimate's error is shared by every
/// later residual, so they are correlated and a threshold for independent residuals
/// ([`threshold`]) alarms far more often than asked (the classical result on CUSUM
/// charts with estimated parameters). h is the (1 − α) quantile of the test's largest
/// sum over `n` residuals `zᵢ = (eᵢ − ē_m)/√(1 + 1/m)`, eᵢ standard normal and ē_m the
/// mean of the first m, each series rescaled by its own baseline spread as the
/// normalisation does (shrunk towards 1 with the weight of
/// [`super::normalise::UNIT_PRIOR`] estimates), simulated (a fixed seed: the same h every
/// time).
pub fn threshold_estimated(alpha: f64, m: usize, n: usize, k: f64) -> f64 {
    use rand::{RngExt, SeedableRng};
    let alpha = alpha.clamp(1e-6, 0.5);
    let sims = ((60.0 / alpha) as usize).clamp(20_000, 400_000);
    let m = m.clamp(1, n.max(1));
    let mut rng =
        rand_chacha::ChaCha8Rng::seed_from_u64(0x05ee_dc05_u64 ^ ((m as u64) << 32) ^ n as u64);
    let mut gauss = || {
        let u1 = 1.0 - rng.random::<f64>();
        let u2: f64 = rng.random();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let scale = 1.0 / (1.0 + 1.0 / m as f64).sqrt();
    let mut e = vec![0.0; n.max(1)];
    // The (1 − α) quantile is the K-th largest of the maxima, K = sims − q: only the K
    // largest are kept (a min-heap), so memory follows α·sims, not sims.
    let q = (((1.0 - alpha) * sims as f64).floor() as usize).min(sims - 1);
    let keep = sims - q;
    let mut largest: std::collections::BinaryHeap<std::cmp::Reverse<Ordered>> =
        std::collections::BinaryHeap::with_capacity(keep + 1);
    for _ in 0..sims {
        let top_of = {
            e.iter_mut().for_each(|v| *v = gauss());
            let mean = e[..m].iter().sum::<f64>() / m as f64;
            // The unit's own scale from its baseline, shrunk as in the normalisation.
            let q = if m > 1 {
                e[..m].iter().map(|v| ((v - mean) * scale).powi(2)).sum::<f64>() / (m - 1) as f64
            } else {
                1.0
            };
            let prior = super::normalise::UNIT_PRIOR;
            let phi = (prior + m as f64 * q) / (prior + m as f64);
            let scale = scale / phi.sqrt();
            let (mut up, mut lo, mut top) = (0.0f64, 0.0f64, 0.0f64);
            for v in &e {
                let z = (v - mean) * scale;
                up = (up + z - k).max(0.0);
                lo = (lo - z - k).max(0.0);
                top = top.max(up).max(lo);
            }
            top
        };
        largest.push(std::cmp::Reverse(Ordered(top_of)));
        if largest.len() > keep {
            largest.pop();
        }
    }
    largest.peek().map_or(f64::NAN, |r| r.0.0)
}

/// A number ordered by `f64::total_cmp` (for the heap of largest maxima).
#[derive(PartialEq)]
struct Ordered(f64);

impl Eq for Ordered {}

impl PartialOrd for Ordered {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Ordered {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The path of the test over one series.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CusumPath {
    /// S⁺ after each sample.
    pub upper: Vec<f64>,
    /// S⁻ after each sample.
    pub lower: Vec<f64>,
    /// Index of the first sample at which S⁺ or S⁻ exceeded h.
    pub alarm: Option<usize>,
    /// +1 for a rise, −1 for a fall (at the alarm).
    pub direction: i8,
    /// Page's estimate of the change: the first sample after the last time the alarming
    /// sum was 0 before the alarm.
    pub onset: Option<usize>,
}

/// Run the two-sided test over `z` (non-finite entries are skipped: the sums hold).
pub fn cusum(z: &[f64], k: f64, h: f64) -> CusumPath {
    let mut p = CusumPath::default();
    let (mut up, mut lo) = (0.0f64, 0.0f64);
    let (mut up_zero, mut lo_zero) = (0usize, 0usize);
    for (i, &zi) in z.iter().enumerate() {
        if zi.is_finite() {
            up = (up + zi - k).max(0.0);
            lo = (lo - zi - k).max(0.0);
            if up == 0.0 {
                up_zero = i + 1;
            }
            if lo == 0.0 {
                lo_zero = i + 1;
            }
            if p.alarm.is_none() && (up > h || lo > h) {
                p.alarm = Some(i);
                p.direction = if up > h { 1 } else { -1 };
                p.onset = Some(if up > h { up_zero } else { lo_zero });
            }
        }
        p.upper.push(up);
        p.lower.push(lo);
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn gauss(rng: &mut ChaCha8Rng) -> f64 {
        let u1 = 1.0 - rng.random::<f64>();
        let u2: f64 = rng.random();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    /// The false-alarm probability of the chosen threshold, counted over 20 000 series of
    /// 60 standard normal residuals: the nominal 5 % must come out within [2.5 %, 7 %]
    /// (Siegmund's approximation is slightly conservative for short series).
    #[test]
    fn the_threshold_gives_the_false_alarm_rate_asked_for() {
        let (alpha, n, k) = (0.05, 60, 0.5);
        let h = threshold(alpha, n, k);
        assert!((arl0(h, k) - (-2.0 * n as f64 / (1.0f64 - alpha).ln())).abs() < 1e-6 * arl0(h, k));
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let series = 20_000;
        let mut alarms = 0;
        for _ in 0..series {
            let z: Vec<f64> = (0..n).map(|_| gauss(&mut rng)).collect();
            alarms += usize::from(cusum(&z, k, h).alarm.is_some());
        }
        let rate = alarms as f64 / series as f64;
        assert!((0.025..0.07).contains(&rate), "false alarms {rate} at h = {h}");
    }

    /// With an estimated baseline level the residuals share its error: the threshold for
    /// independent residuals alarms well above the nominal rate, the simulated one near it
    /// (counted on fresh series, other seeds than the threshold's).
    #[test]
    fn an_estimated_baseline_needs_and_gets_a_higher_threshold() {
        let (alpha, m, n, k) = (0.01, 20, 60, 0.5);
        let h_iid = threshold(alpha, n, k);
        let h_est = threshold_estimated(alpha, m, n, k);
        assert!(h_est > h_iid, "{h_est} vs {h_iid}");
        let mut rng = ChaCha8Rng::seed_from_u64(99);
        let series = 20_000;
        let (mut a_iid, mut a_est) = (0, 0);
        for _ in 0..series {
            let e: Vec<f64> = (0..n).map(|_| gauss(&mut rng)).collect();
            let mean = e[..m].iter().sum::<f64>() / m as f64;
            let z: Vec<f64> =
                e.iter().map(|v| (v - mean) / (1.0 + 1.0 / m as f64).sqrt()).collect();
            a_iid += usize::from(cusum(&z, k, h_iid).alarm.is_some());
            // The unit's own scale, as the normalisation rescales a unit's residuals.
            let q = z[..m].iter().map(|v| v * v).sum::<f64>() / (m - 1) as f64;
            let prior = crate::fleet::normalise::UNIT_PRIOR;
            let phi = (prior + m as f64 * q) / (prior + m as f64);
            let zs: Vec<f64> = z.iter().map(|v| v / phi.sqrt()).collect();
            a_est += usize::from(cusum(&zs, k, h_est).alarm.is_some());
        }
        let (r_iid, r_est) = (a_iid as f64 / series as f64, a_est as f64 / series as f64);
        assert!(r_iid > 2.0 * alpha, "independent threshold: {r_iid}");
        assert!((0.5 * alpha..1.6 * alpha).contains(&r_est), "simulated threshold: {r_est}");
    }

    /// A step of 2 standard deviations at sample 30: found, upwards, onset at the step.
    #[test]
    fn a_step_is_found_with_its_onset_and_direction() {
        let mut z = vec![0.0; 60];
        z[30..].iter_mut().for_each(|v| *v = 2.0);
        let p = cusum(&z, 0.5, 4.0);
        // S⁺ grows by 1.5 a sample from sample 30: above 4 at the third (31 + 2 = 32).
        assert_eq!(p.alarm, Some(32));
        assert_eq!(p.direction, 1);
        assert_eq!(p.onset, Some(30));
        let neg: Vec<f64> = z.iter().map(|v| -v).collect();
        assert_eq!(cusum(&neg, 0.5, 4.0).direction, -1);
    }
}
