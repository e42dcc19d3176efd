//! The torque balance of the motor–gear–load chain (docs/model.md §2.6), written once for
//! every number type: how the motor's torque, the gear's transmitted torque Tb, its friction
//! Tf (acting where [`FrictionVelocity`] says), the load-side friction Tf_L, the dampings
//! and the load torque move the two inertias, and which speeds the gear's laws see.
//!
//! ```text
//! θ̇ = ωj/N − ωz        v = ωj/N (motor), θ̇ (deflection) or ωz (load)
//! Ta = (Tb + s_m·Tf)/N  Tout = Tb + s_l·Tf − Tf_L      (s_m, s_l: the friction's shares)
//! Jj·ω̇j = Tm − Cj·ωj − Ta               Jz·ω̇z = Tout − Cz·ωz − TL
//! ```
//!
//! The simulator ([`crate::system::DriveSystem`]: `f64` rates, and its analytic Jacobian by
//! the same code over dual numbers seeded with the laws' gradients) and the fit's assembly
//! ([`crate::compliant::Compliant`]: `f64` or dual numbers carrying parameter
//! sensitivities) take their speeds and accelerations from here, so a torque added to the
//! chain is added to both.

use crate::FrictionVelocity;
use crate::dual::Scalar;

/// The chain's constants: the gear ratio, the inertias (as reciprocals: every rate
/// evaluation multiplies by them) and the dampings, with where the gear's friction acts.
#[derive(Clone, Copy, Debug)]
pub struct Chain<T> {
    /// 1/N [–].
    pub inv_n: f64,
    /// 1/Jj [1/(kg·m²)].
    pub inv_jj: T,
    /// 1/Jz [1/(kg·m²)].
    pub inv_jz: T,
    /// Motor damping Cj [N·m·s/rad].
    pub cj: T,
    /// Load damping Cz [N·m·s/rad].
    pub cz: T,
    /// Where the gear's friction law acts.
    pub friction_velocity: FrictionVelocity,
}

/// The torques on the chain's two sides [N·m]: the gear's (stiffness and friction) as the
/// load feels it and as the wave generator feels it (already divided by N).
#[derive(Clone, Copy, Debug)]
pub struct GearTorques<T> {
    /// Torque the gear puts on the load, less the load-side friction, Tout [N·m].
    pub on_load: T,
    /// Torque the gear puts against the motor, Ta = (Tb + share·Tf)/N [N·m].
    pub on_motor: T,
}

impl<T: Scalar> Chain<T> {
    /// The chain of gear ratio `n` [–], inertias `jj`, `jz` [kg·m²] and dampings `cj`, `cz`
    /// [N·m·s/rad].
    pub fn new(n: f64, jj: T, jz: T, cj: T, cz: T, friction_velocity: FrictionVelocity) -> Self {
        let one = T::cst(1.0);
        Chain { inv_n: 1.0 / n, inv_jj: one / jj, inv_jz: one / jz, cj, cz, friction_velocity }
    }

    /// The gear's deflection rate θ̇ = ωj/N − ωz and the friction law's sliding speed v
    /// [rad/s] at motor and load speeds ωj, ωz [rad/s]: the one place the laws' speeds
    /// come from.
    #[inline(always)]
    pub fn speeds(&self, omega_j: T, omega_z: T) -> (T, T) {
        let theta_dot = omega_j.fmadd_f(self.inv_n, -omega_z);
        let v = match self.friction_velocity {
            FrictionVelocity::Motor => omega_j * self.inv_n,
            FrictionVelocity::Deflection => theta_dot,
            FrictionVelocity::Load => omega_z,
        };
        (theta_dot, v)
    }

    /// `(∂v/∂ωj, ∂v/∂ωz)`: the sliding speed as a fixed combination of the two speeds.
    pub fn v_coeffs(&self) -> (f64, f64) {
        match self.friction_velocity {
            FrictionVelocity::Motor => (self.inv_n, 0.0),
            FrictionVelocity::Deflection => (self.inv_n, -1.0),
            FrictionVelocity::Load => (0.0, 1.0),
        }
    }

    /// The gear's torques on the load and against the motor from its stiffness torque Tb,
    /// its friction torque Tf and the load-side friction Tf_L [N·m]: the friction acts on
    /// the wave generator (Tf/N against the motor), on the load alone (−Tf on the load) or
    /// across the gear (both).
    #[inline(always)]
    pub fn gear_torques(&self, tb: T, tf: T, tf_load: T) -> GearTorques<T> {
        let at_motor = tb * self.inv_n;
        let (on_load, on_motor) = match self.friction_velocity {
            FrictionVelocity::Motor => (tb, tf.fmadd_f(self.inv_n, at_motor)),
            FrictionVelocity::Deflection => (tb + tf, tf.fmadd_f(self.inv_n, at_motor)),
            FrictionVelocity::Load => (tb - tf, at_motor),
        };
        GearTorques { on_load: on_load - tf_load, on_motor }
    }

