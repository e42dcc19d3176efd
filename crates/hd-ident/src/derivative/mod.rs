//! Speed from a recorded position: a smoothing differentiator for rigs that log only an
//! encoder angle or a slider position.
//!
//! [`savitzky_golay_derivative`] fits, around every sample, a polynomial of low degree to
//! the `2h + 1` neighbouring samples by least squares and takes the slope of that
//! polynomial at the sample — the Savitzky–Golay differentiator, here written for arbitrary
//! (non-uniform) time stamps. Near the ends of the record the window does not shrink: the
//! first and last `h` samples use the first and last full window, evaluated at the sample
//! itself.
//!
//! [`choose_half_window`] picks `h` from the data: large enough that the predicted noise of
//! the speed is about 1 % of its RMS, small enough that a window spans at most an eighth of
//! the shortest stretch between two reversals of the motion, so reversals are not smeared.
//!
//! Units: time [s]; position in any unit [pos]; speeds come out in [pos/s].

use nalgebra::{Matrix5, Vector5};
use serde::Serialize;
use thiserror::Error;

/// Polynomial degree used when nothing else is asked (quadratic: exact for constant
/// acceleration, and its central slope has the same noise as a straight line's).
pub const DEFAULT_ORDER: usize = 2;

/// Highest polynomial degree accepted.
pub const MAX_ORDER: usize = 4;

/// Target of [`choose_half_window`]: predicted speed noise over RMS speed [–].
pub const TARGET_RELATIVE_NOISE: f64 = 0.01;

/// Largest fraction of the shortest interval between speed reversals that one window may
/// span in [`choose_half_window`] [–].
pub const REVERSAL_FRACTION: f64 = 0.125;

/// Smallest half-window [`choose_half_window`] returns.
pub const MIN_HALF_WINDOW: usize = 2;

/// Why a derivative cannot be computed. Rows are 1-based.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DerivativeError {
    /// Time and position have different lengths.
    #[error("time has {t_len} samples but position has {x_len}; they must pair up")]
    LengthMismatch {
        /// Number of time stamps.
        t_len: usize,
        /// Number of positions.
        x_len: usize,
    },
    /// Too few samples for any window of the asked degree.
    #[error(
        "{samples} sample(s) are too few to differentiate with a degree-{order} polynomial; at least {needed} are needed"
    )]
    TooFewSamples {
        /// Number of samples given.
        samples: usize,
        /// Polynomial degree asked.
        order: usize,
        /// Smallest usable number of samples.
        needed: usize,
    },
    /// The polynomial degree is not in 1..=[`MAX_ORDER`].
    #[error("polynomial degree {order} is out of range; expected 1 to {MAX_ORDER}")]
    OrderOutOfRange {
        /// Degree asked.
        order: usize,
    },
    /// The window has fewer samples than the polynomial has coefficients.
    #[error(
        "half-window {half_window} gives {window} samples, too few for a degree-{order} polynomial; expected a half-window of at least {min_half_window}"
    )]
    WindowTooSmall {
        /// Half-window asked.
        half_window: usize,
        /// Samples in the window, 2·half_window + 1.
        window: usize,
        /// Polynomial degree.
        order: usize,
        /// Smallest half-window for this degree.
        min_half_window: usize,
    },
    /// The window is longer than the record.
    #[error(
        "half-window {half_window} needs {window} samples but the record has {samples}; expected a half-window of at most {max_half_window}"
    )]
    WindowTooLarge {
        /// Half-window asked.
        half_window: usize,
        /// Samples in the window, 2·half_window + 1.
        window: usize,
        /// Samples in the record.
        samples: usize,
        /// Largest half-window that fits.
        max_half_window: usize,
    },
    /// A NaN or infinite time or position.
    #[error("{column}, row {row}: {value}; expected a finite number")]
    NonFinite {
        /// `time` or `position`.
        column: &'static str,
        /// 1-based row.
        row: usize,
        /// The value.
        value: f64,
    },
    /// Time does not increase strictly.
    #[error(
        "time, row {row}: {time} s does not come after the previous row's {previous} s; time must increase strictly"
    )]
    NonIncreasingTime {
        /// 1-based row of the later sample.
        row: usize,
        /// Its time [s].
        time: f64,
        /// The previous row's time [s].
        previous: f64,
    },
    /// The time stamps of one window are so unevenly bunched that the local fit is singular.
    #[error(
        "rows {first} to {last}: the time stamps are too bunched for a degree-{order} fit; use a wider window or a lower degree"
    )]
    Degenerate {
        /// First row of the window (1-based).
        first: usize,
        /// Last row of the window (1-based).
        last: usize,
        /// Polynomial degree.
        order: usize,
    },
}

/// Smallest half-window whose `2h + 1` samples determine a degree-`order` polynomial.
pub fn min_half_window(order: usize) -> usize {
    order.div_ceil(2).max(1)
}

