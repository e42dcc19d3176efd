//! The bristle run with its sensitivities, in chunks whose transcendental part is
//! vectorised.
//!
//! Over one sample interval the exact update ([`LuGre::step_interval`], docs/model.md §5)
//! is affine in the state: w₁ = w_ss + (w₀ − w_ss)·e^{−λh}, and its sensitivities are
//! ∂w₁/∂p = e^{−λh}·∂w₀/∂p + (a₁ + a₂·(w₀ − w_ss))·∂G/∂p (+ a₃·(w₀ − w_ss) for σ0), where
//! the level G, λ = σ0·|v̄|/G, e^{−λh}, a₁ = sign(v̄)·(1 − e^{−λh}), a₂ = e^{−λh}·h·λ/G,
//! a₃ = −e^{−λh}·h·|v̄|/G and ∂G/∂p do not depend on the state. So a chunk of intervals
//! first works those out in a loop with no dependence between iterations (and no library
//! call: [`super::vexp`]), which the compiler turns into vector instructions; the
//! sequential recursion over the chunk is then a few multiply–adds per sample. The slip
//! rate ṡ = v − (|v|/G(v))·w and its sensitivities take the same split. An interval across
//! which the speed changes sign (two parts) is stepped by [`LuGre::step_interval`] itself.

use super::super::bristle::start;
use super::vexp::{exp_neg, expm1_small};
use hd_model::laws::friction::{LuGre, floored_level};

/// Intervals per chunk: the chunk's quantities (17 arrays) stay in the L1 cache.
const CHUNK: usize = 128;

/// The state-independent quantities of a chunk (index j: interval k − 1 → k, or sample k).
struct Chunk {
    /// Interval: w_ss, e^{−λh}, a₁, a₂, a₃ and ∂G/∂(Tc, Ts, Tc_neg, Ts_neg, ωs).
    step: [[f64; CHUNK]; 10],
    /// Sample: |v|/G, |v|/G² and ∂G/∂(Tc, Ts, Tc_neg, Ts_neg, ωs).
    slip: [[f64; CHUNK]; 7],
}

/// A chunk's results, slot j for sample k0 + j.
pub(super) struct Out {
    /// Bristle torque w [N·m].
    pub(super) w: [f64; CHUNK],
    /// Slip rate ṡ [rad/s].
    pub(super) slip: [f64; CHUNK],
    /// ∂w/∂p per [`Slots`] entry.
    pub(super) dw: [[f64; CHUNK]; 6],
    /// ∂ṡ/∂p per [`Slots`] entry.
    pub(super) ds: [[f64; CHUNK]; 6],
}

impl Out {
    fn put(&mut self, j: usize, w: f64, slip: f64, dw: &Slots, ds: &Slots) {
        self.w[j] = w;
        self.slip[j] = slip;
        for i in 0..6 {
            self.dw[i][j] = dw[i];
            self.ds[i][j] = ds[i];
        }
    }
}

/// The Stribeck level at v and its derivatives with respect to (Tc, Ts, Tc_neg, Ts_neg,
/// ωs): the symmetric law's levels count for both sides (`asym` false).
#[inline(always)]
fn level(law: &LuGre, inv_ws: f64, asym: bool, v: f64) -> (f64, [f64; 5]) {
    let neg = asym && v < 0.0;
    let (tc, ts) = if neg { (law.tc_neg, law.ts_neg) } else { (law.tc, law.ts) };
    let r = v * inv_ws;
    let e = exp_neg(-(r * r));
    let g = floored_level((ts - tc).mul_add(e, tc), tc, ts);
    let (gc, gs) = (1.0 - e, e);
    let gw = (ts - tc) * e * 2.0 * r * r / law.ws;
    let grad = if neg { [0.0, 0.0, gc, gs, gw] } else { [gc, gs, 0.0, 0.0, gw] };
    (g, grad)
}

/// sign(v) as −1, 0 or 1.
#[inline(always)]
fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

impl Chunk {
    /// Fill the chunk for samples `k0 .. k0 + len` (k0 ≥ 1): slot j holds interval
    /// k − 1 → k and sample k, k = k0 + j. Every value is worked out for every slot, the
    /// cases taken by selection, so that the loop vectorises.
    fn fill(&mut self, law: &LuGre, asym: bool, t: &[f64], omega: &[f64], k0: usize, len: usize) {
        let inv_ws = 1.0 / law.ws;
        let v0 = &omega[k0 - 1..k0 - 1 + len];
        let v1 = &omega[k0..k0 + len];
        let t0 = &t[k0 - 1..k0 - 1 + len];
        let t1 = &t[k0..k0 + len];
        let mut step = self.step.each_mut().map(|s| &mut s[..len]);
        let mut slip = self.slip.each_mut().map(|s| &mut s[..len]);
        for j in 0..len {
            let h = t1[j] - t0[j];
            let vm = 0.5 * (v0[j] + v1[j]);
            let (g, grad) = level(law, inv_ws, asym, vm);
            let av = vm.abs();
            let lambda = law.sigma0 * av / g;
            let lh = lambda * h;
            let m = expm1_small(-lh.min(0.5));
            let d = exp_neg(-lh);
            let small = lh < 0.5;
            let decay = if small { 1.0 + m } else { d };
            let rise = if small { -m } else { 1.0 - d };
            let sv = sign(vm);
            let vals = [
                sv * g,
                decay,
                sv * rise,
                decay * h * lambda / g,
                -decay * h * av / g,
                grad[0],
                grad[1],
                grad[2],
                grad[3],
                grad[4],
            ];
            for (out, x) in step.iter_mut().zip(vals) {
                out[j] = x;
            }
            let (g, grad) = level(law, inv_ws, asym, v1[j]);
            let b1 = v1[j].abs() / g;
            let vals = [b1, b1 / g, grad[0], grad[1], grad[2], grad[3], grad[4]];
            for (out, x) in slip.iter_mut().zip(vals) {
                out[j] = x;
            }
        }
    }
}

