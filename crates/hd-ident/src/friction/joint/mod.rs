//! The joint friction fit: every LuGre parameter from one time series of speed and
//! torque, with no steady-state sweep.
//!
//! The model is `Tf = w + σ1·ṡ + σ2·v (+ offset)`, where the bristle torque w = σ0·s runs
//! along the measured speed by the LuGre law's exact sample updates, its sensitivities
//! carried beside it ([`super::bristle`]), so every trial gives the residuals and their
//! exact Jacobian in one pass. For given levels and rates (Tc, Ts, ωs, σ0 and, with `asymmetric`, Tc_neg,
//! Ts_neg) w and ṡ are fixed, so σ1, σ2 and the offset follow by bounded linear least
//! squares (variable projection); the nonlinear ones are refined together by
//! Levenberg–Marquardt over their logarithms ([`crate::lm`]).
//!
//! The pipeline, each step tolerant of failed trials:
//! 1. start the static parameters from quasi-steady samples of the series itself
//!    ([`super::quasi_steady`]) with the static fit, or from plain torque levels when the series
//!    has too few;
//! 2. start σ0 by a global search over ln σ0 (grid + Brent), the others held;
//! 3. refine all free parameters jointly from that start and from [`EXTRA_STARTS`]
//!    perturbed ones (real data have local optima); the best wins;
//! 4. standard errors, intervals, correlations and determined flags from the Jacobian at
//!    the optimum, as for every fit.

mod exact;
mod fast;
mod finish;
mod kernel;
mod normal;
mod sigma0_pass;
mod start;
mod vexp;

use super::bristle::{BristleRun, bristle_run};
use crate::data::{TransientData, require_samples};
use crate::error::{FitError, chain};
use crate::fix::Fixed;
use crate::linear::bounded_least_squares;
use crate::lm::{
    LmOptions, LmPaused, LmStep, hit_budget, levenberg_marquardt_normal, lm_normal_paused,
    lm_normal_resume,
};
use crate::report::{Explanation, SearchSummary};
use crate::search::{GRID_POINTS, search_log};
use crate::separable::SeparableFit;
use finish::finish;
use hd_model::laws::friction::LuGre;
use hd_model::registry::lookup;
use rayon::prelude::*;
use start::{speed_range, static_start};
use std::time::Instant;

/// Which optional terms the friction fits include.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrictionOptions {
    /// Separate Coulomb and static levels for negative speeds (`Tc_neg`, `Ts_neg`).
    pub asymmetric: bool,
    /// A constant torque offset of the measurement (`offset` [N·m]).
    pub offset: bool,
}

