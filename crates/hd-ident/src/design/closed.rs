//! A design for a drive that runs in its own loop: the input is the position reference
//! [rad, on the encoder the controller reads], played through the fit's discrete
//! controller ([`crate::drive::compliant::closed_loop`]). The record it yields logs the
//! command too, an output of the fit; the voltage (or current) the amplifier delivers is a
//! simulated peak like the others, and the reference's own amplitude is a limit.

use super::info::{Peaks, Problem, Response};
use crate::drive::compliant::closed_loop::simulate_loop_observed;
use crate::drive::compliant::model::{State, ix};
use crate::drive::compliant::{Amplifier, ClosedLoop, Feedback};
use crate::drive::controller::Controller;

/// The loop a closed-loop design plays its reference through.
#[derive(Clone, Debug, PartialEq)]
pub struct Loop {
    /// The discrete controller (its `open_loop` None; its sample period the design's).
    pub controller: Controller,
    /// Which encoder it reads.
    pub feedback: Feedback,
    /// What its output drives.
    pub amplifier: Amplifier,
    /// The logged command's noise level, standard deviation [V or A].
    pub command_noise: f64,
}

impl Loop {
    /// The loop of a record of reference `reference` [rad].
    pub fn closed(&self, reference: &[f64]) -> ClosedLoop {
        ClosedLoop {
            controller: self.controller.clone(),
            feedback: self.feedback,
            amplifier: self.amplifier,
            reference: reference.to_vec(),
        }
    }
}

/// The standard deviation of the command [V or A] that encoder noise of standard deviation
/// `sigma` [rad] on the fed-back angle makes through `c` at a constant reference: the
/// controller's law on 4096 samples of seeded white noise (uniform, the rounding of an
/// encoder), unclamped. What a record's command scatters by around the loop's own
/// simulation of it when the encoders are the only noise.
pub fn command_noise(c: &Controller, sigma: f64) -> f64 {
    let n = 4096;
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut next = || {
        // xorshift64*: a fixed sequence, uniform on [−√3, √3)·sigma (variance sigma²).
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        let u = (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64;
        (2.0 * u - 1.0) * 3f64.sqrt() * sigma
    };
    let q: Vec<f64> = (0..n).map(|_| next()).collect();
    let skip = 16.min(n / 2);
    let u: Vec<f64> = (skip..n).map(|k| c.law::<f64>(0.0, &q, k)).collect();
    let mean = u.iter().sum::<f64>() / u.len() as f64;
    (u.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / u.len() as f64).sqrt()
}

/// Peaks and response of `p`'s drive in loop `l` under reference `r` [rad] (over every
/// substep), stepped as the fit's loop simulation steps it. The voltage is the command
/// with a voltage amplifier, R·i + Ke·ωj (what the amplifier must deliver) with a current
/// one; the current is the command there, the model's algebraic current here.
pub fn response(p: &Problem, l: &Loop, r: &[f64]) -> (Peaks, Response) {
    let spec = &p.spec;
    let d = spec.drive(p.values);
    let rec = p.blank(r);
    let cl = l.closed(r);
    let m = spec.substeps.max(1);
    let (res, ke) = (p.values[ix::R], p.values[ix::KE]);
    let mut pk =
        Peaks { reference: r.iter().fold(0.0f64, |a, v| a.max(v.abs())), ..Default::default() };
    let mut out = Response::default();
    let mut calls = 0usize;
    let mut observe = |y: &State<f64>, slips: &[f64], command: f64| {
        let (volts, amps) = match l.amplifier {
            Amplifier::Voltage => (command, d.current(command, y.omega_j)),
            Amplifier::Current => (res * command + ke * y.omega_j, command),
        };
        let tau = d.gear_torque(y, slips);
        let load = y.theta_j / d.n - y.theta;
        pk.voltage = pk.voltage.max(volts.abs());
        pk.current = pk.current.max(amps.abs());
        pk.speed = pk.speed.max(y.omega_j.abs());
        pk.load_speed = pk.load_speed.max(y.omega_z.abs());
        pk.deflection = pk.deflection.max(y.theta.abs());
        pk.torque = pk.torque.max(tau.abs());
        pk.load_angle = pk.load_angle.max(load.abs());
        // Every (1 + m)-th call is a sample's.
        if calls.is_multiple_of(m + 1) {
            out.voltage.push(volts);
            out.current.push(amps);
            out.speed.push(y.omega_j);
            out.load_speed.push(y.omega_z);
            out.deflection.push(y.theta);
            out.torque.push(tau);
            out.load.push(load);
        }
        calls += 1;
    };
    simulate_loop_observed(&d, &rec, &cl, m, &mut observe);
    (pk, out)
}
