//! Maxwell-slip stiffness (docs/model.md §2.11): an elastic curve f(θ) in parallel with n
//! elastoplastic elements. Element i is a spring of stiffness kᵢ [N·m/rad] in series with
//! a Coulomb slider that slips at the torque Fᵢ [N·m]; its state is the spring's own
//! deflection eᵢ [rad], held within the yield deflection ±δᵢ = ±Fᵢ/kᵢ. The transmitted
//! torque is
//!
//! ```text
//! Tb = f(θ) + Σᵢ kᵢ·eᵢ,        ėᵢ = θ̇ unless |eᵢ| = δᵢ and θ̇ pushes it further (then 0)
//! ```
//!
//! Only increments of θ move the states, never the time they take: the law is
//! rate-independent, and along a deflection that is monotone between samples the update
//! [`SlipElement::step`] is exact.

use super::stiffness::{CubicSpring, ElasticCurve};
use crate::schema::ColumnDoc;
use serde::{Deserialize, Serialize};

/// Parameter names of the law in outputs (`ms_k1`, `ms_f1`, … numbered by increasing
/// yield deflection), with units; the spring keeps the names a, b, c.
pub static PARAMS: &[ColumnDoc] = &[
    ColumnDoc {
        name: "ms_k<i>",
        unit: "N·m/rad",
        doc: "stiffness of Maxwell-slip element i (elements ordered by yield deflection)",
    },
    ColumnDoc { name: "ms_f<i>", unit: "N·m", doc: "slip torque of Maxwell-slip element i" },
];

/// One elastoplastic element: spring k in series with a slider that slips at torque f.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlipElement {
    /// Stiffness k [N·m/rad], ≥ 0.
    pub k: f64,
    /// Slip torque F [N·m], ≥ 0.
    pub f: f64,
}

impl SlipElement {
    /// An element of stiffness `k` [N·m/rad] that yields at deflection `delta` [rad].
    pub fn from_yield(k: f64, delta: f64) -> Self {
        Self { k, f: k * delta }
    }

    /// Yield deflection δ = F/k [rad] (infinite for k = 0: such an element never slips and
    /// carries no torque).
    pub fn yield_deflection(&self) -> f64 {
        if self.k > 0.0 { self.f / self.k } else { f64::INFINITY }
    }

    /// Exact update of the element's deflection `e` [rad] for a monotone deflection
    /// increment `d_theta` [rad]: returns the new deflection and the slider's slip [rad].
    pub fn step(&self, e: f64, d_theta: f64) -> (f64, f64) {
        let d = self.yield_deflection();
        let trial = e + d_theta;
        let held = trial.clamp(-d, d);
        (held, (trial - held).abs())
    }

    /// [`SlipElement::step`] with the sensitivity of the deflection to the yield deflection
    /// δ (at fixed k) carried: from e [rad] and ∂e/∂δ [–] returns the new pair. Where the
    /// element ends clamped at ±δ the derivative is ±1; while it sticks, e moves with θ
    /// and keeps the derivative it had.
    pub fn step_grad(&self, e: f64, d_e: f64, d_theta: f64) -> (f64, f64) {
        let d = self.yield_deflection();
        let trial = e + d_theta;
        if trial > d {
            (d, 1.0)
        } else if trial < -d {
            (-d, -1.0)
        } else {
            (trial, d_e)
        }
    }

    /// Rate of the element's deflection ė [rad/s] at deflection rate θ̇ [rad/s] (the form
    /// an ODE integrator needs): θ̇, or 0 while the slider slips.
    pub fn rate(&self, e: f64, theta_dot: f64) -> f64 {
        let d = self.yield_deflection();
        if (e >= d && theta_dot > 0.0) || (e <= -d && theta_dot < 0.0) { 0.0 } else { theta_dot }
    }

    /// Torque k·e [N·m].
    pub fn torque(&self, e: f64) -> f64 {
        self.k * e
    }

    /// Energy stored in the element's spring, ½·k·e² [J].
    pub fn stored(&self, e: f64) -> f64 {
        0.5 * self.k * e * e
    }

    /// The element's torque on a first loading from e = 0 to deflection θ [rad]:
    /// `clamp(k·θ, −F, F)` [N·m].
    pub fn virgin_torque(&self, theta: f64) -> f64 {
        (self.k * theta).clamp(-self.f, self.f)
    }

