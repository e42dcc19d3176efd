//! The compliant drive in its loop: the fit's closed loop against hd-model's (the
//! simulator's adaptive solver, sample by sample under the held command), its exact
//! derivatives through the controller against central differences, and a fit that
//! recovers the drive from hd-model's closed-loop record.

use super::closed_loop::{Amplifier, ClosedLoop, Feedback};
use super::fit::{CompliantSpec, Signal, substeps_for};
use super::model::{NAMES, P, ix::*};
use super::record::{Between, VoltageRecord};
use super::simulate::simulate;
use super::synth_loop::run_loop;
use super::tests::{
    assert_converging, assert_jacobian_matches, fit_and_judge, quantise, relative_differences,
    test_spec,
};
use crate::drive::controller::Controller;
use hd_model::{Params, SimConfig, SolverOptions};
use std::f64::consts::{PI, TAU};

use super::tests::seed;

/// Smoothed steps (raised-cosine ramps over 30 % of each interval) to `levels` [rad], one
/// every `period` [s], sampled every `h` up to `t_end`.
fn steps(levels: &[f64], period: f64, h: f64, t_end: f64) -> Vec<f64> {
    let n = (t_end / h).round() as usize + 1;
    (0..n)
        .map(|k| {
            let t = k as f64 * h;
            let j = ((t / period).floor() as usize).min(levels.len() - 1);
            let from = if j == 0 { 0.0 } else { levels[j - 1] };
            let s = ((t - j as f64 * period) / (0.3 * period)).min(1.0);
            from + (levels[j] - from) * (0.5 - 0.5 * (PI * s).cos())
        })
        .collect()
}

/// The loop's controller at 1 kHz: kp [1/s], kv [V or A per rad/s], delay [samples].
fn controller(kp: f64, kv: f64, delay: usize) -> Controller {
    Controller {
        kp,
        kv,
        saturation: f64::INFINITY,
        delay,
        speed_filter: vec![1.0],
        h: 1e-3,
        open_loop: None,
    }
}

/// hd-model's closed-loop record of the seed drive (rtol 1e-10) under reference `r`, the
/// encoders quantised to `motor_counts` and `load_counts` per revolution, the fed-back one
/// as the controller read it; the current noiseless.
fn record(
    c: &Controller,
    feedback: Feedback,
    amplifier: Amplifier,
    r: &[f64],
    motor_counts: u64,
    load_counts: u64,
) -> VoltageRecord {
    let cfg = SimConfig {
        solver: SolverOptions { rtol: 1e-10, atol: 1e-13, ..SolverOptions::default() },
        ..SimConfig::default()
    };
    let counts = match feedback {
        Feedback::Motor => motor_counts,
        Feedback::Load => load_counts,
    };
    let run = run_loop(&cfg, c, feedback, amplifier, r, counts).unwrap();
    let tj = quantise(&run.theta_j, TAU / motor_counts as f64);
    let tz = quantise(&run.theta_z, TAU / load_counts as f64);
    VoltageRecord::new("loop", "test", run.t, run.command, tj, tz, Some(run.current))
        .unwrap()
        .in_loop(ClosedLoop { controller: c.clone(), feedback, amplifier, reference: r.to_vec() })
        .unwrap()
}

/// The fit's closed loop of the seed drive (its own Runge–Kutta integration, the
/// controller reading the unquantised encoder) against hd-model's with 2^40-count encoders
/// (quantisation far below the integration error), for a voltage loop on the motor encoder
/// and a current loop on the load encoder. At the substeps the fit picks every output
/// agrees to 5e-7 of its RMS (measured: angles 4.0e-9 and 8.4e-10, current and command
/// up to 4.9e-8), and twice the substeps cut every difference by more than 2.5 or to the
/// comparison's floor: an integration error, not a model difference.
#[test]
fn the_loop_matches_the_simulator() {
    let p = seed();
    let n = Params::default().n;
    let fine = 1u64 << 40;
    for (feedback, amplifier, kv, amp) in [
        (Feedback::Motor, Amplifier::Voltage, 0.5, 2.0),
        (Feedback::Load, Amplifier::Current, 0.3 * n, 0.02),
    ] {
        let c = controller(30.0, kv, 1);
        let r = steps(&[amp, -0.6 * amp, 0.3 * amp], 0.1, c.h, 0.3);
        let rec = record(&c, feedback, amplifier, &r, fine, fine);
        let m = substeps_for(&p, n, c.h);
        let differences = |m: usize| {
            let sim = simulate(&super::model::Compliant::new(p, n), &rec, Between::Hold, m);
            relative_differences([
                (&sim.theta_m, &rec.theta_m),
                (&sim.theta_l, &rec.theta_l),
                (&sim.current, rec.current.as_ref().unwrap()),
                (&sim.command, &rec.u),
            ])
        };
        let (coarse, fine) = (differences(m), differences(2 * m));
        println!("{feedback:?}/{amplifier:?}:");
        let names = ["motor", "load", "current", "command"];
        assert_converging(&names, &coarse, &fine, m, 5e-7, 2.5);
    }
}

