//! The empirical frequency response from an input to an output (Welch's H1 estimate),
//! used to compare a record's measured response with the fitted model's over the record's
//! band.
//!
//! The record is cut into segments of `m` samples (the largest power of two ≤ N/4, at
//! least 16, at most [`MAX_SEGMENT`]), overlapping by half; each segment has its mean
//! removed and a Hann window applied, and its discrete Fourier transforms U and Y are
//! averaged into
//!
//! ```text
//! Puu(f) = Σ |U|²,   Pyy(f) = Σ |Y|²,   Pyu(f) = Σ conj(U)·Y,
//! H1(f) = Pyu/Puu,   γ²(f) = |Pyu|²/(Puu·Pyy)   (coherence, 0 … 1)
//! ```
//!
//! at f = k·fs/m, k = 1 … m/2. H1 is unbiased by noise on the output; where the input has
//! no power it means nothing, so [`Frf::band`] keeps the frequencies where the input's
//! power lies within 60 dB of its peak. In a closed loop with the reference as input, H1
//! is the loop's response from the reference, measured and simulated alike.

use nalgebra::Complex;
use serde::Serialize;

/// Input power kept in the band, relative to its peak: 60 dB.
pub const BAND_DB: f64 = 60.0;

/// An estimated frequency response.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Frf {
    /// Frequencies [Hz].
    pub freq: Vec<f64>,
    /// Real part of H1 at each frequency [output unit / input unit].
    pub re: Vec<f64>,
    /// Imaginary part of H1 [output unit / input unit].
    pub im: Vec<f64>,
    /// Coherence γ² [–].
    pub coherence: Vec<f64>,
    /// Input power at each frequency, summed over segments (relative use only).
    pub input_power: Vec<f64>,
    /// Segment length [samples].
    pub segment: usize,
}

/// In-place radix-2 FFT (length a power of two), forward sign e^{−i2πkn/m}.
fn fft(x: &mut [Complex<f64>]) {
    let n = x.len();
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            x.swap(i, j);
        }
    }
    let mut len = 2;
    while len <= n {
        let ang = -std::f64::consts::TAU / len as f64;
        let w = Complex::new(ang.cos(), ang.sin());
        for start in (0..n).step_by(len) {
            let mut wk = Complex::new(1.0, 0.0);
            for k in 0..len / 2 {
                let a = x[start + k];
                let b = x[start + k + len / 2] * wk;
                x[start + k] = a + b;
                x[start + k + len / 2] = a - b;
                wk *= w;
            }
        }
        len <<= 1;
    }
}

/// Longest segment [`default_segment`] gives [samples]: 2^18, so that the working storage
/// of [`Welch`] (about 120 bytes per segment sample with two outputs) stays under 32 MB
/// whatever the record's length. Records shorter than 2^21 samples are not affected (their
/// quarter is shorter).
pub const MAX_SEGMENT: usize = 1 << 18;

/// The default segment length for `n` samples: the largest power of two ≤ n/4, at least
/// 16 (and at most n), at most [`MAX_SEGMENT`].
pub fn default_segment(n: usize) -> usize {
    let mut m = 16;
    while m * 2 <= n / 4 && m < MAX_SEGMENT {
        m *= 2;
    }
    let mut cap = 1;
    while cap * 2 <= n {
        cap *= 2;
    }
    m.min(cap)
}

/// Welch H1 estimate of the response from `u` to `y` sampled every `h` [s], with segments
/// of `segment` samples (a power of two; [`default_segment`] when None). Empty if the
/// record is shorter than a segment.
pub fn h1(u: &[f64], y: &[f64], h: f64, segment: Option<usize>) -> Frf {
    let n = u.len().min(y.len());
    let m = segment.unwrap_or_else(|| default_segment(n));
    let half = m / 2;
    let (mut puu, mut pyy) = (vec![0.0; half + 1], vec![0.0; half + 1]);
    let mut pyu = vec![Complex::new(0.0, 0.0); half + 1];
    let window: Vec<f64> =
        (0..m).map(|k| 0.5 - 0.5 * (std::f64::consts::TAU * k as f64 / m as f64).cos()).collect();
    let mut start = 0;
    while m >= 2 && start + m <= n {
        let seg = |x: &[f64]| {
            let s = &x[start..start + m];
            let mean = s.iter().sum::<f64>() / m as f64;
            let mut c: Vec<Complex<f64>> =
                s.iter().zip(&window).map(|(v, w)| Complex::new((v - mean) * w, 0.0)).collect();
            fft(&mut c);
            c
        };
        let (cu, cy) = (seg(u), seg(y));
        for k in 0..=half {
            puu[k] += cu[k].norm_sqr();
            pyy[k] += cy[k].norm_sqr();
            pyu[k] += cu[k].conj() * cy[k];
        }
        start += half.max(1);
    }
    response(&puu, &pyy, &pyu, m, h)
}

