//! The fixed-step integration of the compliant drive ([`crate::compliant`]): classical
//! Runge–Kutta on the mechanics, with each LuGre bristle carried by its integrating factor
//! (the Lawson form of the same method). The fits step their generic model with it, on
//! `f64` and on dual numbers alike; a host that wants a fixed step (real time, HIL) gets the
//! same integration.

use crate::compliant::model::{Compliant, State};
use crate::dual::Scalar;

impl<T: Scalar> Compliant<T> {
    /// One step of `d` [s] from `y` with the voltage `u(τ)` at τ = 0, d/2 and d
    /// ([`Compliant::step_by`] with the model's own rates), the slip elements' offsets `o`
    /// held over it and then committed ([`Compliant::commit`]).
    pub fn step(&self, y: &State<T>, o: &mut [T], u: [f64; 3], d: f64) -> State<T> {
        if o.is_empty() {
            return self.step_by(y, |s, at| self.rates(s, u[at], &[]), d);
        }
        let next = self.step_by(y, |s, at| self.rates(s, u[at], o), d);
        self.commit(y, &next, o);
        next
    }

    /// One step of `d` [s] from `y`, `rates(state, at)` giving the rates with the input at
    /// τ = 0 (`at` = 0), d/2 (1) and d (2): classical Runge–Kutta for the mechanics, the
    /// memory and the motor, with each bristle's distance from the value it relaxes to at
    /// the step's start, w − w̄ (w̄ = sign(v)·G(v)), carried by its integrating factor
    /// e^{−λ0·τ} (λ0 the relaxation rate there; the Lawson form of the same method about
    /// w̄). A bristle that relaxes far faster than the step stays stable and exact at a
    /// held speed, and its stages sit at w̄, not at 0: about 0, a stage of a step with
    /// λ0·d ≫ 1 would put the sliding bristle at σ0·|v|·d/6 instead of its level (measured:
    /// three times the level at λ0·d = 19, and the fit's run unstable from there). One
    /// step for every input the drive takes: a voltage test's voltage, a loop's held
    /// command.
    pub fn step_by(
        &self,
        y: &State<T>,
        rates: impl Fn(&State<T>, usize) -> State<T>,
        d: f64,
    ) -> State<T> {
        // Each bristle (the gear law's w; the load-side law's w_L) carried by its own factor.
        let (l0, rest) = self.relaxation(y);
        let e_half = (-(l0 * (0.5 * d))).exp();
        let e_full = e_half * e_half;
        let load_law = self.law_load.is_some();
        let (l_load, rest_load) = self.relaxation_load(y);
        let f_half = if load_law { (-(l_load * (0.5 * d))).exp() } else { T::cst(1.0) };
        let f_full = f_half * f_half;
        // The bristles' rates less their stiff parts, g = ẇ + λ0·(w − w̄), drive the
        // transformed states (the distances from w̄).
        let with_g = |k: State<T>, at: &State<T>| State {
            w: k.w + l0 * (at.w - rest),
            w_load: if load_law { k.w_load + l_load * (at.w_load - rest_load) } else { k.w_load },
            ..k
        };
        let (u0, u0_load) = (y.w - rest, y.w_load - rest_load);
        let k1 = with_g(rates(y, 0), y);
        let mut y2 = y.add(&k1, 0.5 * d);
        y2.w = rest + e_half * (u0 + k1.w * (0.5 * d));
        if load_law {
            y2.w_load = rest_load + f_half * (u0_load + k1.w_load * (0.5 * d));
        }
        let k2 = with_g(rates(&y2, 1), &y2);
        let mut y3 = y.add(&k2, 0.5 * d);
        y3.w = rest + e_half * u0 + k2.w * (0.5 * d);
        if load_law {
            y3.w_load = rest_load + f_half * u0_load + k2.w_load * (0.5 * d);
        }
        let k3 = with_g(rates(&y3, 1), &y3);
        let mut y4 = y.add(&k3, d);
        y4.w = rest + e_full * u0 + e_half * k3.w * d;
        if load_law {
            y4.w_load = rest_load + f_full * u0_load + f_half * k3.w_load * d;
        }
        let k4 = with_g(rates(&y4, 2), &y4);
        let sixth = d / 6.0;
        let comb = |a: T, b: T, c: T, e: T| (a + (b + c) * 2.0 + e) * sixth;
        State {
            theta_j: y.theta_j + comb(k1.theta_j, k2.theta_j, k3.theta_j, k4.theta_j),
            omega_j: y.omega_j + comb(k1.omega_j, k2.omega_j, k3.omega_j, k4.omega_j),
            theta: y.theta + comb(k1.theta, k2.theta, k3.theta, k4.theta),
            omega_z: y.omega_z + comb(k1.omega_z, k2.omega_z, k3.omega_z, k4.omega_z),
            z: y.z + comb(k1.z, k2.z, k3.z, k4.z),
            w: rest + e_full * u0 + (e_full * k1.w + e_half * (k2.w + k3.w) * 2.0 + k4.w) * sixth,
            h: y.h + comb(k1.h, k2.h, k3.h, k4.h),
            w_load: if load_law {
                rest_load
                    + f_full * u0_load
                    + (f_full * k1.w_load + f_half * (k2.w_load + k3.w_load) * 2.0 + k4.w_load)
                        * sixth
            } else {
                y.w_load
            },
        }
    }
}
