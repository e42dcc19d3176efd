//! The Fisher information of a candidate input: the compliant fit's own residuals and exact
//! Jacobian ([`residuals_and_jacobian`]) on a record of the input, logged noise-free by the
//! same simulation ([`simulate_on_zeros`]), each output divided by its noise level; so
//! JᵀJ is the information the fit would get from it. Columns are taken with respect to
//! the parameters' logarithms (relative changes), as the fit steps them. The input is
//! scaled to the largest amplitude whose simulated peaks stay within the rig's limits.
//!
//! Samples where an encoder creeps (moves less than 1.5 counts to the next sample) are not
//! counted, in a candidate's information or in the prior: there the rounding error is a
//! staircase fixed by the true angle, which a fit can follow, not independent noise of
//! count/√12 ([`crate::drive::compliant::creeping`], the rule the fit's own verdict
//! applies). A design whose motion stays under a count per sample would otherwise be
//! credited with information its refits do not find.

use super::closed::Loop;
use crate::drive::compliant::creeping::{drop_creeping, masks};
use crate::drive::compliant::fit::{CompliantSpec, residuals_and_jacobian, simulate_on_zeros};
use crate::drive::compliant::model::{P, State};
use crate::drive::compliant::{CurrentSampled, Signal, VoltageRecord};
use nalgebra::DMatrix;

/// The rig's limits. `None`: not limited.
#[derive(Clone, Debug, PartialEq)]
pub struct Limits {
    /// Peak position reference of a closed-loop design [rad, on the fed-back encoder];
    /// None for a voltage test. Some exactly when the problem has a loop.
    pub reference: Option<f64>,
    /// Peak voltage [V].
    pub voltage: f64,
    /// Peak armature current [A].
    pub current: Option<f64>,
    /// Peak motor speed [rad/s].
    pub speed: Option<f64>,
    /// Peak load speed [rad/s].
    pub load_speed: Option<f64>,
    /// Peak gear deflection [rad].
    pub deflection: Option<f64>,
    /// Peak torque the gear transmits [N·m].
    pub torque: Option<f64>,
    /// Largest excursion of the load from its starting angle, either way [rad] (a rig's
    /// range of travel).
    pub load_angle: Option<f64>,
    /// Record length [s].
    pub duration: f64,
    /// Sample rate [Hz].
    pub rate: f64,
}

impl Limits {
    /// Samples of a record [–].
    pub fn samples(&self) -> usize {
        (self.duration * self.rate).round() as usize + 1
    }
}

/// The simulated peaks of a run (over every Runge–Kutta substep).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Peaks {
    /// |r| of a closed-loop design's reference [rad] (0 for a voltage test).
    pub reference: f64,
    /// |u| [V].
    pub voltage: f64,
    /// |i| [A].
    pub current: f64,
    /// |ωj| [rad/s].
    pub speed: f64,
    /// |ωz| [rad/s].
    pub load_speed: f64,
    /// |θ| [rad].
    pub deflection: f64,
    /// |τ| transmitted by the gear [N·m].
    pub torque: f64,
    /// |θz − θz(0)| [rad].
    pub load_angle: f64,
}

impl Peaks {
    /// (name, peak, limit, unit) of every limited quantity.
    pub fn against(&self, l: &Limits) -> Vec<(&'static str, f64, f64, &'static str)> {
        let mut v = Vec::new();
        if let Some(r) = l.reference {
            v.push(("reference", self.reference, r, "rad"));
        }
        v.push(("voltage", self.voltage, l.voltage, "V"));
        for (name, peak, lim, unit) in [
            ("current", self.current, l.current, "A"),
            ("speed", self.speed, l.speed, "rad/s"),
            ("load speed", self.load_speed, l.load_speed, "rad/s"),
            ("deflection", self.deflection, l.deflection, "rad"),
            ("torque", self.torque, l.torque, "N·m"),
            ("load angle", self.load_angle, l.load_angle, "rad"),
        ] {
            if let Some(lim) = lim {
                v.push((name, peak, lim, unit));
            }
        }
        v
    }

    /// The largest peak/limit ratio and its quantity.
    pub fn worst(&self, l: &Limits) -> (&'static str, f64) {
        self.against(l)
            .into_iter()
            .map(|(n, p, lim, _)| (n, p / lim))
            .fold(("voltage", 0.0), |a, b| if b.1 > a.1 { b } else { a })
    }
}

/// The noise levels of a new record's outputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// Motor encoder [rad].
    pub motor: f64,
    /// Load encoder [rad].
    pub load: f64,
    /// Current [A]; None: the current is not logged.
    pub current: Option<f64>,
}

/// What a design is computed for: the drive, its free parameters, the noise and the prior
/// information (the already fitted records').
#[derive(Clone, Debug)]
pub struct Problem {
    /// The fit's settings (gear ratio, voltage between samples, substeps, ties, offsets);
    /// its outputs are replaced by [`Problem::noise`].
    pub spec: CompliantSpec,
    /// The drive's parameters ([`crate::drive::compliant::NAMES`] order).
    pub values: [f64; P],
    /// The free parameters (no followers), [`crate::drive::compliant::NAMES`] indices.
    pub free: Vec<usize>,
    /// The new record's noise levels.
    pub noise: Noise,
    /// Information of the records already fitted, over `free` in log coordinates (zeros
    /// when there are none).
    pub prior: DMatrix<f64>,
    /// The rig's limits.
    pub limits: Limits,
    /// The loop of a closed-loop design (the input is then its position reference); None
    /// for a voltage test.
    pub closed: Option<Loop>,
}