/// H1, coherence and input power from the sums over the segments (segment `m`, sample
/// period `h` [s]).
fn response(puu: &[f64], pyy: &[f64], pyu: &[Complex<f64>], m: usize, h: f64) -> Frf {
    let half = m / 2;
    let fs = 1.0 / h;
    let ks = 1..=half;
    let hk: Vec<Complex<f64>> = ks.clone().map(|k| pyu[k] / puu[k]).collect();
    Frf {
        freq: ks.clone().map(|k| k as f64 * fs / m as f64).collect(),
        re: hk.iter().map(|c| c.re).collect(),
        im: hk.iter().map(|c| c.im).collect(),
        coherence: ks.clone().map(|k| pyu[k].norm_sqr() / (puu[k] * pyy[k])).collect(),
        input_power: ks.map(|k| puu[k]).collect(),
        segment: m,
    }
}

/// [`h1`] from one input to several outputs, fed one sample at a time: the same numbers
/// (bit for bit) without the record in memory. Working storage: the last segment of the
/// input and of each output, the window, the sums over segments, one transform per
/// signal; about (52 + 20·outputs)·m bytes, whatever the record's length.
#[derive(Clone, Debug)]
pub struct Welch {
    m: usize,
    h: f64,
    window: Vec<f64>,
    u: Vec<f64>,
    y: Vec<Vec<f64>>,
    puu: Vec<f64>,
    pyy: Vec<Vec<f64>>,
    pyu: Vec<Vec<Complex<f64>>>,
}

impl Welch {
    /// The estimate over a record of `n` samples sampled every `h` [s] with `outputs`
    /// outputs, segments of `segment` samples ([`default_segment`] of `n` when None).
    pub fn new(n: usize, outputs: usize, h: f64, segment: Option<usize>) -> Self {
        let m = segment.unwrap_or_else(|| default_segment(n));
        let half = m / 2;
        Welch {
            m,
            h,
            window: (0..m)
                .map(|k| 0.5 - 0.5 * (std::f64::consts::TAU * k as f64 / m as f64).cos())
                .collect(),
            u: Vec::with_capacity(m),
            y: vec![Vec::with_capacity(m); outputs],
            puu: vec![0.0; half + 1],
            pyy: vec![vec![0.0; half + 1]; outputs],
            pyu: vec![vec![Complex::new(0.0, 0.0); half + 1]; outputs],
        }
    }

    /// The next sample: input `u`, outputs `y` (one per output).
    pub fn push(&mut self, u: f64, y: &[f64]) {
        self.u.push(u);
        for (b, v) in self.y.iter_mut().zip(y) {
            b.push(*v);
        }
        if self.m >= 2 && self.u.len() == self.m {
            self.segment();
        }
    }

    /// Add the segment held to the sums, then drop its first half (the next segment
    /// starts half a segment later).
    fn segment(&mut self) {
        let (m, half) = (self.m, self.m / 2);
        let window = &self.window;
        let transform = |s: &[f64]| {
            let mean = s.iter().sum::<f64>() / m as f64;
            let mut c: Vec<Complex<f64>> =
                s.iter().zip(window).map(|(v, w)| Complex::new((v - mean) * w, 0.0)).collect();
            fft(&mut c);
            c
        };
        let cu = transform(&self.u);
        for (p, c) in self.puu.iter_mut().zip(&cu[..=half]) {
            *p += c.norm_sqr();
        }
        for ((y, pyy), pyu) in self.y.iter().zip(&mut self.pyy).zip(&mut self.pyu) {
            let cy = transform(y);
            for k in 0..=half {
                pyy[k] += cy[k].norm_sqr();
                pyu[k] += cu[k].conj() * cy[k];
            }
        }
        let step = half.max(1);
        self.u.drain(..step);
        for y in &mut self.y {
            y.drain(..step);
        }
    }

    /// The response to each output, as [`h1`] gives it.
    pub fn finish(self) -> Vec<Frf> {
        self.pyy
            .iter()
            .zip(&self.pyu)
            .map(|(pyy, pyu)| response(&self.puu, pyy, pyu, self.m, self.h))
            .collect()
    }
}

impl Frf {
    /// Indices of the frequencies where the input's power lies within [`BAND_DB`] of its
    /// peak.
    pub fn band(&self) -> Vec<usize> {
        let peak = self.input_power.iter().copied().fold(0.0, f64::max);
        let floor = peak * 10f64.powf(-BAND_DB / 10.0);
        (0..self.freq.len()).filter(|&k| peak > 0.0 && self.input_power[k] >= floor).collect()
    }

