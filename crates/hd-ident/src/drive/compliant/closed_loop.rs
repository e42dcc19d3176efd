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
fn rates_held<T: Scalar>(d: &Compliant<T>, y: &State<T>, command: T, amp: Amplifier) -> State<T> {
    let p = &d.p;
    let mut r = d.rates(y, 0.0);
    // At zero voltage the model's current is −Ke·ωj/R.
    let current = match amp {
        Amplifier::Voltage => command / p[ix::R],
        Amplifier::Current => command + p[ix::KE] * y.omega_j / p[ix::R],
    };
    r.omega_j = r.omega_j + p[ix::KM] * current / p[ix::JJ];
    r
}

/// `y + k·h`.
fn add<T: Scalar>(y: &State<T>, k: &State<T>, h: f64) -> State<T> {
    State {
        theta_j: y.theta_j + k.theta_j * h,
        omega_j: y.omega_j + k.omega_j * h,
        theta: y.theta + k.theta * h,
        omega_z: y.omega_z + k.omega_z * h,
        z: y.z + k.z * h,
        w: y.w + k.w * h,
    }
}

/// One Runge–Kutta step of `h` [s] under the held command, the bristle carried by its
/// integrating factor (the Lawson form, as [`Compliant::step`] does for a voltage test).
fn step_held<T: Scalar>(
    d: &Compliant<T>,
    y: &State<T>,
    command: T,
    amp: Amplifier,
    h: f64,
) -> State<T> {
    let l0 = d.relaxation(y);
    let e_half = (-(l0 * (0.5 * h))).exp();
    let e_full = e_half * e_half;
    let rates = |at: &State<T>| {
        let k = rates_held(d, at, command, amp);
        State { w: k.w + l0 * at.w, ..k }
    };
    let k1 = rates(y);
    let mut y2 = add(y, &k1, 0.5 * h);
    y2.w = e_half * (y.w + k1.w * (0.5 * h));
    let k2 = rates(&y2);
    let mut y3 = add(y, &k2, 0.5 * h);
    y3.w = e_half * y.w + k2.w * (0.5 * h);
    let k3 = rates(&y3);
    let mut y4 = add(y, &k3, h);
    y4.w = e_full * y.w + e_half * k3.w * h;
    let k4 = rates(&y4);
    let sixth = h / 6.0;
    let comb = |a: T, b: T, c: T, e: T| (a + (b + c) * 2.0 + e) * sixth;
    State {
        theta_j: y.theta_j + comb(k1.theta_j, k2.theta_j, k3.theta_j, k4.theta_j),
        omega_j: y.omega_j + comb(k1.omega_j, k2.omega_j, k3.omega_j, k4.omega_j),
        theta: y.theta + comb(k1.theta, k2.theta, k3.theta, k4.theta),
        omega_z: y.omega_z + comb(k1.omega_z, k2.omega_z, k3.omega_z, k4.omega_z),
        z: y.z + comb(k1.z, k2.z, k3.z, k4.z),
        w: e_full * y.w + (e_full * k1.w + e_half * (k2.w + k3.w) * 2.0 + k4.w) * sixth,
    }
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
        out.current.push(match cl.amplifier {
            Amplifier::Voltage => d.current(0.0, y.omega_j) + command / d.p[ix::R],
            Amplifier::Current => command,
        });
        out.command.push(command);
        if k + 1 == n {
            break;
        }
        for _ in 0..m {
            y = step_held(d, &y, command, cl.amplifier, step);
        }
    }
    out
}
