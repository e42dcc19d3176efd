//! The gear's stiffness as the simulator, the controller model and the tests use it: an
//! elastic curve plus at most one hysteretic part (docs/model.md §2.1, §2.11–2.13).
//!
//! | law (`--stiffness`) | elastic curve | hysteretic part | where its state lives |
//! |---|---|---|---|
//! | `linear` / `damped` variants | K̄·θ | — | — |
//! | `memory` (default) | cubic f(θ) | fading memory z | ODE state `Z` [N·m] |
//! | `bouc-wen` | cubic f(θ) | Bouc–Wen torque z = α·w | ODE state `Z` [N·m] |
//! | `maxwell-slip` | cubic f(θ) | slip elements | offsets in `SLIP..` (see [`super::slip_set`]) |
//! | `catalogue` | three-segment curve (less the elements' first loading) | slip elements for the loss | as above |
//!
//! The value is `Copy` and allocation-free, so a drive system stays a plain value.

use super::bouc_wen::BoucWen;
use super::catalogue::CatalogueSpring;
use super::slip_set::SlipSet;
use super::stiffness::{CubicSpring, ElasticCurve, FadingMemory, LinearSpring, StiffnessEval};

/// The memoryless part of the law.
// The catalogue variant carries its slip set inline so the law stays `Copy` and a run
// allocates nothing; a few hundred bytes per drive system are no cost.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Curve {
    /// `K̄·θ`.
    Linear(LinearSpring),
    /// `a·θ³ + b·θ² + c·θ`.
    Cubic(CubicSpring),
    /// The catalogue's three segments with rounded corners.
    Catalogue(CatalogueSpring),
}

impl Curve {
    /// Torque [N·m] and slope [N·m/rad] at θ [rad].
    #[inline]
    pub fn torque_slope(&self, theta: f64) -> (f64, f64) {
        match self {
            Curve::Linear(l) => (l.k * theta, l.k),
            Curve::Cubic(c) => (c.torque(theta), c.slope(theta)),
            Curve::Catalogue(c) => (c.spring_torque(theta), c.spring_slope(theta)),
        }
    }

    /// Potential energy `∫₀^θ f` [J].
    pub fn energy(&self, theta: f64) -> f64 {
        match self {
            Curve::Linear(l) => 0.5 * l.k * theta * theta,
            Curve::Cubic(c) => c.spring_energy(theta),
            Curve::Catalogue(c) => c.spring_energy(theta),
        }
    }
}

/// The hysteretic part of the law.
// Inline slip set, as for `Curve`.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hyst {
    /// None: the curve alone.
    None,
    /// Fading memory `ż = A·θ̇ − B·z` (rate-dependent, viscoelastic).
    Memory(FadingMemory),
    /// Bouc–Wen, carried as its torque z = α·w (rate-independent).
    BoucWen(BoucWen),
    /// Elastoplastic elements (rate-independent).
    Slip(SlipSet),
}

/// A stiffness law: curve plus hysteretic part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stiffness {
    /// The elastic curve.
    pub curve: Curve,
    /// The hysteretic part.
    pub hyst: Hyst,
}

impl Stiffness {
    /// A law without hysteresis.
    pub fn elastic(curve: Curve) -> Self {
        Self { curve, hyst: Hyst::None }
    }

    /// Torque, rates and partial derivatives at deflection θ [rad], rate θ̇ [rad/s], state
    /// z [N·m] and slip-element offsets `slots` [rad] (missing offsets count as 0).
    #[inline(always)]
    pub fn eval(&self, theta: f64, theta_dot: f64, z: f64, slots: &[f64]) -> StiffnessEval {
        let (f, df) = self.curve.torque_slope(theta);
        let mut e = StiffnessEval { torque: f, d_theta: df, ..Default::default() };
        match &self.hyst {
            Hyst::None => {}
            Hyst::Memory(m) => {
                e.torque += z;
                e.hyst = z;
                e.d_z = 1.0;
                e.z_rate = m.rate(theta_dot, z);
                e.z_rate_d_thetadot = m.a;
                e.z_rate_d_z = -m.b;
                if m.a > 0.0 {
                    e.dissipation = m.b * z * z / m.a;
                    e.diss_d_z = 2.0 * m.b * z / m.a;
                }
            }
            Hyst::BoucWen(bw) => bouc_wen_eval(bw, theta_dot, z, &mut e),
            Hyst::Slip(set) => {
                let (t, s) = set.torque(theta, slots);
                e.torque += t;
                e.d_theta += s;
                e.hyst = t;
            }
        }
        e
    }

    /// Potential energy of the elastic curve at θ [J].
    pub fn potential(&self, theta: f64) -> f64 {
        self.curve.energy(theta)
    }

    /// Energy held by the hysteretic part [J]: z²/(2A) for the memory, z²/(2αA) for
    /// Bouc–Wen, Σ ½kᵢeᵢ² for slip elements.
    pub fn hyst_energy(&self, theta: f64, z: f64, slots: &[f64]) -> f64 {
        match &self.hyst {
            Hyst::None => 0.0,
            Hyst::Memory(m) => {
                if m.a > 0.0 {
                    z * z / (2.0 * m.a)
                } else {
                    0.0
                }
            }
            Hyst::BoucWen(bw) => {
                let k = bw.alpha * bw.a;
                if k > 0.0 { z * z / (2.0 * k) } else { 0.0 }
            }
            Hyst::Slip(set) => set.stored(theta, slots),
        }
    }

