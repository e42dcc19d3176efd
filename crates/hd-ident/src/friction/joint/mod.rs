//! The joint friction fit: every LuGre parameter from one time series of speed and
//! torque, with no steady-state sweep.
//!
//! The model is `Tf = w + σ1·ṡ + σ2·v (+ offset)`, where the bristle torque w = σ0·s runs
//! along the measured speed by the LuGre law's exact sample updates, its sensitivities
//! carried beside it ([`super::bristle`]), so every trial gives the residuals and their
//! exact Jacobian in one pass. For given levels and rates (Tc, Ts, ωs, σ0 and, with `asymmetric`, Tc_neg,
//! Ts_neg) w and ṡ are fixed, so σ1, σ2 and the offset follow by bounded linear least
//! squares (variable projection); the nonlinear ones are refined together by
//! Levenberg–Marquardt over their logarithms ([`crate::lm`]), the Coulomb levels above an
//! active-set floor ([`LEVEL_FLOOR`]) so that an optimum on 0 is reached in a few steps.
//!
//! The pipeline, each step tolerant of failed trials:
//! 1. start the static parameters from quasi-steady samples of the series itself
//!    ([`super::quasi_steady`]) with the static fit, or from plain torque levels when the series
//!    has too few;
//! 2. start σ0 by a global search over ln σ0 (grid + Brent), the others held;
//! 3. refine all free parameters jointly from that start, from [`EXTRA_STARTS`] perturbed
//!    ones, from Stribeck-dominated ones and (asymmetric law) from the symmetric law's
//!    optimum (real data have local optima); the best wins ([`pipeline`]);
//! 4. hold each free Coulomb level at exactly 0 and refine the rest: an optimum on that
//!    bound, which the logarithms can only approach, is reached and reported on its bound;
//! 5. standard errors, intervals, correlations and determined flags from the Jacobian at
//!    the optimum, as for every fit.

mod exact;
mod fast;
mod finish;
mod kernel;
mod normal;
mod pipeline;
mod race;
mod sigma0_pass;
mod start;
mod vexp;

use super::bristle::{BristleRun, bristle_run};
use crate::data::TransientData;
use crate::error::FitError;
use crate::fix::Fixed;
use crate::linear::bounded_least_squares;
use crate::lm::{Formed, LmOptions, LmPaused, LmStep, minimise, minimise_paused, resume, silent};
use crate::report::Explanation;
use hd_model::laws::friction::LuGre;
use hd_model::registry::lookup;
use start::speed_range;

/// Which optional terms the friction fits include.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrictionOptions {
    /// Separate Coulomb and static levels for negative speeds (`Tc_neg`, `Ts_neg`).
    pub asymmetric: bool,
    /// A constant torque offset of the measurement (`offset` [N·m]).
    pub offset: bool,
}

pub use crate::fix::OFFSET;
pub use pipeline::{JointSettings, fit_joint, fit_joint_with};

/// Perturbed starts refined besides the main one (ωs and σ0 moved by a factor each way).
pub const EXTRA_STARTS: usize = 4;
/// Iteration budget of each Levenberg–Marquardt refinement (an iteration is one pass
/// over the record with the sensitivities carried).
pub const MAX_ITERATIONS: usize = 200;
/// Factor by which the extra starts move ωs and σ0.
pub const START_FACTOR: f64 = 5.0;
/// Iterations every start runs before the starts are compared ([`DROP_FACTOR`]).
pub const RACE_ITERATIONS: usize = 10;
/// A start whose cost after [`RACE_ITERATIONS`] exceeds this multiple of the lowest cost
/// any start has reached by then is stopped there. On the records measured (docs/model.md
/// §5) every start that went on to the best optimum was within 0.2 % of the lowest cost at
/// that point; the stopped ones were 8–30× above it and ended far above the best.
pub const DROP_FACTOR: f64 = 5.0;

const NONLINEAR_ALL: [&str; 6] = ["Tc", "Ts", "ws", "sigma0", "Tc_neg", "Ts_neg"];
const LINEAR_ALL: [&str; 3] = ["sigma1", "sigma2", OFFSET];

/// Unit of a parameter of the friction fits.
fn unit_of(name: &str) -> &'static str {
    crate::fix::fitted_info(name).map_or("", |i| i.0)
}

