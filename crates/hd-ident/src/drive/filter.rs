//! Zero-phase low-pass filtering and central differences, for the inverse-model start.
//!
//! The low-pass is a digital Butterworth filter (the analog prototype's poles mapped by the
//! bilinear transform with a pre-warped corner, as cascaded second-order sections of unit
//! DC gain), run forwards and then backwards so it adds no lag. The ends are padded with the
//! signal's odd reflection, as long as the slowest pole needs to settle, and each section
//! starts in its steady state for the first value, so a ramp or an offset at the ends passes
//! without a start-up transient.

use std::f64::consts::PI;

/// One section `H(z) = (b0 + b1 z⁻¹ + b2 z⁻²)/(1 + a1 z⁻¹ + a2 z⁻²)` (b2 = a2 = 0 for a
/// first-order one), in transposed direct form II.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    b: [f64; 3],
    a: [f64; 2],
}

impl Section {
    /// Filter `x` in place, starting from the steady state of a constant `x[0]`.
    fn run(&self, x: &mut [f64]) {
        let Some(&x0) = x.first() else { return };
        let [b0, b1, b2] = self.b;
        let [a1, a2] = self.a;
        let mut z2 = (b2 - a2) * x0;
        let mut z1 = (b1 - a1) * x0 + z2;
        for v in x.iter_mut() {
            let u = *v;
            let y = b0 * u + z1;
            z1 = b1 * u - a1 * y + z2;
            z2 = b2 * u - a2 * y;
            *v = y;
        }
    }
}

/// A Butterworth low-pass of `order` ≥ 1 with corner `fc` [Hz] at sampling rate `fs` [Hz]
/// (fc < fs/2), as sections of unit DC gain.
pub fn butterworth(order: usize, fc: f64, fs: f64) -> Vec<Section> {
    // c = cot(π·fc/fs): the bilinear map of the pre-warped corner.
    let c = 1.0 / (PI * fc / fs).tan();
    let mut out = Vec::new();
    for k in 0..order / 2 {
        // Conjugate pole pair of the normalised prototype: s² + q·s + 1.
        let theta = PI * (2 * k + 1) as f64 / (2 * order) as f64;
        let q = 2.0 * theta.sin();
        let a0 = c * c + q * c + 1.0;
        let a1 = 2.0 * (1.0 - c * c) / a0;
        let a2 = (c * c - q * c + 1.0) / a0;
        let g = (1.0 + a1 + a2) / 4.0;
        out.push(Section { b: [g, 2.0 * g, g], a: [a1, a2] });
    }
    if order % 2 == 1 {
        // Real pole: s + 1.
        let a1 = (1.0 - c) / (1.0 + c);
        let g = (1.0 + a1) / 2.0;
        out.push(Section { b: [g, g, 0.0], a: [a1, 0.0] });
    }
    out
}

/// Samples for the slowest pole's response to decay to 1e-12: the length of the padding,
/// so a start-up transient dies out before the signal begins.
fn settling_samples(sections: &[Section]) -> usize {
    let radius = sections
        .iter()
        .map(|s| {
            let [a1, a2] = s.a;
            if a2 == 0.0 {
                a1.abs()
            } else if a1 * a1 < 4.0 * a2 {
                a2.sqrt() // complex pair: |p|² = a2
            } else {
                let d = (a1 * a1 - 4.0 * a2).sqrt();
                ((-a1 + d) / 2.0).abs().max(((-a1 - d) / 2.0).abs())
            }
        })
        .fold(0.0, f64::max);
    if radius <= 0.0 {
        return 3;
    }
    ((1e-12_f64).ln() / radius.ln()).ceil().max(3.0) as usize
}

/// Forward–backward (zero-phase) filtering of `x` through `sections`; the magnitude
/// response is squared and the phase is zero.
pub fn filtfilt(sections: &[Section], x: &[f64]) -> Vec<f64> {
    let n = x.len();
    if n < 2 {
        return x.to_vec();
    }
    let pad = settling_samples(sections).min(n - 1);
    // Odd reflection about each end: 2·x0 − x[pad..1], then x, then 2·x_end − x[..].
    let mut y = Vec::with_capacity(n + 2 * pad);
    y.extend((1..=pad).rev().map(|k| 2.0 * x[0] - x[k]));
    y.extend_from_slice(x);
    y.extend((1..=pad).map(|k| 2.0 * x[n - 1] - x[n - 1 - k]));
    for s in sections {
        s.run(&mut y);
    }
    y.reverse();
    for s in sections {
        s.run(&mut y);
    }
    y.reverse();
    y[pad..pad + n].to_vec()
}

/// Central differences of `x` sampled every `h` [s] (one-sided at the ends) [unit of x / s].
pub fn central_difference(x: &[f64], h: f64) -> Vec<f64> {
    let n = x.len();
    if n < 2 {
        return vec![0.0; n];
    }
    (0..n)
        .map(|k| {
            if k == 0 {
                (x[1] - x[0]) / h
            } else if k == n - 1 {
                (x[n - 1] - x[n - 2]) / h
            } else {
                (x[k + 1] - x[k - 1]) / (2.0 * h)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steady-state gain of the zero-phase filter at frequency f: |H(e^{jωh})|².
    fn gain_at(sections: &[Section], f: f64, fs: f64) -> f64 {
        let n = 40_000;
        let x: Vec<f64> = (0..n).map(|k| (2.0 * PI * f * k as f64 / fs).sin()).collect();
        let y = filtfilt(sections, &x);
        let mid = n / 4..3 * n / 4;
        let rms = |v: &[f64]| (v.iter().map(|a| a * a).sum::<f64>() / v.len() as f64).sqrt();
        rms(&y[mid.clone()]) / rms(&x[mid])
    }

    /// Butterworth: |H(f)|² = 1/(1 + (tan(πf/fs)/tan(πfc/fs))^{2n}) after the bilinear map;
    /// forward–backward squares it. Checked for orders 1 to 4.
    #[test]
    fn magnitude_is_butterworths_squared() {
        let (fs, fc) = (1000.0, 40.0);
        for order in 1..=4 {
            let s = butterworth(order, fc, fs);
            for f in [5.0, 40.0, 120.0] {
                let ratio = (PI * f / fs).tan() / (PI * fc / fs).tan();
                let h2 = 1.0 / (1.0 + ratio.powi(2 * order as i32));
                let g = gain_at(&s, f, fs);
                assert!((g - h2).abs() < 2e-3 * h2.max(1e-3), "order {order}, {f} Hz: {g} vs {h2}");
            }
        }
    }

    /// A straight line passes unchanged (zero phase, unit DC gain, reflected ends), and
    /// central differences of a parabola are exact inside.
    #[test]
    fn lines_pass_and_parabolas_differentiate() {
        let x: Vec<f64> = (0..500).map(|k| 0.3 + 2e-3 * k as f64).collect();
        let y = filtfilt(&butterworth(4, 20.0, 1000.0), &x);
        let worst = x.iter().zip(&y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(worst < 1e-9, "{worst}");
        let h = 1e-3;
        let p: Vec<f64> = (0..100).map(|k| 3.0 * (k as f64 * h).powi(2)).collect();
        let d = central_difference(&p, h);
        for (k, v) in d.iter().enumerate().take(99).skip(1) {
            assert!((v - 6.0 * k as f64 * h).abs() < 1e-9);
        }
    }
}