    /// Stiffness at rest [N·m/rad]: the curve's slope at 0 plus the hysteretic part's
    /// initial stiffness (A, α·A or Σkᵢ); used to scale tolerances.
    pub fn reference_stiffness(&self) -> f64 {
        let hyst = match &self.hyst {
            Hyst::None => 0.0,
            Hyst::Memory(m) => m.a,
            Hyst::BoucWen(bw) => bw.alpha * bw.a,
            Hyst::Slip(set) => set.as_slice().iter().map(|e| e.k).sum(),
        };
        self.curve.torque_slope(0.0).1 + hyst
    }

    /// Whether the law carries the ODE state z (memory or Bouc–Wen).
    pub fn has_memory(&self) -> bool {
        matches!(self.hyst, Hyst::Memory(_) | Hyst::BoucWen(_))
    }

    /// The slip elements, if the law has them.
    pub fn slips(&self) -> Option<&SlipSet> {
        match &self.hyst {
            Hyst::Slip(s) if !s.is_empty() => Some(s),
            _ => None,
        }
    }
}

/// Bouc–Wen in torque units: with w = z/α,
/// `ż = α·θ̇·(A − |w|ⁿ·(β·sgn(θ̇·w) + γ))` and dissipated power
/// `(α/A)·|θ̇|·|w|ⁿ⁺¹·(β + γ·sgn(θ̇·w))`.
#[inline]
fn bouc_wen_eval(bw: &BoucWen, theta_dot: f64, z: f64, e: &mut StiffnessEval) {
    e.torque += z;
    e.hyst = z;
    e.d_z = 1.0;
    if bw.alpha <= 0.0 {
        return;
    }
    let w = z / bw.alpha;
    let s = (theta_dot * w).signum();
    let shape = bw.beta * s + bw.gamma;
    let aw = w.abs();
    let pn = aw.powf(bw.n);
    e.z_rate = bw.alpha * theta_dot * (bw.a - pn * shape);
    e.z_rate_d_thetadot = bw.alpha * (bw.a - pn * shape);
    // ∂|w|ⁿ/∂z = n·|w|ⁿ⁻¹·sgn(w)/α; undefined at w = 0 for n < 1, where 0 is used.
    let dpn_dz = if aw > 0.0 { bw.n * pn / aw * w.signum() / bw.alpha } else { 0.0 };
    e.z_rate_d_z = -bw.alpha * theta_dot * dpn_dz * shape;
    if bw.a > 0.0 {
        let c = bw.alpha / bw.a * (bw.beta + bw.gamma * s);
        e.dissipation = c * theta_dot.abs() * pn * aw;
        e.diss_d_thetadot = c * theta_dot.signum() * pn * aw;
        let dp1_dz = if aw > 0.0 { (bw.n + 1.0) * pn * w.signum() / bw.alpha } else { 0.0 };
        e.diss_d_z = c * theta_dot.abs() * dp1_dz;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The analytic partial derivatives of the Bouc–Wen part against central differences.
    #[test]
    fn bouc_wen_partials_match_differences() {
        let bw = BoucWen { alpha: 4e4, a: 1.0, beta: 3e3, gamma: 1e3, n: 1.5 };
        let law = Stiffness {
            curve: Curve::Cubic(CubicSpring { a: 0.1, b: 0.5, c: 5e4 }),
            hyst: Hyst::BoucWen(bw),
        };
        for (thd, z) in [(0.3, 2.0), (-0.2, 3.5), (0.5, -1.0), (-0.4, -2.5)] {
            let e = law.eval(1e-4, thd, z, &[]);
            let hz = 1e-6 * z.abs();
            let ht = 1e-6 * thd.abs();
            let ez = |z: f64| law.eval(1e-4, thd, z, &[]);
            let et = |t: f64| law.eval(1e-4, t, z, &[]);
            let num_zz = (ez(z + hz).z_rate - ez(z - hz).z_rate) / (2.0 * hz);
            let num_zt = (et(thd + ht).z_rate - et(thd - ht).z_rate) / (2.0 * ht);
            let num_dz = (ez(z + hz).dissipation - ez(z - hz).dissipation) / (2.0 * hz);
            let num_dt = (et(thd + ht).dissipation - et(thd - ht).dissipation) / (2.0 * ht);
            for (a, n) in [
                (e.z_rate_d_z, num_zz),
                (e.z_rate_d_thetadot, num_zt),
                (e.diss_d_z, num_dz),
                (e.diss_d_thetadot, num_dt),
            ] {
                assert!((a - n).abs() <= 1e-6 * n.abs().max(1e-3), "{a} vs {n}");
            }
            // Power in = rate of storage + dissipation: z·θ̇ = z·ż/(αA) + P.
            let balance = z * thd - z * e.z_rate / (bw.alpha * bw.a) - e.dissipation;
            assert!(balance.abs() <= 1e-12 * (z * thd).abs(), "{balance}");
        }
    }
}
