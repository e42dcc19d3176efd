//! The input families a rig can play, as shapes of unit peak on the record's sample grid:
//! multisines (a band of log-spaced lines, per-line amplitudes tilted by a power of the
//! frequency, Schroeder phases), linear chirps, slow ramps with dwell at zero (speed
//! reversals for the friction and stiction), and their concatenation. Each family has a
//! few parameters ([`Family::params`]) that the search ([`super::search`]) moves within
//! bounds.

use std::f64::consts::{PI, TAU};

/// One segment of a designed input.
#[derive(Clone, Debug, PartialEq)]
pub enum Segment {
    /// Linear chirp from `f0` to `f1` [Hz] over the segment.
    Chirp { f0: f64, f1: f64 },
    /// `lines` log-spaced sines from `f0` to `f1` [Hz], amplitude ∝ (f/f0)^`tilt`,
    /// Schroeder phases.
    Multisine { f0: f64, f1: f64, lines: usize, tilt: f64 },
    /// Triangle wave of frequency `f` [Hz] with a dead band: the share `dwell` ∈ [0, 1) of
    /// each half period held at zero.
    Ramp { f: f64, dwell: f64 },
    /// Sines at given frequencies [Hz] and relative amplitudes [–] (`tones`: pairs), with
    /// Schroeder's phases for an uneven spectrum ([`schroeder_phases`]): a multisine whose
    /// every line is chosen ([`super::spectrum`]).
    Lines { tones: Vec<(f64, f64)> },
}

/// Schroeder's phases for the sines `tones` ((frequency [Hz], amplitude [–]) in rising
/// frequency) over a period `period` [s]: φ_k = −2π Σ_{l<k} (f_k − f_l)·period·p_l, with p_l
/// line l's share of the power. Line k is then delayed by the power below it, so the
/// instantaneous frequency sweeps the lines once per period like a chirp and the peak stays
/// low, for an uneven spectrum and uneven spacing alike [rad].
pub fn schroeder_phases(tones: &[(f64, f64)], period: f64) -> Vec<f64> {
    let total: f64 = tones.iter().map(|p| p.1 * p.1).sum::<f64>().max(f64::MIN_POSITIVE);
    (0..tones.len())
        .map(|k| {
            -TAU * (0..k)
                .map(|l| (tones[k].0 - tones[l].0) * period * tones[l].1 * tones[l].1 / total)
                .sum::<f64>()
        })
        .collect()
}

impl Segment {
    /// The segment's shape at times `t` [s] from its start (peak 1 over those samples),
    /// `len` its duration [s].
    pub fn shape(&self, t: &[f64], len: f64) -> Vec<f64> {
        let mut u = self.raw(t, len);
        let peak = u.iter().fold(0.0f64, |p, v| p.max(v.abs()));
        if peak > 0.0 {
            u.iter_mut().for_each(|v| *v /= peak);
        }
        u
    }

    /// The segment before it is scaled to peak 1: sines of their own amplitudes, a chirp
    /// and ramps of unit amplitude.
    pub fn raw(&self, t: &[f64], len: f64) -> Vec<f64> {
        match self {
            &Segment::Chirp { f0, f1 } => {
                let k = (f1 - f0) / len.max(f64::MIN_POSITIVE);
                t.iter().map(|&t| (TAU * (f0 * t + 0.5 * k * t * t)).sin()).collect()
            }
            &Segment::Multisine { f0, f1, lines, tilt } => {
                let m = lines.max(1);
                let tones: Vec<(f64, f64, f64)> = (0..m)
                    .map(|k| {
                        let f = if m == 1 {
                            f0
                        } else {
                            f0 * (f1 / f0).powf(k as f64 / (m - 1) as f64)
                        };
                        let phase = -PI * (k * (k + 1)) as f64 / m as f64;
                        (f, (f / f0).powf(tilt), phase)
                    })
                    .collect();
                t.iter()
                    .map(|&t| tones.iter().map(|(f, a, ph)| a * (TAU * f * t + ph).sin()).sum())
                    .collect()
            }
            Segment::Lines { tones } => {
                let phases = schroeder_phases(tones, len);
                t.iter()
                    .map(|&t| {
                        tones
                            .iter()
                            .zip(&phases)
                            .map(|((f, a), ph)| a * (TAU * f * t + ph).sin())
                            .sum()
                    })
                    .collect()
            }
            &Segment::Ramp { f, dwell } => t
                .iter()
                .map(|&t| {
                    // Triangle 0 → 1 → 0 → −1 → 0 over a period, then the dead band.
                    let ph = (t * f).fract();
                    let tri = if ph < 0.25 {
                        4.0 * ph
                    } else if ph < 0.75 {
                        2.0 - 4.0 * ph
                    } else {
                        4.0 * ph - 4.0
                    };
                    let d = dwell.clamp(0.0, 0.95);
                    tri.signum() * ((tri.abs() - d).max(0.0) / (1.0 - d))
                })
                .collect(),
        }
    }