/// Check the inputs of [`savitzky_golay_derivative`].
fn check(t: &[f64], x: &[f64], half_window: usize, order: usize) -> Result<(), DerivativeError> {
    if !(1..=MAX_ORDER).contains(&order) {
        return Err(DerivativeError::OrderOutOfRange { order });
    }
    if t.len() != x.len() {
        return Err(DerivativeError::LengthMismatch { t_len: t.len(), x_len: x.len() });
    }
    let n = t.len();
    let needed = 2 * min_half_window(order) + 1;
    if n < needed {
        return Err(DerivativeError::TooFewSamples { samples: n, order, needed });
    }
    let window = 2 * half_window + 1;
    if half_window < min_half_window(order) {
        return Err(DerivativeError::WindowTooSmall {
            half_window,
            window,
            order,
            min_half_window: min_half_window(order),
        });
    }
    if window > n {
        return Err(DerivativeError::WindowTooLarge {
            half_window,
            window,
            samples: n,
            max_half_window: (n - 1) / 2,
        });
    }
    for (column, v) in [("time", t), ("position", x)] {
        if let Some(k) = v.iter().position(|v| !v.is_finite()) {
            return Err(DerivativeError::NonFinite { column, row: k + 1, value: v[k] });
        }
    }
    if let Some(k) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(DerivativeError::NonIncreasingTime {
            row: k + 2,
            time: t[k + 1],
            previous: t[k],
        });
    }
    Ok(())
}

/// Slope at `t[i]` of the degree-`order` least-squares polynomial through the samples
/// `lo..=hi`. The abscissa is centred on `t[i]` and scaled by the window's largest
/// distance from it (so it lies in [−1, 1]) and the ordinate is taken relative to `x[i]`;
/// the normal equations are then conditioned well enough for degrees up to 4 (condition
/// number below about 1e6 even for a one-sided end window of degree 4, so about ten digits
/// survive) and are solved by Cholesky in a fixed 5×5 matrix (unused degrees padded with an
/// identity block), without allocating.
/// Returns `None` when the matrix is singular.
/// Solve the m × m normal equations G·c = b with G[r][c] = sums[r + c] (a Hankel matrix
/// of power sums) by Cholesky's method on the stack; `None` where a pivot is not positive
/// (the window's times cannot carry a polynomial of that degree).
#[inline]
fn solve_normal(
    sums: &[f64; 2 * MAX_ORDER + 1],
    b: &[f64; MAX_ORDER + 1],
    m: usize,
) -> Option<[f64; MAX_ORDER + 1]> {
    let mut l = [[0.0f64; MAX_ORDER + 1]; MAX_ORDER + 1];
    for r in 0..m {
        for c in 0..=r {
            let mut v = sums[r + c];
            for (a, b) in l[r][..c].iter().zip(&l[c][..c]) {
                v -= a * b;
            }
            if r == c {
                if v.is_nan() || v <= 0.0 {
                    return None;
                }
                l[r][r] = v.sqrt();
            } else {
                l[r][c] = v / l[c][c];
            }
        }
    }
    let mut z = [0.0f64; MAX_ORDER + 1];
    for r in 0..m {
        let mut v = b[r];
        for (a, zk) in l[r][..r].iter().zip(&z[..r]) {
            v -= a * zk;
        }
        z[r] = v / l[r][r];
    }
    for r in (0..m).rev() {
        let mut v = z[r];
        for (row, zk) in l[r + 1..m].iter().zip(&z[r + 1..m]) {
            v -= row[r] * zk;
        }
        z[r] = v / l[r][r];
    }
    Some(z)
}

fn local_slope(t: &[f64], x: &[f64], lo: usize, hi: usize, i: usize, order: usize) -> Option<f64> {
    let (tc, xc) = (t[i], x[i]);
    let scale = (t[hi] - tc).max(tc - t[lo]);
    let inv = 1.0 / scale;
    // Power sums Σ u^k (k ≤ 2·order) and moments Σ u^k·(x − xc) (k ≤ order).
    let mut sums = [0.0; 2 * MAX_ORDER + 1];
    let mut moments = [0.0; MAX_ORDER + 1];
    for j in lo..=hi {
        let u = (t[j] - tc) * inv;
        let y = x[j] - xc;
        let mut p = 1.0;
        for k in 0..=2 * order {
            sums[k] += p;
            if k <= order {
                moments[k] += p * y;
            }
            p *= u;
        }
    }
    let coef = solve_normal(&sums, &moments, order + 1)?;
    let slope = coef[1] * inv;
    slope.is_finite().then_some(slope)
}

/// Derivative dx/dt [pos/s] of a sampled signal `x` [pos] at times `t` [s] by a local
/// least-squares polynomial of degree `order` (1..=4; [`DEFAULT_ORDER`] is the usual choice)
/// over the `2·half_window + 1` samples centred on each sample (Savitzky–Golay). Time stamps
/// need not be evenly spaced; each window is fitted in its actual times. The first and last
/// `half_window` samples take the slope of the first or last full window at their own time.
/// Exact for polynomials of degree ≤ `order`. Cost O(n·window).
pub fn savitzky_golay_derivative(
    t: &[f64],
    x: &[f64],
    half_window: usize,
    order: usize,
) -> Result<Vec<f64>, DerivativeError> {
    check(t, x, half_window, order)?;
    let n = t.len();
    let h = half_window;
    (0..n)
        .map(|i| {
            let lo = i.saturating_sub(h).min(n - 1 - 2 * h);
            let hi = lo + 2 * h;
            local_slope(t, x, lo, hi, i, order).ok_or(DerivativeError::Degenerate {
                first: lo + 1,
                last: hi + 1,
                order,
            })
        })
        .collect()
}

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

#[cfg(test)]
mod tests;
