//! The assembled drive: motor, gear (stiffness + friction) and load, as an ODE system
//! with its analytic Jacobian (docs/model.md §2.6).

use crate::balance::{Chain, GearTorques};
use crate::control::{Controller, CtlEval, Hold};
use crate::dual::{Dual, Scalar};
use crate::fma::fmadd;
use crate::laws::friction::LuGre;
use crate::laws::friction::{Friction, FrictionEval, FrictionLaw};
use crate::laws::input::Input;
use crate::laws::load::LoadTorque;
use crate::laws::motor::DcMotor;
use crate::laws::stiffness::{Stiffness, StiffnessEval};
use crate::params::Params;
use crate::solver::OdeSystem;
use crate::state::*;
use crate::variant::{FrictionKind, StiffnessKind, friction_law, load_friction_law, stiffness_law};
use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

/// Which speed the friction law sees.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FrictionVelocity {
    /// `v = ωj/N` (the seed's choice): friction acts on the wave generator only.
    #[default]
    Motor,
    /// `v = θ̇ = ωj/N − ωz`: friction acts across the gear, on both sides (−Tf/N on
    /// the motor, +Tf on the load), so its power is `Tf·θ̇`.
    Deflection,
    /// `v = ωz`: friction acts on the load only (−Tf on the load; the output bearing's or
    /// the guide's friction), so its power is `Tf·ωz`.
    Load,
}

impl FrictionVelocity {
    /// Every setting, by its name in study files, params files and on the command line.
    pub const NAMES: [(&'static str, FrictionVelocity); 3] = [
        ("motor", FrictionVelocity::Motor),
        ("deflection", FrictionVelocity::Deflection),
        ("load", FrictionVelocity::Load),
    ];

    /// The setting's name (`motor`, `deflection`, `load`).
    pub fn name(self) -> &'static str {
        Self::NAMES.iter().find(|(_, v)| *v == self).map_or("motor", |(n, _)| n)
    }
}

impl std::str::FromStr for FrictionVelocity {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Self::NAMES.iter().find(|(n, _)| *n == s).map(|(_, v)| *v).ok_or_else(|| {
            format!("'{s}': expected one of {}", Self::NAMES.map(|(n, _)| n).join(", "))
        })
    }
}

/// The motor–gear–load system.
#[derive(Clone, Debug)]
pub struct DriveSystem {
    /// Stiffness law of the gear.
    pub stiffness: Stiffness,
    /// Friction law of the gear.
    pub friction: Friction,
    /// The DC motor.
    pub motor: DcMotor,
    /// Armature voltage of an open-loop run (ignored when a controller is set).
    pub input: Input,
    /// External load torque on the load side.
    pub load: LoadTorque,
    /// Closed-loop controller; `None` drives the motor open loop with `input`.
    pub ctl: Option<Controller>,
    /// Values a sampled controller holds over the current sampling period.
    pub hold: Hold,
    /// Speed seen by the friction law.
    pub friction_velocity: FrictionVelocity,
    /// A second LuGre law on the load's speed ωz (the `*_load` parameters), beside the
    /// gear's own; its bristle is the state `W_LOAD`.
    pub friction_load: Option<LuGre>,
    /// Gear ratio N [–] (read-only after [`DriveSystem::new`], which derives 1/N).
    pub n: f64,
    /// Motor inertia Jj [kg·m²] (read-only after `new`, which derives 1/Jj).
    pub jj: f64,
    /// Load inertia Jz [kg·m²] (read-only after `new`, which derives 1/Jz).
    pub jz: f64,
    /// 1/N, 1/Jj [1/(kg·m²)] and 1/Jz: every rate evaluation multiplies by them (a
    /// division's latency is several multiplications' on the critical path).
    inv_n: f64,
    inv_jj: f64,
    inv_jz: f64,
    /// Motor damping Cj [N·m·s/rad].
    pub cj: f64,
    /// Load damping Cz [N·m·s/rad].
    pub cz: f64,
    /// Constant load torque TL [N·m], added to `load`'s.
    pub tl: f64,
}

/// The controller's states in `y`: integrator, derivative filter, observer, pre-filter.
pub fn ctl_states(y: &State) -> [f64; 4] {
    [y[CTL_I], y[CTL_D], y[OBS_W], y[CMP_Q]]
}

