//! Residual analysis of a fit, as identification engineers read it (MATLAB's `resid`):
//! the residuals' autocorrelation and their cross-correlation with the input, against the
//! 99 % bounds of white noise, and a one-line verdict.
//!
//! With e the residual and u the input, both with their means removed, over N samples:
//!
//! ```text
//! ρ_e(k)  = Σ_t e(t)·e(t+k) / Σ_t e(t)²                       k = 0 … L
//! ρ_eu(τ) = Σ_t e(t+τ)·u(t) / √(Σ e² · Σ u²)                  τ = −L … L
//! ```
//!
//! (the biased estimates, sums over the samples where both indices exist). If e is white
//! and independent of u, each ρ (k ≠ 0 for the autocorrelation) is approximately normal
//! with variance 1/N, whatever the colour of u, so the 99 % bounds are ±2.576/√N. A
//! positive τ is the residual after the input: left-over dynamics from input to output;
//! a negative τ is the input after the residual, which is what feedback does in a loop.
//!
//! **Verdict.** Even white residuals leave about 1 lag in 100 outside the 99 % bounds, so
//! a single lag just outside is chance. The residuals are called white when (a) the number
//! of lags outside the bounds is no more than a binomial count with probability 0.01 per
//! lag exceeds with probability ≤ 1 % (2 of the 25 autocorrelation lags, 3 of the 51
//! cross-correlation lags), and (b) no lag exceeds 1.5 times the bound (3.9 standard
//! deviations, probability 1e-4 per lag). Otherwise the verdict is "model error left" and
//! names the lags outside the bounds. The two tests together call white residuals model
//! error about 2 % of the time.

use serde::Serialize;

/// The two-sided 99 % quantile of the standard normal distribution.
pub const Z99: f64 = 2.575_829_303_548_901;

/// Default number of lags [samples].
pub const DEFAULT_LAGS: usize = 25;

/// A lag beyond this many times the bound is model error on its own.
pub const STRONG: f64 = 1.5;

/// Correlations at a run of lags, with the 99 % white-noise bound.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Correlation {
    /// The lags [samples].
    pub lags: Vec<i64>,
    /// The normalised correlation at each lag [–].
    pub values: Vec<f64>,
    /// ±2.576/√N [–].
    pub bound: f64,
}

impl Correlation {
    /// Lags (other than the autocorrelation's lag 0) whose value lies outside the bound.
    pub fn outside(&self, skip_zero: bool) -> Vec<i64> {
        self.lags
            .iter()
            .zip(&self.values)
            .filter(|(l, v)| !(skip_zero && **l == 0) && v.abs() > self.bound)
            .map(|(l, _)| *l)
            .collect()
    }

    /// Largest |value|/bound over the lags tested.
    fn worst(&self, skip_zero: bool) -> f64 {
        self.lags
            .iter()
            .zip(&self.values)
            .filter(|(l, _)| !(skip_zero && **l == 0))
            .map(|(_, v)| v.abs() / self.bound)
            .fold(0.0, f64::max)
    }

    /// Lags tested.
    fn tested(&self, skip_zero: bool) -> usize {
        self.lags.iter().filter(|l| !(skip_zero && **l == 0)).count()
    }
}

/// The residual analysis of one output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ResidualAnalysis {
    /// ρ_e(k), k = 0 … L.
    pub autocorrelation: Correlation,
    /// ρ_eu(τ), τ = −L … L.
    pub cross_correlation: Correlation,
    /// Whether the residuals pass as white and independent of the input.
    pub white: bool,
    /// Autocorrelation lags outside the bound (lag 0 excluded).
    pub auto_outside: Vec<i64>,
    /// Cross-correlation lags outside the bound.
    pub cross_outside: Vec<i64>,
    /// The verdict in one line: "residuals white" or "model error left at lags …".
    pub verdict: String,
}

fn centred(x: &[f64]) -> Vec<f64> {
    let m = x.iter().sum::<f64>() / x.len().max(1) as f64;
    x.iter().map(|v| v - m).collect()
}

