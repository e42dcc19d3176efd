//! Bouc–Wen stiffness (docs/model.md §2.12): an elastic curve f(θ) plus a hysteretic
//! torque α·w whose internal deflection w [rad] follows
//!
//! ```text
//! ẇ = A·θ̇ − β·|θ̇|·|w|^(n−1)·w − γ·θ̇·|w|^n
//! Tb = f(θ) + α·w
//! ```
//!
//! ẇ is proportional to θ̇, so along θ the state obeys `dw/dθ = A − |w|^n·(β·sgn(θ̇·w) + γ)`
//! whatever the rate: the law is rate-independent. It holds one state. On a first loading
//! w saturates at `w_u = (A/(β + γ))^(1/n)`, so `α·w_u` is the largest hysteretic torque.
//! The four constants (α, A, β, γ) are redundant by one scale (w → s·w leaves Tb unchanged
//! with α/s, A·s, β/sⁿ, γ/sⁿ); fits hold A = 1.

use super::stiffness::{CubicSpring, ElasticCurve};
use serde::{Deserialize, Serialize};

/// The Bouc–Wen hysteretic element.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoucWen {
    /// Hysteretic stiffness α [N·m/rad].
    pub alpha: f64,
    /// Rate gain A [–].
    pub a: f64,
    /// Shape constant β [rad^−n]; β ≥ |γ| makes every dissipation non-negative.
    pub beta: f64,
    /// Shape constant γ [rad^−n].
    pub gamma: f64,
    /// Smoothness exponent n [–], > 0.
    pub n: f64,
}

/// Largest change of w per sub-step relative to the local scale: keeps RK4's error far
/// below any measurement noise.
const SUBSTEP_SHARE: f64 = 0.02;
/// Upper bound on sub-steps per increment.
const MAX_SUBSTEPS: usize = 2000;

impl BoucWen {
    /// dw/dθ [–] at state w [rad] while θ moves in direction `dir` (±1).
    pub fn slope(&self, w: f64, dir: f64) -> f64 {
        let p = w.abs().powf(self.n);
        self.a - p * (self.beta * (dir * w).signum() + self.gamma)
    }

    /// ẇ [rad/s] at deflection rate θ̇ [rad/s] (the form an ODE integrator needs).
    pub fn rate(&self, theta_dot: f64, w: f64) -> f64 {
        theta_dot * self.slope(w, theta_dot.signum())
    }

    /// Saturation deflection on a first loading, (A/(β + γ))^(1/n) [rad] (infinite when
    /// β + γ ≤ 0).
    pub fn saturation(&self) -> f64 {
        let s = self.beta + self.gamma;
        if s > 0.0 && self.a > 0.0 { (self.a / s).powf(1.0 / self.n) } else { f64::INFINITY }
    }

    /// Hysteretic torque α·w [N·m].
    pub fn torque(&self, w: f64) -> f64 {
        self.alpha * w
    }

    /// Energy held by the element, α·w²/(2A) [J] (its rate is α·w·ẇ/A).
    pub fn stored(&self, w: f64) -> f64 {
        if self.a > 0.0 { 0.5 * self.alpha * w * w / self.a } else { 0.0 }
    }

    /// Dissipated power `(α/A)·|θ̇|·|w|^(n+1)·(β + γ·sgn(θ̇·w))` [W] (power in minus the
    /// rate of [`BoucWen::stored`]).
    pub fn dissipation(&self, theta_dot: f64, w: f64) -> f64 {
        if self.a <= 0.0 {
            return 0.0;
        }
        let s = (theta_dot * w).signum();
        self.alpha / self.a
            * theta_dot.abs()
            * w.abs().powf(self.n + 1.0)
            * (self.beta + self.gamma * s)
    }

    /// Sub-steps of an increment of length `len` [rad] from `w`: their number and length,
    /// small against the saturation deflection (or the increment, or w itself).
    fn substeps(&self, w: f64, len: f64) -> (usize, f64) {
        let scale = self.saturation().min(len.max(1e-300) * 1e6).max(w.abs());
        let m = ((len / (SUBSTEP_SHARE * scale)).ceil() as usize).clamp(1, MAX_SUBSTEPS);
        (m, len / m as f64)
    }

    /// State after a monotone deflection increment `d_theta` [rad] from `w` [rad], and the
    /// energy dissipated over it [J]: classical RK4 in θ with sub-steps small against the
    /// saturation deflection.
    pub fn step(&self, w: f64, d_theta: f64) -> (f64, f64) {
        if d_theta == 0.0 {
            return (w, 0.0);
        }
        let dir = d_theta.signum();
        let (m, h) = self.substeps(w, d_theta.abs());
        // d/dφ of (w, dissipated) with φ the distance moved along θ.
        let f = |w: f64| -> (f64, f64) {
            let dw = dir * self.slope(w, dir);
            (dw, self.dissipation(dir, w))
        };
        let (mut w, mut d) = (w, 0.0);
        for _ in 0..m {
            let (k1, q1) = f(w);
            let (k2, q2) = f(w + 0.5 * h * k1);
            let (k3, q3) = f(w + 0.5 * h * k2);
            let (k4, q4) = f(w + h * k3);
            w += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            d += h / 6.0 * (q1 + 2.0 * q2 + 2.0 * q3 + q4);
        }
        (w, d)
    }

