//! A simulator run ([`SimConfig`]) as the compliant assembly, and the simulator's state
//! vector as the assembly's [`State`] and back, so that a host can advance the run at a
//! fixed step ([`crate::solver::fixed_step`]) and still read every signal the way the
//! simulator samples it.

use super::model::{Compliant, NAMES, P, State, gear_law, ix, on_law};
use super::supported::{load_law_problem, unsupported};
use crate::registry;
use crate::state::{OMEGA_J, OMEGA_Z, Q_DISS, Q_ELEC, Q_FRIC, Q_HYST, Q_IN, Q_LOAD, Q_OUT};
use crate::state::{Q_SLIP, SLIP, THETA, THETA_J, W, W_LOAD, Z};
use crate::{HystLaw, SimConfig, Variant};

/// The energy integrals of the simulator's state: a fixed-step run does not carry them.
const QUADRATURES: [usize; 8] = [Q_HYST, Q_FRIC, Q_OUT, Q_IN, Q_ELEC, Q_DISS, Q_LOAD, Q_SLIP];

/// The drive of a run, as the compliant assembly steps it.
#[derive(Clone, Debug)]
pub struct FixedDrive {
    /// The assembly at the run's parameters.
    pub drive: Compliant<f64>,
    /// The gear's hysteretic law.
    pub law: HystLaw,
    /// The slip elements' offsets oᵢ = eᵢ − θ [rad] (Maxwell-slip gears; empty otherwise).
    pub offsets: Vec<f64>,
    /// The run's constant load torque TL [N·m], to which a host's load torque adds.
    pub tl: f64,
}

/// The compliant assembly of `cfg`'s drive, or every setting of `cfg` it cannot stand for,
/// one sentence each, naming the setting.
pub fn fixed_drive(cfg: &SimConfig) -> Result<FixedDrive, String> {
    let mut problems = Vec::new();
    if cfg.variant != Variant::Full {
        problems.push(format!(
            "variant = \"{}\": a fixed step integrates the `full` variant only",
            cfg.variant.name()
        ));
    }
    if cfg.controller.is_some() {
        problems.push(
            "[controller]: a fixed step integrates the open-loop drive only (the host closes the loop)"
                .to_string(),
        );
    }
    problems.extend(unsupported(&cfg.params, Some(cfg.stiffness)));
    let mut p: [f64; P] = [0.0; P];
    for (k, name) in NAMES.iter().enumerate() {
        match registry::find(name) {
            Some(info) => p[k] = info.get(&cfg.params),
            None => problems.push(format!("{name}: not a parameter of the simulator")),
        }
    }
    on_law(&mut p, cfg.stiffness);
    if let Some(e) = load_law_problem(&p, cfg.friction_velocity) {
        problems.push(e);
    }
    if !problems.is_empty() {
        return Err(problems.join("; "));
    }
    let drive = Compliant::new(p, cfg.params.n).with_friction_velocity(cfg.friction_velocity);
    let offsets = vec![0.0; drive.slip_count()];
    Ok(FixedDrive { law: gear_law(&p), drive, offsets, tl: cfg.params.tl })
}

impl FixedDrive {
    /// The simulator's state `y` in the assembly's coordinates (the slip offsets are read
    /// into [`FixedDrive::offsets`]).
    pub fn read(&mut self, y: &crate::state::State) -> State<f64> {
        for (i, o) in self.offsets.iter_mut().enumerate() {
            *o = y[SLIP + i];
        }
        let bouc_wen = self.law == HystLaw::BoucWen;
        let alpha = self.drive.p[ix::BW_ALPHA];
        State {
            theta_j: y[THETA_J],
            omega_j: y[OMEGA_J],
            theta: y[THETA],
            omega_z: y[OMEGA_Z],
            // The simulator carries the Bouc–Wen element as its torque α·h.
            z: if bouc_wen { 0.0 } else { y[Z] },
            h: if bouc_wen { y[Z] / alpha } else { 0.0 },
            w: y[W],
            w_load: y[W_LOAD],
        }
    }

    /// Write the assembly's state `s` (and the slip offsets) back into the simulator's `y`.
    /// The energy integrals, which a fixed step does not carry, become NaN (not computed).
    pub fn write(&self, s: &State<f64>, y: &mut crate::state::State) {
        y[THETA_J] = s.theta_j;
        y[OMEGA_J] = s.omega_j;
        y[THETA] = s.theta;
        y[OMEGA_Z] = s.omega_z;
        y[Z] = if self.law == HystLaw::BoucWen { self.drive.p[ix::BW_ALPHA] * s.h } else { s.z };
        y[W] = s.w;
        y[W_LOAD] = s.w_load;
        for (i, o) in self.offsets.iter().enumerate() {
            y[SLIP + i] = *o;
        }
        for q in QUADRATURES {
            y[q] = f64::NAN;
        }
    }

    /// Advance `y` by `h` [s] in `m` equal substeps, the voltage u(τ) = `u0` + `du`·τ [V]
    /// and the load torque `t_load` [N·m] (added to the run's TL) held over the span (τ from
    /// its start).
    pub fn advance(
        &mut self,
        y: &mut crate::state::State,
        h: f64,
        m: usize,
        u0: f64,
        du: f64,
        t_load: f64,
    ) {
        let m = m.max(1);
        let d = h / m as f64;
        self.drive.p[ix::TL] = self.tl + t_load;
        let mut s = self.read(y);
        let mut o = std::mem::take(&mut self.offsets);
        for k in 0..m {
            let t0 = k as f64 * d;
            let u = [u0 + du * t0, u0 + du * (t0 + 0.5 * d), u0 + du * (t0 + d)];
            s = self.drive.step(&s, &mut o, u, d);
        }
        self.offsets = o;
        self.write(&s, y);
    }
}