/// Normalised autocorrelation of `e` at lags 0 … `lags`.
pub fn autocorrelation(e: &[f64], lags: usize) -> Correlation {
    let e = centred(e);
    let n = e.len();
    let c0: f64 = e.iter().map(|v| v * v).sum();
    let values = (0..=lags)
        .map(|k| {
            if k >= n || c0 == 0.0 {
                return f64::NAN;
            }
            e[..n - k].iter().zip(&e[k..]).map(|(a, b)| a * b).sum::<f64>() / c0
        })
        .collect();
    Correlation { lags: (0..=lags as i64).collect(), values, bound: Z99 / (n.max(1) as f64).sqrt() }
}

/// Normalised cross-correlation ρ_eu(τ) = Σ e(t+τ)·u(t)/√(Σe²·Σu²), τ = −`lags` … `lags`.
pub fn cross_correlation(u: &[f64], e: &[f64], lags: usize) -> Correlation {
    let n = u.len().min(e.len());
    let (u, e) = (centred(&u[..n]), centred(&e[..n]));
    let norm = (u.iter().map(|v| v * v).sum::<f64>() * e.iter().map(|v| v * v).sum::<f64>()).sqrt();
    let l = lags as i64;
    let values = (-l..=l)
        .map(|tau| {
            let k = tau.unsigned_abs() as usize;
            if k >= n || norm == 0.0 {
                return f64::NAN;
            }
            let s: f64 = if tau >= 0 {
                e[k..].iter().zip(&u[..n - k]).map(|(a, b)| a * b).sum()
            } else {
                e[..n - k].iter().zip(&u[k..]).map(|(a, b)| a * b).sum()
            };
            s / norm
        })
        .collect();
    Correlation { lags: (-l..=l).collect(), values, bound: Z99 / (n.max(1) as f64).sqrt() }
}

/// The most lags out of `m` that white noise leaves outside 99 % bounds with probability
/// above 1 %: the smallest c with P(Binomial(m, 0.01) > c) ≤ 0.01.
pub fn allowed_outside(m: usize) -> usize {
    let p: f64 = 0.01;
    let mut pmf = (1.0 - p).powi(m as i32); // P(X = 0)
    let mut cdf = pmf;
    let mut c = 0;
    while 1.0 - cdf > 0.01 && c < m {
        pmf *= (m - c) as f64 / (c + 1) as f64 * p / (1.0 - p);
        cdf += pmf;
        c += 1;
    }
    c
}

/// Lags as short runs: "1–25", "−3, 0–2".
pub fn lag_runs(lags: &[i64]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut k = 0;
    while k < lags.len() {
        let start = lags[k];
        let mut end = start;
        while k + 1 < lags.len() && lags[k + 1] == end + 1 {
            k += 1;
            end = lags[k];
        }
        let f = |v: i64| if v < 0 { format!("−{}", -v) } else { v.to_string() };
        out.push(if end > start { format!("{}–{}", f(start), f(end)) } else { f(start) });
        k += 1;
    }
    out.join(", ")
}

/// The sums behind [`autocorrelation`] and [`cross_correlation`], fed one sample at a time
/// with the means known beforehand (a first pass over the record): the same numbers, bit
/// for bit, keeping only the last `lags` samples.
#[derive(Clone, Debug)]
pub struct CorrelationSums {
    lags: usize,
    mean_u: f64,
    mean_e: f64,
    /// The last `lags` centred residuals and inputs, oldest first.
    e_hist: std::collections::VecDeque<f64>,
    u_hist: std::collections::VecDeque<f64>,
    see: f64,
    suu: f64,
    /// Σ e(t)·e(t+k), k = 0 … L.
    auto: Vec<f64>,
    /// Σ e(t+k)·u(t), k = 0 … L (τ = +k).
    after: Vec<f64>,
    /// Σ e(t)·u(t+k), k = 0 … L (τ = −k; k = 0 unused).
    before: Vec<f64>,
    n: usize,
}

impl CorrelationSums {
    /// Sums over `lags` lags for a residual of mean `mean_e` and an input of mean `mean_u`
    /// (each the plain sum over the samples divided by their count).
    pub fn new(lags: usize, mean_u: f64, mean_e: f64) -> Self {
        // -0.0: the neutral element `Iterator::sum` starts from, so sums of zeros keep their sign.
        CorrelationSums {
            lags,
            mean_u,
            mean_e,
            e_hist: std::collections::VecDeque::with_capacity(lags + 1),
            u_hist: std::collections::VecDeque::with_capacity(lags + 1),
            see: -0.0,
            suu: -0.0,
            auto: vec![-0.0; lags + 1],
            after: vec![-0.0; lags + 1],
            before: vec![-0.0; lags + 1],
            n: 0,
        }
    }

