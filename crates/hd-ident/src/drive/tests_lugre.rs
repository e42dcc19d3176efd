//! The LuGre drive: its sample step against a fine Runge–Kutta integration of the ODE, its
//! forward sensitivities against central differences, and the output-error fit against the
//! parameters that made a record.

use super::dual::{Dual, Scalar};
use super::fit::{FitSpec, OutputKind, fit_drive};
use super::lugre::LuGreDrive;
use super::model::{Drive, FrictionLaw, Motion};
use super::simulate::simulate;
use super::tests::{assert_exact_derivatives, controller, record};
use crate::lm::LmOptions;

/// EMPS-like directional LuGre values (order of [`FrictionLaw::names`]): M, Fv_pos, Fc_pos,
/// Fv_neg, Fc_neg, Fs_pos, Fs_neg, vs, sigma0, sigma1, gain.
const TRUTH: [f64; 11] = [95.0, 170.0, 21.5, 240.0, 22.0, 14.0, 16.0, 0.0175, 2.8e6, 1.0e3, 35.0];

/// The symmetric law's values: M, Fv, Fc, offset, Fs, vs, sigma0, sigma1, gain.
const TRUTH_SYM: [f64; 9] = [95.0, 200.0, 20.0, -3.0, 15.0, 0.017, 2.0e6, 1.2e3, 35.0];

fn truth(law: FrictionLaw) -> Vec<f64> {
    match law {
        FrictionLaw::LuGre => TRUTH_SYM.to_vec(),
        _ => TRUTH.to_vec(),
    }
}

fn lugre(law: FrictionLaw, p: &[f64]) -> LuGreDrive<f64> {
    match law.drive(p) {
        Drive::LuGre(d) => d,
        Drive::Rigid(_) => panic!("{} is not a LuGre law", law.name()),
    }
}

/// Fine classical Runge–Kutta integration of the LuGre drive over `h` under force `f`, in
/// `m` steps, written from the equations (not from the drive's code).
fn fine(d: &LuGreDrive<f64>, s: Motion<f64>, f: f64, h: f64, m: usize) -> Motion<f64> {
    let rhs = |v: f64, w: f64| {
        let (fc, fs, fv) =
            if v >= 0.0 { (d.fc_pos, d.fs_pos, d.fv_pos) } else { (d.fc_neg, d.fs_neg, d.fv_neg) };
        let g = fc + (fs - fc) * (-(v / d.vs).powi(2)).exp();
        let w_rate = d.sigma0 * (v - v.abs() * w / g);
        let friction = w + d.sigma1 / d.sigma0 * w_rate + fv * v;
        ((f - d.offset - friction) / d.m, w_rate)
    };
    let dt = h / m as f64;
    let (mut x, mut v, mut w) = (s.x, s.v, s.w);
    for _ in 0..m {
        let (a1, b1) = rhs(v, w);
        let (a2, b2) = rhs(v + 0.5 * dt * a1, w + 0.5 * dt * b1);
        let (a3, b3) = rhs(v + 0.5 * dt * a2, w + 0.5 * dt * b2);
        let (a4, b4) = rhs(v + dt * a3, w + dt * b3);
        x += dt / 6.0
            * ((v) + 2.0 * (v + 0.5 * dt * a1) + 2.0 * (v + 0.5 * dt * a2) + (v + dt * a3));
        v += dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
        w += dt / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
    }
    Motion { x, v, w, friction: 0.0 }
}

/// The closed loop of a record run twice, at values like the EMPS fit's: with the drive's
/// sample step, and with the fine Runge–Kutta integration (2000 steps per sample) under the
/// same controller. Measured over reversals, stops and breakaways (2 substeps per sample):
/// position differences 1.9–2.2e-9 m RMS (a twelfth of the EMPS record's position noise,
/// 2.55e-8 m; at most 2.2e-8 m at single samples after a reversal) and force differences
/// 0.0034–0.0038 N RMS (a thirtieth of its force noise, 0.117 N). Tolerances: 10× those.
#[test]
fn closed_loop_matches_a_fine_integration() {
    for law in [FrictionLaw::LuGre, FrictionLaw::DirectionalLuGre] {
        let p = truth(law);
        let d = lugre(law, &p);
        let c = controller(0);
        let e = record(law, &p, 0, 3000);
        let fast = simulate(law, &p, &c, &e);
        let mut q = vec![e.position[0]];
        let mut s = Motion::rest(e.position[0]);
        let mut force = Vec::new();
        for k in 0..e.len() {
            let u = c.clamp(c.law(e.reference[k], &q, k));
            force.push(d.gain * u);
            s = fine(&d, s, d.gain * u, c.h, 2000);
            q.push(s.x);
        }
        let dx = fast.position.iter().zip(&q).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        let rx = (fast.position.iter().zip(&q).map(|(a, b)| (a - b).powi(2)).sum::<f64>()
            / q.len() as f64)
            .sqrt();
        let df =
            (fast.command.iter().zip(&force).map(|(u, f)| (d.gain * u - f).powi(2)).sum::<f64>()
                / force.len() as f64)
                .sqrt();
        assert!(
            rx < 2.5e-8 && dx < 2.5e-7 && df < 0.05,
            "{}: position {rx:e} m RMS, {dx:e} m at most; force {df:e} N RMS",
            law.name()
        );
    }
}