/// Everything the right-hand side computes at one instant, shared by the RHS, the
/// Jacobian and the reported signals.
#[derive(Clone, Copy, Debug)]
pub struct Parts {
    /// Voltage u [V].
    pub u: f64,
    /// Current i [A].
    pub i: f64,
    /// Deflection rate θ̇ [rad/s].
    pub theta_dot: f64,
    /// Sliding speed v [rad/s].
    pub v: f64,
    /// Stiffness law output.
    pub st: StiffnessEval,
    /// Friction law output.
    pub fr: FrictionEval,
    /// The load-side law's output at v = ωz (zero without that law).
    pub fr_load: FrictionEval,
    /// Torque on the load from the gear [N·m].
    pub t_out: f64,
    /// Torque on the wave generator `Ta = (Tb + Tf)/N` (`Tb/N` with the friction on the
    /// load alone) [N·m].
    pub ta: f64,
    /// External load torque T_L [N·m].
    pub tl: f64,
    /// The controller's outputs (closed loop only).
    pub ctl: Option<CtlEval>,
}

impl DriveSystem {
    /// Assemble the system from parameters, law choices and input; the error names the
    /// stiffness parameter a law could not be built from.
    pub fn new(
        p: &Params,
        stiffness: StiffnessKind,
        friction: FrictionKind,
        input: Input,
        friction_velocity: FrictionVelocity,
    ) -> Result<Self, crate::error::ConfigError> {
        Ok(Self {
            stiffness: stiffness_law(stiffness, p)?,
            friction: friction_law(friction, p),
            motor: DcMotor { r: p.r, km: p.km, ke: p.ke, l: p.l },
            input,
            load: LoadTorque::default(),
            ctl: None,
            hold: Hold::default(),
            friction_velocity,
            friction_load: load_friction_law(p, friction_velocity)?,
            n: p.n,
            inv_n: 1.0 / p.n,
            inv_jj: 1.0 / p.jj,
            inv_jz: 1.0 / p.jz,
            jj: p.jj,
            jz: p.jz,
            cj: p.cj,
            cz: p.cz,
            tl: p.tl,
        })
    }

    /// Whether all of the system's stiffness is the bristle term that
    /// [`OdeSystem::stiff_split`] hands to the implicit–explicit method (no inductance,
    /// no friction observer).
    pub fn split_covers_stiffness(&self) -> bool {
        let observer = self.ctl.as_ref().is_some_and(|c| c.friction.has_state());
        !self.motor.has_inductance() && !observer && self.friction_load.is_none()
    }

    /// Whether the system has a stiff part that calls for the implicit method.
    pub fn is_stiff(&self) -> bool {
        let observer = self.ctl.as_ref().is_some_and(|c| c.friction.has_state());
        matches!(self.friction, Friction::LuGre(_))
            || self.motor.has_inductance()
            || observer
            || self.friction_load.is_some()
    }

    /// The frequency of the periodic drive [Hz]: the reference's in closed loop, the
    /// input's open loop.
    pub fn drive_frequency(&self) -> Option<f64> {
        match &self.ctl {
            Some(c) => c.reference().period().map(|p| 1.0 / p),
            None => self.input.drive_frequency(),
        }
    }

    /// Load angle θz = θj/N − θ [rad].
    pub fn theta_z(&self, y: &State) -> f64 {
        y[THETA_J] / self.n - y[THETA]
    }

    /// The chain's torque balance ([`crate::balance`]) at this drive's constants.
    #[inline(always)]
    fn chain(&self) -> Chain<f64> {
        Chain {
            inv_n: self.inv_n,
            inv_jj: self.inv_jj,
            inv_jz: self.inv_jz,
            cj: self.cj,
            cz: self.cz,
            friction_velocity: self.friction_velocity,
        }
    }

    /// Evaluate the laws at (t, y).
    #[inline]
    pub fn parts(&self, t: f64, y: &State) -> Parts {
        self.parts_with(t, y, |v, tb| self.friction.eval_loaded(v, y[W], tb))
    }

    /// The gear's deflection rate θ̇ = ωj/N − ωz and the friction law's sliding speed v
    /// [rad/s] in state y ([`Chain::speeds`]).
    #[inline(always)]
    fn gear_speeds(&self, y: &State) -> (f64, f64) {
        self.chain().speeds(y[OMEGA_J], y[OMEGA_Z])
    }

