//! The closed loop re-run: the controller acting on the simulated position, the rigid drive
//! advanced exactly over each sample under the held command. Generic over the arithmetic, so
//! the same code gives plain runs (`f64`) and runs with forward sensitivities ([`Dual`]).
//!
//! [`Dual`]: super::dual::Dual

use super::controller::Controller;
use super::dual::Scalar;
use super::model::{FrictionLaw, Motion};
use super::record::Experiment;

/// Simulated outputs at the record's samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Simulated<T> {
    /// Command acting over each sample (after delay, disturbance and saturation)
    /// [command unit].
    pub command: Vec<T>,
    /// Position at each sample [m or rad].
    pub position: Vec<T>,
}

/// Run the loop of record `e` with drive parameters `p` (order of [`FrictionLaw::names`]),
/// from rest at the record's first position. Before the computation delay has filled, the
/// recorded command acts.
pub fn simulate<T: Scalar>(
    law: FrictionLaw,
    p: &[T],
    c: &Controller,
    e: &Experiment,
) -> Simulated<T> {
    let drive = law.drive(p);
    if let Some(segment) = c.open_loop {
        return open_loop(&drive, segment, e);
    }
    let n = e.len();
    let mut q: Vec<T> = Vec::with_capacity(n);
    let mut computed: Vec<T> = Vec::with_capacity(n);
    let mut applied: Vec<T> = Vec::with_capacity(n);
    let mut s = Motion::rest(T::cst(e.position[0]));
    q.push(s.x);
    for k in 0..n {
        computed.push(c.clamp(c.law(e.reference[k], &q, k) + e.disturbance[k]));
        let u = if k >= c.delay { computed[k - c.delay] } else { T::cst(e.command[k]) };
        applied.push(u);
        if k + 1 < n {
            s = drive.step(s, drive.gain() * u, e.h);
            q.push(s.x);
        }
    }
    Simulated { command: applied, position: q }
}

/// An open-loop record by multiple shooting: the recorded command (plus any disturbance)
/// drives the model, which restarts every `segment` samples at the measured position and
/// its low-passed speed ([`Experiment::speed`]; at rest where that is empty), with the
/// bristle unloaded. Each segment's first position is the record's own.
fn open_loop<T: Scalar>(
    drive: &super::model::Drive<T>,
    segment: usize,
    e: &Experiment,
) -> Simulated<T> {
    let n = e.len();
    let mut q: Vec<T> = Vec::with_capacity(n);
    let mut applied: Vec<T> = Vec::with_capacity(n);
    let mut s = Motion::rest(T::cst(e.position[0]));
    for k in 0..n {
        if k % segment.max(1) == 0 {
            s = Motion {
                v: T::cst(e.speed.get(k).copied().unwrap_or(0.0)),
                ..Motion::rest(T::cst(e.position[k]))
            };
        }
        q.push(s.x);
        let u = T::cst(e.command[k] + e.disturbance[k]);
        applied.push(u);
        s = drive.step(s, drive.gain() * u, e.h);
    }
    Simulated { command: applied, position: q }
}