#[test]
fn sensitivities_match_central_differences() {
    for law in [FrictionLaw::LuGre, FrictionLaw::DirectionalLuGre] {
        assert_exact_derivatives::<12>(law, &truth(law), 2000, 1e-5);
    }
    let _ = Dual::<4>::cst(1.0).re();
}

/// From a start 10 % off (σ0 and σ1 30 % off), the fit returns the parameters that made the
/// record, with force and position compared.
#[test]
fn output_error_fit_recovers_a_lugre_drive() {
    for law in [FrictionLaw::LuGre, FrictionLaw::DirectionalLuGre] {
        let truth = truth(law);
        let e = record(law, &truth, 0, 6000);
        let n = truth.len();
        let names = law.names();
        let start: Vec<f64> = names
            .iter()
            .zip(&truth)
            .map(|(name, v)| match *name {
                "gain" => *v,
                "sigma0" | "sigma1" => v * 1.3,
                _ => v * 1.1,
            })
            .collect();
        let mut free = vec![true; n];
        free[n - 1] = false;
        let spec = FitSpec {
            law,
            controller: controller(0),
            gain: truth[n - 1],
            outputs: vec![(OutputKind::Force, 0.1), (OutputKind::Position, 1e-6)],
            start,
            free,
            lower: vec![1e-12; n]
                .iter()
                .zip(names)
                .map(|(l, m)| if *m == "offset" { f64::NEG_INFINITY } else { *l })
                .collect(),
            upper: vec![f64::INFINITY; n],
            settings: LmOptions::drive(),
        };
        let fit = fit_drive(&spec, std::slice::from_ref(&e), &|_, _| {}).unwrap();
        for k in 0..n - 1 {
            let rel = (fit.values[k] - truth[k]).abs() / truth[k].abs();
            assert!(
                rel < 1e-4,
                "{}: {} {} vs {} ({}, {} iterations)",
                law.name(),
                names[k],
                fit.values[k],
                truth[k],
                fit.termination,
                fit.iterations
            );
        }
    }
}

/// The documented LuGre start: σ0 = M·(2π·f_s/40)², σ1 = 0.2·√(σ0·M), vs a tenth of the RMS
/// speed, Fs± = 1.2·Fc± and a second start at 0.8·Fc±; `[params]` values are kept and not
/// varied.
#[test]
fn lugre_start_values_and_the_second_start() {
    use super::config::DriveConfig;
    use super::setup::{lugre_start, stribeck_variants};
    let law = FrictionLaw::DirectionalLuGre;
    let e = record(law, &TRUTH, 0, 2000);
    let speeds: Vec<f64> = e.position.windows(2).map(|w| (w[1] - w[0]) / e.h).collect();
    let rms = (speeds.iter().map(|v| v * v).sum::<f64>() / speeds.len() as f64).sqrt();
    let mut start = TRUTH.to_vec();
    for (k, v) in lugre_start(law, &start, std::slice::from_ref(&e)) {
        start[k] = v;
    }
    let at = |n: &str| start[law.names().iter().position(|m| *m == n).unwrap()];
    let sigma0 = 95.0 * (std::f64::consts::TAU * 1000.0 / 40.0f64).powi(2);
    assert!((at("sigma0") / sigma0 - 1.0).abs() < 1e-12);
    assert!((at("sigma1") / (0.2 * (sigma0 * 95.0).sqrt()) - 1.0).abs() < 1e-12);
    assert!((at("vs") / (0.1 * rms) - 1.0).abs() < 1e-12);
    assert_eq!((at("Fs_pos"), at("Fs_neg")), (1.2 * 21.5, 1.2 * 22.0));
    let cfg = |params: &str| {
        let text = format!(
            "gain = 35.0\nfriction = \"directional-lugre\"\n[[experiment]]\nname = \"e\"\nfile = \"e.csv\"\ntime = \"t\"\nposition = \"q\"\nreference = \"r\"\ncommand = \"u\"\n[controller]\nkp = 1.0\nkv = 1.0\n{params}"
        );
        DriveConfig::parse(&text, "fit.toml").unwrap()
    };
    let n = start.len();
    let spec = FitSpec {
        law,
        controller: controller(0),
        gain: 35.0,
        outputs: vec![(OutputKind::Force, 0.1)],
        start: start.clone(),
        free: vec![true; n],
        lower: vec![0.0; n],
        upper: vec![f64::INFINITY; n],
        settings: LmOptions::drive(),
    };
    let v = stribeck_variants(&cfg(""), &spec);
    assert_eq!(v.len(), 2);
    assert_eq!(v[1].start[5..7], [0.8 * 21.5, 0.8 * 22.0]);
    assert_eq!(v[1].start[..5], spec.start[..5]);
    let v = stribeck_variants(&cfg("[params]\nFs_pos = 30.0\nFs_neg = 31.0\n"), &spec);
    assert_eq!(v.len(), 1);
}