    /// Evaluate the laws at (t, y), the friction law by `friction(v, Tb)` (sliding speed
    /// [rad/s], transmitted torque [N·m]).
    #[inline(always)]
    fn parts_with(
        &self,
        t: f64,
        y: &State,
        friction: impl FnOnce(f64, f64) -> FrictionEval,
    ) -> Parts {
        let ctl =
            self.ctl.as_ref().map(|c| c.eval(t, &self.measured(y), &ctl_states(y), &self.hold));
        let u = ctl.map_or_else(|| self.input.value(t), |c| c.u);
        let i = if self.motor.has_inductance() {
            y[CURRENT]
        } else {
            self.motor.static_current(u, y[OMEGA_J])
        };
        let (theta_dot, v) = self.gear_speeds(y);
        let st = self.stiffness.eval(y[THETA], theta_dot, y[Z], slots(y));
        let fr = friction(v, st.torque);
        let fr_load = self.load_friction(y);
        let g = self.chain().gear_torques(st.torque, fr.torque, fr_load.torque);
        let (t_out, ta) = (g.on_load, g.on_motor);
        let tl = self.load.value(t) + self.tl;
        Parts { u, i, theta_dot, v, st, fr, fr_load, t_out, ta, tl, ctl }
    }

    /// The load-side law's output in state y (v = ωz, bristle `W_LOAD`); zero without it.
    #[inline(always)]
    fn load_friction(&self, y: &State) -> FrictionEval {
        self.friction_load
            .as_ref()
            .map_or_else(FrictionEval::default, |l| l.eval(y[OMEGA_Z], y[W_LOAD]))
    }

    /// The stiffness torque Tb and the friction torque Tf [N·m] in state y with rates
    /// `rate` (the solver's f(t, y)): the values [`DriveSystem::parts`] gives, with the
    /// friction torque read from the bristle rate instead of the Stribeck level
    /// ([`FrictionLaw::torque_with_rate`]), so no exponential is evaluated.
    pub fn gear_torque_pair(&self, y: &State, rate: &State) -> (f64, f64) {
        let (theta_dot, v) = self.gear_speeds(y);
        let tb = self.stiffness.eval(y[THETA], theta_dot, y[Z], slots(y)).torque;
        (tb, self.friction.torque_with_rate(v, y[W], rate[W]))
    }

    /// The stiffness torque Tb [N·m] and the friction law's output in state y.
    fn gear_laws(&self, y: &State) -> (f64, FrictionEval) {
        let (theta_dot, v) = self.gear_speeds(y);
        let tb = self.stiffness.eval(y[THETA], theta_dot, y[Z], slots(y)).torque;
        (tb, self.friction.eval_loaded(v, y[W], tb))
    }

    /// The state rates from the laws' values `p` at (t, y).
    #[inline]
    pub(crate) fn rates(&self, y: &State, p: &Parts) -> State {
        let mut d = State::zeros();
        self.rates_into(y, p, &mut d);
        d
    }

    /// [`DriveSystem::rates`] written into `d` (every component set).
    #[inline(always)]
    fn rates_into(&self, y: &State, p: &Parts, d: &mut State) {
        let m = &self.motor;
        let (wj, wz) = (y[OMEGA_J], y[OMEGA_Z]);
        *d = State::zeros();
        d[THETA_J] = wj;
        let g = GearTorques { on_load: p.t_out, on_motor: p.ta };
        (d[OMEGA_J], d[OMEGA_Z]) = self.chain().accelerations(wj, wz, m.torque(p.i), &g, p.tl);
        d[THETA] = p.theta_dot;
        d[Z] = p.st.z_rate;
        d[W] = p.fr.w_rate;
        d[W_LOAD] = p.fr_load.w_rate;
        if m.has_inductance() {
            d[CURRENT] = m.current_rate(p.u, p.i, wj);
        }
        if let Some(c) = p.ctl {
            d[CTL_I] = c.rates[0];
            d[CTL_D] = c.rates[1];
            d[OBS_W] = c.rates[2];
            d[CMP_Q] = c.rates[3];
        }
        d[Q_LOAD] = p.tl * wz;
        d[Q_HYST] = p.st.hyst * p.theta_dot;
        d[Q_FRIC] = fmadd(p.fr_load.torque, wz, p.fr.torque * p.v);
        d[Q_OUT] = (p.t_out * wz).max(0.0);
        d[Q_IN] = (p.ta * wj).max(0.0);
        d[Q_ELEC] = p.u * p.i;
        d[Q_DISS] = m.r * p.i * p.i + self.cj * wj * wj + self.cz * wz * wz + p.st.dissipation;
    }

