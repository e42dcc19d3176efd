//! The exact bristle updates against hd-model's Rodas4 on the same held speed, and their
//! parameter derivatives against central differences.

use super::*;
use crate::laws::friction::FrictionLaw;
use crate::solver::{Method, OdeSystem, SolverOptions, solve};
use nalgebra::{SMatrix, SVector};

/// A law with unequal levels on the two sides, so every column of the gradient is live.
fn law(sigma0: f64) -> LuGre {
    LuGre { tc_neg: 0.17, ts_neg: 0.31, ..LuGre::symmetric(sigma0, 0.8, 0.0, 0.15, 0.25, 0.01) }
}

/// A speed record with reversals, uneven intervals and exact zeros [s], [rad/s].
fn record(amp: f64) -> (Vec<f64>, Vec<f64>) {
    let mut t = vec![0.0];
    for k in 1..400 {
        let h = 1e-3 * (1.0 + 0.5 * (0.37 * k as f64).sin());
        t.push(t[k - 1] + h);
    }
    let v = t
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            if k % 97 == 0 {
                0.0
            } else {
                amp * ((std::f64::consts::TAU * 3.0 * t).sin() + 0.3 * (41.0 * t).cos())
            }
        })
        .collect();
    (t, v)
}

/// The speed held piecewise as the fits read it: each interval at its mean, split at the
/// zero of the line between samples when the sign changes. Returns the pieces' ends [s]
/// and speeds [rad/s].
fn held_pieces(t: &[f64], v: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let (mut knots, mut speed) = (vec![t[0]], Vec::new());
    for k in 1..t.len() {
        let (v0, v1, h) = (v[k - 1], v[k], t[k] - t[k - 1]);
        if v0 * v1 < 0.0 {
            knots.push(t[k - 1] + h * v0.abs() / (v0.abs() + v1.abs()));
            speed.extend([0.5 * v0, 0.5 * v1]);
        } else {
            speed.push(0.5 * (v0 + v1));
        }
        knots.push(t[k]);
    }
    (knots, speed)
}

/// The bristle rate at one constant speed, for the solver.
struct AtSpeed {
    law: LuGre,
    v: f64,
}

impl OdeSystem<1> for AtSpeed {
    fn rhs(&self, _t: f64, y: &SVector<f64, 1>) -> SVector<f64, 1> {
        SVector::from([self.law.eval(self.v, y[0]).w_rate])
    }
    fn jacobian(&self, _t: f64, y: &SVector<f64, 1>) -> (SMatrix<f64, 1, 1>, SVector<f64, 1>) {
        let e = self.law.eval(self.v, y[0]);
        (SMatrix::from([[e.w_rate_d_w]]), SVector::from([0.0]))
    }
    fn abs_scale(&self) -> SVector<f64, 1> {
        SVector::from([self.law.max_level()])
    }
}

/// The states at the samples by the exact updates, from w0.
fn exact(law: &LuGre, t: &[f64], v: &[f64], w0: f64) -> Vec<f64> {
    let mut w = vec![w0];
    for k in 1..t.len() {
        w.push(law.step_interval(v[k - 1], v[k], w[k - 1], t[k] - t[k - 1]).w);
    }
    w
}

/// Each piece integrated by Rodas4 on its own (a fresh start at every knot, so no step
/// straddles a jump of the held speed), read at the samples.
fn reference(law: &LuGre, t: &[f64], v: &[f64], w0: f64) -> Vec<f64> {
    let (knots, speed) = held_pieces(t, v);
    let opts =
        SolverOptions { method: Method::Rodas4, rtol: 1e-12, atol: 1e-14, ..Default::default() };
    let mut w = w0;
    let mut out = vec![w0];
    for (piece, &v) in knots.windows(2).zip(&speed) {
        let sys = AtSpeed { law: *law, v };
        let h = piece[1] - piece[0];
        let (y, _) = solve(&sys, 0.0, SVector::from([w]), h, &[], &opts, &mut |_| {}).unwrap();
        w = y[0];
        if t.contains(&piece[1]) {
            out.push(w);
        }
    }
    out
}

#[test]
fn exact_updates_match_rodas4_on_the_held_speed() {
    // Bristle relaxation from a hundredth of a sample (λh ≈ 40 at 0.05 rad/s) to many
    // samples (σ0 = 30: λh ≈ 0.01).
    for (sigma0, amp) in [(1.2e5, 0.05), (3e3, 0.02), (30.0, 0.05)] {
        let l = law(sigma0);
        let (t, v) = record(amp);
        let a = exact(&l, &t, &v, 0.1);
        let b = reference(&l, &t, &v, 0.1);
        assert_eq!(a.len(), b.len());
        let range = a.iter().fold(f64::NEG_INFINITY, |m, x| m.max(*x))
            - a.iter().fold(f64::INFINITY, |m, x| m.min(*x));
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        println!("σ0 {sigma0:e}: worst {worst:.2e} of a range {range:.3}");
        assert!(range > 0.01, "the record should swing the bristles: range {range}");
        assert!(worst <= 1e-9 * range, "σ0 {sigma0}: {worst:e} against range {range}");
    }
}

