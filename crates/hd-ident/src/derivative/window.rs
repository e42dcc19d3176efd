//! The half-window of the Savitzky–Golay differentiator chosen from the data
//! ([`choose_half_window`]): noise target, reversal spacing, quantisation.

use super::{
    MAX_ORDER, MIN_HALF_WINDOW, REVERSAL_FRACTION, TARGET_RELATIVE_NOISE, check, min_half_window,
};
use nalgebra::{Matrix5, Vector5};
use serde::Serialize;

/// The window chosen by [`choose_half_window`], with the numbers behind it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WindowChoice {
    /// Half-window h: each slope uses 2h + 1 samples.
    pub half_window: usize,
    /// Polynomial degree.
    pub order: usize,
    /// Estimated standard deviation of the position noise σx [pos] (white noise plus
    /// quantisation), from the third differences or the quantisation step.
    pub noise_std: f64,
    /// Predicted standard deviation of the speed noise with this window [pos/s].
    pub predicted_speed_noise: f64,
    /// RMS of the speed, from smoothed central differences with their noise removed [pos/s].
    pub speed_rms: f64,
    /// Largest half-window allowed by the reversals of the motion and the record length.
    pub max_half_window: usize,
    /// Number of reversals (sign changes) of the speed found.
    pub reversals: usize,
    /// Shortest interval between two reversals of the speed [s], if there are at least two.
    pub shortest_reversal_interval: Option<f64>,
    /// One sentence on how the window was chosen.
    pub reason: String,
}

/// Standard deviation of the central slope of a least-squares fit of degree `order` over
/// `2h + 1` evenly spaced samples with white noise of unit size and unit spacing. For
/// degree ≤ 2 this is the closed form √(3 / (h(h+1)(2h+1))) (the quadratic term is
/// orthogonal to the slope on a symmetric window); for degree 3 and 4 it is √(Σ wⱼ²) of
/// the fit's slope weights wⱼ, computed here.
pub fn unit_slope_noise(h: usize, order: usize) -> f64 {
    let hf = h as f64;
    if order <= 2 {
        return (3.0 / (hf * (hf + 1.0) * (2.0 * hf + 1.0))).sqrt();
    }
    // The slope is linear in the data: wⱼ is the slope for data eⱼ (unit impulse at j).
    // Build the Gram matrix of u = k/h once and solve for the slope row of its inverse.
    let order = order.min(MAX_ORDER);
    let mut sums = [0.0; 2 * MAX_ORDER + 1];
    for k in -(h as i64)..=(h as i64) {
        let u = k as f64 / hf;
        let mut p = 1.0;
        for s in sums.iter_mut().take(2 * order + 1) {
            *s += p;
            p *= u;
        }
    }
    let g = Matrix5::from_fn(|r, c| {
        if r <= order && c <= order {
            sums[r + c]
        } else if r == c {
            1.0
        } else {
            0.0
        }
    });
    let Some(chol) = g.cholesky() else { return f64::NAN };
    // Row 1 of G⁻¹ (G is symmetric): a = G⁻¹·e₁; then wⱼ = Σ_k a_k·u_j^k / h.
    let a = chol.solve(&Vector5::from_fn(|r, _| if r == 1 { 1.0 } else { 0.0 }));
    let mut sum_sq = 0.0;
    for k in -(h as i64)..=(h as i64) {
        let u = k as f64 / hf;
        let mut p = 1.0;
        let mut w = 0.0;
        for c in a.iter().take(order + 1) {
            w += c * p;
            p *= u;
        }
        sum_sq += (w / hf).powi(2);
    }
    sum_sq.sqrt()
}

/// Median of the sample spacings [s].
fn median_spacing(t: &[f64]) -> f64 {
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = d.len() / 2;
    *d.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// σx from the third differences: for white noise of size σ, Δ³x has variance 20σ²
/// (1 + 9 + 9 + 1), and a smooth signal contributes only x'''·dt³. Quantisation of a
/// position that moves by a step or more per sample shows up here as white noise too.
fn third_difference_noise(x: &[f64]) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for w in x.windows(4) {
        let d = w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0];
        sum += d * d;
        count += 1;
    }
    (sum / count.max(1) as f64 / 20.0).sqrt()
}