/// The Jacobian through the loop (controller, delay, held command) equals central
/// differences of the plain run, column by column, for a voltage loop on the motor encoder
/// and a current loop on the load encoder ([`assert_jacobian_matches`]; largest relative
/// difference measured 2.2e-5, ws and Cz: the differences' own truncation error).
#[test]
fn exact_derivatives_through_the_loop() {
    let n = Params::default().n;
    let start = seed();
    for (feedback, amplifier, kv, amp) in [
        (Feedback::Motor, Amplifier::Voltage, 0.5, 2.0),
        (Feedback::Load, Amplifier::Current, 0.3 * n, 0.02),
    ] {
        let c = controller(30.0, kv, 1);
        let r = steps(&[amp, -amp], 0.06, c.h, 0.12);
        let rec = record(&c, feedback, amplifier, &r, 1 << 16, 1 << 20);
        // Behind an ideal current amplifier R and Ke act on nothing.
        let free_idx: Vec<usize> =
            [R, KM, KE, JJ, JZ, CJ, CZ, C, MEM_A, MEM_B, SIGMA0, SIGMA1, TC, TS, WS]
                .into_iter()
                .filter(|&k| amplifier == Amplifier::Voltage || (k != R && k != KE))
                .collect();
        let outputs = vec![
            (Signal::Motor, vec![1e-4]),
            (Signal::Load, vec![1e-6]),
            (Signal::Current, vec![1e-2]),
            (Signal::Command, vec![1e-2]),
        ];
        let spec = CompliantSpec {
            between: Between::Hold,
            free: [true; P],
            km_is_ke: false,
            ..test_spec(n, start, outputs, 8)
        };
        println!("{feedback:?}/{amplifier:?}:");
        assert_jacobian_matches(&spec, &start, &free_idx, &rec, 2e-4);
    }
}

/// Fit the seed drive to hd-model's record of its position loop (smoothed steps of the
/// motor angle; cascade P–P voltage controller on a 2^16-count motor encoder; load encoder
/// 2^20 counts; current noise 1 % of its RMS). The motor's constants and the friction
/// start 25 % off; the gear and the load are held at the truth (a 0.6 s record of steps
/// does not reach the gear's 310 Hz resonance).
///
/// A drive held in position by its loop sits in the bristle's pre-sliding, where the
/// speed changes sign within samples. At the default substeps ([`substeps_for`]) every
/// determined parameter is within 0.65 standard errors (measured). Before the bristle was
/// carried about the value it relaxes to, σ0 landed 3.05 standard errors off there, and
/// the fit took four times as many substeps in closed loop.
///
/// The recorded command carries the encoder's quantisation through the controller, which
/// the fit's loop (reading the exact angle) does not: its noise level is σq·√(Σ g_j²), g_j
/// the law's gain on the reading j samples back (σq the count/√12), and the current's adds
/// that over R to the sensor's. Every residual must sit at its noise (≤ 1.2×; 0.99–1.02
/// measured) and every parameter reported as determined within 3 standard errors of the
/// truth (R, Ke, Jj, Cj and Tc are; σ0, σ1, Ts and ωs are named as not determined).
#[test]
fn fits_the_drive_in_its_loop() {
    let (kp, kv) = (30.0, 0.5);
    let c = controller(kp, kv, 0);
    let r = steps(&[2.0, -1.0, 1.5, -2.0], 0.15, c.h, 0.6);
    let (cm, cl) = (1u64 << 16, 1u64 << 20);
    let mut rec = record(&c, Feedback::Motor, Amplifier::Voltage, &r, cm, cl);
    let truth = seed();
    let n = Params::default().n;
    let current = rec.current.as_mut().unwrap();
    let sigma_i =
        crate::synth::add_noise(current, &crate::synth::Noise { relative: 0.01, seed: 3 });
    let (qm, ql) = (TAU / cm as f64 / 12f64.sqrt(), TAU / cl as f64 / 12f64.sqrt());
    let h = c.h;
    // The command's response to the reading errors e_(k−j): −kp·kv·[j = 0] − kv·(c_j − c_(j−1))/h.
    let f = &c.speed_filter;
    let gain2: f64 = (0..=f.len())
        .map(|j| {
            let cj = f.get(j).copied().unwrap_or(0.0);
            let prev = if j == 0 { 0.0 } else { f[j - 1] };
            let g = -kv * (cj - prev) / h - if j == 0 { kp * kv } else { 0.0 };
            g * g
        })
        .sum();
    let sigma_u = qm * gain2.sqrt();
    let sigma_i = ((sigma_u / truth[R]).powi(2) + sigma_i * sigma_i).sqrt();
    let free_idx = [R, KE, JJ, CJ, SIGMA0, SIGMA1, TC, TS, WS];
    let mut free = [false; P];
    let mut start = truth;
    for (j, &k) in free_idx.iter().enumerate() {
        free[k] = true;
        start[k] *= if j % 2 == 0 { 1.25 } else { 0.75 };
    }
    free[KM] = true;
    start[KM] = start[KE];
    let noise = [qm, ql, sigma_i, sigma_u];
    let outputs = Signal::ALL.iter().zip(noise).map(|(s, v)| (*s, vec![v])).collect();
    let spec = CompliantSpec {
        between: Between::Hold,
        free,
        lower: start.map(|v| v * 1e-3),
        upper: start.map(|v| v * 1e3),
        ..test_spec(n, start, outputs, substeps_for(&start, n, h))
    };
    let fit = fit_and_judge(&spec, rec, &truth, &free_idx);
    let determined = free_idx.iter().filter(|&&k| fit.determined[k]).count();
    // The motor's constants and the Coulomb level are seen by any loop that moves it.
    for k in [R, KE, JJ, CJ, TC] {
        assert!(fit.determined[k], "{} not determined", NAMES[k]);
    }
    assert!(determined >= 5, "only {determined} determined");
}