/// Sensitivity slots: Tc, Ts, ωs, σ0, Tc_neg, Ts_neg (the symmetric law's levels in the
/// first two).
pub(super) type Slots = [f64; 6];

/// Run the bristle torque of `law` along `omega` sampled at `t` from `first_torque`
/// (see [`start`]) with its sensitivities; `emit(k0, len, out)` receives the samples
/// k0 … k0 + len − 1 in `out`'s first `len` slots. `asym` false folds the negative-side
/// levels into Tc and Ts.
pub(super) fn grad_run(
    law: &LuGre,
    asym: bool,
    t: &[f64],
    omega: &[f64],
    first_torque: f64,
    mut emit: impl FnMut(usize, usize, &Out),
) {
    let n = t.len();
    if n == 0 {
        return;
    }
    let (mut w, mut dw) = start(law, omega[0], first_torque);
    if !asym {
        dw = [dw[0] + dw[4], dw[1] + dw[5], dw[2], dw[3], 0.0, 0.0];
    }
    let inv_ws = 1.0 / law.ws;
    let slip_at = |v: f64, w: f64, dw: &Slots| {
        let (g, grad) = level(law, inv_ws, asym, v);
        let b1 = v.abs() / g;
        slip_parts(v, w, dw, [b1, b1 / g, grad[0], grad[1], grad[2], grad[3], grad[4]])
    };
    let mut out = Box::new(Out {
        w: [0.0; CHUNK],
        slip: [0.0; CHUNK],
        dw: [[0.0; CHUNK]; 6],
        ds: [[0.0; CHUNK]; 6],
    });
    let (slip, ds) = slip_at(omega[0], w, &dw);
    out.put(0, w, slip, &dw, &ds);
    emit(0, 1, &out);
    let mut chunk = Box::new(Chunk { step: [[0.0; CHUNK]; 10], slip: [[0.0; CHUNK]; 7] });
    let mut k0 = 1;
    while k0 < n {
        let len = CHUNK.min(n - k0);
        chunk.fill(law, asym, t, omega, k0, len);
        let (s, p) = (&chunk.step, &chunk.slip);
        for j in 0..len {
            let k = k0 + j;
            let (v0, v1) = (omega[k - 1], omega[k]);
            if v0 * v1 < 0.0 {
                let step = law.step_interval(v0, v1, w, t[k] - t[k - 1]);
                let mut g = step.grad;
                if !asym {
                    g = [g[0] + g[4], g[1] + g[5], g[2], g[3], 0.0, 0.0];
                }
                for (d, gi) in dw.iter_mut().zip(g) {
                    *d = step.d_w0 * *d + gi;
                }
                w = step.w;
            } else {
                let gap = w - s[0][j];
                let decay = s[1][j];
                w = gap.mul_add(decay, s[0][j]);
                let dl = gap.mul_add(s[3][j], s[2][j]);
                for d in dw.iter_mut() {
                    *d *= decay;
                }
                dw[0] = dl.mul_add(s[5][j], dw[0]);
                dw[1] = dl.mul_add(s[6][j], dw[1]);
                dw[4] = dl.mul_add(s[7][j], dw[4]);
                dw[5] = dl.mul_add(s[8][j], dw[5]);
                dw[2] = dl.mul_add(s[9][j], dw[2]);
                dw[3] = gap.mul_add(s[4][j], dw[3]);
            }
            let (slip, ds) = slip_parts(v1, w, &dw, std::array::from_fn(|i| p[i][j]));
            out.put(j, w, slip, &dw, &ds);
        }
        emit(k0, len, &out);
        k0 += len;
    }
}

/// ṡ = v − (|v|/G)·w and ∂ṡ/∂p from the sample's quantities `p` (as in [`Chunk::slip`]).
#[inline(always)]
fn slip_parts(v: f64, w: f64, dw: &Slots, p: [f64; 7]) -> (f64, Slots) {
    let b1 = p[0];
    let slip = (-b1).mul_add(w, v);
    let c = p[1] * w;
    let mut ds = dw.map(|d| -b1 * d);
    ds[0] = c.mul_add(p[2], ds[0]);
    ds[1] = c.mul_add(p[3], ds[1]);
    ds[4] = c.mul_add(p[4], ds[4]);
    ds[5] = c.mul_add(p[5], ds[5]);
    ds[2] = c.mul_add(p[6], ds[2]);
    (slip, ds)
}
