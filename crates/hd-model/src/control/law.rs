//! The assembled controller: reference, PID with derivative filter, anti-windup and
//! saturation, friction-observer feedforward and compliance pre-distortion, evaluated in
//! continuous time (docs/model.md §6.2–6.4).

use super::{ControllerConfig, Feedback, Hold, Reference};
use crate::error::ConfigError;
use crate::laws::friction::{Friction, FrictionLaw};
use crate::laws::stiffness::Stiffness;
use crate::params::Params;
use crate::variant::{FrictionKind, StiffnessKind, friction_law, stiffness_law};

/// What the controller measures at one instant (ideal sensors; the sampled controller
/// quantises them itself).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    /// Load angle θz [rad].
    pub theta_z: f64,
    /// Motor angle θj [rad].
    pub theta_j: f64,
    /// Motor speed ωj [rad/s].
    pub omega_j: f64,
}

/// The controller's own states: integrator [rad·s], derivative filter [rad], observer
/// bristle torque [N·m] and compliance pre-filter [N·m].
pub type CtlStates = [f64; 4];

/// The controller's outputs and state rates at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CtlEval {
    /// Load-angle reference θz_ref [rad].
    pub reference: f64,
    /// Reference speed [rad/s].
    pub ref_speed: f64,
    /// Tracking error θz_ref − θz of the true load angle [rad].
    pub error: f64,
    /// Voltage command after saturation [V].
    pub u: f64,
    /// Voltage command before saturation [V].
    pub u_raw: f64,
    /// Feedforward part of the command (friction compensation) [V].
    pub u_ff: f64,
    /// Friction torque the controller model estimates [N·m].
    pub tf_hat: f64,
    /// Rates of the controller states (zero for the held states of a sampled
    /// controller).
    pub rates: CtlStates,
}

/// A controller assembled from its configuration and the controller model's parameters.
#[derive(Clone, Debug)]
pub struct Controller {
    /// The settings.
    pub cfg: ControllerConfig,
    /// Controller-model gear ratio N [–].
    pub n: f64,
    /// Controller-model armature resistance R [Ω].
    pub r: f64,
    /// Controller-model torque constant Km [N·m/A].
    pub km: f64,
    /// Controller-model motor inertia Jj [kg·m²].
    pub jj: f64,
    /// Controller-model motor damping Cj [N·m·s/rad].
    pub cj: f64,
    /// Controller-model load inertia Jz [kg·m²].
    pub jz: f64,
    /// Controller-model load damping Cz [N·m·s/rad].
    pub cz: f64,
    /// Controller-model friction law (the plant's law, the model's parameters).
    pub friction: Friction,
    /// Controller-model stiffness law.
    pub stiffness: Stiffness,
}

impl Controller {
    /// Assemble the controller for a plant with parameters `plant` and laws of the given
    /// kinds; the model uses the same laws with `cfg.model`'s parameter values.
    pub fn new(
        cfg: &ControllerConfig,
        plant: &Params,
        stiffness: StiffnessKind,
        friction: FrictionKind,
    ) -> Result<Self, ConfigError> {
        let m = cfg.model_params(plant)?;
        Ok(Self {
            cfg: cfg.clone(),
            n: m.n,
            r: m.r,
            km: m.km,
            jj: m.jj,
            cj: m.cj,
            jz: m.jz,
            cz: m.cz,
            friction: friction_law(friction, &m),
            stiffness: stiffness_law(stiffness, &m)?,
        })
    }

    /// Whether the controller runs sampled with a zero-order hold.
    pub fn is_sampled(&self) -> bool {
        self.cfg.period > 0.0
    }

    /// The reference.
    pub fn reference(&self) -> &Reference {
        &self.cfg.reference
    }

    /// Deflection θ̂ [rad] the model's stiffness law needs to transmit the torque the
    /// reference motion asks of the gear, `T_req = Jz·θ̈z_ref + Cz·θ̇z_ref`, given the
    /// pre-filter state q = ẑ − A·θ̂: the root of `f(θ̂) + A·θ̂ + q = T_req` (for the linear
    /// law `K̄·θ̂ = T_req`). Newton's method on the law's own torque and slope.
    pub fn predicted_deflection(&self, ref_speed: f64, ref_accel: f64, q: f64) -> f64 {
        let t_req = self.jz * ref_accel + self.cz * ref_speed;
        let a = self.stiffness.eval(0.0, 0.0, 0.0, &[]).z_rate_d_thetadot;
        let g = |th: f64| {
            let e = self.stiffness.eval(th, 0.0, 0.0, &[]);
            (e.torque + a * th + q - t_req, e.d_theta + a)
        };
        let mut th = (t_req - q) / g(0.0).1;
        for _ in 0..50 {
            let (res, slope) = g(th);
            let step = res / slope;
            th -= step;
            if step.abs() <= 1e-15 * th.abs().max(1e-300) {
                break;
            }
        }
        th
    }