/// The simulated response of a run, sampled at the record's samples.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Response {
    /// Voltage across the motor [V].
    pub voltage: Vec<f64>,
    /// Current [A].
    pub current: Vec<f64>,
    /// Motor speed [rad/s].
    pub speed: Vec<f64>,
    /// Load speed [rad/s].
    pub load_speed: Vec<f64>,
    /// Gear deflection [rad].
    pub deflection: Vec<f64>,
    /// Torque the gear transmits [N·m].
    pub torque: Vec<f64>,
    /// Load angle from its start [rad].
    pub load: Vec<f64>,
}

impl Problem {
    /// The spec of a single new record with [`Problem::noise`].
    pub fn record_spec(&self) -> CompliantSpec {
        let mut outputs =
            vec![(Signal::Motor, vec![self.noise.motor]), (Signal::Load, vec![self.noise.load])];
        if let Some(c) = self.noise.current {
            outputs.push((Signal::Current, vec![c]));
        }
        if let Some(l) = &self.closed {
            outputs.push((Signal::Command, vec![l.command_noise]));
        }
        CompliantSpec { noise_estimated: vec![false; outputs.len()], outputs, ..self.spec.clone() }
    }

    /// Each free parameter's scale: |value| (1 where zero).
    pub fn scales(&self) -> Vec<f64> {
        self.free
            .iter()
            .map(|&k| if self.values[k] != 0.0 { self.values[k].abs() } else { 1.0 })
            .collect()
    }

    /// A record of input `u` (voltage [V], or a closed loop's reference [rad]) at the
    /// limits' rate, its outputs the drive's own (noise-free); in closed loop its command
    /// column is the simulated command.
    pub fn record(&self, u: &[f64]) -> VoltageRecord {
        let mut rec = self.blank(u);
        let spec = CompliantSpec { current_offset: false, ..self.record_spec() };
        let (sim, _, _) = simulate_on_zeros(&spec, &spec.drive(self.values), &rec);
        if rec.closed.is_some() {
            rec.u = sim.command;
        }
        rec.theta_m = sim.theta_m;
        rec.theta_l = sim.theta_l;
        if rec.current.is_some() {
            rec.current = Some(sim.current);
        }
        rec
    }

    /// A record of input `u` at the limits' rate with zero outputs (in closed loop, `u`
    /// is the reference and the command column zero).
    pub(crate) fn blank(&self, u: &[f64]) -> VoltageRecord {
        let n = u.len();
        let h = 1.0 / self.limits.rate;
        let zeros = vec![0.0; n];
        VoltageRecord {
            name: "design".into(),
            source: "design".into(),
            h,
            t: (0..n).map(|k| k as f64 * h).collect(),
            u: if self.closed.is_some() { zeros.clone() } else { u.to_vec() },
            theta_m: zeros.clone(),
            theta_l: zeros.clone(),
            current: self.noise.current.map(|_| zeros),
            closed: self.closed.as_ref().map(|l| l.closed(u)),
            current_sampled: CurrentSampled::After,
        }
    }

    /// Peaks and response of the drive under input `u` (over every substep), stepped as
    /// the fit's simulation steps it: a voltage, or in closed loop the reference
    /// ([`super::closed::response`]).
    pub fn response(&self, u: &[f64]) -> (Peaks, Response) {
        if let Some(l) = &self.closed {
            return super::closed::response(self, l, u);
        }
        let spec = &self.spec;
        let d = spec.drive(self.values);
        let rec = self.blank(u);
        let m = spec.substeps.max(1);
        let step = rec.h / m as f64;
        let mut y = State::<f64>::rest(0.0);
        let mut slips = vec![0.0; d.slip_count()];
        let mut pk =
            Peaks { voltage: u.iter().fold(0.0f64, |a, v| a.max(v.abs())), ..Default::default() };
        let mut r = Response::default();
        let n = u.len();
        // The load angle θz = θj/N − θ, from its start (the rest state's θz is 0).
        let track = |y: &State<f64>, i: f64, tau: f64, pk: &mut Peaks| {
            pk.current = pk.current.max(i.abs());
            pk.speed = pk.speed.max(y.omega_j.abs());
            pk.load_speed = pk.load_speed.max(y.omega_z.abs());
            pk.deflection = pk.deflection.max(y.theta.abs());
            pk.torque = pk.torque.max(tau.abs());
            pk.load_angle = pk.load_angle.max((y.theta_j / d.n - y.theta).abs());
        };
        for (k, &uk) in u.iter().enumerate() {
            let i = d.current(rec.voltage_at_current(k, spec.between), y.omega_j);
            let tau = d.gear_torque(&y, &slips);
            track(&y, i, tau, &mut pk);
            r.voltage.push(uk);
            r.current.push(i);
            r.speed.push(y.omega_j);
            r.load_speed.push(y.omega_z);
            r.deflection.push(y.theta);
            r.torque.push(tau);
            r.load.push(y.theta_j / d.n - y.theta);
            if k + 1 == n {
                break;
            }
            for j in 0..m {
                let at = |f: f64| rec.voltage(k, (j as f64 + f) / m as f64, spec.between);
                y = d.step(&y, &mut slips, [at(0.0), at(0.5), at(1.0)], step);
                let i = d.current(at(1.0), y.omega_j);
                track(&y, i, d.gear_torque(&y, &slips), &mut pk);
            }
        }
        (pk, r)
    }