    /// Magnitude [dB] at each frequency: 20·log10|H1|.
    pub fn mag_db(&self) -> Vec<f64> {
        self.re.iter().zip(&self.im).map(|(r, i)| 20.0 * r.hypot(*i).log10()).collect()
    }

    /// Phase [°] at each frequency, in (−180, 180].
    pub fn phase_deg(&self) -> Vec<f64> {
        self.re.iter().zip(&self.im).map(|(r, i)| i.atan2(*r).to_degrees()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::{Noise, add_noise};

    #[test]
    fn fft_of_a_cosine_is_two_lines() {
        let m = 64;
        let mut x: Vec<Complex<f64>> = (0..m)
            .map(|k| Complex::new((std::f64::consts::TAU * 5.0 * k as f64 / m as f64).cos(), 0.0))
            .collect();
        fft(&mut x);
        for (k, c) in x.iter().enumerate() {
            let want = if k == 5 || k == m - 5 { m as f64 / 2.0 } else { 0.0 };
            assert!((c.re - want).abs() < 1e-9 && c.im.abs() < 1e-9, "{k}: {c}");
        }
    }

    #[test]
    fn a_fir_filter_gives_its_exact_response() {
        // y(t) = Σ b_k·u(t−k) on white u: H(f) = Σ b_k·e^{−i2πfk·h}. The Hann segments
        // leak a little at the segment edges (the filter reaches 3 samples back): measured
        // largest error 4.7e-4 over every bin, 4.9e-5 RMS; 0.006 dB and 0.011° at the first.
        let b = [0.5, 0.3, -0.2, 0.1];
        let n = 1 << 16;
        let mut u = vec![1.0; n];
        add_noise(&mut u, &Noise { relative: 1.0, seed: 11 });
        let y: Vec<f64> = (0..n)
            .map(|t| b.iter().enumerate().filter(|(k, _)| *k <= t).map(|(k, c)| c * u[t - k]).sum())
            .collect();
        let h = 1e-3;
        let f = h1(&u, &y, h, None);
        assert_eq!(f.segment, 1 << 14);
        assert_eq!(f.band().len(), f.freq.len());
        let (mut worst, mut ss) = (0.0f64, 0.0);
        for (k, fr) in f.freq.iter().enumerate() {
            let exact: Complex<f64> = b
                .iter()
                .enumerate()
                .map(|(j, c)| Complex::from_polar(*c, -std::f64::consts::TAU * fr * j as f64 * h))
                .sum();
            let err = (Complex::new(f.re[k], f.im[k]) - exact).norm();
            worst = worst.max(err);
            ss += err * err;
            assert!(f.coherence[k] > 0.99, "{fr} Hz: γ² {}", f.coherence[k]);
        }
        let rms = (ss / f.freq.len() as f64).sqrt();
        assert!(worst < 5e-3 && rms < 5e-4, "worst {worst}, rms {rms}");
        // Magnitude and phase at 0+: the DC gain 0.7, no phase.
        assert!((f.mag_db()[0] - 20.0 * 0.7f64.log10()).abs() < 0.06);
        assert!(f.phase_deg()[0].abs() < 0.1);
    }

    #[test]
    fn segments_default_to_a_quarter_of_the_record() {
        assert_eq!(default_segment(24_841), 4096);
        assert_eq!(default_segment(100), 16);
        assert_eq!(default_segment(10), 8);
        assert_eq!(default_segment(1_000_000), 1 << 17);
        assert_eq!(default_segment((1 << 21) - 1), 1 << 18);
        assert_eq!(default_segment(5_000_000), MAX_SEGMENT);
    }

    /// Fed sample by sample, two outputs at once, the estimate is `h1`'s bit for bit
    /// (lengths with and without a partial last segment, the shortest records too).
    #[test]
    fn streamed_estimate_is_the_whole_record_one() {
        for n in [5, 10, 17, 100, 1000, 4099] {
            let mut u = vec![1.0; n];
            add_noise(&mut u, &Noise { relative: 1.0, seed: 3 });
            let y1: Vec<f64> =
                (0..n).map(|t| 0.5 * u[t] + if t > 0 { 0.2 * u[t - 1] } else { 0.0 }).collect();
            let y2: Vec<f64> = u.iter().map(|v| v * v).collect();
            let mut w = Welch::new(n, 2, 1e-3, None);
            for t in 0..n {
                w.push(u[t], &[y1[t], y2[t]]);
            }
            let got = w.finish();
            let a = h1(&u, &y1, 1e-3, None);
            let b = h1(&u, &y2, 1e-3, None);
            let same =
                |x: &Frf, y: &Frf| format!("{x:?}") == format!("{y:?}") && x.segment == y.segment;
            assert!(same(&got[0], &a) && same(&got[1], &b), "n = {n}");
        }
    }
}