/// The joint problem on one series.
pub struct JointProblem<'a> {
    data: &'a TransientData,
    /// Free nonlinear parameters, in [`NONLINEAR_ALL`] order.
    nonlinear: Vec<&'static str>,
    /// Linear parameters in the model, in [`LINEAR_ALL`] order, with their fixed values.
    linear: Vec<(&'static str, Option<f64>)>,
    /// Values of every nonlinear parameter (fixed ones stay; free ones are overwritten).
    base: [f64; 6],
    asymmetric: bool,
    /// The part of the first measured torque that is not bristle torque (offset and
    /// viscous term at the first sample) [N·m]: the bristle state starts at the first
    /// torque minus this.
    first_bias: f64,
    /// A column of ones (the offset's).
    ones: Vec<f64>,
    /// Buffers for the evaluations ([`fast`]).
    pool: fast::Pool,
    /// Levels held on their lower bound 0 because the fit is best there
    /// ([`pipeline`]'s bound stage): reported "on its bound", not "fixed".
    on_bound: Vec<&'static str>,
    /// The Coulomb levels' floor in the refinement [N·m]: [`LEVEL_FLOOR`] × the start's
    /// largest level, or none (0) ([`JointProblem::bounds`]).
    level_floor: f64,
}

/// The Coulomb levels' lower bound in the joint refinement, as a share of the start's
/// largest level [–]. The levels move by their logarithms, which can only approach 0: a
/// start drawn to an optimum on Tc = 0 would crawl towards it (40-odd iterations on such a
/// record). With this floor kept as an active-set bound, the level lands on it in a few
/// steps and is held while the rest converges; a level that ends on the floor is then held
/// at exactly 0 and, separately, freed from just above 0 ([`pipeline`]), so the floor only
/// shortens the way, it does not decide where the fit ends.
pub const LEVEL_FLOOR: f64 = 1e-6;

/// The model's pieces for one set of nonlinear values.
struct Pieces {
    /// The bristle run: w (the torque with σ1 = σ2 = 0 and no offset) [N·m], ṡ, and
    /// their sensitivities when asked.
    run: BristleRun,
    /// One column per model linear parameter.
    columns: Vec<Vec<f64>>,
}

/// A projected solution: the linear parameters and the residuals.
struct Projected {
    pieces: Pieces,
    beta: Vec<f64>,
    at_bound: Vec<bool>,
    residuals: Vec<f64>,
}

