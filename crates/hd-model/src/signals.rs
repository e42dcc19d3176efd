//! Derived signals at one instant: the reported coordinates of docs/model.md §1 and the
//! seed's K(t) and C0(t), NaN where they are undefined (§2, §3).

use crate::laws::friction::FrictionLaw;
use crate::state::*;
use crate::system::{DriveSystem, FrictionVelocity};

/// All reported signals at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Time [s].
    pub t: f64,
    /// Voltage [V].
    pub u: f64,
    /// Current [A].
    pub i: f64,
    /// Motor angle [rad].
    pub theta_j: f64,
    /// Motor speed [rad/s].
    pub omega_j: f64,
    /// Load angle [rad].
    pub theta_z: f64,
    /// Load speed [rad/s].
    pub omega_z: f64,
    /// Deflection [rad].
    pub theta: f64,
    /// Hysteretic torque [N·m] (memory z, Bouc–Wen α·w, or Σkᵢeᵢ of slip elements).
    pub z: f64,
    /// Bristle deflection [rad].
    pub s: f64,
    /// Transmitted torque [N·m].
    pub tb: f64,
    /// Friction torque [N·m].
    pub tf: f64,
    /// dTb/dθ [N·m/rad].
    pub k: f64,
    /// dTf/dv [N·m·s/rad].
    pub c0: f64,
    /// Load-angle reference [rad] (NaN open loop).
    pub reference: f64,
    /// Tracking error [rad] (NaN open loop).
    pub error: f64,
    /// Friction feedforward [V] (NaN open loop).
    pub u_ff: f64,
    /// Friction estimate [N·m] (NaN open loop).
    pub tf_hat: f64,
    /// Transmitted-torque estimate [N·m] (NaN open loop).
    pub tb_hat: f64,
}

/// Thresholds below which the ratio signals are reported as NaN.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thresholds {
    /// Smallest |θ̇| [rad/s] at which K is defined (memory laws only).
    pub theta_dot: f64,
    /// Smallest |v̇| [rad/s²] at which C0 is defined (stateful friction laws only).
    pub v_dot: f64,
}

impl Default for Thresholds {
    fn default() -> Self {
        Self { theta_dot: 1e-9, v_dot: 1e-9 }
    }
}

impl DriveSystem {
    /// Load angle θz = θj/N − θ [rad] of state y.
    pub fn load_angle(&self, y: &State) -> f64 {
        y[THETA_J] / self.n - y[THETA]
    }

    /// Reported signals at (t, y).
    pub fn sample(&self, t: f64, y: &State, eps: &Thresholds) -> Sample {
        let p = self.parts(t, y);
        // The state's rates from the laws just evaluated (what `rhs` would evaluate again),
        // for the signals that need them.
        let rates = std::cell::OnceCell::new();
        let d = || *rates.get_or_init(|| self.rates(y, &p));
        let k = if self.stiffness.has_memory() {
            // K = dTb/dt / θ̇ = ∂Tb/∂θ + ∂Tb/∂z · ż/θ̇.
            if p.theta_dot.abs() > eps.theta_dot {
                p.st.d_theta + p.st.d_z * p.st.z_rate / p.theta_dot
            } else {
                f64::NAN
            }
        } else {
            p.st.d_theta
        };
        let c0 = if self.friction.has_state() {
            // C0 = dTf/dt / v̇ = ∂Tf/∂v + (∂Tf/∂w · ẇ + ∂Tf/∂Tb · Ṫb)/v̇ (the last term
            // only with load-dependent levels).
            let d = d();
            let v_dot = match self.friction_velocity {
                FrictionVelocity::Motor => d[OMEGA_J] / self.n,
                FrictionVelocity::Deflection => d[OMEGA_J] / self.n - d[OMEGA_Z],
                FrictionVelocity::Load => d[OMEGA_Z],
            };
            if v_dot.abs() > eps.v_dot {
                let tb_rate = p.st.d_theta * p.theta_dot + p.st.d_z * p.st.z_rate;
                p.fr.d_v + (p.fr.d_w * p.fr.w_rate + p.fr.d_tb * tb_rate) / v_dot
            } else {
                f64::NAN
            }
        } else {
            p.fr.d_v
        };
        let nan = f64::NAN;
        let (reference, error, u_ff, tf_hat, tb_hat) = match (p.ctl, self.ctl.as_ref()) {
            (Some(c), Some(ctl)) => {
                let wj_dot = d()[OMEGA_J];
                let tb_hat = ctl.torque_estimate(p.i, y[OMEGA_J], wj_dot, c.tf_hat);
                (c.reference, c.error, c.u_ff, c.tf_hat, tb_hat)
            }
            _ => (nan, nan, nan, nan, nan),
        };
        Sample {
            t,
            u: p.u,
            i: p.i,
            theta_j: y[THETA_J],
            omega_j: y[OMEGA_J],
            theta_z: self.load_angle(y),
            omega_z: y[OMEGA_Z],
            theta: y[THETA],
            z: p.st.hyst,
            s: self.friction.deflection(y[W]),
            tb: p.st.torque,
            tf: p.fr.torque,
            k,
            c0,
            reference,
            error,
            u_ff,
            tf_hat,
            tb_hat,
        }
    }
}

impl crate::trace::Trace {
    /// Append one sample.
    pub fn push(&mut self, s: &Sample) {
        self.t.push(s.t);
        self.u.push(s.u);
        self.i.push(s.i);
        self.theta_j.push(s.theta_j);
        self.omega_j.push(s.omega_j);
        self.theta_z.push(s.theta_z);
        self.omega_z.push(s.omega_z);
        self.theta.push(s.theta);
        self.z.push(s.z);
        self.s.push(s.s);
        self.tb.push(s.tb);
        self.tf.push(s.tf);
        self.k.push(s.k);
        self.c0.push(s.c0);
        self.reference.push(s.reference);
        self.error.push(s.error);
        self.u_ff.push(s.u_ff);
        self.tf_hat.push(s.tf_hat);
        self.tb_hat.push(s.tb_hat);
    }
}
