//! The full harmonic-drive model (docs/model.md: hysteretic stiffness, LuGre friction, seed
//! parameters, 24 V sine at 50 Hz) in hd-model's state coordinates
//! `x = [θj, ωj, θ, ωz, z, w]` with θ = θj/N − θz and w = σ0·s.

use std::f64::consts::TAU;

pub const N: f64 = 100.0;
const A3: f64 = 0.12; // a [N·m/rad³]
const B2: f64 = 0.56; // b [N·m/rad²]
pub const C1: f64 = 52_000.0; // c [N·m/rad]
pub const MEM_A: f64 = 40_000.0; // A [N·m/rad]
const MEM_B: f64 = 300.0; // B [1/s]
const SIGMA0: f64 = 1.2e5;
const SIGMA1: f64 = 0.8;
const SIGMA2: f64 = 0.0;
const TC: f64 = 0.15;
const TS: f64 = 0.25;
const WS: f64 = 0.01;
const R: f64 = 6.0;
const KM: f64 = 0.52;
const KE: f64 = 0.52;
const JJ: f64 = 6.8e-4;
const JZ: f64 = 2.4e-2;
const CJ: f64 = 0.003;
const CZ: f64 = 0.005;
const U_AMP: f64 = 24.0;
const FREQ: f64 = 50.0;

/// Number of states.
pub const NX: usize = 6;

/// Absolute tolerance per state: `atol`, and `atol/(c + A)` for the deflection, as
/// hd-model's `DriveSystem::abs_scale` does.
pub fn atol_vector(atol: f64) -> Vec<f64> {
    let mut v = vec![atol; NX];
    v[2] = atol / (C1 + MEM_A);
    v
}

/// θz = θj/N − θ.
pub fn theta_z(x: &[f64]) -> f64 {
    x[0] / N - x[2]
}

/// ẋ = f(x, t).
pub fn rhs(x: &[f64], _p: &[f64], t: f64, dx: &mut [f64]) {
    let (wj, th, wz, z, w) = (x[1], x[2], x[3], x[4], x[5]);
    let i = (U_AMP * (TAU * FREQ * t).sin() - KE * wj) / R;
    let thd = wj / N - wz;
    let v = wj / N;
    let tb = ((A3 * th + B2) * th + C1) * th + z;
    let g = TC + (TS - TC) * (-(v / WS) * (v / WS)).exp();
    let sd = v - v.abs() * w / g;
    let tf = w + SIGMA1 * sd + SIGMA2 * v;
    dx[0] = wj;
    dx[1] = (KM * i - CJ * wj - (tb + tf) / N) / JJ;
    dx[2] = thd;
    dx[3] = (tb - CZ * wz) / JZ;
    dx[4] = MEM_A * thd - MEM_B * z;
    dx[5] = SIGMA0 * sd;
}

/// The Jacobian action `(∂f/∂x)·u` (analytic).
pub fn jac_vec(x: &[f64], _p: &[f64], _t: f64, u: &[f64], out: &mut [f64]) {
    let (wj, th, w) = (x[1], x[2], x[5]);
    let v = wj / N;
    let e = (-(v / WS) * (v / WS)).exp();
    let g = TC + (TS - TC) * e;
    let dg = (TS - TC) * e * (-2.0 * v / (WS * WS));
    let sv = if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    };
    let sd_v = 1.0 - w * (sv * g - v.abs() * dg) / (g * g);
    let sd_w = -v.abs() / g;
    let kth = (3.0 * A3 * th + 2.0 * B2) * th + C1;
    let tf_v = SIGMA1 * sd_v + SIGMA2;
    let tf_w = 1.0 + SIGMA1 * sd_w;
    let (u_wj, u_th, u_wz, u_z, u_w) = (u[1], u[2], u[3], u[4], u[5]);
    out[0] = u_wj;
    out[1] =
        ((-KM * KE / R - CJ - tf_v / (N * N)) * u_wj - kth / N * u_th - u_z / N - tf_w / N * u_w)
            / JJ;
    out[2] = u_wj / N - u_wz;
    out[3] = (kth * u_th + u_z - CZ * u_wz) / JZ;
    out[4] = MEM_A / N * u_wj - MEM_A * u_wz - MEM_B * u_z;
    out[5] = SIGMA0 * (sd_v / N * u_wj + sd_w * u_w);
}

/// Start from rest.
pub fn init(_p: &[f64], _t: f64, x: &mut [f64]) {
    x.fill(0.0);
}