impl<'a> JointProblem<'a> {
    /// Set up the problem with `fixed` values held and `start` values for the rest.
    fn new(
        data: &'a TransientData,
        fixed: &Fixed,
        opts: FrictionOptions,
        start: &[(&'static str, f64)],
    ) -> Self {
        let asymmetric = opts.asymmetric;
        let value = |name: &str| {
            fixed
                .get(name)
                .or_else(|| start.iter().find(|(n, _)| *n == name).map(|v| v.1))
                .unwrap_or_else(|| lookup(name).map_or(0.0, |i| i.default_value()))
        };
        let mut base = NONLINEAR_ALL.map(value);
        if !asymmetric {
            base[4] = base[0];
            base[5] = base[1];
        }
        let nonlinear = NONLINEAR_ALL
            .iter()
            .take(if asymmetric { 6 } else { 4 })
            .copied()
            .filter(|n| fixed.get(n).is_none())
            .collect();
        let linear = LINEAR_ALL
            .iter()
            .copied()
            .filter(|&n| n != OFFSET || opts.offset)
            .map(|n| (n, if n == OFFSET { None } else { fixed.get(n) }))
            .collect();
        let largest = [base[0], base[1], base[4], base[5]].into_iter().fold(0.0f64, f64::max);
        let level_floor = if largest.is_finite() { LEVEL_FLOOR * largest } else { 0.0 };
        Self {
            data,
            nonlinear,
            linear,
            base,
            asymmetric,
            first_bias: 0.0,
            ones: vec![1.0; data.len()],
            pool: fast::Pool::default(),
            on_bound: Vec::new(),
            level_floor,
        }
    }

    /// All nonlinear values with the free ones taken from `x` (logarithms).
    fn values(&self, x: &[f64]) -> [f64; 6] {
        let mut v = self.base;
        for (name, xi) in self.nonlinear.iter().zip(x) {
            let k = NONLINEAR_ALL.iter().position(|n| n == name).expect("a nonlinear name");
            v[k] = xi.exp();
        }
        if !self.asymmetric {
            v[4] = v[0];
            v[5] = v[1];
        }
        v
    }

    fn x_of(&self, values: &[f64; 6]) -> Vec<f64> {
        self.nonlinear
            .iter()
            .map(|name| values[NONLINEAR_ALL.iter().position(|n| n == name).unwrap()].ln())
            .collect()
    }

    /// Bounds of the optimiser's variables (logarithms): the Coulomb levels from their
    /// floor ([`LEVEL_FLOOR`]), the rest free.
    fn bounds(&self) -> Vec<(f64, f64)> {
        self.nonlinear
            .iter()
            .map(|name| match *name {
                "Tc" | "Tc_neg" if self.level_floor > 0.0 => (self.level_floor.ln(), f64::INFINITY),
                _ => (f64::NEG_INFINITY, f64::INFINITY),
            })
            .collect()
    }

    /// Whether the free level `name` ended on its floor at values `v`.
    fn on_floor(&self, name: &str, v: &[f64; 6]) -> bool {
        let k = NONLINEAR_ALL.iter().position(|n| *n == name).expect("a level");
        self.nonlinear.contains(&name)
            && self.level_floor > 0.0
            && v[k] <= self.level_floor * (1.0 + 1e-9)
    }

    /// The LuGre law with nonlinear values `v` and no linear terms.
    fn law(&self, v: &[f64; 6]) -> LuGre {
        LuGre {
            sigma0: v[3],
            sigma1: 0.0,
            sigma2: 0.0,
            tc: v[0],
            ts: v[1],
            ws: v[2],
            tc_neg: v[4],
            ts_neg: v[5],
            mu: hd_model::laws::friction::LoadFactors::default(),
        }
    }

    /// The model's pieces at nonlinear values `v`; with `grad`, the bristle run carries
    /// its sensitivities too.
    fn pieces_with(&self, v: &[f64; 6], grad: bool) -> Result<Pieces, FitError> {
        let law = self.law(v);
        let (t, omega) = (self.data.t(), self.data.omega());
        let run = bristle_run(t, omega, &law, self.data.torque()[0] - self.first_bias, grad)?;
        let mut columns = Vec::with_capacity(self.linear.len());
        for (name, _) in &self.linear {
            let col: Vec<f64> = match *name {
                "sigma1" => run.slip.clone(),
                "sigma2" => omega.to_vec(),
                _ => vec![1.0; omega.len()],
            };
            columns.push(col);
        }
        Ok(Pieces { run, columns })
    }

    fn project(&self, v: &[f64; 6]) -> Result<Projected, FitError> {
        self.project_with(v, false)
    }

    /// [`JointProblem::project`], the bristle run carrying its sensitivities with `grad`.
    fn project_with(&self, v: &[f64; 6], grad: bool) -> Result<Projected, FitError> {
        let pieces = self.pieces_with(v, grad)?;
        let y = self.data.torque();
        let mut target: Vec<f64> = y.iter().zip(&pieces.run.w).map(|(a, b)| a - b).collect();
        let mut free = Vec::new();
        for (j, (_, fixed)) in self.linear.iter().enumerate() {
            match fixed {
                Some(val) => {
                    target.iter_mut().zip(&pieces.columns[j]).for_each(|(t, c)| *t -= val * c)
                }
                None => free.push(j),
            }
        }
        let bounds = |j: usize| -> (f64, f64) {
            match self.linear[j].0 {
                OFFSET => (f64::NEG_INFINITY, f64::INFINITY),
                name => lookup(name).map_or((f64::NEG_INFINITY, f64::INFINITY), |i| (i.min, i.max)),
            }
        };
        let cols: Vec<&[f64]> = free.iter().map(|&j| pieces.columns[j].as_slice()).collect();
        let lo: Vec<f64> = free.iter().map(|&j| bounds(j).0).collect();
        let hi: Vec<f64> = free.iter().map(|&j| bounds(j).1).collect();
        let sol = bounded_least_squares(&cols, &target, &lo, &hi);
        let mut beta: Vec<f64> = self.linear.iter().map(|(_, f)| f.unwrap_or(0.0)).collect();
        let mut at_bound = vec![false; beta.len()];
        for (k, &j) in free.iter().enumerate() {
            beta[j] = sol.coef[k];
            at_bound[j] = sol.at_bound[k];
        }
        let mut residuals = target;
        for (k, &j) in free.iter().enumerate() {
            residuals.iter_mut().zip(&pieces.columns[j]).for_each(|(r, c)| *r -= sol.coef[k] * c);
        }
        Ok(Projected { pieces, beta, at_bound, residuals })
    }

    fn rss_at(&self, v: &[f64; 6]) -> Result<f64, FitError> {
        self.rss_fast(v)
    }

    /// Levenberg–Marquardt over the free nonlinear parameters' logarithms from `x0`, the
    /// Coulomb levels bounded below by their floor ([`JointProblem::bounds`]).
    fn refine(&self, x0: &[f64], lm: &LmOptions) -> Result<crate::lm::LmOutcome, FitError> {
        let model = Formed(|x: &[f64]| self.pool.with(|ws| self.normal_at(x, ws)));
        minimise(&model, x0, &self.bounds(), lm, &silent)
    }

    /// [`JointProblem::refine`], paused after `iterations` unless it ends before.
    fn refine_paused(
        &self,
        x0: &[f64],
        lm: &LmOptions,
        iterations: usize,
    ) -> Result<LmStep, FitError> {
        let model = Formed(|x: &[f64]| self.pool.with(|ws| self.normal_at(x, ws)));
        minimise_paused(&model, x0, &self.bounds(), lm, iterations)
    }

    /// Resume a paused [`JointProblem::refine_paused`] to its end.
    fn resume(&self, paused: LmPaused, lm: &LmOptions) -> Result<crate::lm::LmOutcome, FitError> {
        let model = Formed(|x: &[f64]| self.pool.with(|ws| self.normal_at(x, ws)));
        resume(&model, paused, &self.bounds(), lm)
    }

    /// Range of σ0 worth searching, from the record: see [`super::transient`].
    fn sigma0_range(&self, level: f64) -> (f64, f64) {
        let (t, w) = (self.data.t(), self.data.omega());
        let mut steps: Vec<f64> =
            (1..t.len()).map(|k| 0.5 * (w[k].abs() + w[k - 1].abs()) * (t[k] - t[k - 1])).collect();
        steps.sort_by(f64::total_cmp);
        let median = steps[steps.len() / 2];
        let step =
            if median > 0.0 { median } else { steps.iter().sum::<f64>() / steps.len() as f64 };
        let (mut x, mut lo, mut hi) = (0.0f64, 0.0f64, 0.0f64);
        for k in 1..t.len() {
            x += 0.5 * (w[k] + w[k - 1]) * (t[k] - t[k - 1]);
            lo = lo.min(x);
            hi = hi.max(x);
        }
        let span = (hi - lo).max(step);
        (
            level / (super::transient::SIGMA0_LOW_SPAN * span),
            super::transient::SIGMA0_HIGH_PER_SAMPLE * level / step,
        )
    }

    fn explain(&self, name: &str, v: &[f64; 6]) -> Explanation {
        let (lo, hi) = speed_range(self.data.omega());
        let presliding = v[1].max(v[5]) / v[3];
        let (effect, remedy) = match name {
            "Tc" | "Tc_neg" => (
                format!("the Coulomb level {name}"),
                format!("sliding well above ωs ≈ {:.2e} rad/s (here |ω| up to {hi:.2e} rad/s) in that direction would reveal it", v[2]),
            ),
            "Ts" | "Ts_neg" => (
                format!("the static level {name}"),
                format!("slow sliding well below ωs ≈ {:.2e} rad/s (here |ω| from {lo:.2e} rad/s) in that direction would reveal it", v[2]),
            ),
            "ws" => (
                "the Stribeck speed ωs".into(),
                format!("sliding at speeds spread from well below to well above ωs (here |ω| from {lo:.2e} to {hi:.2e} rad/s) would reveal it"),
            ),
            "sigma0" => (
                "the bristle stiffness σ0 (pre-sliding)".into(),
                format!("reversals sampled finely enough to resolve the pre-sliding displacement Ts/σ0 ≈ {presliding:.2e} rad would reveal it"),
            ),
            "sigma1" => (
                "the bristle damping σ1·ṡ".into(),
                format!("fast reversals that cross the pre-sliding displacement ≈ {presliding:.2e} rad quickly, finely sampled, would reveal it"),
            ),
            "sigma2" => (
                "the viscous torque σ2·ω".into(),
                format!("faster sliding than |ω| ≤ {hi:.2e} rad/s would reveal it; a value consistent with 0 means no viscous friction shows in the data"),
            ),
            _ => (
                "the torque offset".into(),
                "it is confounded with the difference between the two directions' levels unless the record shows the torque pass through the pre-sliding range at reversals; a record with a known zero (the drive at rest, unloaded) would fix it".into(),
            ),
        };
        Explanation { effect, remedy }
    }
}

#[cfg(test)]
mod tests;