#[test]
fn held_step_is_the_law_step_at_speed() {
    let l = law(1.2e5);
    for (v, w, h) in [(0.003, 0.1, 1e-3), (-0.02, 0.2, 2e-4), (0.0, 0.05, 1.0)] {
        assert_eq!(l.step_held(v, w, h).w, l.step_at_speed(v, w, h));
    }
}

/// Central differences of the whole recursion (states and the slip rate at every
/// sample) in each parameter, against the carried sensitivities: 1e-6 relative to each
/// column's largest entry.
#[test]
fn carried_sensitivities_match_central_differences() {
    let (t, v) = record(0.03);
    for sigma0 in [1.2e5, 3e3] {
        let base = law(sigma0);
        let (w, s_rate, dw, ds) = along(&base, &t, &v);
        let _ = (w, s_rate);
        for p in 0..6 {
            let value = get(&base, p);
            let h = 1e-6 * value;
            let (mut up, mut down) = (base, base);
            set(&mut up, p, value + h);
            set(&mut down, p, value - h);
            let (wu, su, _, _) = along(&up, &t, &v);
            let (wd, sd, _, _) = along(&down, &t, &v);
            for (name, fd, exact) in [
                ("w", diff(&wu, &wd, h), dw.iter().map(|g| g[p]).collect::<Vec<_>>()),
                ("ṡ", diff(&su, &sd, h), ds.iter().map(|g| g[p]).collect::<Vec<_>>()),
            ] {
                let scale = exact.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let worst = fd.iter().zip(&exact).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
                println!("σ0 {sigma0:e} ∂{name}/∂{}: {worst:.1e} of {scale:.3e}", SHAPE_PARAMS[p]);
                assert!(scale > 0.0, "{} never moves {name}", SHAPE_PARAMS[p]);
                assert!(
                    worst <= 1e-6 * scale,
                    "∂{name}/∂{}: {worst:e} of {scale:e}",
                    SHAPE_PARAMS[p]
                );
            }
        }
    }
}

fn diff(a: &[f64], b: &[f64], h: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| (x - y) / (2.0 * h)).collect()
}

fn get(l: &LuGre, p: usize) -> f64 {
    [l.tc, l.ts, l.ws, l.sigma0, l.tc_neg, l.ts_neg][p]
}

fn set(l: &mut LuGre, p: usize, x: f64) {
    *[&mut l.tc, &mut l.ts, &mut l.ws, &mut l.sigma0, &mut l.tc_neg, &mut l.ts_neg][p] = x;
}

/// States, slip rates and their carried sensitivities along the record from w0 = 0.1.
#[allow(clippy::type_complexity)]
fn along(l: &LuGre, t: &[f64], v: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<ShapeGrad>, Vec<ShapeGrad>) {
    let (mut w, mut s, mut dw, mut ds) = (vec![0.1], Vec::new(), vec![[0.0; 6]], Vec::new());
    for k in 1..t.len() {
        let step = l.step_interval(v[k - 1], v[k], w[k - 1], t[k] - t[k - 1]);
        let mut g = step.grad;
        for (gi, prev) in g.iter_mut().zip(dw[k - 1]) {
            *gi += step.d_w0 * prev;
        }
        w.push(step.w);
        dw.push(g);
    }
    for k in 0..t.len() {
        let (rate, d_w, grad) = l.slip_rate_grad(v[k], w[k]);
        let mut g = grad;
        for (gi, dwi) in g.iter_mut().zip(dw[k]) {
            *gi += d_w * dwi;
        }
        s.push(rate);
        ds.push(g);
    }
    (w, s, dw, ds)
}

/// ∂w₁/∂v of [`LuGre::step_held_with_speed`] against central differences in v, on both
/// sides, with the state behind, at and ahead of its steady level.
#[test]
fn speed_slope_matches_central_differences() {
    let l = law(2e3);
    for v in [-0.03, -0.004, 0.002, 0.01, 0.05] {
        for w0 in [-0.3, 0.0, 0.2] {
            let (step, d_v) = l.step_held_with_speed(v, w0, 1e-3);
            assert_eq!(step, l.step_held(v, w0, 1e-3));
            let dv = 1e-7 * v.abs();
            let fd =
                (l.step_held(v + dv, w0, 1e-3).w - l.step_held(v - dv, w0, 1e-3).w) / (2.0 * dv);
            assert!((fd - d_v).abs() <= 1e-6 * fd.abs().max(1.0), "v {v}, w0 {w0}: {fd} vs {d_v}");
        }
    }
    // At rest: the bristle integrates the speed, ∂w₁/∂v = σ0·h.
    assert_eq!(l.step_held_with_speed(0.0, 0.1, 1e-3).1, 2e3 * 1e-3);
}
