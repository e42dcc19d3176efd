//! The drive identification checked on records made by its own closed loop: the exact
//! sample step against a fine integration of the ODE, the forward sensitivities against
//! central differences, the inverse-model start and the output-error fit against the
//! parameters that made the record, and the controller check against the delay used.

use super::controller::{Controller, reproduce};
use super::dual::{Dual, Scalar};
use super::fit::{FitSpec, OutputKind, fit_drive};
use super::idim::{IdimOptions, idim_ls};
use super::model::{Drive, FrictionLaw, Motion, Rigid};
use super::record::Experiment;
use super::simulate::simulate;
use crate::lm::LmOptions;

/// The Coulomb–viscous laws (LuGre has its own tests, tests_lugre.rs).
pub(super) const RIGID: [FrictionLaw; 2] = [FrictionLaw::CoulombViscous, FrictionLaw::Directional];

/// The rigid drive of `law` with parameters `p`.
fn rigid(law: FrictionLaw, p: &[f64]) -> Rigid<f64> {
    match law.drive(p) {
        Drive::Rigid(d) => d,
        Drive::LuGre(_) => panic!("{} is not a Coulomb–viscous law", law.name()),
    }
}

/// EMPS-like values: M, Fv, Fc, offset, gain.
pub(super) const TRUTH: [f64; 5] = [95.0, 200.0, 20.0, -3.0, 35.0];

pub(super) fn controller(delay: usize) -> Controller {
    Controller {
        kp: 160.0,
        kv: 243.0,
        saturation: 10.0,
        delay,
        speed_filter: vec![0.5, 0.5],
        h: 1e-3,
        open_loop: None,
    }
}

/// A record of `law` with parameters `p` following a reference with smooth moves both ways
/// and dwells (so the drive stops and sticks), `n` samples at 1 kHz.
pub(super) fn record(law: FrictionLaw, p: &[f64], delay: usize, n: usize) -> Experiment {
    let h = 1e-3;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
    let reference: Vec<f64> = t
        .iter()
        .map(|&t| {
            0.05 * (1.0 - (2.0 * std::f64::consts::PI * t / 2.0).cos())
                * (0.6 + 0.4 * (1.3 * t).sin())
        })
        .collect();
    let zeros = vec![0.0; n];
    let seed = Experiment::new(
        "synthetic",
        "test",
        t.clone(),
        reference.clone(),
        reference.clone(),
        zeros.clone(),
        vec![],
    )
    .unwrap();
    let s = simulate(law, p, &controller(delay), &seed);
    Experiment::new("synthetic", "test", t, s.position, reference, s.command, vec![]).unwrap()
}

/// Fine explicit integration of M·v̇ = f − offset − Fv·v − Fc·sign(v) with sticking: a
/// substep that would change the sign of v stops at v = 0 and sticks unless the net force
/// exceeds the Coulomb level.
fn fine(d: &Rigid<f64>, mut x: f64, mut v: f64, f: f64, h: f64) -> (f64, f64) {
    let m = 200_000;
    let dt = h / m as f64;
    let net = f - d.offset;
    for _ in 0..m {
        let dir = if v != 0.0 {
            v.signum()
        } else if net > d.fc_pos {
            1.0
        } else if net < -d.fc_neg {
            -1.0
        } else {
            0.0
        };
        if dir == 0.0 {
            continue;
        }
        let (fv, fc) = if dir > 0.0 { (d.fv_pos, d.fc_pos) } else { (d.fv_neg, d.fc_neg) };
        let acc = (net - fv * v - fc * dir) / d.m;
        let vn = v + acc * dt;
        if vn * dir < 0.0 && v != 0.0 {
            x += 0.5 * v * dt;
            v = 0.0;
        } else {
            x += 0.5 * (v + vn) * dt;
            v = vn;
        }
    }
    (x, v)
}

#[test]
fn exact_step_matches_a_fine_integration() {
    let d = rigid(FrictionLaw::Directional, &[2.0, 30.0, 5.0, 45.0, 8.0, 1.0]);
    let h = 0.02;
    // (v0, force): slide on; decelerate to rest and stick; stop and slide back; break away; stay stuck.
    for (v0, f) in [
        (0.3, 40.0),
        (0.05, 0.0),
        (0.05, -60.0),
        (0.0, 20.0),
        (0.0, -15.0),
        (0.0, 4.0),
        (-0.2, 3.0),
    ] {
        let s = d.step(Motion { v: v0, ..Motion::rest(0.1) }, f, h);
        let (x, v) = fine(&d, 0.1, v0, f, h);
        assert!(
            (s.x - x).abs() < 1e-8 && (s.v - v).abs() < 1e-5,
            "v0 {v0}, f {f}: {s:?} vs ({x}, {v})"
        );
    }
}

#[test]
fn sensitivities_match_central_differences() {
    // A relative step of 1e-6: small enough that no stop or stick decision of the record
    // changes between the ± trials (a larger one flips some, and the difference quotient then
    // measures a jump, not a derivative).
    for law in RIGID {
        let p: Vec<f64> = match law {
            FrictionLaw::CoulombViscous => TRUTH.to_vec(),
            _ => vec![95.0, 170.0, 20.0, 240.0, 21.0, 35.0],
        };
        assert_exact_derivatives::<8>(law, &p, 3000, 1e-6);
    }
}

