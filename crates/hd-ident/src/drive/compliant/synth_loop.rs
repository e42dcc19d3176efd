//! A closed-loop record of the simulator's drive, made with hd-model's adaptive solver (not
//! the fit's own integration): the discrete controller of the fit reads the quantised
//! encoder at each sample, and hd-model integrates the sample under the held command from
//! the state the previous sample ended in (the zero-order-hold loop exactly). Used by
//! `hdw synth drive --loop-kp …` and by the tests of the closed-loop fit.

use super::closed_loop::{Amplifier, Feedback};
use crate::drive::controller::Controller;
use hd_model::control::quantise;
use hd_model::state::{OMEGA_J, THETA_J};
use hd_model::stepper::Stepper;
use hd_model::{Input, SimConfig, SimError};
use std::f64::consts::TAU;

/// The logged columns of a closed-loop run, one value per sample.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoopRun {
    /// Sample times [s].
    pub t: Vec<f64>,
    /// The command acting over each sample [V or A].
    pub command: Vec<f64>,
    /// Armature current at each sample, noiseless [A].
    pub current: Vec<f64>,
    /// True motor angle θj [rad].
    pub theta_j: Vec<f64>,
    /// True load angle θz [rad].
    pub theta_z: Vec<f64>,
}

/// Run the drive of `cfg` (open loop, checked; its input is replaced) from rest under the
/// reference `r` [rad, one value per sample of `c.h`], with controller `c` reading the
/// `feedback` encoder quantised to `counts` per revolution, its output driving the motor as
/// `amplifier` says. Before the delay has filled the command is zero. An ideal current
/// amplifier is the motor without back-EMF driven by R·command: its current is the command.
pub fn run_loop(
    cfg: &SimConfig,
    c: &Controller,
    feedback: Feedback,
    amplifier: Amplifier,
    r: &[f64],
    counts: u64,
) -> Result<LoopRun, SimError> {
    let n = r.len();
    let mut run = Stepper::new(cfg)?;
    let (res, ke) = (run.sys.motor.r, run.sys.motor.ke);
    if amplifier == Amplifier::Current {
        run.sys.motor.ke = 0.0;
    }
    let mut read: Vec<f64> = Vec::with_capacity(n);
    let mut computed: Vec<f64> = Vec::with_capacity(n);
    let mut out = LoopRun::default();
    for k in 0..n {
        let tk = k as f64 * c.h;
        let (theta_j, theta_z) = (run.y[THETA_J], run.sys.theta_z(&run.y));
        let angle = match feedback {
            Feedback::Motor => theta_j,
            Feedback::Load => theta_z,
        };
        read.push(quantise(angle, TAU / counts as f64));
        computed.push(c.clamp(c.law(r[k], &read, k)));
        let command = if k >= c.delay { computed[k - c.delay] } else { 0.0 };
        let (volts, current) = match amplifier {
            Amplifier::Voltage => (command, (command - ke * run.y[OMEGA_J]) / res),
            Amplifier::Current => (res * command, command),
        };
        out.t.push(tk);
        out.command.push(command);
        out.current.push(current);
        out.theta_j.push(theta_j);
        out.theta_z.push(theta_z);
        if k + 1 < n {
            run.sys.input = Input::Constant { amplitude: volts };
            run.advance((k + 1) as f64 * c.h, &[], &cfg.solver, &mut |_, _| {})?;
        }
    }
    Ok(out)
}