    /// A short description.
    pub fn describe(&self) -> String {
        match self {
            Segment::Chirp { f0, f1 } => format!("chirp {f0:.3}–{f1:.3} Hz"),
            Segment::Multisine { f0, f1, lines, tilt } => {
                format!("multisine of {lines} lines {f0:.3}–{f1:.3} Hz, amplitude ∝ f^{tilt:.2}")
            }
            Segment::Lines { tones } if tones.len() == 1 => format!("sine {:.3} Hz", tones[0].0),
            Segment::Lines { tones } => {
                let top = tones.iter().fold(0.0f64, |m, p| m.max(p.1)).max(f64::MIN_POSITIVE);
                let list: Vec<String> = tones
                    .iter()
                    .map(|(f, a)| format!("{f:.3} Hz at {:.0} %", 100.0 * a / top))
                    .collect();
                format!("multisine of {} chosen lines: {}", tones.len(), list.join(", "))
            }
            Segment::Ramp { f, dwell } => {
                format!("ramps at {f:.3} Hz, {:.0} % dwell at zero", 100.0 * dwell)
            }
        }
    }
}

/// A segment with its share of the record's duration and its amplitude relative to the
/// input's peak.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// The segment.
    pub segment: Segment,
    /// Its share of the duration [–].
    pub share: f64,
    /// Its peak relative to the input's [–], in (0, 1].
    pub weight: f64,
}

/// An input: segments played one after the other.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// The pieces, in playing order.
    pub pieces: Vec<Piece>,
}

impl Design {
    /// One segment over the whole record at full amplitude.
    pub fn single(segment: Segment) -> Design {
        Design { pieces: vec![Piece { segment, share: 1.0, weight: 1.0 }] }
    }

    /// The shape on `n` samples at `rate` [Hz], peak 1: each piece normalised to its
    /// weight over its share of the samples (the last takes the remainder).
    pub fn shape(&self, n: usize, rate: f64) -> Vec<f64> {
        let total: f64 = self.pieces.iter().map(|p| p.share.max(0.0)).sum::<f64>().max(1e-12);
        let wmax = self.pieces.iter().fold(0.0f64, |m, p| m.max(p.weight)).max(1e-12);
        let mut u = Vec::with_capacity(n);
        for (k, p) in self.pieces.iter().enumerate() {
            let len = if k + 1 == self.pieces.len() {
                n - u.len()
            } else {
                (((p.share.max(0.0) / total) * n as f64).round() as usize).min(n - u.len())
            };
            let t: Vec<f64> = (0..len).map(|j| j as f64 / rate).collect();
            let s = p.segment.shape(&t, len as f64 / rate);
            u.extend(s.into_iter().map(|v| v * p.weight / wmax));
        }
        u
    }

    /// A short description.
    pub fn describe(&self) -> String {
        if self.pieces.is_empty() {
            return "the given input".into();
        }
        if self.pieces.len() == 1 {
            return self.pieces[0].segment.describe();
        }
        self.pieces
            .iter()
            .map(|p| {
                format!(
                    "{:.0} % of the time: {} at {:.0} % of the peak",
                    100.0 * p.share,
                    p.segment.describe(),
                    100.0 * p.weight
                )
            })
            .collect::<Vec<_>>()
            .join("; then ")
    }
}

/// A family of inputs with a few parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// Linear chirp: log f0, log f1.
    Chirp,
    /// Multisine: log f0, log f1, tilt.
    Multisine,
    /// Ramps with dwell: log f, dwell.
    Ramp,
    /// A multisine then ramps: the multisine's three, the ramps' two, the ramps' share of
    /// the time and their relative amplitude.
    Mix,
    /// A multisine whose lines and their amplitudes are chosen from the information of
    /// each line alone ([`super::spectrum`]); its parameters are the chosen (frequency
    /// [Hz], relative amplitude [–]) pairs, flattened.
    Spectrum,
}

/// Lines of a designed multisine [–].
pub const LINES: usize = 16;

impl Family {
    /// Every family.
    pub const ALL: [Family; 5] =
        [Family::Chirp, Family::Multisine, Family::Ramp, Family::Mix, Family::Spectrum];

