//! The output-error fit: the closed loop simulated over every experiment, the simulated
//! outputs (force = nominal gain × command, and/or position) compared with the recorded ones,
//! each divided by its noise level, and Σ residual² minimised by Levenberg–Marquardt with the
//! exact Jacobian of the simulation ([`super::dual`]).

use super::controller::Controller;
use super::dual::{Dual, NP, SIZES, Scalar};
use super::identifiability::{Determination, determination};
use super::lm::{LmResult, LmSettings, minimise};
use super::model::FrictionLaw;
use super::record::Experiment;
use super::score::{Score, score};
use super::simulate::simulate;
use crate::error::FitError;
use nalgebra::DMatrix;

/// An output compared with the record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputKind {
    /// Drive force (or torque): nominal gain × command [N or N·m].
    Force,
    /// Position [m or rad].
    Position,
}

impl OutputKind {
    /// Its name in configurations and reports.
    pub fn name(self) -> &'static str {
        match self {
            OutputKind::Force => "force",
            OutputKind::Position => "position",
        }
    }

    /// Parse `force` or `position`.
    pub fn parse(s: &str) -> Option<OutputKind> {
        [OutputKind::Force, OutputKind::Position].into_iter().find(|o| o.name() == s)
    }

    /// The recorded signal of `e` for this output (force scaled by `gain`).
    pub fn measured(self, e: &Experiment, gain: f64) -> Vec<f64> {
        match self {
            OutputKind::Force => e.command.iter().map(|u| gain * u).collect(),
            OutputKind::Position => e.position.clone(),
        }
    }
}

/// Noise level of a sampled signal from its third differences, which remove a smooth
/// signal's trend up to a parabola: for white noise Var(Δ³y) = 20σ². [unit of y]
pub fn noise_level(y: &[f64]) -> f64 {
    let d: Vec<f64> = y.windows(4).map(|w| w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]).collect();
    (d.iter().map(|v| v * v).sum::<f64>() / (20.0 * d.len().max(1) as f64)).sqrt()
}

/// What to fit.
#[derive(Clone, Debug, PartialEq)]
pub struct FitSpec {
    /// Friction law.
    pub law: FrictionLaw,
    /// The loop's controller.
    pub controller: Controller,
    /// Nominal gain that turns the recorded command into the force output [N/V or N·m/V].
    pub gain: f64,
    /// Outputs compared, with their noise levels [output unit].
    pub outputs: Vec<(OutputKind, f64)>,
    /// Start values, one per parameter of the law ([`FrictionLaw::names`]).
    pub start: Vec<f64>,
    /// Which parameters are free.
    pub free: Vec<bool>,
    /// Lower and upper bounds per parameter.
    pub lower: Vec<f64>,
    /// Upper bounds.
    pub upper: Vec<f64>,
    /// Optimiser settings.
    pub settings: LmSettings,
}

/// Scores of one experiment.
#[derive(Clone, Debug, PartialEq)]
pub struct ExperimentScore {
    /// The experiment's name.
    pub name: String,
    /// Per output: its kind and score.
    pub outputs: Vec<(OutputKind, Score)>,
}

/// A fitted drive.
#[derive(Clone, Debug, PartialEq)]
pub struct DriveFit {
    /// Friction law.
    pub law: FrictionLaw,
    /// Parameter names.
    pub names: Vec<&'static str>,
    /// Values of every parameter [axis units].
    pub values: Vec<f64>,
    /// Which were free.
    pub free: Vec<bool>,
    /// Standard error of each free parameter (None where undetermined or fixed).
    pub std_errors: Vec<Option<f64>>,
    /// Correlations among the free parameters (order of the free ones).
    pub correlation: Vec<Vec<Option<f64>>>,
    /// Σ (residual/noise)².
    pub cost: f64,
    /// Number of residuals.
    pub n: usize,
    /// Bayesian information criterion n·ln(cost/n) + k·ln n.
    pub bic: f64,
    /// Optimiser outcome.
    pub iterations: usize,
    /// Trials that could not be evaluated.
    pub failed_trials: usize,
    /// Why the optimiser stopped.
    pub termination: String,
    /// What the record determines, in words.
    pub determination: Determination,
    /// Scores per experiment on the fitted experiments.
    pub scores: Vec<ExperimentScore>,
}

/// Scores of parameters `p` on the experiments.
pub fn score_all(
    law: FrictionLaw,
    p: &[f64],
    c: &Controller,
    gain: f64,
    experiments: &[Experiment],
    outputs: &[OutputKind],
) -> Vec<ExperimentScore> {
    experiments
        .iter()
        .map(|e| {
            let s = simulate(law, p, c, e);
            let outs = outputs
                .iter()
                .map(|&o| {
                    let sim: Vec<f64> = match o {
                        OutputKind::Force => s.command.iter().map(|u| gain * u).collect(),
                        OutputKind::Position => s.position.clone(),
                    };
                    (o, score(&o.measured(e, gain), &sim))
                })
                .collect();
            ExperimentScore { name: e.name.clone(), outputs: outs }
        })
        .collect()
}