    /// The state after [`BoucWen::step`]'s increment, with its derivatives with respect to
    /// (β, γ, n): `dw` holds ∂w/∂(β, γ, n) at the start [rad per unit], and the result the
    /// same at the end. The derivatives are those of the RK4 map itself (the same sub-steps,
    /// differentiated stage by stage), so they are exact for the state [`BoucWen::step`]
    /// computes, which a fit needs for its Jacobian.
    pub fn step_sensitive(&self, w: f64, dw: [f64; 3], d_theta: f64) -> (f64, [f64; 3]) {
        if d_theta == 0.0 {
            return (w, dw);
        }
        let dir = d_theta.signum();
        let (m, h) = self.substeps(w, d_theta.abs());
        // dw/dφ = dir·slope(w) and its derivatives in w and in (β, γ, n) at fixed w.
        let f = |w: f64| -> (f64, f64, [f64; 3]) {
            let s = (dir * w).signum();
            let aw = w.abs();
            let p = aw.powf(self.n);
            let shape = self.beta * s + self.gamma;
            let k = dir * (self.a - p * shape);
            // ∂|w|^n/∂w = n·|w|^(n−1)·sgn w, written as n·p/w (0 at w = 0 for n > 0).
            let dp_dw = if aw > 0.0 { self.n * p / w } else { 0.0 };
            let log = if aw > 0.0 { aw.ln() } else { 0.0 };
            let k_w = -dir * dp_dw * shape;
            let k_q = [-dir * p * s, -dir * p, -dir * p * log * shape];
            (k, k_w, k_q)
        };
        let (mut w, mut dw) = (w, dw);
        let lin =
            |a: [f64; 3], b: [f64; 3], c: f64| [a[0] + c * b[0], a[1] + c * b[1], a[2] + c * b[2]];
        for _ in 0..m {
            // Each stage: its value k and its total derivative dk = k_w·(stage state)' + k_q.
            let stage = |ws: f64, dws: [f64; 3]| -> (f64, [f64; 3]) {
                let (k, k_w, k_q) = f(ws);
                (k, [k_w * dws[0] + k_q[0], k_w * dws[1] + k_q[1], k_w * dws[2] + k_q[2]])
            };
            let (k1, d1) = stage(w, dw);
            let (k2, d2) = stage(w + 0.5 * h * k1, lin(dw, d1, 0.5 * h));
            let (k3, d3) = stage(w + 0.5 * h * k2, lin(dw, d2, 0.5 * h));
            let (k4, d4) = stage(w + h * k3, lin(dw, d3, h));
            w += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            for j in 0..3 {
                dw[j] += h / 6.0 * (d1[j] + 2.0 * d2[j] + 2.0 * d3[j] + d4[j]);
            }
        }
        (w, dw)
    }
}

/// Bouc–Wen stiffness: an elastic curve plus the hysteretic element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoucWenStiffness<S: ElasticCurve = CubicSpring> {
    /// The elastic curve f(θ).
    pub spring: S,
    /// The hysteretic element.
    pub element: BoucWen,
}

impl<S: ElasticCurve> BoucWenStiffness<S> {
    /// Transmitted torque f(θ) + α·w [N·m].
    pub fn torque(&self, theta: f64, w: f64) -> f64 {
        self.spring.spring_torque(theta) + self.element.torque(w)
    }

    /// The state along a sampled deflection record, from w = 0 at the first sample [rad]
    /// (θ taken as monotone between samples).
    pub fn state_along(&self, theta: &[f64]) -> Vec<f64> {
        let mut w = 0.0;
        let mut prev = theta.first().copied().unwrap_or(0.0);
        theta
            .iter()
            .map(|&th| {
                w = self.element.step(w, th - prev).0;
                prev = th;
                w
            })
            .collect()
    }

