//! The rigid drive with LuGre friction: one mass (or inertia) against a bristle force w, its
//! damping and a viscous term, each direction with its own levels where the law asks:
//!
//! `M·ẍ = g·u − offset − F`, `F = w + (σ1/σ0)·ẇ + Fv±·ẋ`,
//! `ẇ = σ0·(ẋ − |ẋ|·w/G(ẋ))`, `G(v) = Fc± + (Fs± − Fc±)·e^{−(v/vs)²}`.
//!
//! The bristle state is hd-model's LuGre law in force units (w = σ0·z, z the mean bristle
//! deflection [m or rad]); its exact update at a held speed
//! ([`hd_model::laws::friction::LuGre::step_held_with_speed`]) and its Stribeck level come
//! from that one law, evaluated in `f64`, and enter the generic arithmetic through
//! [`Scalar::lift`] with the law's own partial derivatives. The viscous term is the
//! drive's (`Fv±`, by direction), so the law's σ2 is zero here.
//!
//! Each sample (held command) is cut into substeps; in each, the bristle is advanced
//! exactly at a held speed (so any bristle stiffness is stable), the mean bristle force over
//! the substep follows from the same exponential, and the speed by a predictor–corrector:
//! the end speed predicted with the previous substep's mean friction, the bristle then held
//! at the mean of the start and predicted end speeds. Second order in the substep for the
//! mass, exact for the stiff bristle, one bristle update per substep.

use super::dual::Scalar;
use super::model::Motion;
use hd_model::laws::friction::LuGre;

/// Largest (rate × substep) the substep count allows: the bristle-mass oscillation
/// √(σ0/M) and the bristle damping 2σ1/M [1/s] times the substep [s].
const RATE_STEP: f64 = 0.125;

/// Fewest substeps per sample: two, so that the count does not flip between one and two
/// (a small jump of the objective) while a fit moves σ0 and σ1 about moderate values.
const MIN_SUBSTEPS: usize = 2;

/// Most substeps per sample.
const MAX_SUBSTEPS: usize = 64;

/// A LuGre drive's parameters, in the axis's units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LuGreDrive<T> {
    /// Mass or inertia [kg or kg·m²].
    pub m: T,
    /// Viscous friction for v ≥ 0 [N·s/m or N·m·s/rad].
    pub fv_pos: T,
    /// Viscous friction for v < 0 [N·s/m or N·m·s/rad].
    pub fv_neg: T,
    /// Coulomb level for v ≥ 0 [N or N·m].
    pub fc_pos: T,
    /// Coulomb level for v < 0 (positive) [N or N·m].
    pub fc_neg: T,
    /// Static (breakaway) level for v ≥ 0 [N or N·m].
    pub fs_pos: T,
    /// Static level for v < 0 (positive) [N or N·m].
    pub fs_neg: T,
    /// Stribeck speed [m/s or rad/s].
    pub vs: T,
    /// Bristle stiffness [N/m or N·m/rad].
    pub sigma0: T,
    /// Bristle damping [N·s/m or N·m·s/rad].
    pub sigma1: T,
    /// Constant force opposing the drive [N or N·m].
    pub offset: T,
    /// Force per unit command [N/V or N·m/V].
    pub gain: T,
}

impl<T: Scalar> LuGreDrive<T> {
    /// hd-model's law at the current values (σ2 = 0: the drive adds its own viscous term).
    fn law(&self) -> LuGre {
        LuGre {
            tc_neg: self.fc_neg.re(),
            ts_neg: self.fs_neg.re(),
            ..LuGre::symmetric(
                self.sigma0.re(),
                self.sigma1.re(),
                0.0,
                self.fc_pos.re(),
                self.fs_pos.re(),
                self.vs.re(),
            )
        }
    }

    /// The law's shape parameters as this drive's scalars, in
    /// [`hd_model::laws::lugre_step::SHAPE_PARAMS`] order (Tc, Ts, ωs, σ0, Tc_neg, Ts_neg).
    fn shape(&self) -> [T; 6] {
        [self.fc_pos, self.fs_pos, self.vs, self.sigma0, self.fc_neg, self.fs_neg]
    }

