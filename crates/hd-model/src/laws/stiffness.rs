//! Stiffness laws: the torque the gear transmits as a function of deflection and, for the
//! hysteretic law, of a fading-memory state `z` (docs/model.md §2.1).

use crate::fma::fmadd;
use serde::{Deserialize, Serialize};

/// A stiffness law evaluated at one instant, with the partial derivatives the implicit
/// integrator needs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StiffnessEval {
    /// Transmitted torque `Tb` [N·m].
    pub torque: f64,
    /// ∂Tb/∂θ [N·m/rad].
    pub d_theta: f64,
    /// ∂Tb/∂z [–].
    pub d_z: f64,
    /// Memory rate ż [N·m/s] (0 for laws without memory).
    pub z_rate: f64,
    /// ∂ż/∂θ̇ [N·m/rad].
    pub z_rate_d_thetadot: f64,
    /// ∂ż/∂z [1/s].
    pub z_rate_d_z: f64,
    /// The hysteretic part of the torque (z for the memory and Bouc–Wen laws, Σkᵢeᵢ for
    /// slip elements) [N·m].
    pub hyst: f64,
    /// Power dissipated inside the hysteretic part's rate law [W] (slip elements dissipate
    /// at step acceptance instead; see `laws::slip_set`).
    pub dissipation: f64,
    /// ∂(dissipation)/∂z [W/(N·m)].
    pub diss_d_z: f64,
    /// ∂(dissipation)/∂θ̇ [W·s/rad].
    pub diss_d_thetadot: f64,
}

/// A stiffness law: transmitted torque from the deflection θ [rad], its rate θ̇ [rad/s]
/// and the memory state z [N·m].
pub trait StiffnessLaw: Send + Sync {
    /// Torque, memory rate and their partial derivatives.
    fn eval(&self, theta: f64, theta_dot: f64, z: f64) -> StiffnessEval;
    /// Elastic potential energy stored at deflection θ [J].
    fn potential(&self, theta: f64) -> f64;
    /// Energy stored in the memory element at state z [J].
    fn memory_energy(&self, z: f64) -> f64;
    /// Power dissipated by the memory element at state z [W].
    fn memory_dissipation(&self, z: f64) -> f64;
    /// Stiffness at zero deflection (for tolerance scaling) [N·m/rad].
    fn reference_stiffness(&self) -> f64;
    /// Whether the law carries the memory state z.
    fn has_memory(&self) -> bool;
}

/// Linear spring `Tb = K̄·θ` (the `linear` and `damped` variants).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinearSpring {
    /// Stiffness K̄ [N·m/rad].
    pub k: f64,
}

impl StiffnessLaw for LinearSpring {
    fn eval(&self, theta: f64, _theta_dot: f64, _z: f64) -> StiffnessEval {
        StiffnessEval { torque: self.k * theta, d_theta: self.k, ..Default::default() }
    }
    fn potential(&self, theta: f64) -> f64 {
        0.5 * self.k * theta * theta
    }
    fn memory_energy(&self, _z: f64) -> f64 {
        0.0
    }
    fn memory_dissipation(&self, _z: f64) -> f64 {
        0.0
    }
    fn reference_stiffness(&self) -> f64 {
        self.k
    }
    fn has_memory(&self) -> bool {
        false
    }
}

/// Cubic spring `f(θ) = a·θ³ + b·θ² + c·θ`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CubicSpring {
    /// Cubic coefficient a [N·m/rad³].
    pub a: f64,
    /// Quadratic coefficient b [N·m/rad²].
    pub b: f64,
    /// Linear coefficient c [N·m/rad].
    pub c: f64,
}

impl CubicSpring {
    /// f(θ) [N·m].
    pub fn torque(&self, theta: f64) -> f64 {
        fmadd(fmadd(self.a, theta, self.b), theta, self.c) * theta
    }
    /// f'(θ) [N·m/rad].
    pub fn slope(&self, theta: f64) -> f64 {
        fmadd(fmadd(3.0 * self.a, theta, 2.0 * self.b), theta, self.c)
    }
}

impl StiffnessLaw for CubicSpring {
    fn eval(&self, theta: f64, _theta_dot: f64, _z: f64) -> StiffnessEval {
        StiffnessEval {
            torque: self.torque(theta),
            d_theta: self.slope(theta),
            ..Default::default()
        }
    }
    fn potential(&self, theta: f64) -> f64 {
        let t2 = theta * theta;
        self.a * t2 * t2 / 4.0 + self.b * t2 * theta / 3.0 + self.c * t2 / 2.0
    }
    fn memory_energy(&self, _z: f64) -> f64 {
        0.0
    }
    fn memory_dissipation(&self, _z: f64) -> f64 {
        0.0
    }
    fn reference_stiffness(&self) -> f64 {
        self.c
    }
    fn has_memory(&self) -> bool {
        false
    }
}