    /// Work done on the element over that first loading [J].
    pub fn virgin_work(&self, theta: f64) -> f64 {
        let d = self.yield_deflection();
        let x = theta.abs();
        if x <= d { 0.5 * self.k * x * x } else { self.f * (x - 0.5 * d) }
    }
}

/// The elements' deflections [rad] and the energy each has dissipated so far [J].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SlipState {
    /// Deflection eᵢ of each element's spring [rad].
    pub e: Vec<f64>,
    /// Energy dissipated by each element's slider since the start, Fᵢ·(total slip) [J].
    pub dissipated: Vec<f64>,
}

/// Maxwell-slip stiffness: an elastic curve plus elastoplastic elements.
#[derive(Clone, Debug, PartialEq)]
pub struct MaxwellSlip<S: ElasticCurve = CubicSpring> {
    /// The elastic curve f(θ).
    pub spring: S,
    /// The elements, by increasing yield deflection.
    pub elements: Vec<SlipElement>,
}

impl<S: ElasticCurve> MaxwellSlip<S> {
    /// Every element at rest (e = 0, nothing dissipated): the state at the first sample.
    pub fn rest(&self) -> SlipState {
        let n = self.elements.len();
        SlipState { e: vec![0.0; n], dissipated: vec![0.0; n] }
    }

    /// Move every element by the monotone deflection increment `d_theta` [rad].
    pub fn step(&self, state: &mut SlipState, d_theta: f64) {
        for (i, el) in self.elements.iter().enumerate() {
            let (e, slip) = el.step(state.e[i], d_theta);
            state.e[i] = e;
            state.dissipated[i] += el.f * slip;
        }
    }

    /// Transmitted torque at deflection θ [rad] and state `state` [N·m].
    pub fn torque(&self, theta: f64, state: &SlipState) -> f64 {
        self.spring.spring_torque(theta) + self.hysteretic_torque(state)
    }

    /// The elements' share of the torque, Σ kᵢ·eᵢ [N·m].
    pub fn hysteretic_torque(&self, state: &SlipState) -> f64 {
        self.elements.iter().zip(&state.e).map(|(el, e)| el.torque(*e)).sum()
    }

    /// Energy stored in each element's spring [J].
    pub fn stored(&self, state: &SlipState) -> Vec<f64> {
        self.elements.iter().zip(&state.e).map(|(el, e)| el.stored(*e)).collect()
    }

    /// Energy stored in the whole law at deflection θ: the curve's potential plus every
    /// element's spring [J].
    pub fn stored_total(&self, theta: f64, state: &SlipState) -> f64 {
        self.spring.spring_energy(theta) + self.stored(state).iter().sum::<f64>()
    }

    /// Torque along a sampled deflection record, from rest at the first sample [N·m]
    /// (θ taken as monotone between samples).
    pub fn torque_along(&self, theta: &[f64]) -> Vec<f64> {
        let mut st = self.rest();
        let mut prev = theta.first().copied().unwrap_or(0.0);
        theta
            .iter()
            .map(|&th| {
                self.step(&mut st, th - prev);
                prev = th;
                self.torque(th, &st)
            })
            .collect()
    }

    /// Energy dissipated per steady cycle between ±C [rad] (closed form): each element
    /// whose yield deflection δᵢ is below C slips 4·(C − δᵢ) per cycle at torque Fᵢ, so
    /// `ΔE = Σ 4·Fᵢ·max(C − δᵢ, 0)` [J]; the elastic curve returns what it stores.
    pub fn loop_energy(&self, amplitude: f64) -> f64 {
        self.elements
            .iter()
            .filter(|el| el.k > 0.0)
            .map(|el| 4.0 * el.f * (amplitude - el.yield_deflection()).max(0.0))
            .sum()
    }