pub use crate::fix::OFFSET;

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
}

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
        Self {
            data,
            nonlinear,
            linear,
            base,
            asymmetric,
            first_bias: 0.0,
            ones: vec![1.0; data.len()],
            pool: fast::Pool::default(),
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

    /// Levenberg–Marquardt over the free nonlinear parameters' logarithms from `x0`.
    fn refine(&self, x0: &[f64], lm: &LmOptions) -> Result<crate::lm::LmOutcome, FitError> {
        let model = |x: &[f64]| self.pool.with(|ws| self.normal_at(x, ws));
        levenberg_marquardt_normal(&model, x0, lm)
    }

    /// [`JointProblem::refine`], paused after `iterations` unless it ends before.
    fn refine_paused(
        &self,
        x0: &[f64],
        lm: &LmOptions,
        iterations: usize,
    ) -> Result<LmStep, FitError> {
        let model = |x: &[f64]| self.pool.with(|ws| self.normal_at(x, ws));
        lm_normal_paused(&model, x0, lm, iterations)
    }

    /// Resume a paused [`JointProblem::refine_paused`] to its end.
    fn resume(&self, paused: LmPaused, lm: &LmOptions) -> Result<crate::lm::LmOutcome, FitError> {
        let model = |x: &[f64]| self.pool.with(|ws| self.normal_at(x, ws));
        lm_normal_resume(&model, paused, lm)
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

impl Refined {
    fn from_outcome(problem: &JointProblem, out: crate::lm::LmOutcome) -> Self {
        Refined {
            values: problem.values(&out.x),
            rss: out.cost,
            iterations: out.iterations,
            evaluations: out.evaluations,
            failed: out.failed_trials,
            termination: out.termination,
            dropped: false,
        }
    }
}

/// How many of the refinement's `ends` were starts stopped early.
fn refined_dropped(ends: &[String]) -> usize {
    ends.iter().filter(|e| e.starts_with("stopped after")).count()
}

/// One refined start.
struct Refined {
    values: [f64; 6],
    rss: f64,
    iterations: usize,
    evaluations: usize,
    failed: usize,
    termination: String,
    /// Stopped early as far above the other starts ([`DROP_FACTOR`]).
    dropped: bool,
}

/// Fit every free LuGre parameter (and, by `opts`, the negative-side levels and the
/// offset) to one time series.
pub fn fit_joint(
    data: &TransientData,
    fixed: &Fixed,
    opts: FrictionOptions,
) -> Result<SeparableFit, FitError> {
    let started = Instant::now();
    let mut remarks = Vec::new();
    let (start, how) = static_start(data, fixed, opts);
    remarks.push(how);
    let mut problem = JointProblem::new(data, fixed, opts, &start);
    let free_linear: Vec<&str> =
        problem.linear.iter().filter(|(_, f)| f.is_none()).map(|(n, _)| *n).collect();
    let free_names: Vec<&str> =
        problem.nonlinear.iter().copied().chain(free_linear.iter().copied()).collect();
    if free_names.is_empty() {
        return Err(FitError::NothingFree { fit: "friction" });
    }
    if let Some(w) = require_samples(data.len(), &free_names)? {
        remarks.push(w);
    }

    // σ0's start: a global search over ln σ0 with the static start held.
    let mut base = problem.base;
    let mut search = None;
    let mut evaluations = 0usize;
    let mut failed = 0usize;
    if problem.nonlinear.contains(&"sigma0") {
        let level = base[0].max(base[1]).max(base[4]).max(base[5]);
        let (mut lo, mut hi) = problem.sigma0_range(level);
        lo = lo.max(f64::MIN_POSITIVE);
        hi = hi.min(f64::MAX);
        // One pass per trial with the levels' quantities worked out once; the general
        // path where that pass cannot be used.
        let pass = sigma0_pass::Sigma0Pass::new(&problem, problem.law(&base));
        let cost = |s0: f64| match pass.rss(&problem, s0) {
            Some(c) => Ok(c),
            None => {
                let mut v = base;
                v[3] = s0;
                problem.rss_at(&v)
            }
        };
        let out = search_log(&cost, lo, hi)?;
        base[3] = out.value;
        evaluations += out.evaluations as usize;
        failed += out.failed_trials as usize;
        if out.failed_trials > 0 {
            remarks.push(format!(
                "{} of the σ0 search's trials failed and counted as the worst cost (first: {})",
                out.failed_trials,
                out.first_failure.as_deref().unwrap_or("a non-finite cost")
            ));
        }
        search = Some(SearchSummary {
            parameter: "sigma0".into(),
            range: [lo, hi],
            grid_points: GRID_POINTS,
            starts: out.starts,
        });
    }

    // Joint refinement from the main start and the perturbed ones.
    let mut starts = vec![base];
    let k_ws = 2;
    let k_s0 = 3;
    for (k, factor) in [
        (k_ws, START_FACTOR),
        (k_ws, 1.0 / START_FACTOR),
        (k_s0, START_FACTOR),
        (k_s0, 1.0 / START_FACTOR),
    ] {
        if problem.nonlinear.contains(&NONLINEAR_ALL[k]) && starts.len() <= EXTRA_STARTS {
            let mut v = base;
            v[k] *= factor;
            starts.push(v);
        }
    }
    let lm = LmOptions { max_iterations: MAX_ITERATIONS, secant: true, ..Default::default() };
    // Every start runs RACE_ITERATIONS iterations; those far above the lowest cost reached
    // by then stop, the rest resume where they stood. The comparison is made at the same
    // point for every start, so the outcome does not depend on which thread ran first.
    let first: Vec<Result<LmStep, FitError>> = starts
        .par_iter()
        .map(|v| problem.refine_paused(&problem.x_of(v), &lm, RACE_ITERATIONS))
        .collect();
    let lowest = first
        .iter()
        .filter_map(|r| match r {
            Ok(LmStep::Done(out)) => Some(out.cost),
            Ok(LmStep::Paused(p)) => Some(p.cost()),
            Err(_) => None,
        })
        .fold(f64::INFINITY, f64::min);
    let refined: Vec<Result<Refined, FitError>> = first
        .into_par_iter()
        .map(|r| match r? {
            LmStep::Done(out) => Ok(Refined::from_outcome(&problem, out)),
            LmStep::Paused(p) if p.cost() > DROP_FACTOR * lowest => Ok(Refined {
                values: problem.values(p.x()),
                rss: p.cost(),
                iterations: p.iterations(),
                evaluations: p.evaluations(),
                failed: p.failed_trials(),
                termination: format!(
                    "stopped after {} iterations: RSS {:.6e} above {DROP_FACTOR} × the lowest of all starts then ({lowest:.6e})",
                    p.iterations(),
                    p.cost()
                ),
                dropped: true,
            }),
            LmStep::Paused(p) => Ok(Refined::from_outcome(&problem, problem.resume(p, &lm)?)),
        })
        .collect();
    let ends: Vec<String> = refined
        .iter()
        .map(|r| match r {
            Ok(r) if r.dropped => r.termination.clone(),
            Ok(r) => {
                format!("RSS {:.6e} after {} iterations ({})", r.rss, r.iterations, r.termination)
            }
            Err(e) => format!("could not be evaluated: {}", chain(e)),
        })
        .collect();
    let mut best: Option<Refined> = None;
    let mut iterations = 0usize;
    let mut start_failures = Vec::new();
    for r in refined {
        match r {
            Ok(r) => {
                iterations += r.iterations;
                evaluations += r.evaluations;
                failed += r.failed;
                if !r.dropped && best.as_ref().is_none_or(|b| r.rss < b.rss) {
                    best = Some(r);
                }
            }
            Err(e) => start_failures.push(chain(&e)),
        }
    }
    let Some(best) = best else {
        return Err(FitError::Optimiser(format!(
            "no start of the joint refinement could be evaluated ({})",
            start_failures.join("; ")
        )));
    };
    let dropped = refined_dropped(&ends);
    if dropped > 0 {
        remarks.push(format!(
            "{dropped} of {} starts stopped after {RACE_ITERATIONS} iterations, their RSS over {DROP_FACTOR} × the lowest any start had reached then (fit.json refinement_ends)",
            starts.len()
        ));
    }
    if !start_failures.is_empty() {
        remarks.push(format!(
            "{} of {} starts could not be evaluated and were skipped",
            start_failures.len(),
            starts.len()
        ));
    }
    if failed > 0 {
        remarks.push(format!("{failed} trial parameter sets failed to integrate or gave non-finite torques; each counted as a rejected trial"));
    }
    // The bristle state starts from the first torque less the offset and viscous term,
    // which are only known now: refine once more with that start (a fixed point in one
    // step: the start's effect on the optimum is second order).
    let mut best = best;
    let proj = problem.project(&best.values)?;
    let beta = |name: &str| {
        problem.linear.iter().position(|(n, _)| *n == name).map_or(0.0, |j| proj.beta[j])
    };
    let bias = beta(OFFSET) + beta("sigma2") * data.omega()[0];
    if bias != 0.0 {
        problem.first_bias = bias;
        let x0 = problem.x_of(&best.values);
        if let Ok(out) = problem.refine(&x0, &lm) {
            iterations += out.iterations;
            evaluations += out.evaluations;
            best = Refined::from_outcome(&problem, out);
        }
    }
    if hit_budget(&best.termination) {
        remarks.push(format!(
            "warning: the best start's refinement stopped on its iteration budget ({MAX_ITERATIONS}) before converging; the optimum may lie further on (try --fix on a poorly determined parameter)"
        ));
    }
    let fit = finish(
        &problem,
        &best.values,
        started,
        remarks,
        search,
        iterations,
        evaluations,
        &best.termination,
        &starts,
        ends,
    )?;
    Ok(fit)
}

#[cfg(test)]
mod tests;