    /// Scale `shape` (peak 1) to the largest amplitude whose simulated peaks stay within
    /// the limits (the voltage's exactly; the others by repeated proportional steps, the
    /// response being close to proportional above the friction). Returns the input, its
    /// peaks and the quantity that binds.
    pub fn scaled(&self, shape: &[f64]) -> Scaled {
        // The amplitude's own limit: the reference's in closed loop, else the voltage's.
        let (lead, limit) = match self.limits.reference {
            Some(r) => ("reference", r),
            None => ("voltage", self.limits.voltage),
        };
        let mut a = limit;
        let mut tries = 0;
        loop {
            let u: Vec<f64> = shape.iter().map(|v| v * a).collect();
            let (peaks, response) = self.response(&u);
            let (worst, ratio) = peaks.worst(&self.limits);
            tries += 1;
            if ratio <= 1.0 + 1e-9 || tries >= 12 || !ratio.is_finite() {
                let own = if lead == "reference" { peaks.reference } else { peaks.voltage };
                let binds = if (own / limit - 1.0).abs() < 1e-9 && ratio <= 1.0 + 1e-9 {
                    lead
                } else {
                    worst
                };
                return Scaled {
                    u,
                    peaks,
                    response,
                    binds,
                    within: ratio <= 1.0 + 1e-9,
                    amplitude: a,
                };
            }
            a *= 0.995 / ratio;
        }
    }

    /// The information of the noise-free record of voltage `u` over [`Problem::free`], log
    /// coordinates, or None where the drive cannot be simulated: the samples where an
    /// encoder creeps not counted (the module's note).
    pub fn information(&self, u: &[f64]) -> Option<DMatrix<f64>> {
        self.information_of(u, true)
    }

    /// [`Problem::information`] with every sample counted, creeping or not: JᵀJ of the
    /// fit's own Jacobian.
    pub fn information_all(&self, u: &[f64]) -> Option<DMatrix<f64>> {
        self.information_of(u, false)
    }

    fn information_of(&self, u: &[f64], drop_creep: bool) -> Option<DMatrix<f64>> {
        let rec = self.record(u);
        let spec = self.record_spec();
        let records = std::slice::from_ref(&rec);
        let (r, mut j) = residuals_and_jacobian(&spec, &self.values, &self.free, records);
        if !r.iter().all(|v| v.is_finite()) || !j.iter().all(|v| v.is_finite()) {
            return None;
        }
        if drop_creep {
            drop_creeping(&mut j, &masks(&spec, records, is_encoder));
        }
        for (c, s) in self.scales().iter().enumerate() {
            j.column_mut(c).scale_mut(*s);
        }
        Some(j.transpose() * j)
    }
}

/// An input scaled to the limits.
#[derive(Clone, Debug)]
pub struct Scaled {
    /// The input at the record's samples: voltage [V], or a closed loop's reference [rad].
    pub u: Vec<f64>,
    /// Its simulated peaks.
    pub peaks: Peaks,
    /// Its simulated response.
    pub response: Response,
    /// The limit that binds (`reference`, `voltage`, `current`, `speed`, `load speed`,
    /// `deflection`, `torque` or `load angle`).
    pub binds: &'static str,
    /// Whether every peak is within its limit.
    pub within: bool,
    /// The shape's amplitude [V, or rad of a reference].
    pub amplitude: f64,
}

/// Whether `o` is an encoder, whose samples creep (a current or a command does not count).
fn is_encoder(o: Signal) -> bool {
    matches!(o, Signal::Motor | Signal::Load)
}

/// Information of `records` (log coordinates) over `free` at `values`, each output divided
/// by `spec`'s noise levels: the prior of a design (zeros without records).
pub fn prior_information(
    spec: &CompliantSpec,
    values: &[f64; P],
    free: &[usize],
    records: &[VoltageRecord],
) -> DMatrix<f64> {
    let k = free.len();
    if records.is_empty() {
        return DMatrix::zeros(k, k);
    }
    let (_, mut j) = residuals_and_jacobian(spec, values, free, records);
    drop_creeping(&mut j, &masks(spec, records, is_encoder));
    for (c, &p) in free.iter().enumerate() {
        let s = if values[p] != 0.0 { values[p].abs() } else { 1.0 };
        j.column_mut(c).scale_mut(s);
    }
    j.transpose() * j
}