/// The derivatives that the simulation on dual numbers (of size N) carries, against
/// central differences of the simulation in f64 with a relative step of 1e-6, over a
/// record of `n` samples made with parameters `p`: every parameter, position and command,
/// within `rel` of the difference quotient's norm plus what rounding allows.
pub(super) fn assert_exact_derivatives<const N: usize>(
    law: FrictionLaw,
    p: &[f64],
    n: usize,
    rel: f64,
) {
    let e = record(law, p, 0, n);
    let c = controller(0);
    let pd: Vec<Dual<N>> = p.iter().enumerate().map(|(k, &v)| Dual::var(v, k)).collect();
    let sd = simulate(law, &pd, &c, &e);
    for k in 0..p.len() {
        let dp = 1e-6 * p[k].abs();
        let mut up = p.to_vec();
        up[k] += dp;
        let mut dn = p.to_vec();
        dn[k] -= dp;
        let (su, sn) = (simulate(law, &up, &c, &e), simulate(law, &dn, &c, &e));
        for (sig, a, b) in
            [(&sd.position, &su.position, &sn.position), (&sd.command, &su.command, &sn.command)]
        {
            let fd: Vec<f64> = a.iter().zip(b).map(|(u, d)| (u - d) / (2.0 * dp)).collect();
            let ad: Vec<f64> = sig.iter().map(|x| x.d[k]).collect();
            let norm = fd.iter().map(|v| v * v).sum::<f64>().sqrt();
            let diff = fd.iter().zip(&ad).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
            // The differences cannot beat rounding: ε·|position|/dp per sample, amplified
            // in the command by the law's gain on the newest position, kv·(kp + 1/h).
            let amp = if std::ptr::eq(sig, &sd.command) { c.kv * (c.kp + 1.0 / c.h) } else { 1.0 };
            let scale = sd.position.iter().map(|x| x.v * x.v).sum::<f64>().sqrt();
            let rounding = 2.0 * f64::EPSILON * scale * amp / dp;
            assert!(
                diff <= rel * norm + rounding,
                "{} {}: |fd − exact| {diff:e} vs |fd| {norm:e}",
                law.name(),
                law.names()[k]
            );
        }
    }
}

#[test]
fn controller_check_finds_the_delay_that_made_the_record() {
    for delay in [0, 1] {
        let e = record(FrictionLaw::CoulombViscous, &TRUTH, delay, 4000);
        let r = reproduce(
            &controller(0),
            &e.position,
            &e.reference,
            &e.disturbance,
            &e.command,
            &[0, 1],
        );
        assert!(r[delay].rms < 1e-12, "delay {delay}: {r:?}");
        assert!(r[1 - delay].rms > 1e-3, "delay {delay}: {r:?}");
    }
}

#[test]
fn inverse_model_recovers_the_parameters_of_a_clean_record() {
    let e = record(FrictionLaw::CoulombViscous, &TRUTH, 0, 20_000);
    let f = idim_ls(FrictionLaw::CoulombViscous, &[e], TRUTH[4], &IdimOptions::default()).unwrap();
    for ((name, v), truth) in f.names.iter().zip(&f.values).zip(TRUTH) {
        let rel = (v - truth).abs() / truth.abs();
        assert!(rel < 0.02, "{name}: {v} vs {truth}");
    }
}

#[test]
fn output_error_fit_recovers_the_parameters_from_a_poor_start() {
    for law in RIGID {
        let truth: Vec<f64> = match law {
            FrictionLaw::CoulombViscous => TRUTH.to_vec(),
            _ => vec![95.0, 170.0, 20.0, 240.0, 21.0, 35.0],
        };
        let e = record(law, &truth, 0, 8000);
        let n = truth.len();
        let start: Vec<f64> = truth.iter().map(|v| v * 1.2).collect();
        let mut free = vec![true; n];
        free[n - 1] = false; // the gain
        let spec = FitSpec {
            law,
            controller: controller(0),
            gain: truth[n - 1],
            outputs: vec![(OutputKind::Force, 0.1), (OutputKind::Position, 1e-6)],
            start,
            free,
            lower: vec![f64::NEG_INFINITY; n],
            upper: vec![f64::INFINITY; n],
            settings: LmOptions::drive(),
        };
        let mut spec = spec;
        spec.start[n - 1] = truth[n - 1];
        let fit = fit_drive(&spec, std::slice::from_ref(&e), &|_, _| {}).unwrap();
        for (k, truth_k) in truth.iter().enumerate().take(n - 1) {
            let rel = (fit.values[k] - truth_k).abs() / truth_k.abs();
            assert!(
                rel < 1e-6,
                "{}: {} {} vs {} ({})",
                law.name(),
                fit.names[k],
                fit.values[k],
                truth_k,
                fit.termination
            );
        }
        assert!(fit.determination.all_determined, "{:?}", fit.determination.sentences);
        // Freeing the gain too: M, friction, offset and gain scale together.
        spec.free[n - 1] = true;
        let fit = fit_drive(&spec, std::slice::from_ref(&e), &|_, _| {}).unwrap();
        let s = fit.determination.sentences.join(" ");
        assert!(s.contains("not separable") && s.contains("gain"), "{s}");
    }
}

#[test]
fn constant_force_below_the_coulomb_level_holds() {
    let d = rigid(FrictionLaw::CoulombViscous, &TRUTH);
    let s = d.step(Motion::rest(0.2), 16.0, 1e-3); // 16 − (−3) = 19 < 20
    assert_eq!(s, Motion::rest(0.2));
    let s = d.step(Motion::rest(0.2), 17.5, 1e-3); // 20.5 > 20: breaks away
    assert!(s.v > 0.0 && s.x > 0.2);
    let _ = Dual::<4>::cst(0.0).re();
}