    /// The elements' torque on a first loading from rest to θ, Σ clamp(kᵢ·θ, ±Fᵢ) [N·m].
    pub fn virgin_torque(&self, theta: f64) -> f64 {
        self.elements.iter().map(|el| el.virgin_torque(theta)).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    fn law() -> MaxwellSlip {
        let deltas = [2e-5, 5e-5, 1.2e-4, 3e-4, 6e-4];
        MaxwellSlip {
            spring: CubicSpring { a: 1e8, b: 2e5, c: 5.2e4 },
            elements: deltas.iter().map(|&d| SlipElement::from_yield(8e3, d)).collect(),
        }
    }

    /// ∮ Tb dθ over the last of three cycles of θ = C·sin(2πft), sampled at uneven times
    /// (a time step that wobbles by ±40 %), and the dissipated energy of that cycle.
    fn cycle_energy(law: &MaxwellSlip, c: f64, freq: f64) -> (f64, f64) {
        let period = 1.0 / freq;
        let mut t = 0.0;
        let mut k = 0u64;
        let (mut st, mut prev_th, mut prev_tb) = (law.rest(), 0.0, 0.0);
        let (mut work, mut diss0) = (0.0, 0.0);
        while t < 3.0 * period {
            k += 1;
            let h = period / 5000.0 * (1.0 + 0.4 * ((k as f64) * 0.7).sin());
            // Land exactly on the start and the end of the measured cycle.
            let t_new = if t < 2.0 * period {
                (t + h).min(2.0 * period)
            } else {
                (t + h).min(3.0 * period)
            };
            let t_start = t;
            t = t_new;
            let th = c * (TAU * freq * t).sin();
            law.step(&mut st, th - prev_th);
            if t == 2.0 * period {
                diss0 = st.dissipated.iter().sum();
            }
            let tb = law.torque(th, &st);
            if t_start >= 2.0 * period {
                work += 0.5 * (tb + prev_tb) * (th - prev_th);
            }
            (prev_th, prev_tb) = (th, tb);
        }
        (work, st.dissipated.iter().sum::<f64>() - diss0)
    }

    #[test]
    fn loop_energy_is_rate_independent_and_matches_the_closed_form() {
        let law = law();
        let c = 4e-4;
        let exact = law.loop_energy(c);
        let (slow, d_slow) = cycle_energy(&law, c, 0.01);
        let (fast, d_fast) = cycle_energy(&law, c, 100.0);
        println!("closed form {exact:e} J; 0.01 Hz {slow:e}, 100 Hz {fast:e}");
        // Measured relative residual of the trapezoidal loop area ≈ 6.5e-7 (5000 uneven
        // samples per cycle: the cubic spring's share of the area is not exactly zero).
        for e in [slow, fast, d_slow, d_fast] {
            assert!((e / exact - 1.0).abs() < 7e-6, "{e} vs {exact}");
        }
        // The same at both rates, to rounding.
        assert!((slow / fast - 1.0).abs() < 1e-13);
    }

    #[test]
    fn energy_balance_closes_for_each_element() {
        let law = law();
        let mut st = law.rest();
        let (mut prev, mut work) = (0.0, 0.0);
        let mut prev_tb = 0.0;
        for k in 1..=20_000 {
            let t = k as f64 * 1e-4;
            let th = 5e-4 * (TAU * 3.0 * t).sin() * (1.0 + 0.5 * (TAU * 0.7 * t).sin());
            law.step(&mut st, th - prev);
            let tb = law.torque(th, &st);
            work += 0.5 * (tb + prev_tb) * (th - prev);
            (prev, prev_tb) = (th, tb);
        }
        let stored = law.stored_total(prev, &st);
        let diss: f64 = st.dissipated.iter().sum();
        let resid = (work - stored - diss).abs() / work.abs().max(diss);
        println!("work {work:e} J, stored {stored:e} J, dissipated {diss:e} J, residual {resid:e}");
        // Measured ≈ 6.8e-7 (trapezoidal work).
        assert!(resid < 7e-6, "{resid}");
        assert!(st.dissipated.iter().all(|d| *d >= 0.0));
    }

    #[test]
    fn rate_form_and_virgin_curve_agree_with_the_step() {
        let el = SlipElement::from_yield(1e4, 1e-4);
        assert_eq!(el.rate(1e-4, 1.0), 0.0);
        assert_eq!(el.rate(1e-4, -1.0), -1.0);
        assert_eq!(el.rate(0.0, 2.0), 2.0);
        let (e, slip) = el.step(0.0, 3e-4);
        assert!((e - 1e-4).abs() < 1e-18 && (slip - 2e-4).abs() < 1e-18);
        assert!((el.virgin_torque(3e-4) - el.torque(e)).abs() < 1e-12);
        // Virgin work = stored + dissipated on a first loading.
        assert!((el.virgin_work(3e-4) - (el.stored(e) + el.f * slip)).abs() < 1e-15);
    }
}