/// A memoryless elastic curve `T = f(θ)`: the spring beside which every hysteretic law
/// (fading memory, Maxwell-slip, Bouc–Wen, catalogue) adds its hysteretic torque.
pub trait ElasticCurve: Send + Sync {
    /// Torque f(θ) [N·m] at deflection θ [rad].
    fn spring_torque(&self, theta: f64) -> f64;
    /// Slope f'(θ) [N·m/rad].
    fn spring_slope(&self, theta: f64) -> f64;
    /// Potential energy `∫₀^θ f` [J].
    fn spring_energy(&self, theta: f64) -> f64;
}

impl ElasticCurve for CubicSpring {
    fn spring_torque(&self, theta: f64) -> f64 {
        self.torque(theta)
    }
    fn spring_slope(&self, theta: f64) -> f64 {
        self.slope(theta)
    }
    fn spring_energy(&self, theta: f64) -> f64 {
        StiffnessLaw::potential(self, theta)
    }
}

/// Fading memory of the deflection rate: `z(t) = ∫ A·e^{−B(t−τ)}·θ̇(τ) dτ`, i.e.
/// `ż = A·θ̇ − B·z`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FadingMemory {
    /// Intensity A [N·m/rad].
    pub a: f64,
    /// Decay rate B [1/s].
    pub b: f64,
}

impl FadingMemory {
    /// ż [N·m/s].
    pub fn rate(&self, theta_dot: f64, z: f64) -> f64 {
        fmadd(self.a, theta_dot, -self.b * z)
    }

    /// Exact solution of `ż = A·θ̇ − B·z` over an interval of length `h` [s] during which
    /// the deflection changes by `d_theta` [rad] at a constant rate (θ piecewise linear, as
    /// between the samples of a measured record): returns z [N·m] at the interval's end from
    /// z [N·m] at its start,
    /// `z₁ = e^{−B·h}·z₀ + A·(d_theta/h)·(1 − e^{−B·h})/B` (→ `z₀ + A·d_theta` as B → 0).
    pub fn step_linear(&self, z: f64, d_theta: f64, h: f64) -> f64 {
        if h <= 0.0 {
            return z + self.a * d_theta;
        }
        let (decay, gain) = self.step_factors(h);
        self.step_with(z, d_theta, decay, gain)
    }

    /// The factors of [`FadingMemory::step_linear`] for an interval of `h` > 0 seconds:
    /// `(e^{−B·h}, (1 − e^{−B·h})/(B·h))` [–]. A record sampled at a constant interval
    /// needs them once ([`FadingMemory::step_with`] then takes each step).
    #[inline]
    pub fn step_factors(&self, h: f64) -> (f64, f64) {
        let bh = self.b * h;
        // (1 − e^{−Bh})/(Bh), accurate for small Bh.
        let gain = if bh.abs() < 1e-12 { 1.0 } else { -(-bh).exp_m1() / bh };
        ((-bh).exp(), gain)
    }

    /// The factors of [`FadingMemory::step_linear_grad`] for an interval of `h` > 0 seconds:
    /// those of [`FadingMemory::step_factors`] and `h·φ′(B·h)` [s], so that
    /// `∂z₁/∂B = −h·e^{−Bh}·z₀ + A·d_theta·h·φ′(Bh)` (a record sampled at a constant
    /// interval needs them once).
    #[inline]
    pub fn step_grad_factors(&self, h: f64) -> (f64, f64, f64) {
        let (decay, gain) = self.step_factors(h);
        (decay, gain, h * phi_slope(self.b * h))
    }

    /// [`FadingMemory::step_linear`] with its factors from [`FadingMemory::step_factors`].
    #[inline]
    pub fn step_with(&self, z: f64, d_theta: f64, decay: f64, gain: f64) -> f64 {
        decay * z + self.a * d_theta * gain
    }

    /// [`FadingMemory::step_linear`] with its derivatives: returns `(z₁, ∂z₁/∂z₀,
    /// ∂z₁/∂B)` [N·m, –, N·m·s], the last at fixed z₀:
    /// `∂z₁/∂B = h·(−e^{−Bh}·z₀ + A·d_theta·φ′(Bh))` with `φ(x) = (1 − e^{−x})/x`.
    /// Carried along a record (`∂z/∂B ← ∂z₁/∂z₀·∂z/∂B + ∂z₁/∂B`) this is the exact
    /// sensitivity of the memory to B.
    pub fn step_linear_grad(&self, z: f64, d_theta: f64, h: f64) -> (f64, f64, f64) {
        if h <= 0.0 {
            return (z + self.a * d_theta, 1.0, 0.0);
        }
        let x = self.b * h;
        let decay = (-x).exp();
        let z1 = self.step_linear(z, d_theta, h);
        (z1, decay, h * (-decay * z + self.a * d_theta * phi_slope(x)))
    }
}

/// φ′(x) for φ(x) = (1 − e^{−x})/x: `(e^{−x}·(1 + x) − 1)/x²`, by its series where that
/// difference cancels (|x| < 1e-2: the next term is below 1e-13 of the sum).
fn phi_slope(x: f64) -> f64 {
    if x.abs() < 1e-2 {
        -0.5 + x * (1.0 / 3.0 + x * (-1.0 / 8.0 + x * (1.0 / 30.0 - x / 144.0)))
    } else {
        ((-x).exp() * (1.0 + x) - 1.0) / (x * x)
    }
}

