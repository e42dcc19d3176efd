//! Exact updates of the LuGre bristle state over one sample interval of a recorded speed,
//! with their derivatives with respect to the law's parameters (docs/model.md §5).
//!
//! At a held speed v ≠ 0 the bristle equation is linear in w = σ0·s:
//! `ẇ = λ·(w_ss − w)` with `w_ss = sign(v)·G(v)`, `λ = σ0·|v|/G(v)` [1/s] and the Stribeck
//! level `G(v) = Tc + (Ts − Tc)·e^{−(v/ωs)²}` [N·m] (the negative-side levels for v < 0), so
//! `w(h) = w_ss + (w₀ − w_ss)·e^{−λ·h}` exactly. The fits read the recorded speed as linear
//! between samples and step each interval at its mean speed, which carries the linear
//! reading's sliding displacement exactly; an interval across which the speed changes sign
//! is split at the zero of the line and each part stepped at its own mean. The derivatives
//! of these maps with respect to the parameters ([`ShapeGrad`]) are carried beside the
//! state, so one pass over a record gives the states and their exact sensitivities.
//! The load-dependent levels (`mu_*`) are not used here: these updates are for records of
//! friction alone (the fits hold the factors at zero).

use super::friction::{FrictionLaw, LuGre, floored_level, term_is_invisible};

/// Index of each parameter in a [`ShapeGrad`]: the Coulomb and static levels, the
/// Stribeck speed, the bristle stiffness, and the negative-side levels.
pub const SHAPE_PARAMS: [&str; 6] = ["Tc", "Ts", "ws", "sigma0", "Tc_neg", "Ts_neg"];

/// Derivatives with respect to the parameters in [`SHAPE_PARAMS`] order
/// (∂/∂Tc, ∂/∂Ts [1 per N·m], ∂/∂ωs [per rad/s], ∂/∂σ0 [per N·m/rad], ∂/∂Tc_neg, ∂/∂Ts_neg).
pub type ShapeGrad = [f64; 6];

/// The Stribeck level at one speed with its derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelGrad {
    /// `G(v)` [N·m].
    pub level: f64,
    /// ∂G/∂v [N·m·s/rad] (the same as [`LuGre::stribeck`]'s, from the same exponential).
    pub slope: f64,
    /// ∂G/∂p for p in [`SHAPE_PARAMS`] (∂G/∂σ0 = 0).
    pub grad: ShapeGrad,
}

/// One bristle step with its sensitivities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BristleStep {
    /// The state after the step w₁ [N·m].
    pub w: f64,
    /// ∂w₁/∂w₀ [–].
    pub d_w0: f64,
    /// ∂w₁/∂p at fixed w₀, for p in [`SHAPE_PARAMS`].
    pub grad: ShapeGrad,
}

impl LuGre {
    /// The Stribeck level `G(v)` [N·m] (unloaded) and its derivatives with respect to the
    /// levels and ωs. Only the levels of v's side have non-zero entries (v = 0 counts as
    /// positive, as in [`LuGre::levels`]). Where the Stribeck term cannot change the level
    /// by a bit (as in [`LuGre::stribeck`]) no exponential is evaluated and e^{−(v/ωs)²}
    /// counts as 0: the level is tc, and ∂G/∂Ts, ∂G/∂ωs drop a term below 1e-16 of it.
    #[inline(always)]
    pub fn level_grad(&self, v: f64) -> LevelGrad {
        let (tc, ts) = self.levels(v);
        // The same level as [`LuGre::stribeck`] (unloaded) from one exponential.
        let r = v * (1.0 / self.ws);
        let x = r * r;
        let e = if term_is_invisible(x, ts - tc, tc) { 0.0 } else { (-x).exp() };
        let level = floored_level(crate::fma::fmadd(ts - tc, e, tc), tc, ts);
        let mut grad = [0.0; 6];
        let (kc, ks) = if v < 0.0 { (4, 5) } else { (0, 1) };
        grad[kc] = 1.0 - e;
        grad[ks] = e;
        grad[2] = (ts - tc) * e * 2.0 * r * r / self.ws;
        let slope = (ts - tc) * e * (-2.0 * r / self.ws);
        LevelGrad { level, slope, grad }
    }