    /// The state at rest with zero current and no stored memory or bristle torque.
    pub fn rest_state(&self) -> State {
        State::zeros()
    }

    /// What the controller's sensors see in `y` (ideal; a sampled controller quantises).
    pub fn measured(&self, y: &State) -> crate::control::Measured {
        crate::control::Measured {
            theta_z: self.theta_z(y),
            theta_j: y[THETA_J],
            omega_j: y[OMEGA_J],
        }
    }

    /// Total stored energy: kinetic, spring, memory and magnetic [J].
    pub fn stored_energy(&self, y: &State) -> f64 {
        let ke = 0.5 * self.jj * y[OMEGA_J].powi(2) + 0.5 * self.jz * y[OMEGA_Z].powi(2);
        let magnetic =
            if self.motor.has_inductance() { 0.5 * self.motor.l * y[CURRENT].powi(2) } else { 0.0 };
        ke + self.stiffness.potential(y[THETA])
            + self.stiffness.hyst_energy(y[THETA], y[Z], slots(y))
            + magnetic
    }
}

impl OdeSystem<DIM> for DriveSystem {
    const COUPLED: usize = COUPLED;
    // The plant and the controller's integrator: two vector registers. Open loop the
    // integrator's rate is zero, so the stages leave it at zero.
    const COUPLED_LEAD: usize = PLANT + 1;

    fn coupled(&self) -> usize {
        if self.ctl.is_some() || self.friction_load.is_some() { COUPLED } else { PLANT }
    }

    fn live(&self) -> usize {
        // The slip energy and the slip offsets change only in `commit`.
        LIVE
    }

    #[inline]
    fn rhs(&self, t: f64, y: &State) -> State {
        self.rates(y, &self.parts(t, y))
    }

    fn rhs_into(&self, t: f64, y: &State, rate: &mut State) {
        self.rates_into(y, &self.parts(t, y), rate);
    }

    fn may_be_stiff(&self) -> bool {
        self.is_stiff()
    }

    fn split_is_complete(&self) -> bool {
        self.friction.has_state() && self.split_covers_stiffness()
    }

    fn implicit_stage(&self, t: f64, y: &mut State, k: usize, c: f64, rate: &mut State) -> f64 {
        assert_eq!(k, W, "the drive's split component is the bristle torque");
        // The bristle rate is affine in w: the friction law solves the stage for w and
        // evaluates itself there, inside the one evaluation of the laws.
        let base = y[W];
        let mut w = base;
        let p = self.parts_with(t, y, |v, tb| {
            let (solved, fr) = self.friction.implicit_state(v, base, c, tb);
            w = solved;
            fr
        });
        y[W] = w;
        self.rates_into(y, &p, rate);
        p.fr.w_rate_d_w
    }

