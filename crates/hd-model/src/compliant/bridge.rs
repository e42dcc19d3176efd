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
        // The simulator's one hysteresis state: the memory's torque z, or the Bouc–Wen
        // element's torque α·h; the other laws leave it unused.
        let (memory, bouc_wen) = (self.law == HystLaw::Memory, self.law == HystLaw::BoucWen);
        let alpha = self.drive.p[ix::BW_ALPHA];
        State {
            theta_j: y[THETA_J],
            omega_j: y[OMEGA_J],
            theta: y[THETA],
            omega_z: y[OMEGA_Z],
            z: if memory { y[Z] } else { 0.0 },
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
        y[Z] = match self.law {
            HystLaw::BoucWen => self.drive.p[ix::BW_ALPHA] * s.h,
            HystLaw::Memory => s.z,
            _ => y[Z],
        };
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::DIM;
    use crate::{FrictionVelocity, Input};

    /// A state of `cfg`'s drive away from rest: every coupled state of the plant and the
    /// load-side bristle set from `seed` (a small linear congruential sequence), each slip
    /// element's deflection θ + oᵢ within its yield ms_delta·(i + 1)/n, as every accepted
    /// step leaves it.
    fn state(seed: u64, slips: usize, delta: f64) -> crate::state::State {
        let mut x = seed;
        let mut next = |scale: f64| {
            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            scale * ((x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0)
        };
        let mut y = crate::state::State::zeros();
        for (k, scale) in
            [(THETA_J, 3.0), (OMEGA_J, 80.0), (THETA, 2e-4), (OMEGA_Z, 0.8), (Z, 2.0), (W, 0.15)]
        {
            y[k] = next(scale);
        }
        y[W_LOAD] = next(0.05);
        for i in 0..slips {
            y[SLIP + i] = next(delta * (i + 1) as f64 / slips as f64) - y[THETA];
        }
        y
    }

    /// The two assemblies of the drive's equations, the simulator's (`DriveSystem`, with its
    /// analytic Jacobian) and the generic one the fits and the fixed step run, give the same
    /// rates at random states, for every gear law, every place of the gear's friction and
    /// with a load-side law: to rounding, 3e-14 of each rate at most (measured 3.3e-15),
    /// and within 1e-12 of its size or of one where a rate is near zero.
    #[test]
    fn both_assemblies_give_the_same_rates() {
        let mut worst: f64 = 0.0;
        let laws = [HystLaw::Memory, HystLaw::BoucWen, HystLaw::MaxwellSlip, HystLaw::Catalogue];
        let places =
            [FrictionVelocity::Motor, FrictionVelocity::Load, FrictionVelocity::Deflection];
        for law in laws {
            for fv in places {
                for load_law in [false, true] {
                    if load_law && fv == FrictionVelocity::Load {
                        continue;
                    }
                    let mut cfg = SimConfig {
                        stiffness: law,
                        friction_velocity: fv,
                        input: Input::Constant { amplitude: 7.5 },
                        ..SimConfig::default()
                    };
                    cfg.params.cat_loss = 0.0;
                    cfg.params.tl = 0.03;
                    if load_law {
                        cfg.params.tc_load = 0.05;
                        cfg.params.ts_load = 0.08;
                        cfg.params.ws_load = 0.02;
                        cfg.params.sigma0_load = 2e4;
                        cfg.params.sigma1_load = 0.5;
                    }
                    let sys = cfg.system().unwrap();
                    let mut fixed = fixed_drive(&cfg).unwrap();
                    let slips = fixed.offsets.len();
                    for seed in 1..40 {
                        let y = state(seed, slips, cfg.params.ms_delta);
                        let d = sys.rates(&y, &sys.parts(0.0, &y));
                        let s = fixed.read(&y);
                        let r = fixed.drive.rates(&s, 7.5, &fixed.offsets);
                        let z_rate = if law == HystLaw::BoucWen {
                            fixed.drive.p[ix::BW_ALPHA] * r.h
                        } else {
                            r.z
                        };
                        let pairs = [
                            (r.theta_j, d[THETA_J]),
                            (r.omega_j, d[OMEGA_J]),
                            (r.theta, d[THETA]),
                            (r.omega_z, d[OMEGA_Z]),
                            (z_rate, d[Z]),
                            (r.w, d[W]),
                            (r.w_load, d[W_LOAD]),
                        ];
                        for (k, (a, b)) in pairs.into_iter().enumerate() {
                            let e = (a - b).abs() / (b.abs() + 1e-300);
                            let ok = (a - b).abs() <= 1e-12 * b.abs() + 1e-12 * b.abs().max(1.0);
                            assert!(
                                ok,
                                "{law:?} {fv:?} load law {load_law}, seed {seed}, rate {k}: {a} vs {b}"
                            );
                            if b.abs() > 1e-9 {
                                worst = worst.max(e);
                            }
                        }
                        assert_eq!(d.len(), DIM);
                    }
                }
            }
        }
        assert!(worst < 3e-14, "{worst}");
    }
}