/// Hysteretic stiffness of the full model: `Tb = f(θ) + z` with fading memory.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Hysteretic {
    /// The instantaneous cubic spring.
    pub spring: CubicSpring,
    /// The memory term.
    pub memory: FadingMemory,
}

impl StiffnessLaw for Hysteretic {
    fn eval(&self, theta: f64, theta_dot: f64, z: f64) -> StiffnessEval {
        StiffnessEval {
            torque: self.spring.torque(theta) + z,
            d_theta: self.spring.slope(theta),
            d_z: 1.0,
            z_rate: self.memory.rate(theta_dot, z),
            z_rate_d_thetadot: self.memory.a,
            z_rate_d_z: -self.memory.b,
            hyst: z,
            dissipation: self.memory_dissipation(z),
            diss_d_z: if self.memory.a > 0.0 {
                2.0 * self.memory.b * z / self.memory.a
            } else {
                0.0
            },
            diss_d_thetadot: 0.0,
        }
    }
    fn potential(&self, theta: f64) -> f64 {
        self.spring.potential(theta)
    }
    fn memory_energy(&self, z: f64) -> f64 {
        if self.memory.a > 0.0 { z * z / (2.0 * self.memory.a) } else { 0.0 }
    }
    fn memory_dissipation(&self, z: f64) -> f64 {
        if self.memory.a > 0.0 { self.memory.b * z * z / self.memory.a } else { 0.0 }
    }
    fn reference_stiffness(&self) -> f64 {
        self.spring.c + self.memory.a
    }
    fn has_memory(&self) -> bool {
        true
    }
}

pub use super::composed::Stiffness;

#[cfg(test)]
mod tests {
    /// The carried sensitivity ∂z/∂B along an uneven record against central differences
    /// in B, across the switch between φ′'s series and its closed form (Bh from 3e-4
    /// to 3): 1e-6 of the column's largest entry.
    #[test]
    fn memory_sensitivity_to_b_matches_central_differences() {
        let times: Vec<f64> = (0..=300).map(|k| 1e-4 * (k as f64).powf(1.3)).collect();
        let theta = |t: f64| 1e-3 * (2.0 * std::f64::consts::PI * 40.0 * t).sin();
        for b in [3.0, 300.0, 3e3] {
            let run = |b: f64| {
                let m = FadingMemory { a: 4e4, b };
                let (mut z, mut dz) = (0.0, 0.0);
                let mut out = Vec::new();
                for w in times.windows(2) {
                    let (z1, dz0, db) =
                        m.step_linear_grad(z, theta(w[1]) - theta(w[0]), w[1] - w[0]);
                    dz = dz0 * dz + db;
                    z = z1;
                    out.push((z, dz));
                }
                out
            };
            let h = 1e-6 * b;
            let (up, down, exact) = (run(b + h), run(b - h), run(b));
            let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.1.abs()));
            let worst = (0..exact.len())
                .map(|k| ((up[k].0 - down[k].0) / (2.0 * h) - exact[k].1).abs())
                .fold(0.0, f64::max);
            println!("B {b}: {worst:.1e} of {scale:.3e}");
            assert!(scale > 0.0 && worst <= 1e-6 * scale, "B {b}: {worst:e} of {scale:e}");
        }
    }

    use super::FadingMemory;

    /// `step_linear` against a fine RK4 integration of `rate()` along a piecewise-linear
    /// deflection record with uneven intervals.
    #[test]
    fn exact_memory_step_matches_rate_integration() {
        let m = FadingMemory { a: 4e4, b: 300.0 };
        let times: Vec<f64> = (0..=60).map(|k| 1e-4 * (k as f64).powf(1.3)).collect();
        let theta = |t: f64| 1e-3 * (2.0 * std::f64::consts::PI * 40.0 * t).sin();
        let (mut z_exact, mut z_rk) = (0.0, 0.0);
        for w in times.windows(2) {
            let (t0, t1) = (w[0], w[1]);
            let h = t1 - t0;
            let d_theta = theta(t1) - theta(t0);
            z_exact = m.step_linear(z_exact, d_theta, h);
            let rate = d_theta / h;
            let n = 200;
            let dt = h / n as f64;
            for _ in 0..n {
                let k1 = m.rate(rate, z_rk);
                let k2 = m.rate(rate, z_rk + 0.5 * dt * k1);
                let k3 = m.rate(rate, z_rk + 0.5 * dt * k2);
                let k4 = m.rate(rate, z_rk + dt * k3);
                z_rk += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            }
            assert!((z_exact - z_rk).abs() <= 1e-9 * z_rk.abs().max(1e-3), "{z_exact} vs {z_rk}");
        }
        // B = 0: a pure integrator of the deflection.
        let pure = FadingMemory { a: 2.0, b: 0.0 };
        assert_eq!(pure.step_linear(1.0, 0.5, 0.1), 2.0);
    }
}