    /// The families searched unless asked otherwise: every one but [`Family::Spectrum`].
    /// Its best on the docs' worked example (A-optimal on the load and the gear) is a
    /// single sine just above the load's resonance, predicted better than the searched
    /// families' 224–366 Hz chirp (relative SE of Jz 0.21 against 0.30 at the truth) but
    /// worse in 20 refits each (spread 0.38 against 0.25, 1.8 times its prediction against
    /// 0.8, Jz biased 25 % low): one line leaves the friction free to wander with the load.
    pub const DEFAULT: [Family; 4] = [Family::Chirp, Family::Multisine, Family::Ramp, Family::Mix];

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Family::Chirp => "chirp",
            Family::Multisine => "multisine",
            Family::Ramp => "ramp",
            Family::Mix => "mix",
            Family::Spectrum => "spectrum",
        }
    }

    /// Parse a name.
    pub fn parse(s: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.name() == s)
    }

    /// Parameter names, bounds (lower, upper) and start, for a record at `rate` [Hz] of
    /// `duration` [s]: frequencies by their logarithms, from 1/duration to 0.45·rate. None
    /// for [`Family::Spectrum`], which is not searched by Nelder–Mead.
    pub fn params(self, rate: f64, duration: f64) -> Vec<(&'static str, f64, f64, f64)> {
        let lo = (1.0 / duration).ln();
        let hi = (0.45 * rate).ln();
        let band = |s0: f64, s1: f64| {
            [("ln_f0", lo, hi, s0.clamp(lo, hi)), ("ln_f1", lo, hi, s1.clamp(lo, hi))]
        };
        let ramp_hi = (20.0f64).max(2.0 / duration).ln();
        let ramp = [("ln_ramp_f", lo, ramp_hi, (2.0 / duration).ln()), ("dwell", 0.0, 0.8, 0.2)];
        let top = (0.4 * rate).ln();
        match self {
            Family::Chirp => band(2f64.ln(), top).to_vec(),
            Family::Multisine => {
                let mut v = band(2f64.ln(), top).to_vec();
                v.push(("tilt", -2.0, 3.0, 0.0));
                v
            }
            Family::Ramp => ramp.to_vec(),
            Family::Mix => {
                let mut v = band(2f64.ln(), top).to_vec();
                v.push(("tilt", -2.0, 3.0, 0.0));
                v.extend(ramp);
                v.push(("ramp_share", 0.05, 0.7, 0.25));
                v.push(("ramp_weight", 0.05, 1.0, 0.3));
                v
            }
            Family::Spectrum => Vec::new(),
        }
    }

    /// The input at parameters `x` (the order of [`Family::params`]; for
    /// [`Family::Spectrum`], (frequency, amplitude) pairs); a band given upside down is
    /// played upwards.
    pub fn design(self, x: &[f64]) -> Design {
        let band = |a: f64, b: f64| {
            let (a, b) = (a.exp(), b.exp());
            (a.min(b), a.max(b).max(a.min(b) * 1.01))
        };
        match self {
            Family::Chirp => {
                let (f0, f1) = band(x[0], x[1]);
                Design::single(Segment::Chirp { f0, f1 })
            }
            Family::Multisine => {
                let (f0, f1) = band(x[0], x[1]);
                Design::single(Segment::Multisine { f0, f1, lines: LINES, tilt: x[2] })
            }
            Family::Ramp => Design::single(Segment::Ramp { f: x[0].exp(), dwell: x[1] }),
            Family::Mix => {
                let (f0, f1) = band(x[0], x[1]);
                Design {
                    pieces: vec![
                        Piece {
                            segment: Segment::Multisine { f0, f1, lines: LINES, tilt: x[2] },
                            share: 1.0 - x[5],
                            weight: 1.0,
                        },
                        Piece {
                            segment: Segment::Ramp { f: x[3].exp(), dwell: x[4] },
                            share: x[5],
                            weight: x[6],
                        },
                    ],
                }
            }
            Family::Spectrum => Design::single(Segment::Lines {
                tones: x.chunks_exact(2).map(|p| (p[0], p[1])).collect(),
            }),
        }
    }
}

/// Share of a closed loop's record over which its reference fades in, and again out [–].
pub const FADE: f64 = 0.05;

/// Fade `u` in and out over `share` of its samples at each end (a raised cosine, 0 at the
/// first and last sample), so it starts and ends at zero: a position loop's reference then
/// starts without a step and brings the drive back to where it started.
pub fn fade(u: &mut [f64], share: f64) {
    let n = u.len();
    let m = ((share * n as f64).round() as usize).min(n / 2);
    for k in 0..m {
        let w = 0.5 * (1.0 - (std::f64::consts::PI * k as f64 / m as f64).cos());
        u[k] *= w;
        u[n - 1 - k] *= w;
    }
}