    /// Rate of the compliance pre-filter, `q̇ = −B·(q + A·θ̂)` [N·m/s] (the model's memory
    /// `ż = A·θ̂̇ − B·ẑ` rewritten for q = ẑ − A·θ̂, which stays continuous where θ̂ jumps).
    fn prefilter_rate(&self, q: f64, theta_pred: f64) -> f64 {
        let e = self.stiffness.eval(0.0, 0.0, 0.0, &[]);
        let (a, b) = (e.z_rate_d_thetadot, -e.z_rate_d_z);
        -b * (q + a * theta_pred)
    }

    /// Reference for the fed-back angle [rad] and the load reference, its speed, and the
    /// pre-filter rate, at time t with pre-filter state q.
    pub fn feedback_reference(&self, t: f64, q: f64) -> (f64, [f64; 3], f64) {
        let r = self.cfg.reference.eval(t);
        if !self.cfg.compensation.compliance() {
            return (r[0], r, 0.0);
        }
        let theta_pred = self.predicted_deflection(r[1], r[2], q);
        let shift = if self.cfg.feedback == Feedback::Motor { theta_pred } else { 0.0 };
        (r[0] + shift, r, self.prefilter_rate(q, theta_pred))
    }

    /// The fed-back angle [rad] from the measured angles.
    pub fn feedback_angle(&self, theta_z: f64, theta_j: f64) -> f64 {
        match self.cfg.feedback {
            Feedback::Load => theta_z,
            Feedback::Motor => theta_j / self.n,
        }
    }

    /// Friction feedforward voltage for an estimated friction torque tf_hat [N·m]: the
    /// voltage whose current cancels Tf/N at the motor, `R·Tf/(N·Km)` [V] (0 when the
    /// friction compensation is off).
    pub fn friction_feedforward(&self, tf_hat: f64) -> f64 {
        if self.cfg.compensation.friction() { self.r * tf_hat / (self.n * self.km) } else { 0.0 }
    }

    /// The PID command before saturation [V] for error e [rad], integrator i [rad·s] and
    /// filter state x [rad]: `u_ff + kp·e + ki·i + kd·(e − x)/τd`.
    pub fn pid(&self, u_ff: f64, e: f64, i: f64, x: f64) -> f64 {
        let c = &self.cfg;
        u_ff + c.kp * e + c.ki * i + c.kd * (e - x) / c.tau_d
    }

    /// Saturated command [V].
    pub fn saturate(&self, u_raw: f64) -> f64 {
        u_raw.clamp(-self.cfg.u_max, self.cfg.u_max)
    }

    /// Integrator rate with back-calculation anti-windup, `e + (u − u_raw)/kp` [rad]
    /// (tracking time constant kp/ki).
    pub fn integrator_rate(&self, e: f64, u: f64, u_raw: f64) -> f64 {
        if self.cfg.kp > 0.0 { e + (u - u_raw) / self.cfg.kp } else { e }
    }

    /// Transmitted torque estimated from the motor equation, the virtual torque sensor:
    /// `T̂b = N·(Km·i − Cj·ωj − Jj·ω̇j) − T̂f` [N·m], with current i [A], motor speed ωj
    /// [rad/s], acceleration ω̇j [rad/s²] and friction estimate tf_hat [N·m] (0 for an
    /// estimate without friction model).
    pub fn torque_estimate(&self, i: f64, omega_j: f64, omega_j_dot: f64, tf_hat: f64) -> f64 {
        self.n * (self.km * i - self.cj * omega_j - self.jj * omega_j_dot) - tf_hat
    }

    /// Outputs and state rates at time t for measurement `m`, controller states `s` and,
    /// for a sampled controller, the held values `hold`.
    pub fn eval(&self, t: f64, m: &Measured, s: &CtlStates, hold: &Hold) -> CtlEval {
        let [i, x, w_hat, q] = *s;
        let (r_fb, r, q_rate) = self.feedback_reference(t, q);
        let error = r[0] - m.theta_z;
        if self.is_sampled() {
            return CtlEval {
                reference: r[0],
                ref_speed: r[1],
                error,
                u: hold.u,
                u_raw: hold.u_raw,
                u_ff: hold.u_ff,
                tf_hat: hold.tf_hat,
                rates: [0.0, 0.0, 0.0, q_rate],
            };
        }
        let e = r_fb - self.feedback_angle(m.theta_z, m.theta_j);
        let fr = self.friction.eval(m.omega_j / self.n, w_hat);
        let u_ff = self.friction_feedforward(fr.torque);
        let u_raw = self.pid(u_ff, e, i, x);
        let u = self.saturate(u_raw);
        CtlEval {
            reference: r[0],
            ref_speed: r[1],
            error,
            u,
            u_raw,
            u_ff,
            tf_hat: fr.torque,
            rates: [self.integrator_rate(e, u, u_raw), (e - x) / self.cfg.tau_d, fr.w_rate, q_rate],
        }
    }
}
