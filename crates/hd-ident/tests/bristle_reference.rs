//! The bristle state the friction fits use (the LuGre law's exact sample updates at the
//! held mean speed of each interval) against hd-model's Rodas4 on the shipped tribometer
//! recording and a synthetic joint record: the same held speed to 1e-9 of the state's
//! range, and the difference from the speed read as a straight line between samples
//! (the reading of the ODE-based fits before) measured and bounded.

mod common;

use common::*;
use hd_ident::derivative::{DEFAULT_ORDER, choose_half_window, savitzky_golay_derivative};
use hd_ident::friction::bristle::bristle_run;
use hd_ident::path::{BristleAlong, Sampled, state_at_samples};
use hd_ident::synth::Noise;
use hd_model::laws::friction::{FrictionLaw, LuGre};
use hd_model::solver::{Method, OdeSystem, SolverOptions, solve};
use nalgebra::{SMatrix, SVector};

/// The bristle rate at one constant speed.
struct AtSpeed {
    law: LuGre,
    v: f64,
}

impl OdeSystem<1> for AtSpeed {
    fn rhs(&self, _t: f64, y: &SVector<f64, 1>) -> SVector<f64, 1> {
        SVector::from([self.law.eval(self.v, y[0]).w_rate])
    }
    fn jacobian(&self, _t: f64, y: &SVector<f64, 1>) -> (SMatrix<f64, 1, 1>, SVector<f64, 1>) {
        (SMatrix::from([[self.law.eval(self.v, y[0]).w_rate_d_w]]), SVector::from([0.0]))
    }
    fn abs_scale(&self) -> SVector<f64, 1> {
        SVector::from([self.law.max_level()])
    }
}

/// Rodas4 over each held piece (mean speed; split at a sign change), from w0.
fn held_reference(law: &LuGre, t: &[f64], v: &[f64], w0: f64) -> Vec<f64> {
    let opts =
        SolverOptions { method: Method::Rodas4, rtol: 1e-12, atol: 1e-14, ..Default::default() };
    let piece = |w: f64, v: f64, h: f64| {
        let sys = AtSpeed { law: *law, v };
        solve(&sys, 0.0, SVector::from([w]), h, &[], &opts, &mut |_| {}).unwrap().0[0]
    };
    let mut out = vec![w0];
    for k in 1..t.len() {
        let (v0, v1, h) = (v[k - 1], v[k], t[k] - t[k - 1]);
        let w = out[k - 1];
        out.push(if v0 * v1 < 0.0 {
            let tz = h * v0.abs() / (v0.abs() + v1.abs());
            piece(piece(w, 0.5 * v0, tz), 0.5 * v1, h - tz)
        } else if v0 + v1 == 0.0 {
            w
        } else {
            piece(w, 0.5 * (v0 + v1), h)
        });
    }
    out
}

fn range(x: &[f64]) -> f64 {
    x.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v))
        - x.iter().fold(f64::INFINITY, |m, v| m.min(*v))
}

fn worst(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// The comparison on one record: returns (held error, linear-reading difference), both
/// relative to the state's range.
fn compare(what: &str, law: &LuGre, t: &[f64], v: &[f64]) -> (f64, f64) {
    let exact = bristle_run(t, v, law, 0.0, false).unwrap().w;
    let w0 = exact[0];
    let held = held_reference(law, t, v, w0);
    let speed = Sampled::new(t, v);
    let opts =
        SolverOptions { method: Method::Rodas4, rtol: 1e-10, atol: 1e-12, ..Default::default() };
    let linear =
        state_at_samples(&BristleAlong { law: *law, speed: &speed }, t, w0, &opts).unwrap();
    let r = range(&exact);
    let (e_held, e_lin) = (worst(&exact, &held) / r, worst(&exact, &linear) / r);
    let rms = (exact.iter().zip(&linear).map(|(a, b)| (a - b).powi(2)).sum::<f64>()
        / exact.len() as f64)
        .sqrt();
    println!(
        "{what}: {} samples, range {r:.3e} N·m; exact vs Rodas4 on the held speed {e_held:.1e} of the range; \
         vs the linear reading: worst {e_lin:.2e} of the range, RMS {rms:.2e} N·m",
        t.len()
    );
    (e_held, e_lin)
}

#[test]
fn tribometer_recording() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/tribometer-reciprocating.txt"
    ))
    .unwrap();
    let (mut t, mut x) = (Vec::new(), Vec::new());
    for line in text.lines().skip(1) {
        let f: Vec<f64> = line.split('\t').map(|c| c.trim().parse().unwrap()).collect();
        t.push(f[0]);
        x.push(f[2] * 1e-3);
    }
    let h = choose_half_window(&t, &x, DEFAULT_ORDER).half_window;
    let v = savitzky_golay_derivative(&t, &x, h, DEFAULT_ORDER).unwrap();
    // The symmetric fit's values (data/README.md), in N, N/m and m/s.
    let law = LuGre::symmetric(3.55e4, 0.0, 33.0, 2.894, 0.0599, 3.08e-5);
    let (held, linear) = compare("tribometer", &law, &t, &v);
    assert!(held <= 1e-9, "held: {held:e}");
    assert!(linear <= 1e-2, "linear reading: {linear:e}");
}

#[test]
fn synthetic_joint_record() {
    let p = params(&["Tc=0.2", "Ts=0.35", "ws=0.02", "sigma2=0.05", "sigma0=8e4", "sigma1=0.5"]);
    let d = joint_data(&p, Noise { relative: 0.01, seed: 11 });
    let law = LuGre::symmetric(8e4, 0.5, 0.05, 0.2, 0.35, 0.02);
    let (held, linear) = compare("synthetic joint", &law, d.t(), d.omega());
    assert!(held <= 1e-9, "held: {held:e}");
    assert!(linear <= 5e-2, "linear reading: {linear:e}");
}