    fn jacobian(&self, t: f64, y: &State) -> (SMatrix<f64, DIM, DIM>, State) {
        type G = SVector<f64, COUPLED>;
        type D = Dual<COUPLED>;
        let unit = |k: usize| G::ith(k, 1.0);
        let p = self.parts(t, y);
        // The command's gradient over the coupled states and its explicit time rate: zero
        // gradient and the input's slope open loop; the controller's otherwise.
        let cj = self.ctl.as_ref().map(|_| self.controller_jacobian(t, y));
        let (g_u, du) = match &cj {
            Some(c) => (c.g_u, c.du_dt),
            None => (G::zeros(), self.input.value_and_rate(t).1),
        };
        let m = &self.motor;
        let (wj, wz) = (y[OMEGA_J], y[OMEGA_Z]);
        let inductive = m.has_inductance();

        // Gradients (over the coupled states) of the intermediate quantities; the chain's
        // balance ([`Chain`]) is differentiated by running it on numbers that carry them.
        let chain: Chain<D> = self.chain().as_constants();
        let dual = |v: f64, g: G| D { v, d: std::array::from_fn(|k| g[k]) };
        let grad = |x: D| G::from(x.d);
        let cst = <D as Scalar>::cst;
        let (wj_d, wz_d) = (dual(wj, unit(OMEGA_J)), dual(wz, unit(OMEGA_Z)));
        let (thd_d, v_d) = chain.speeds(wj_d, wz_d);
        let (g_thd, g_v) = (grad(thd_d), grad(v_d));
        let g_tb = p.st.d_theta * unit(THETA) + p.st.d_z * unit(Z);
        let g_tf = p.fr.d_v * g_v + p.fr.d_w * unit(W) + p.fr.d_tb * g_tb;
        let g_i = if inductive { unit(CURRENT) } else { (g_u - m.ke * unit(OMEGA_J)) / m.r };
        let g_tf_load = p.fr_load.d_v * unit(OMEGA_Z) + p.fr_load.d_w * unit(W_LOAD);
        let torques = chain.gear_torques(
            dual(p.st.torque, g_tb),
            dual(p.fr.torque, g_tf),
            dual(p.fr_load.torque, g_tf_load),
        );
        let motor = dual(m.torque(p.i), m.km * g_i);
        let (wj_rate, wz_rate) = chain.accelerations(wj_d, wz_d, motor, &torques, cst(p.tl));
        let (g_out, g_ta) = (grad(torques.on_load), grad(torques.on_motor));
        // ∂(u-dependent terms)/∂t: only the current depends on u directly.
        let di_dt = if inductive { 0.0 } else { du / m.r };

        let mut rows: [G; DIM] = [G::zeros(); DIM];
        let mut dfdt = State::zeros();
        rows[THETA_J] = unit(OMEGA_J);
        rows[OMEGA_J] = grad(wj_rate);
        dfdt[OMEGA_J] = m.km * di_dt / self.jj;
        rows[THETA] = g_thd;
        rows[OMEGA_Z] = grad(wz_rate);
        dfdt[OMEGA_Z] = -self.load.rate(t) / self.jz;
        rows[Z] = p.st.z_rate_d_thetadot * g_thd + p.st.z_rate_d_z * unit(Z);
        rows[W] = p.fr.w_rate_d_v * g_v + p.fr.w_rate_d_w * unit(W) + p.fr.w_rate_d_tb * g_tb;
        if self.friction_load.is_some() {
            rows[W_LOAD] =
                p.fr_load.w_rate_d_v * unit(OMEGA_Z) + p.fr_load.w_rate_d_w * unit(W_LOAD);
        }
        if inductive {
            rows[CURRENT] = (g_u - m.r * unit(CURRENT) - m.ke * unit(OMEGA_J)) / m.l;
            dfdt[CURRENT] = du / m.l;
        }
        // ∂(hysteretic torque) = ∂Tb less the curve's slope (the hysteretic torque's own
        // slope in θ is the slip elements' sticking stiffness).
        let curve_slope = self.stiffness.curve.torque_slope(y[THETA]).1;
        let g_hyst = (p.st.d_theta - curve_slope) * unit(THETA) + p.st.d_z * unit(Z);
        rows[Q_HYST] = p.st.hyst * g_thd + p.theta_dot * g_hyst;
        rows[Q_FRIC] =
            p.v * g_tf + p.fr.torque * g_v + wz * g_tf_load + p.fr_load.torque * unit(OMEGA_Z);
        if p.t_out * wz > 0.0 {
            rows[Q_OUT] = wz * g_out + p.t_out * unit(OMEGA_Z);
        }
        if p.ta * wj > 0.0 {
            rows[Q_IN] = wj * g_ta + p.ta * unit(OMEGA_J);
        }
        if let Some(c) = &cj {
            for (k, idx) in [CTL_I, CTL_D, OBS_W, CMP_Q].into_iter().enumerate() {
                rows[idx] = c.rows[k];
                dfdt[idx] = c.drates_dt[k];
            }
        }
        rows[Q_LOAD] = p.tl * unit(OMEGA_Z);
        dfdt[Q_LOAD] = self.load.rate(t) * wz;
        rows[Q_ELEC] = p.u * g_i + p.i * g_u;
        dfdt[Q_ELEC] = du * p.i + p.u * di_dt;
        rows[Q_DISS] = 2.0 * m.r * p.i * g_i
            + 2.0 * self.cj * wj * unit(OMEGA_J)
            + 2.0 * self.cz * wz * unit(OMEGA_Z)
            + p.st.diss_d_z * unit(Z)
            + p.st.diss_d_thetadot * g_thd;
        dfdt[Q_DISS] = 2.0 * m.r * p.i * di_dt;

        let mut jac = SMatrix::<f64, DIM, DIM>::zeros();
        for (r, g) in rows.iter().enumerate().take(LIVE) {
            for c in 0..COUPLED {
                jac[(r, c)] = g[c];
            }
        }
        (jac, dfdt)
    }

