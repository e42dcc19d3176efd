//! The compliant drive against hd-model's own solver, its exact derivatives against
//! central differences, and a fit that recovers the drive from a record of it.

use super::fit::{CompliantSpec, Signal, residuals_and_jacobian, substeps_for};
use super::model::{Compliant, NAMES};
use super::record::{Between, VoltageRecord};
use super::simulate::simulate;
use crate::drive::lm::LmSettings;
use hd_model::{Input, Params, Profile, SimConfig, SolverOptions, simulate_streaming};
use std::f64::consts::TAU;

/// The seed drive's parameters in [`NAMES`] order.
fn seed() -> [f64; 18] {
    let p = Params::default();
    NAMES.map(|n| p.get(n).unwrap())
}

/// hd-model's solve of the seed drive (rtol 1e-11) under a chirp sampled every `h` and
/// read linearly between samples, logged every `h`: (t, u, θj, θz, i).
fn reference(t_end: f64, h: f64, volts: f64) -> [Vec<f64>; 5] {
    let n = (t_end / h).round() as usize + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
    // A chirp from 2 to 60 Hz, starting at zero.
    let u: Vec<f64> =
        t.iter().map(|&t| volts * (TAU * (2.0 * t + 58.0 * t * t / (2.0 * t_end))).sin()).collect();
    let cfg = SimConfig {
        input: Input::Recorded(Profile::new(t.clone(), u.clone(), "chirp").unwrap()),
        t_end,
        dt_out: h,
        solver: SolverOptions { rtol: 1e-11, atol: 1e-14, ..SolverOptions::default() },
        ..SimConfig::default()
    };
    let mut cols: [Vec<f64>; 5] = Default::default();
    simulate_streaming(
        &cfg,
        Some(&mut |s: &hd_model::signals::Sample| {
            for (c, v) in cols.iter_mut().zip([s.t, s.u, s.theta_j, s.theta_z, s.i]) {
                c.push(v);
            }
        }),
    )
    .unwrap();
    cols
}

fn record(cols: &[Vec<f64>; 5], name: &str) -> VoltageRecord {
    let [t, u, tj, tz, i] = cols.clone();
    VoltageRecord::new(name, "test", t, u, tj, tz, Some(i)).unwrap()
}

fn rms(a: &[f64]) -> f64 {
    (a.iter().map(|v| v * v).sum::<f64>() / a.len() as f64).sqrt()
}

/// The fit's integration of the seed drive matches hd-model's adaptive solve (rtol 1e-11):
/// at the substeps the fit picks, motor angle, load angle and current agree to 1e-4 of their
/// RMS (8.7e-5, 8.7e-5 and 3.9e-5 measured), and twice the substeps cut every difference by
/// more than four (an integration error of at least second order, not a model difference;
/// 6.7× measured).
#[test]
fn matches_the_simulator() {
    let h = 1e-3;
    let cols = reference(0.4, h, 12.0);
    let rec = record(&cols, "ref");
    let p = seed();
    let n = Params::default().n;
    let m = substeps_for(&p, n, h);
    let differences = |m: usize| {
        let sim = simulate(&Compliant::new(p, n), &rec, Between::Linear, m);
        [
            (&sim.theta_m, &rec.theta_m),
            (&sim.theta_l, &rec.theta_l),
            (&sim.current, rec.current.as_ref().unwrap()),
        ]
        .map(|(a, b)| {
            let diff: Vec<f64> = a.iter().zip(b.iter()).map(|(x, y)| x - y).collect();
            rms(&diff) / rms(b)
        })
    };
    let (coarse, fine) = (differences(m), differences(2 * m));
    for (k, what) in ["motor", "load", "current"].iter().enumerate() {
        println!(
            "{what}: relative difference {:.3e} ({m} substeps), {:.3e} ({})",
            coarse[k],
            fine[k],
            2 * m
        );
        assert!(coarse[k] < 1e-3, "{what}: relative difference {:e}", coarse[k]);
        assert!(fine[k] < coarse[k] / 4.0, "{what}: {:e} then {:e}", coarse[k], fine[k]);
    }
}

/// The Jacobian from dual numbers equals central differences of the plain simulation on
/// every column (all parameters but the two cubic terms, whose columns are below rounding
/// at the seed's deflections). Measured: at most 3.1e-6 (σ2, Cz), most below 1e-7.
#[test]
fn exact_derivatives() {
    let h = 1e-3;
    let cols = reference(0.15, h, 12.0);
    let rec = record(&cols, "ref");
    let n = Params::default().n;
    let mut start = seed();
    start[super::model::ix::SIGMA2] = 0.01;
    let free_idx: Vec<usize> = (0..18).filter(|&k| k != 8 && k != 9).collect();
    let spec = CompliantSpec {
        n,
        between: Between::Linear,
        start,
        free: [true; 18],
        lower: [f64::NEG_INFINITY; 18],
        upper: [f64::INFINITY; 18],
        outputs: vec![
            (Signal::Motor, vec![1e-3]),
            (Signal::Load, vec![1e-5]),
            (Signal::Current, vec![1e-2]),
        ],
        substeps: 8,
        settings: LmSettings::default(),
    };
    let (_, jac) = residuals_and_jacobian(&spec, &start, &free_idx, &[rec.clone()]);
    for (c, &k) in free_idx.iter().enumerate() {
        let step = 1e-5 * start[k].abs().max(1e-6);
        let at = |s: f64| {
            let mut p = start;
            p[k] += s;
            residuals_and_jacobian(&spec, &p, &[], &[rec.clone()]).0
        };
        let (up, down) = (at(step), at(-step));
        let fd: Vec<f64> = up.iter().zip(&down).map(|(a, b)| (a - b) / (2.0 * step)).collect();
        let col: Vec<f64> = jac.column(c).iter().copied().collect();
        let diff: Vec<f64> = col.iter().zip(&fd).map(|(a, b)| a - b).collect();
        let rel = rms(&diff) / rms(&col).max(1e-300);
        println!("{}: column rms {:.3e}, relative difference {rel:.2e}", NAMES[k], rms(&col));
        assert!(rel < 3e-5, "{}: relative difference {rel:e}", NAMES[k]);
    }
}
