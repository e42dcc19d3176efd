//! The compliant drive re-run under a record's voltage, from rest at the record's first
//! encoder readings, sampled where the record is. Generic over the arithmetic: plain runs
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
    let n = rec.len();
    let m = substeps.max(1);
    let step = rec.h / m as f64;
    let zero_l = rec.theta_l[0] - rec.theta_m[0] / d.n;
    let mut out = Outputs {
        theta_m: Vec::with_capacity(n),
        theta_l: Vec::with_capacity(n),
        current: Vec::with_capacity(n),
    };
    let mut y = State::<T>::rest(rec.theta_m[0]);
    for k in 0..n {
        out.theta_m.push(y.theta_j);
        out.theta_l.push(y.theta_j / d.n - y.theta + zero_l);
        out.current.push(d.current(rec.u[k], y.omega_j));
        if k + 1 == n {
            break;
        }
        for j in 0..m {
            let at = |f: f64| rec.voltage(k, (j as f64 + f) / m as f64, between);
            y = d.step(&y, [at(0.0), at(0.5), at(1.0)], step);
        }
    }
    out
}
