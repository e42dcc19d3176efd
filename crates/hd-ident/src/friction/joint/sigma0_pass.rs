//! The σ0 search's cost in one pass with no stored column.
//!
//! During the search the levels (Tc, Ts, ωs and the negative-side ones) are held, so the
//! Stribeck level at every interval's mean speed and at every sample is the same in each
//! trial: they are worked out once ([`Sigma0Pass::new`]). A trial then steps the bristle
//! torque with one exponential per interval part (a chunk of them at once, vectorised:
//! [`super::vexp`]), w₁ = w_ss + (w₀ − w_ss)·e^{−σ0·c}
//! (c = |v̄|·h/G(v̄) [rad/(N·m)]), forms ṡ = v − (|v|/G(v))·w, and adds each sample's
//! products to the Gram matrix of (ṡ, ω, 1, y − w): the bounded projection onto σ1, σ2
//! and the offset and the residual sum of squares follow from that 4 × 4 matrix
//! ([`super::fast::gram_solve`]). Where the scaled matrix is too ill-conditioned for that,
//! the trial (or one whose state is not finite) is evaluated by the general path instead.

use super::JointProblem;
use super::vexp::exp_neg;
use hd_model::laws::friction::LuGre;

/// Above this decay exponent e^{−x} is 0 to the last bit: no exponential is evaluated
/// (the library's slow underflow path).
const UNDERFLOW: f64 = 745.2;

/// One part of an interval: the state relaxes towards `w_ss` [N·m] at rate σ0·`c`.
#[derive(Clone, Copy, Debug)]
struct Part {
    /// |v̄|·h/G(v̄) [rad/(N·m)].
    c: f64,
    /// sign(v̄)·G(v̄) [N·m].
    w_ss: f64,
}

/// Intervals whose decays are worked out together, in a loop that vectorises.
const CHUNK: usize = 256;

/// The search's fixed per-sample quantities for one set of held levels.
pub(super) struct Sigma0Pass {
    /// The (first) part of each interval k − 1 → k, index k − 1: its c …
    part_c: Vec<f64>,
    /// … and its w_ss.
    part_w_ss: Vec<f64>,
    /// Intervals across which the speed changes sign: (index k, the second part).
    splits: Vec<(usize, Part)>,
    /// |v_k|/G(v_k) [1/(N·m·s)·rad]: ṡ = v − this·w.
    slip_gain: Vec<f64>,
    /// The law with the held levels (σ0 set per trial).
    law: LuGre,
}

fn part(law: &LuGre, v: f64, h: f64) -> Part {
    if v == 0.0 {
        return Part { c: 0.0, w_ss: 0.0 };
    }
    let level = law.stribeck(v).0;
    Part { c: v.abs() * h / level, w_ss: v.signum() * level }
}

impl Sigma0Pass {
    /// The fixed quantities of the series of `problem` under the levels of `law`.
    pub(super) fn new(problem: &JointProblem, law: LuGre) -> Self {
        let (t, omega) = (problem.data.t(), problem.data.omega());
        let n = t.len();
        let mut parts = Vec::with_capacity(n.saturating_sub(1));
        let mut splits = Vec::new();
        for k in 1..n {
            let (v0, v1, h) = (omega[k - 1], omega[k], t[k] - t[k - 1]);
            if v0 * v1 < 0.0 {
                let t_zero = h * v0.abs() / (v0.abs() + v1.abs());
                parts.push(part(&law, 0.5 * v0, t_zero));
                splits.push((k, part(&law, 0.5 * v1, h - t_zero)));
            } else {
                parts.push(part(&law, 0.5 * (v0 + v1), h));
            }
        }
        let slip_gain = omega.iter().map(|&v| v.abs() / law.stribeck(v).0).collect();
        let part_c = parts.iter().map(|p| p.c).collect();
        let part_w_ss = parts.iter().map(|p| p.w_ss).collect();
        Self { part_c, part_w_ss, splits, slip_gain, law }
    }

    /// The residual sum of squares [N²·m²] of the projected model at bristle stiffness
    /// `sigma0` [N·m/rad]; `None` where the Gram matrix is not usable (the caller then
    /// evaluates the trial by the general path).
    pub(super) fn rss(&self, problem: &JointProblem, sigma0: f64) -> Option<f64> {
        let (omega, y) = (problem.data.omega(), problem.data.torque());
        let law = LuGre { sigma0, ..self.law };
        let (mut w, _) = super::super::bristle::start(&law, omega[0], y[0] - problem.first_bias);
        let relax = |w: f64, p: &Part| {
            let x = sigma0 * p.c;
            let decay = if x < UNDERFLOW { (-x).exp() } else { 0.0 };
            p.w_ss + (w - p.w_ss) * decay
        };
        // Gram of (ṡ, ω, 1, y − w), upper triangle.
        let mut g = [0.0f64; 10];
        let mut add = |k: usize, w: f64| {
            let v = omega[k];
            let z = [v - self.slip_gain[k] * w, v, 1.0, y[k] - w];
            let mut i = 0;
            for a in 0..4 {
                for b in a..4 {
                    g[i] += z[a] * z[b];
                    i += 1;
                }
            }
        };
        add(0, w);
        let mut next = self.splits.iter().peekable();
        let mut decay = [0.0f64; CHUNK];
        let n = omega.len();
        let mut k0 = 1;
        while k0 < n {
            let len = CHUNK.min(n - k0);
            let c = &self.part_c[k0 - 1..k0 - 1 + len];
            for (d, &c) in decay[..len].iter_mut().zip(c) {
                *d = exp_neg(-(sigma0 * c));
            }
            for (j, &dj) in decay[..len].iter().enumerate() {
                let k = k0 + j;
                let w_ss = self.part_w_ss[k - 1];
                w = w_ss + (w - w_ss) * dj;
                if let Some(&&(ks, ref second)) = next.peek()
                    && ks == k
                {
                    w = relax(w, second);
                    next.next();
                }
                add(k, w);
            }
            k0 += len;
        }
        if !g.iter().all(|x| x.is_finite()) {
            return None; // the general path names the failure
        }
        let full = |a: usize, b: usize| {
            let (a, b) = (a.min(b), a.max(b));
            g[a * 4 - a * (a + 1) / 2 + b]
        };
        problem.rss_from_gram(
            |a, b| full(problem.kind(a), problem.kind(b)),
            full(3, 3),
            |a| full(problem.kind(a), 3),
        )
    }
}