    /// The state along a sampled deflection record with its derivatives with respect to
    /// (β, γ, n) ([`BoucWen::step_sensitive`]), from w = 0 and zero derivatives.
    pub fn state_sensitive_along(&self, theta: &[f64]) -> (Vec<f64>, [Vec<f64>; 3]) {
        let (mut w, mut dw) = (0.0, [0.0; 3]);
        let mut prev = theta.first().copied().unwrap_or(0.0);
        let mut out = Vec::with_capacity(theta.len());
        let mut d: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(theta.len()));
        for &th in theta {
            (w, dw) = self.element.step_sensitive(w, dw, th - prev);
            prev = th;
            out.push(w);
            for j in 0..3 {
                d[j].push(dw[j]);
            }
        }
        (out, d)
    }

    /// Torque along a sampled deflection record, from w = 0 [N·m].
    pub fn torque_along(&self, theta: &[f64]) -> Vec<f64> {
        let w = self.state_along(theta);
        theta.iter().zip(&w).map(|(&th, &w)| self.torque(th, w)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    const EL: BoucWen = BoucWen { alpha: 3e4, a: 1.0, beta: 3e3, gamma: 1e3, n: 1.0 };

    #[test]
    fn first_loading_matches_the_closed_form_for_n_one() {
        // n = 1, θ rising from 0: dw/dθ = A − (β + γ)·w, so w = A/(β+γ)·(1 − e^{−(β+γ)θ}).
        let s = EL.beta + EL.gamma;
        let (mut w, mut worst) = (0.0f64, 0.0f64);
        for k in 1..=400 {
            w = EL.step(w, 2.5e-6).0;
            let th = 2.5e-6 * k as f64;
            let exact = EL.a / s * (1.0 - (-s * th).exp());
            worst = worst.max((w - exact).abs() / exact);
        }
        println!("largest relative error {worst:e}");
        // Measured ≈ 8.4e-11 (RK4 in θ).
        assert!(worst < 1e-9, "{worst}");
        assert!((EL.saturation() - 2.5e-4).abs() < 1e-18);
    }

    /// Work ∮ α·w dθ, stored and dissipated energy over a sinusoidal history at frequency
    /// `freq`, sampled 4000 times per cycle.
    fn history(freq: f64, el: &BoucWen) -> (f64, f64, f64) {
        let (mut w, mut diss, mut work, mut prev) = (0.0, 0.0, 0.0, 0.0);
        let steps = 12_000;
        for k in 1..=steps {
            let t = 3.0 / freq * k as f64 / steps as f64;
            let th = 6e-4 * (TAU * freq * t).sin();
            let (w1, d) = el.step(w, th - prev);
            work += 0.5 * el.alpha * (w + w1) * (th - prev);
            (w, prev) = (w1, th);
            diss += d;
        }
        (work, el.stored(w), diss)
    }

    #[test]
    fn energy_balance_closes_and_is_rate_independent() {
        for el in [EL, BoucWen { n: 2.0, beta: 2e7, gamma: -5e6, ..EL }] {
            let (work, stored, diss) = history(0.01, &el);
            let (work_fast, _, diss_fast) = history(100.0, &el);
            let resid = (work - stored - diss).abs() / diss;
            println!(
                "n = {}: work {work:e}, stored {stored:e}, dissipated {diss:e}, residual {resid:e}",
                el.n
            );
            // Measured ≈ 4.8e-7: the trapezoidal work against the sub-stepped dissipation.
            assert!(resid < 5e-6, "{resid}");
            assert!(diss > 0.0);
            assert!(
                (work / work_fast - 1.0).abs() < 1e-12 && (diss / diss_fast - 1.0).abs() < 1e-12
            );
        }
    }

    #[test]
    fn sensitivities_match_central_differences_and_the_state_matches_step() {
        let el = BoucWen { alpha: 2e4, a: 1.0, beta: 3e5, gamma: 1e5, n: 1.6 };
        let law = BoucWenStiffness { spring: CubicSpring { a: 0.0, b: 0.0, c: 0.0 }, element: el };
        // Two cycles of unequal amplitude, so branches reverse at different states.
        let theta: Vec<f64> = (0..600)
            .map(|k| {
                let t = k as f64 / 600.0;
                1.2e-3 * (std::f64::consts::TAU * 2.0 * t).sin() * (1.0 - 0.4 * t)
            })
            .collect();
        let (w, d) = law.state_sensitive_along(&theta);
        assert_eq!(w, law.state_along(&theta), "the state differs from step's");
        let set = [
            |e: BoucWen, v: f64| BoucWen { beta: v, ..e },
            |e: BoucWen, v: f64| BoucWen { gamma: v, ..e },
            |e: BoucWen, v: f64| BoucWen { n: v, ..e },
        ];
        let values = [el.beta, el.gamma, el.n];
        let mut worst: f64 = 0.0;
        for j in 0..3 {
            let dv = 1e-6 * values[j];
            let at = |v| BoucWenStiffness { element: set[j](el, v), ..law }.state_along(&theta);
            let (up, down) = (at(values[j] + dv), at(values[j] - dv));
            let scale = d[j].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for k in 0..theta.len() {
                let fd = (up[k] - down[k]) / (2.0 * dv);
                worst = worst.max((fd - d[j][k]).abs() / scale);
            }
        }
        // Central differences at 1e-6 of each value agree to 4.2e-9 of each column's
        // largest value here (their own truncation and rounding).
        assert!(worst < 5e-8, "worst relative deviation {worst:e}");
    }

    #[test]
    fn rate_form_is_the_slope_times_the_rate() {
        for (td, w) in [(2.0, 1e-4), (-3.0, 1e-4), (0.5, -2e-4)] {
            let slope = EL.slope(w, f64::signum(td));
            assert_eq!(EL.rate(td, w), td * slope);
        }
        let law = BoucWenStiffness { spring: CubicSpring { a: 0.0, b: 0.0, c: 5e4 }, element: EL };
        let tb = law.torque_along(&[0.0, 1e-4, 2e-4, 1e-4]);
        assert!(tb[2] > tb[1] && tb[3] < tb[2]);
    }
}