    /// The state [N·m] after `h` seconds at the held speed v [rad/s] from w₀ [N·m]
    /// (unchanged at v = 0), with ∂w₁/∂w₀ and ∂w₁/∂p. The same map as
    /// [`crate::laws::friction::FrictionLaw::step_at_speed`].
    #[inline(always)]
    pub fn step_held(&self, v: f64, w0: f64, h: f64) -> BristleStep {
        if v == 0.0 || h <= 0.0 {
            return BristleStep { w: w0, d_w0: 1.0, grad: [0.0; 6] };
        }
        let lg = self.level_grad(v);
        let g = lg.level;
        let sv = v.signum();
        let av = v.abs();
        let lambda = self.sigma0 * av / g;
        // e^{−λh} and 1 − e^{−λh} from one transcendental: e^{−λh} − 1 where λh is small
        // (no cancellation in the rise), e^{−λh} where it is not (no cancellation in the
        // decay; the rise 1 − e^{−λh} ≥ 1 − e^{−1/2} then loses under a bit).
        let lh = lambda * h;
        let (decay, rise) = if lh < 0.5 {
            let m = (-lh).exp_m1();
            (1.0 + m, -m)
        } else {
            let d = (-lh).exp();
            (d, 1.0 - d)
        };
        let w_ss = sv * g;
        let gap = w0 - w_ss;
        let w = w_ss + gap * decay;
        // ∂w/∂G through w_ss and through λ (∂λ/∂G = −λ/G); ∂w/∂σ0 through λ only.
        let d_level = sv * rise + gap * decay * h * lambda / g;
        let mut grad = lg.grad.map(|d| d_level * d);
        grad[3] = -gap * decay * h * av / g;
        BristleStep { w, d_w0: decay, grad }
    }

    /// [`LuGre::step_held`] together with ∂w₁/∂v [N·m·s/rad] at fixed w₀ and parameters,
    /// for callers whose speed is itself computed (a simulated drive carries the step's
    /// sensitivity to the speed on to its parameters). With w_ss = sign(v)·G(v) and
    /// λ = σ0·|v|/G: ∂w₁/∂v = sign(v)·G′·(1 − e^{−λh}) − (w₀ − w_ss)·e^{−λh}·h·∂λ/∂v,
    /// ∂λ/∂v = σ0·(sign(v)·G − |v|·G′)/G². At v = 0 the two one-sided limits differ by the
    /// |v| term (∓ w₀·σ0·h/G); their mean σ0·h is returned.
    pub fn step_held_with_speed(&self, v: f64, w0: f64, h: f64) -> (BristleStep, f64) {
        let step = self.step_held(v, w0, h);
        if h <= 0.0 {
            return (step, 0.0);
        }
        if v == 0.0 {
            return (step, self.sigma0 * h);
        }
        let (g, g_v) = self.stribeck(v);
        let (sv, av) = (v.signum(), v.abs());
        let lambda = self.sigma0 * av / g;
        let decay = (-lambda * h).exp();
        let rise = -(-lambda * h).exp_m1();
        let w_ss = sv * g;
        let d_lambda = self.sigma0 * (sv * g - av * g_v) / (g * g);
        let d_v = sv * g_v * rise - (w0 - w_ss) * decay * h * d_lambda;
        (step, d_v)
    }

    /// One sample interval of a speed record read as linear from v₀ to v₁ [rad/s] over
    /// `h` [s]: stepped at the mean speed, or, when the speed changes sign inside, in two
    /// parts split at the zero crossing, each at its own mean (v₀/2, then v₁/2).
    #[inline]
    pub fn step_interval(&self, v0: f64, v1: f64, w0: f64, h: f64) -> BristleStep {
        if v0 * v1 < 0.0 {
            let t_zero = h * v0.abs() / (v0.abs() + v1.abs());
            let a = self.step_held(0.5 * v0, w0, t_zero);
            let b = self.step_held(0.5 * v1, a.w, h - t_zero);
            let mut grad = b.grad;
            for (g, ga) in grad.iter_mut().zip(a.grad) {
                *g += b.d_w0 * ga;
            }
            BristleStep { w: b.w, d_w0: b.d_w0 * a.d_w0, grad }
        } else {
            self.step_held(0.5 * (v0 + v1), w0, h)
        }
    }

    /// [`LuGre::step_interval`]'s state alone [N·m], without the derivatives.
    #[inline]
    pub fn step_interval_state(&self, v0: f64, v1: f64, w0: f64, h: f64) -> f64 {
        if v0 * v1 < 0.0 {
            let t_zero = h * v0.abs() / (v0.abs() + v1.abs());
            let mid = self.step_at_speed(0.5 * v0, w0, t_zero);
            self.step_at_speed(0.5 * v1, mid, h - t_zero)
        } else {
            self.step_at_speed(0.5 * (v0 + v1), w0, h)
        }
    }

    /// The bristle rate ṡ = v − |v|·w/G(v) [rad/s] at speed v and state w (unloaded), with
    /// ∂ṡ/∂w [1/(N·m·s)] and ∂ṡ/∂p at fixed w.
    #[inline]
    pub fn slip_rate_grad(&self, v: f64, w: f64) -> (f64, f64, ShapeGrad) {
        let lg = self.level_grad(v);
        let av = v.abs();
        let d_w = -av / lg.level;
        let rate = v + d_w * w;
        let d_level = av * w / (lg.level * lg.level);
        (rate, d_w, lg.grad.map(|d| d_level * d))
    }
}

#[cfg(test)]
mod tests;