    /// The motor's and the load's accelerations (ω̇j, ω̇z) [rad/s²] at speeds ωj, ωz
    /// [rad/s], motor torque Tm = Km·i [N·m], gear torques `g` and load torque TL [N·m].
    #[inline(always)]
    pub fn accelerations(
        &self,
        omega_j: T,
        omega_z: T,
        motor: T,
        g: &GearTorques<T>,
        load: T,
    ) -> (T, T) {
        // The gear's torque, ready last, meets one multiply–add.
        let wj_rate =
            (-g.on_motor).fmadd(self.inv_jj, (-self.cj).fmadd(omega_j, motor) * self.inv_jj);
        let wz_rate = g.on_load.fmadd(self.inv_jz, -(self.cz.fmadd(omega_z, load)) * self.inv_jz);
        (wj_rate, wz_rate)
    }
}

impl Chain<f64> {
    /// The same chain in number type `U`, its constants carrying no derivatives (to
    /// differentiate the balance along the states only).
    pub fn as_constants<U: Scalar>(&self) -> Chain<U> {
        Chain {
            inv_n: self.inv_n,
            inv_jj: U::cst(self.inv_jj),
            inv_jz: U::cst(self.inv_jz),
            cj: U::cst(self.cj),
            cz: U::cst(self.cz),
            friction_velocity: self.friction_velocity,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dual::Dual;

    fn chain(fv: FrictionVelocity) -> Chain<f64> {
        Chain::new(80.0, 2e-4, 0.5, 1e-3, 0.2, fv)
    }

    /// The power the gear's torques deliver balances: with no damping, what leaves the
    /// motor (Ta·ωj) is what reaches the load (Tout·ωz), what the spring stores (Tb·θ̇),
    /// and what the friction dissipates (Tf·v, Tf_L·ωz), for every place the friction acts.
    #[test]
    fn the_gear_passes_on_the_power_it_does_not_store_or_dissipate() {
        for (_, fv) in FrictionVelocity::NAMES {
            let c = chain(fv);
            let (wj, wz) = (120.0, 1.3);
            let (tb, tf, tfl) = (7.0, 0.9, 0.4);
            let (thd, v) = c.speeds(wj, wz);
            let g = c.gear_torques(tb, tf, tfl);
            let lhs = g.on_motor * wj;
            let rhs = g.on_load * wz + tb * thd + tf * v + tfl * wz;
            assert!((lhs - rhs).abs() < 1e-12 * lhs.abs(), "{fv:?}: {lhs} vs {rhs}");
        }
    }

    /// Newton's law on each inertia: Jj·ω̇j = Tm − Cj·ωj − Ta and Jz·ω̇z = Tout − Cz·ωz − TL.
    #[test]
    fn each_inertia_accelerates_by_its_net_torque() {
        let c = chain(FrictionVelocity::Motor);
        let g = GearTorques { on_load: 3.0, on_motor: 0.05 };
        let (a, b) = c.accelerations(100.0, 1.0, 0.4, &g, 0.5);
        assert!((a * 2e-4 - (0.4 - 1e-3 * 100.0 - 0.05)).abs() < 1e-15);
        assert!((b * 0.5 - (3.0 - 0.2 - 0.5)).abs() < 1e-15);
    }

    /// Over dual numbers the balance carries the derivatives of its inputs: d(ω̇z)/dJz
    /// = −ω̇z/Jz, d(ω̇j)/dTb = −1/(N·Jj) with the friction on the motor.
    #[test]
    fn its_derivatives_are_the_closed_forms() {
        let seed = |v: f64, k: usize| {
            let mut d = Dual::<2> { v, d: [0.0; 2] };
            d.d[k] = 1.0;
            d
        };
        let cst = <Dual<2> as Scalar>::cst;
        let (jz, tb) = (seed(0.5, 0), seed(7.0, 1));
        let c = Chain::new(80.0, cst(2e-4), jz, cst(1e-3), cst(0.2), FrictionVelocity::Motor);
        let g = c.gear_torques(tb, cst(0.9), cst(0.0));
        let (a, b) = c.accelerations(cst(100.0), cst(1.0), cst(0.4), &g, cst(0.5));
        assert!((b.d[0] + b.v / 0.5).abs() < 1e-12 * b.v.abs());
        assert!((a.d[1] + 1.0 / (80.0 * 2e-4)).abs() < 1e-9);
    }
}