    /// The next sample: input `u`, residual `e`.
    pub fn push(&mut self, u: f64, e: f64) {
        let (e, u) = (e - self.mean_e, u - self.mean_u);
        self.see += e * e;
        self.suu += u * u;
        self.auto[0] += e * e;
        self.after[0] += e * u;
        let len = self.e_hist.len();
        for k in 1..=len {
            let (ep, up) = (self.e_hist[len - k], self.u_hist[len - k]);
            self.auto[k] += ep * e;
            self.after[k] += e * up;
            self.before[k] += ep * u;
        }
        self.e_hist.push_back(e);
        self.u_hist.push_back(u);
        if self.e_hist.len() > self.lags {
            self.e_hist.pop_front();
            self.u_hist.pop_front();
        }
        self.n += 1;
    }

    /// The autocorrelation and the cross-correlation, as [`autocorrelation`] and
    /// [`cross_correlation`] give them.
    pub fn finish(&self) -> (Correlation, Correlation) {
        let (n, lags) = (self.n, self.lags);
        let bound = Z99 / (n.max(1) as f64).sqrt();
        let c0 = self.see;
        let values = (0..=lags)
            .map(|k| if k >= n || c0 == 0.0 { f64::NAN } else { self.auto[k] / c0 })
            .collect();
        let auto = Correlation { lags: (0..=lags as i64).collect(), values, bound };
        let norm = (self.suu * self.see).sqrt();
        let l = lags as i64;
        let values = (-l..=l)
            .map(|tau| {
                let k = tau.unsigned_abs() as usize;
                if k >= n || norm == 0.0 {
                    return f64::NAN;
                }
                let s = if tau >= 0 { self.after[k] } else { self.before[k] };
                s / norm
            })
            .collect();
        let cross = Correlation { lags: (-l..=l).collect(), values, bound };
        (auto, cross)
    }
}

/// Analyse residual `e` against input `u` (named `input` in the verdict) over `lags`.
pub fn analyse(u: &[f64], e: &[f64], lags: usize, input: &str) -> ResidualAnalysis {
    judge(autocorrelation(e, lags), cross_correlation(u, e, lags), input)
}

