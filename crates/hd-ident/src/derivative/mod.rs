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

mod window;
pub use window::{WindowChoice, choose_half_window, quantisation_step, unit_slope_noise};

#[cfg(test)]
mod tests;