/// The quantisation step [pos] of an encoder-like record, if it is one: at least a fifth of
/// the sample-to-sample changes are exactly zero (the position dwells on a level) and every
/// other change is a whole multiple of the smallest one. Such a record moves by less than a
/// step per sample, its error is a sawtooth the third differences see only at the steps,
/// and q/√12 is the better measure of its noise.
pub fn quantisation_step(x: &[f64]) -> Option<f64> {
    let diffs = || x.windows(2).map(|w| (w[1] - w[0]).abs());
    let zeros = diffs().filter(|&d| d == 0.0).count();
    if x.len() < 3 || 5 * zeros < x.len() - 1 {
        return None;
    }
    let q = diffs().filter(|&d| d > 0.0).fold(f64::INFINITY, f64::min);
    if !q.is_finite() {
        return None;
    }
    let whole = |d: f64| {
        let r = d / q;
        (r - r.round()).abs() <= 1e-6 * r.max(1.0)
    };
    diffs().filter(|&d| d > 0.0).all(whole).then_some(q)
}

/// Secant speed over `±m` samples (a central difference smoothed over 2m intervals) [pos/s].
fn secant_speed(t: &[f64], x: &[f64], m: usize) -> Vec<f64> {
    let n = t.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(m), (i + m).min(n - 1));
            (x[b] - x[a]) / (t[b] - t[a])
        })
        .collect()
}

/// Times [s] at which the speed changes sign, found with hysteresis: a reversal counts only
/// once the speed has gone beyond `threshold` on the other side, and is dated at the last
/// zero crossing before that.
fn reversal_times(t: &[f64], v: &[f64], threshold: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut state = 0i8; // sign of the last confirmed motion
    let mut last_crossing = 0usize; // last sample at or before which the sign changed
    for i in 0..v.len() {
        if i > 0 && (v[i] > 0.0) != (v[i - 1] > 0.0) {
            last_crossing = i;
        }
        let s = if v[i] > threshold {
            1
        } else if v[i] < -threshold {
            -1
        } else {
            0
        };
        if s != 0 && s != state {
            if state != 0 {
                out.push(t[last_crossing]);
            }
            state = s;
        }
    }
    out
}

/// `v` with four significant digits, in plain notation between 1e-3 and 1e5.
fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return v.to_string();
    }
    let mag = v.abs().log10().floor();
    if !(-3.0..5.0).contains(&mag) {
        return format!("{v:.3e}");
    }
    format!("{v:.*}", (3.0 - mag).max(0.0) as usize)
}

/// A choice that could not look at the data (too short, or not valid samples).
fn fallback(order: usize, why: String) -> WindowChoice {
    WindowChoice {
        half_window: MIN_HALF_WINDOW.max(min_half_window(order)),
        order,
        noise_std: f64::NAN,
        predicted_speed_noise: f64::NAN,
        speed_rms: f64::NAN,
        max_half_window: MIN_HALF_WINDOW.max(min_half_window(order)),
        reversals: 0,
        shortest_reversal_interval: None,
        reason: why,
    }
}