    fn stiff_split(&self, _t: f64, y: &State) -> Option<(usize, f64)> {
        // ẇ = σ0·v − (σ0·|v|/G(v, Tb))·w: v and Tb do not depend on w.
        if !self.friction.has_state() {
            return None;
        }
        Some((W, self.gear_laws(y).1.w_rate_d_w))
    }

    fn switch_value(&self, _t: f64, y: &State) -> Option<f64> {
        // LuGre's bristle rate has |v| in it: a kink where the sliding speed reverses. With
        // only the load-side law, that is where the load reverses; with both, the gear law's
        // kink is located and the load law's is left to error control.
        let (a, b) = if self.friction.has_state() {
            self.chain().v_coeffs()
        } else if self.friction_load.is_some() {
            (0.0, 1.0)
        } else {
            return None;
        };
        Some(a * y[OMEGA_J] + b * y[OMEGA_Z])
    }

    fn switch_rate(&self, t: f64, _y: &State, f: &State) -> Option<f64> {
        // v is a fixed combination of the speeds: its rate is the same combination of
        // their rates, which is the switching function applied to f.
        self.switch_value(t, f)
    }

    fn commit(&self, t0: f64, t1: f64, y0: &State, f0: &State, y1: &mut State, f1: &State) {
        if let Some(set) = self.stiffness.slips() {
            let path = deflection_path(t1 - t0, y0[THETA], f0[THETA], y1[THETA], f1[THETA]);
            let n = set.len();
            let mut o = [0.0; crate::laws::slip_set::MAX_SLIP];
            o[..n].copy_from_slice(&y1.as_slice()[SLIP..SLIP + n]);
            y1[Q_SLIP] += set.commit(path.as_slice(), &mut o[..n]);
            y1.as_mut_slice()[SLIP..SLIP + n].copy_from_slice(&o[..n]);
        }
    }

    fn abs_scale(&self) -> State {
        // The deflection is held to the same absolute accuracy as a torque: an error of
        // atol [N·m] in Tb, i.e. atol/k0 [rad] in θ.
        let mut s = State::from_element(1.0);
        s[THETA] = 1.0 / self.stiffness.reference_stiffness().max(1.0);
        s
    }
}

/// The slip elements' offsets held in `y` [rad].
#[inline]
pub fn slots(y: &State) -> &[f64] {
    &y.as_slice()[SLIP..]
}

/// The deflection along an accepted step of length `h` [s] at its start, at each turning
/// point of the step's cubic Hermite interpolant (from θ0, θ̇0, θ1, θ̇1), and at its end:
/// the path is monotone between consecutive entries.
pub fn deflection_path(h: f64, th0: f64, thd0: f64, th1: f64, thd1: f64) -> DeflectionPath {
    let mut p = DeflectionPath { pts: [th0, 0.0, 0.0, 0.0], len: 1 };
    if h > 0.0 {
        // dθ/ds = a·s² + b·s + c over s ∈ [0, 1].
        let d = th0 - th1;
        let (a, b, c) = (
            6.0 * d + 3.0 * h * (thd0 + thd1),
            -6.0 * d - 4.0 * h * thd0 - 2.0 * h * thd1,
            h * thd0,
        );
        let mut roots = [f64::NAN; 2];
        if a.abs() > 1e-300 {
            let disc = b * b - 4.0 * a * c;
            if disc > 0.0 {
                let q = -0.5 * (b + disc.sqrt().copysign(b));
                roots = [q / a, if q != 0.0 { c / q } else { f64::NAN }];
            }
        } else if b != 0.0 {
            roots[0] = -c / b;
        }
        roots.sort_by(f64::total_cmp);
        for s in roots {
            if s > 0.0 && s < 1.0 {
                let [h00, h10, h01, h11] = crate::interp::hermite_basis(s);
                p.pts[p.len] = h00 * th0 + h10 * h * thd0 + h01 * th1 + h11 * h * thd1;
                p.len += 1;
            }
        }
    }
    p.pts[p.len] = th1;
    p.len += 1;
    p
}

/// A deflection path of at most four points (see [`deflection_path`]).
#[derive(Clone, Copy, Debug)]
pub struct DeflectionPath {
    pts: [f64; 4],
    len: usize,
}

impl DeflectionPath {
    /// The points [rad].
    pub fn as_slice(&self) -> &[f64] {
        &self.pts[..self.len]
    }
}