    /// Substeps per sample of `h` [s]: enough that the bristle–mass oscillation and the
    /// bristle damping are resolved ([`RATE_STEP`]).
    pub fn substeps(&self, h: f64) -> usize {
        let m = self.m.re();
        let rate = (self.sigma0.re() / m).max(0.0).sqrt().max(2.0 * self.sigma1.re() / m);
        ((rate * h / RATE_STEP).ceil() as usize).clamp(MIN_SUBSTEPS, MAX_SUBSTEPS)
    }

    /// The bristle force after `d` [s] at the held speed `v` from `w0`, and its mean over
    /// the interval [N or N·m].
    fn bristle(&self, law: &LuGre, shape: &[T; 6], v: T, w0: T, d: f64) -> (T, T) {
        let (vr, w0r) = (v.re(), w0.re());
        let (step, d_v) = law.step_held_with_speed(vr, w0r, d);
        let g = step.grad;
        let w1 = T::lift(
            step.w,
            &[
                (step.d_w0, w0),
                (d_v, v),
                (g[0], shape[0]),
                (g[1], shape[1]),
                (g[2], shape[2]),
                (g[3], shape[3]),
                (g[4], shape[4]),
                (g[5], shape[5]),
            ],
        );
        if vr == 0.0 {
            return (w1, w0);
        }
        // The Stribeck level G and its derivatives, from the law.
        let lg = law.level_grad(vr);
        let slope = lg.slope;
        let lg_parts = lg.grad;
        let level = T::lift(
            lg.level,
            &[
                (slope, v),
                (lg_parts[0], shape[0]),
                (lg_parts[1], shape[1]),
                (lg_parts[2], shape[2]),
                (lg_parts[4], shape[4]),
                (lg_parts[5], shape[5]),
            ],
        );
        // ẇ = λ·(w_ss − w): the mean of w is w_ss + (w0 − w_ss)·(1 − e^{−λd})/(λd).
        let w_ss = if vr > 0.0 { level } else { -level };
        let x = self.sigma0 * v.abs() / level * d;
        let phi =
            if x.re() < 1e-4 { T::cst(1.0) - x * 0.5 + x * x / 6.0 } else { -(-x).exp_m1() / x };
        (w1, w_ss + (w0 - w_ss) * phi)
    }

    /// Viscous force at speed v [N or N·m].
    fn viscous(&self, v: T) -> T {
        if v.re() >= 0.0 { self.fv_pos * v } else { self.fv_neg * v }
    }

    /// The motion after `h` [s] under the constant drive force `f` [N or N·m] from `s`.
    pub fn step(&self, s: Motion<T>, f: T, h: f64) -> Motion<T> {
        let law = self.law();
        let shape = self.shape();
        let n = self.substeps(h);
        let d = h / n as f64;
        let net = f - self.offset;
        let per_mass = T::cst(d) / self.m; // [s/kg]
        let damping = self.sigma1 / self.sigma0 / d; // (σ1/σ0)/d [1]
        let mut s = s;
        // The predictor's friction is the previous substep's mean (also across samples): an
        // O(d) error in the force is O(d²) in the predicted speed, which the corrector only
        // reads at its midpoint. One bristle update per substep.
        for _ in 0..n {
            let force = |v: T| {
                let (w1, mean) = self.bristle(&law, &shape, v, s.w, d);
                (w1, mean + (w1 - s.w) * damping + self.viscous(v))
            };
            let predicted = s.v + (net - s.friction) * per_mass;
            let mid = (s.v + predicted) * 0.5;
            let (w1, fm) = force(mid);
            let v1 = s.v + (net - fm) * per_mass;
            s = Motion { x: s.x + (s.v + v1) * (0.5 * d), v: v1, w: w1, friction: fm };
        }
        s
    }
}
