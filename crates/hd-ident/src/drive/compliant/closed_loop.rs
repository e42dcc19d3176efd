//! The compliant drive in its own loop: a recorded position reference through the record's
//! discrete controller ([`Controller`], the rigid fit's), whose output drives the motor as a
//! voltage or as a current command.
//!
//! At each sample k the controller reads the simulated encoder it is wired to (motor angle
//! θj [rad], or load angle θz [rad] on the record's zero; not quantised), computes its law
//! on the reference, clamps it, and the command computed `delay` samples earlier is held
//! over the sample (zero-order hold). Before the delay has filled, the recorded command
//! acts. With `amplifier = "voltage"` the current is the model's algebraic one; with
//! `"current"` the amplifier is ideal: the current equals the command and the motor torque
//! is Km × command. The same code runs on dual numbers, so the exact Jacobian is carried
//! through the controller too.

use super::model::{Compliant, State, ix};
use super::record::VoltageRecord;
use super::simulate::Outputs;
use crate::drive::controller::Controller;
use crate::drive::dual::Scalar;

/// Which encoder the loop reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Feedback {
    /// The motor encoder: the controller's positions are motor radians.
    #[default]
    Motor,
    /// The load encoder: the controller's positions are load radians.
    Load,
}

impl Feedback {
    /// Parse `motor` or `load`.
    pub fn parse(s: &str) -> Option<Feedback> {
        match s {
            "motor" => Some(Feedback::Motor),
            "load" => Some(Feedback::Load),
            _ => None,
        }
    }

    /// The configuration name.
    pub fn name(self) -> &'static str {
        match self {
            Feedback::Motor => "motor",
            Feedback::Load => "load",
        }
    }
}

/// What the controller's output is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Amplifier {
    /// A voltage [V] across the motor.
    #[default]
    Voltage,
    /// A current command [A] to an ideal current-controlled amplifier.
    Current,
}

impl Amplifier {
    /// Parse `voltage` or `current`.
    pub fn parse(s: &str) -> Option<Amplifier> {
        match s {
            "voltage" => Some(Amplifier::Voltage),
            "current" => Some(Amplifier::Current),
            _ => None,
        }
    }

    /// The configuration name.
    pub fn name(self) -> &'static str {
        match self {
            Amplifier::Voltage => "voltage",
            Amplifier::Current => "current",
        }
    }

    /// The command's unit.
    pub fn unit(self) -> &'static str {
        match self {
            Amplifier::Voltage => "V",
            Amplifier::Current => "A",
        }
    }
}

/// The loop a record was logged in.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedLoop {
    /// The discrete controller (its `open_loop` is None; positions in the feedback's
    /// radians, output in the amplifier's unit).
    pub controller: Controller,
    /// Which encoder it reads.
    pub feedback: Feedback,
    /// What its output drives.
    pub amplifier: Amplifier,
    /// The position reference at each sample [rad, motor or load side as `feedback`].
    pub reference: Vec<f64>,
}

impl ClosedLoop {
    /// The recorded encoder the controller reads in `rec` [rad].
    pub fn measured_feedback<'a>(&self, rec: &'a VoltageRecord) -> &'a [f64] {
        match self.feedback {
            Feedback::Motor => &rec.theta_m,
            Feedback::Load => &rec.theta_l,
        }
    }
}

/// The rates of `d` at state `y` with `command` held: a voltage, or the current of an
/// ideal current amplifier (then Km × command is the motor torque and no back-EMF acts).
/// The model's own rates at zero voltage, plus the command's share, which enters only the
/// motor's speed.
fn rates_held<T: Scalar>(
    d: &Compliant<T>,
    y: &State<T>,
    slips: &[T],
    command: T,
    amp: Amplifier,
) -> State<T> {
    let p = &d.p;
    let mut r = d.rates(y, 0.0, slips);
    // At zero voltage the model's current is −Ke·ωj/R.
    let current = match amp {
        Amplifier::Voltage => command / p[ix::R],
        Amplifier::Current => command + p[ix::KE] * y.omega_j / p[ix::R],
    };
    r.omega_j = r.omega_j + p[ix::KM] * current * d.chain().inv_jj;
    r
}

/// Run drive `d` in the loop `cl` of record `rec`, `substeps` Runge–Kutta steps per sample,
/// from rest at the record's first motor and load readings. The command output is the
/// command acting over each sample [V or A].
pub fn simulate_loop<T: Scalar>(
    d: &Compliant<T>,
    rec: &VoltageRecord,
    cl: &ClosedLoop,
    substeps: usize,
) -> Outputs<T> {
    simulate_loop_observed(d, rec, cl, substeps, &mut |_, _, _| {})
}

/// A callback seeing the state, the bristle slips and the command [V] or [A].
pub type Observer<'a, T> = dyn FnMut(&State<T>, &[T], T) + 'a;

/// [`simulate_loop`], calling `observe(state, slips, command)` at each sample (with the
/// command that then starts to act) and after every substep (with the command held).
pub fn simulate_loop_observed<T: Scalar>(
    d: &Compliant<T>,
    rec: &VoltageRecord,
    cl: &ClosedLoop,
    substeps: usize,
    observe: &mut Observer<'_, T>,
) -> Outputs<T> {
    let n = rec.len();
    let m = substeps.max(1);
    let step = rec.h / m as f64;
    let c = &cl.controller;
    let zero_l = rec.theta_l[0] - rec.theta_m[0] / d.n;
    let mut out = Outputs {
        theta_m: Vec::with_capacity(n),
        theta_l: Vec::with_capacity(n),
        current: Vec::with_capacity(n),
        command: Vec::with_capacity(n),
    };
    let mut read: Vec<T> = Vec::with_capacity(n);
    let mut computed: Vec<T> = Vec::with_capacity(n);
    let mut y = State::<T>::rest(rec.theta_m[0]);
    let mut slips = vec![T::cst(0.0); d.slip_count()];
    for k in 0..n {
        let theta_l = y.theta_j / d.n - y.theta + zero_l;
        read.push(match cl.feedback {
            Feedback::Motor => y.theta_j,
            Feedback::Load => theta_l,
        });
        computed.push(c.clamp(c.law(cl.reference[k], &read, k)));
        let command = if k >= c.delay { computed[k - c.delay] } else { T::cst(rec.u[k]) };
        out.theta_m.push(y.theta_j);
        out.theta_l.push(theta_l);
        // A current read just before the new command follows the one held until then.
        let driving = match (rec.current_sampled, out.command.last()) {
            (super::record::CurrentSampled::Before, Some(&prev)) => prev,
            _ => command,
        };
        out.current.push(match cl.amplifier {
            Amplifier::Voltage => d.current(0.0, y.omega_j) + driving / d.p[ix::R],
            Amplifier::Current => driving,
        });
        out.command.push(command);
        observe(&y, &slips, command);
        if k + 1 == n {
            break;
        }
        for _ in 0..m {
            let next = d.step_by(&y, |s, _| rates_held(d, s, &slips, command, cl.amplifier), step);
            d.commit(&y, &next, &mut slips);
            y = next;
            observe(&y, &slips, command);
        }
    }
    out
}