/// The verdict on an autocorrelation `auto` and a cross-correlation `cross` with the input
/// (named `input` in the verdict).
pub fn judge(auto: Correlation, cross: Correlation, input: &str) -> ResidualAnalysis {
    let (ao, co) = (auto.outside(true), cross.outside(false));
    let passes = |c: &Correlation, out: &[i64], skip: bool| {
        out.len() <= allowed_outside(c.tested(skip)) && c.worst(skip) <= STRONG
    };
    let white = passes(&auto, &ao, true) && passes(&cross, &co, false);
    let verdict = if white {
        let n = ao.len() + co.len();
        if n == 0 {
            "residuals white".to_string()
        } else {
            format!("residuals white ({n} lag(s) just outside the 99 % bounds, as chance allows)")
        }
    } else {
        let mut parts = Vec::new();
        if !ao.is_empty() {
            parts.push(format!("{} (autocorrelation)", lag_runs(&ao)));
        }
        if !co.is_empty() {
            parts.push(format!("{} (cross-correlation with the {input})", lag_runs(&co)));
        }
        format!("model error left at lags {}", parts.join("; "))
    };
    ResidualAnalysis {
        autocorrelation: auto,
        cross_correlation: cross,
        white,
        auto_outside: ao,
        cross_outside: co,
        verdict,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::{Noise, add_noise};

    /// Unit-variance Gaussian noise from `seed`.
    fn white(n: usize, seed: u64) -> Vec<f64> {
        let mut v = vec![1.0; n];
        add_noise(&mut v, &Noise { relative: 1.0, seed });
        v.iter().map(|v| v - 1.0).collect()
    }

    #[test]
    fn white_noise_stays_inside_the_bounds() {
        // 400 records of 2000 samples: the fraction of the 25 + 51 lags inside the 99 %
        // bounds averages 0.99 (measured 0.9907 autocorrelation, 0.9889 cross; one standard
        // deviation of either fraction is 0.0007).
        let (mut inside_a, mut inside_c, mut tests_a, mut tests_c, mut white_n) = (0, 0, 0, 0, 0);
        for seed in 0..400 {
            let e = white(2000, seed);
            let u = white(2000, 10_000 + seed);
            let r = analyse(&u, &e, DEFAULT_LAGS, "input");
            inside_a += 25 - r.auto_outside.len();
            inside_c += 51 - r.cross_outside.len();
            tests_a += 25;
            tests_c += 51;
            white_n += r.white as usize;
        }
        let fa = inside_a as f64 / tests_a as f64;
        let fc = inside_c as f64 / tests_c as f64;
        assert!(fa >= 0.986 && fc >= 0.986, "{fa} {fc}");
        // The verdict calls white noise white in ≥ 96 % of records (measured 393 of 400; about
        // 98 % expected).
        assert!(white_n >= 384, "{white_n}");
    }

    #[test]
    fn ar1_autocorrelation_is_a_to_the_k() {
        // x(t) = a·x(t−1) + w(t): ρ(k) = a^k. Standard error of each estimate about
        // √((1+a²)/(1−a²)/N) = 0.0048 at N = 2e5; measured largest error 0.0094 (lag 7): the
        // tolerance is about six standard errors.
        let a = 0.8;
        let w = white(200_000, 3);
        let mut x = vec![0.0; w.len()];
        for t in 1..w.len() {
            x[t] = a * x[t - 1] + w[t];
        }
        let r = autocorrelation(&x, 10);
        for (k, v) in r.values.iter().enumerate() {
            assert!((v - a.powi(k as i32)).abs() < 0.03, "lag {k}: {v}");
        }
        let v = analyse(&w, &x, DEFAULT_LAGS, "input");
        assert!(!v.white && v.verdict.starts_with("model error left at lags 1–"), "{}", v.verdict);
    }

    #[test]
    fn a_delayed_input_shows_at_its_lag() {
        // e(t) = u(t − 3) + small noise: the cross-correlation peaks at τ = +3 at 1/√1.01
        // (measured 3.7e-4 off).
        let u = white(5000, 5);
        let noise = white(5000, 6);
        let e: Vec<f64> =
            (0..5000).map(|t| if t >= 3 { u[t - 3] } else { 0.0 } + 0.1 * noise[t]).collect();
        let r = analyse(&u, &e, 5, "reference");
        let at3 = r.cross_correlation.values[5 + 3];
        assert!((at3 - 1.0 / (1.01f64).sqrt()).abs() < 0.004, "{at3}");
        assert_eq!(r.cross_outside, vec![3]);
        assert_eq!(r.verdict, "model error left at lags 3 (cross-correlation with the reference)");
    }

    /// Fed sample by sample after a first pass for the means, the correlations are the
    /// whole-record ones bit for bit (records shorter than the lags too).
    #[test]
    fn streamed_sums_are_the_whole_record_ones() {
        for n in [1, 3, 10, 26, 500] {
            let u = white(n, 21);
            let e: Vec<f64> = white(n, 22).iter().zip(&u).map(|(w, u)| w + 0.3 * u + 2.0).collect();
            let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len().max(1) as f64;
            let mut s = CorrelationSums::new(DEFAULT_LAGS, mean(&u), mean(&e));
            for (a, b) in u.iter().zip(&e) {
                s.push(*a, *b);
            }
            let (auto, cross) = s.finish();
            let text = |c: &Correlation| format!("{c:?}");
            assert_eq!(text(&auto), text(&autocorrelation(&e, DEFAULT_LAGS)), "n = {n}");
            assert_eq!(text(&cross), text(&cross_correlation(&u, &e, DEFAULT_LAGS)), "n = {n}");
        }
    }

    #[test]
    fn allowances_and_runs() {
        assert_eq!(allowed_outside(25), 2);
        assert_eq!(allowed_outside(51), 3);
        assert_eq!(lag_runs(&[-3, -1, 0, 1, 2, 7]), "−3, −1–2, 7");
    }
}