/// The weighted residuals (simulated − measured)/noise of every experiment and output, and
/// with `T = Dual` their derivatives.
fn residuals<T: Scalar>(spec: &FitSpec, p: &[T], experiments: &[Experiment]) -> Vec<T> {
    let mut out = Vec::new();
    for e in experiments {
        let s = simulate(spec.law, p, &spec.controller, e);
        for &(o, sigma) in &spec.outputs {
            let meas = o.measured(e, spec.gain);
            match o {
                OutputKind::Force => out.extend(
                    s.command.iter().zip(&meas).map(|(&u, &y)| (u * spec.gain - y) / sigma),
                ),
                OutputKind::Position => {
                    out.extend(s.position.iter().zip(&meas).map(|(&x, &y)| (x - y) / sigma))
                }
            }
        }
    }
    out
}

/// The residuals at `p` and their Jacobian with respect to the free parameters
/// `free_idx` (at most N of them), from one simulation in `Dual<N>`.
fn jacobian<const N: usize>(
    spec: &FitSpec,
    p: &[f64],
    free_idx: &[usize],
    experiments: &[Experiment],
) -> (Vec<f64>, DMatrix<f64>) {
    let pd: Vec<Dual<N>> = (0..p.len())
        .map(|k| match free_idx.iter().position(|&f| f == k) {
            Some(slot) => Dual::var(p[k], slot),
            None => Dual::cst(p[k]),
        })
        .collect();
    let rd = residuals(spec, &pd, experiments);
    let r: Vec<f64> = rd.iter().map(|d| d.v).collect();
    let j = DMatrix::from_fn(r.len(), free_idx.len(), |i, c| rd[i].d[c]);
    (r, j)
}

/// Fit `spec` to the experiments. `progress(iteration, cost)` is called as it goes.
pub fn fit_drive(
    spec: &FitSpec,
    experiments: &[Experiment],
    progress: &dyn Fn(usize, f64),
) -> Result<DriveFit, FitError> {
    let names: Vec<&'static str> = spec.law.names().to_vec();
    let free_idx: Vec<usize> = (0..names.len()).filter(|&k| spec.free[k]).collect();
    if free_idx.len() > NP {
        return Err(FitError::Optimiser(format!("at most {NP} free parameters")));
    }
    let full = |x: &[f64]| {
        let mut p = spec.start.clone();
        for (slot, &k) in free_idx.iter().enumerate() {
            p[k] = x[slot];
        }
        p
    };
    let finite = |r: &[f64]| r.iter().all(|v| v.is_finite());
    let plain = |x: &[f64]| {
        let r = residuals(spec, &full(x), experiments);
        finite(&r).then_some(r)
    };
    let with_jac = |x: &[f64]| {
        let p = full(x);
        let (r, j) = match free_idx.len() {
            k if k <= SIZES[0] => jacobian::<{ SIZES[0] }>(spec, &p, &free_idx, experiments),
            k if k <= SIZES[1] => jacobian::<{ SIZES[1] }>(spec, &p, &free_idx, experiments),
            _ => jacobian::<{ SIZES[2] }>(spec, &p, &free_idx, experiments),
        };
        finite(&r).then_some((r, j))
    };
    let x0: Vec<f64> = free_idx.iter().map(|&k| spec.start[k]).collect();
    let lo: Vec<f64> = free_idx.iter().map(|&k| spec.lower[k]).collect();
    let hi: Vec<f64> = free_idx.iter().map(|&k| spec.upper[k]).collect();
    let LmResult { x, cost, iterations, failed_trials, termination } =
        minimise(&with_jac, &plain, &x0, &lo, &hi, &spec.settings, progress).ok_or_else(|| {
            FitError::Optimiser(format!(
                "the {} drive cannot be simulated at the start values",
                spec.law.name()
            ))
        })?;
    let values = full(&x);
    let (r, jac) = with_jac(&x)
        .ok_or_else(|| FitError::Optimiser("the fitted drive cannot be simulated".into()))?;
    let n = r.len();
    let k = free_idx.len();
    let bic = n as f64 * (cost / n as f64).ln() + k as f64 * (n as f64).ln();
    let free_names: Vec<&str> = free_idx.iter().map(|&k| names[k]).collect();
    let free_values: Vec<f64> = free_idx.iter().map(|&k| values[k]).collect();
    let det = determination(&jac, cost, &free_names, &free_values);
    let mut std_errors = vec![None; names.len()];
    for (slot, &k) in free_idx.iter().enumerate() {
        std_errors[k] = det.std_errors[slot];
    }
    let outputs: Vec<OutputKind> = spec.outputs.iter().map(|o| o.0).collect();
    Ok(DriveFit {
        law: spec.law,
        names,
        scores: score_all(spec.law, &values, &spec.controller, spec.gain, experiments, &outputs),
        values,
        free: spec.free.clone(),
        std_errors,
        correlation: det.correlation.clone(),
        cost,
        n,
        bic,
        iterations,
        failed_trials,
        termination,
        determination: det,
    })
}