/// Pick the half-window for [`savitzky_golay_derivative`] from the data.
///
/// 1. Position noise σx [pos] = RMS(Δ³x)/√20 (white noise, and the quantisation of a
///    position moving a step or more per sample); for an encoder record dwelling on its
///    levels ([`quantisation_step`] q) at least q/√12.
/// 2. A crude speed: secant slopes over ±m samples, m doubled from 2 until its own noise
///    σx·√2/(2m·dt) is at most 5 % of its RMS; the speed RMS is that RMS with the noise
///    variance removed.
/// 3. Reversals: sign changes of the crude speed, with a hysteresis of the larger of 3× its
///    noise and 10 % of the speed RMS. The window span 2h·dt may be at most
///    [`REVERSAL_FRACTION`] of the shortest interval between reversals (of the record length
///    when there are fewer than two), and 2h + 1 at most the number of samples.
/// 4. The smallest h ≥ [`MIN_HALF_WINDOW`] whose predicted speed noise σx·u(h, order)/dt,
///    with u from [`unit_slope_noise`], is at most [`TARGET_RELATIVE_NOISE`] of the speed
///    RMS; if even the largest allowed h misses the target, that largest h.
///
/// dt is the median spacing, so for unevenly sampled data the prediction is approximate.
/// Never fails: inputs the derivative would reject (too short, non-finite, time not
/// increasing) get the smallest window and a reason saying why, and
/// [`savitzky_golay_derivative`] then reports the error. A degree outside 1..=4 is clamped.
pub fn choose_half_window(t: &[f64], x: &[f64], order: usize) -> WindowChoice {
    let asked = order;
    let order = order.clamp(1, MAX_ORDER);
    let n = t.len().min(x.len());
    let h_min = MIN_HALF_WINDOW.max(min_half_window(order));
    if n < 2 * h_min + 4 {
        return fallback(
            order,
            format!(
                "half-window {h_min}, the smallest: {n} samples are too few to estimate the noise"
            ),
        );
    }
    let (t, x) = (&t[..n], &x[..n]);
    if let Err(e) = check(t, x, h_min, order) {
        return fallback(
            order,
            format!("half-window {h_min}, the smallest: the data are not usable ({e})"),
        );
    }
    let dt = median_spacing(t);
    let duration = t[n - 1] - t[0];
    let sigma_3 = third_difference_noise(x);
    let step = quantisation_step(x);
    let sigma_x = step.map_or(sigma_3, |q| sigma_3.max(q / 12f64.sqrt()));

    // Crude speed and its RMS.
    let m_max = ((n - 1) / 16).max(2);
    let mut m = 2;
    let (v, v_noise, speed_rms) = loop {
        let v = secant_speed(t, x, m);
        let noise = sigma_x * std::f64::consts::SQRT_2 / (2.0 * m as f64 * dt);
        let ms = v.iter().map(|v| v * v).sum::<f64>() / n as f64;
        let rms = (ms - noise * noise).max(0.0).sqrt();
        if noise <= 0.05 * rms || 2 * m > m_max {
            break (v, noise, rms);
        }
        m *= 2;
    };

    // Cap from the reversals and the record length.
    let reversals = reversal_times(t, &v, (3.0 * v_noise).max(0.1 * speed_rms));
    let shortest = reversals
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(None, |a: Option<f64>, d| Some(a.map_or(d, |a| a.min(d))));
    let span_limit = REVERSAL_FRACTION * shortest.unwrap_or(duration);
    let h_fit = (n - 1) / 2;
    let h_cap = ((span_limit / (2.0 * dt)).floor() as usize).min(h_fit);
    let cap_text = match shortest {
        Some(s) => format!(
            "{} reversals of the speed, the closest {} s apart, allow a span of at most {} s (h ≤ {h_cap})",
            reversals.len(),
            sig(s),
            sig(span_limit)
        ),
        None => format!(
            "with no two reversals of the speed, the span is capped at {} s, 1/8 of the record (h ≤ {h_cap})",
            sig(span_limit)
        ),
    };
    let noise_at = |h: usize| sigma_x * unit_slope_noise(h, order) / dt;
    let target = TARGET_RELATIVE_NOISE * speed_rms;
    let noise_source = match step {
        Some(q) if sigma_x > sigma_3 => format!(
            "quantisation step {q:.3e} / √12, above the third-difference estimate {sigma_3:.3e}"
        ),
        _ => "RMS of third differences / √20".to_string(),
    };
    let noise_text = format!(
        "position noise σx ≈ {sigma_x:.3e} ({noise_source}), RMS speed {speed_rms:.3e} (position units per second)"
    );

    let (h, how) = if h_cap <= h_min {
        (h_min, format!("the smallest half-window, since {cap_text}"))
    } else if sigma_x == 0.0 {
        (h_min, "the smallest half-window: the position shows no noise".to_string())
    } else if speed_rms == 0.0 {
        (h_cap, format!("the largest allowed half-window: the position hardly moves; {cap_text}"))
    } else if noise_at(h_cap) > target {
        (
            h_cap,
            format!(
                "the largest allowed half-window, short of the 1 % target: predicted speed noise {:.2} % of the RMS speed; {cap_text}",
                100.0 * noise_at(h_cap) / speed_rms
            ),
        )
    } else {
        // Smallest h in [h_min, h_cap] meeting the target (noise falls with h).
        let (mut lo, mut hi) = (h_min, h_cap);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if noise_at(mid) <= target { hi = mid } else { lo = mid + 1 }
        }
        (
            lo,
            format!(
                "the smallest half-window whose predicted speed noise is ≤ 1 % of the RMS speed ({:.2} %); {cap_text}",
                100.0 * noise_at(lo) / speed_rms
            ),
        )
    };
    let clamped = if asked == order {
        String::new()
    } else {
        format!(" (degree {asked} asked, outside 1 to {MAX_ORDER})")
    };
    let reason = format!(
        "half-window {h} ({} samples, {} s) for a degree-{order} fit{clamped}: {how}; {noise_text}",
        2 * h + 1,
        sig(2.0 * h as f64 * dt)
    );
    WindowChoice {
        half_window: h,
        order,
        noise_std: sigma_x,
        predicted_speed_noise: noise_at(h),
        speed_rms,
        max_half_window: h_cap.max(h_min),
        reversals: reversals.len(),
        shortest_reversal_interval: shortest,
        reason,
    }
}
