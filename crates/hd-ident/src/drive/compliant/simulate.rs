//! The compliant drive re-run under a record's voltage (or in its loop,
//! [`super::closed_loop`]), from rest at the record's first encoder readings, sampled where
//! the record is. Generic over the arithmetic: plain runs
//! (`f64`) and runs carrying forward sensitivities ([`crate::drive::dual::Dual`]).

use super::model::{Compliant, State};
use super::record::{Between, VoltageRecord};
use crate::drive::dual::Scalar;

/// The simulated outputs at the record's samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Outputs<T> {
    /// Motor angle θj [rad].
    pub theta_m: Vec<T>,
    /// Load angle θz = θj/N − θ [rad], on the load encoder's zero.
    pub theta_l: Vec<T>,
    /// Armature current [A].
    pub current: Vec<T>,
    /// Closed loop: the command acting over each sample [V or A]; empty for a voltage test.
    pub command: Vec<T>,
}

/// Run drive `d` under the voltage of `rec` (read between samples as `between`), `substeps`
/// Runge–Kutta steps per sample, from rest at the first motor reading; the load angle is
/// put on the load encoder's zero (its first reading less θj/N there).
pub fn simulate<T: Scalar>(
    d: &Compliant<T>,
    rec: &VoltageRecord,
    between: Between,
    substeps: usize,
) -> Outputs<T> {
    if let Some(cl) = &rec.closed {
        return super::closed_loop::simulate_loop(d, rec, cl, substeps);
    }
    let n = rec.len();
    let m = substeps.max(1);
    let step = rec.h / m as f64;
    let zero_l = rec.theta_l[0] - rec.theta_m[0] / d.n;
    let mut out = Outputs {
        theta_m: Vec::with_capacity(n),
        theta_l: Vec::with_capacity(n),
        current: Vec::with_capacity(n),
        command: Vec::new(),
    };
    let mut y = State::<T>::rest(rec.theta_m[0]);
    let mut slips = vec![T::cst(0.0); d.slip_count()];
    for k in 0..n {
        out.theta_m.push(y.theta_j);
        out.theta_l.push(y.theta_j / d.n - y.theta + zero_l);
        out.current.push(d.current(rec.voltage_at_current(k, between), y.omega_j));
        if k + 1 == n {
            break;
        }
        for j in 0..m {
            let at = |f: f64| rec.voltage(k, (j as f64 + f) / m as f64, between);
            y = d.step(&y, &mut slips, [at(0.0), at(0.5), at(1.0)], step);
        }
    }
    out
}

/// Put the simulated encoder angles on the record's encoder zeros: add to each the constant
/// that best fits it to its record in least squares (the mean of measured − simulated). An
/// encoder's zero is not a property of the drive: the laws depend on no absolute angle, so
/// a constant offset is all that tells the zeros apart, and the first reading alone carries
/// its quantisation and noise into every sample. Returns the offsets added [rad]
/// (motor, load); in a run with sensitivities they carry their derivatives, so the fit sees
/// the residuals with the zeros projected out.
///
/// In closed loop the encoder the controller reads is not shifted: its zero enters the
/// error r − q, so the run starts at that encoder's first reading and stays there (its
/// offset is reported as 0). The other encoder's zero is still fitted as a constant.
pub fn on_encoder_zeros<T: Scalar>(rec: &VoltageRecord, out: &mut Outputs<T>) -> [T; 2] {
    use super::closed_loop::Feedback;
    let fixed = rec.closed.as_ref().map(|c| c.feedback);
    let shift = |sim: &mut Vec<T>, meas: &[f64], fixed: bool| {
        if fixed {
            return T::cst(0.0);
        }
        let n = sim.len().min(meas.len()).max(1) as f64;
        let mut acc = T::cst(0.0);
        for (s, m) in sim.iter().zip(meas) {
            acc = acc + (-*s + *m);
        }
        let off = acc / n;
        for s in sim.iter_mut() {
            *s = *s + off;
        }
        off
    };
    [
        shift(&mut out.theta_m, &rec.theta_m, fixed == Some(Feedback::Motor)),
        shift(&mut out.theta_l, &rec.theta_l, fixed == Some(Feedback::Load)),
    ]
}

/// Put the simulated current on the record's current sensor zero: add the mean of measured
/// − simulated (a sensor's constant offset, fitted by least squares). Returns the offset
/// added [A], or None when the record logs no current.
pub fn on_current_zero<T: Scalar>(rec: &VoltageRecord, out: &mut Outputs<T>) -> Option<T> {
    let meas = rec.current.as_deref()?;
    let n = out.current.len().min(meas.len()).max(1) as f64;
    let mut acc = T::cst(0.0);
    for (s, m) in out.current.iter().zip(meas) {
        acc = acc + (-*s + *m);
    }
    let off = acc / n;
    for s in out.current.iter_mut() {
        *s = *s + off;
    }
    Some(off)
}
