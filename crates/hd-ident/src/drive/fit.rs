//! The output-error fit: the closed loop simulated over every experiment, the simulated
//! outputs (force = nominal gain × command, and/or position) compared with the recorded ones,
//! each divided by its noise level, and Σ residual² minimised by Levenberg–Marquardt with the
//! exact Jacobian of the simulation ([`super::dual`]).
//!
//! Nothing here holds a column of the record's length: the residuals are visited as the
//! simulation runs ([`Run`]), the optimiser gets the normal equations accumulated row by row
//! ([`Accumulator`]), the standard errors and the undetermined combinations come from the
//! triangular factor R of the Jacobian built in blocks ([`StreamingQr`]; an SVD of R has the
//! singular values and right vectors of one of the Jacobian), and the scores from running
//! sums. A fit's working storage is O(p²) whatever the record's length; only the record's
//! own columns grow with it.

use super::controller::Controller;
use super::dual::{Dual, NP, SIZES, Scalar};
use super::identifiability::{Determination, determination_r};
use super::model::FrictionLaw;
use super::record::Experiment;
use super::score::Score;
use super::simulate::Run;
use crate::error::FitError;
use crate::lm::{
    Accumulator, LeastSquares, LmOptions, LmOutcome, Normal, minimise, not_finite, pairs,
};
use crate::qr_stream::StreamingQr;
use nalgebra::DVector;

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
    let d = y.windows(4).map(|w| w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]);
    let count = y.len().saturating_sub(3);
    (d.map(|v| v * v).sum::<f64>() / (20.0 * count.max(1) as f64)).sqrt()
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
    pub settings: LmOptions,
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

/// Scores of parameters `p` on the experiments (from running sums: no simulated column is
/// kept).
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
            // Σ (measured − simulated)² per output, summed in the samples' order.
            let mut err = vec![0.0; outputs.len()];
            for (k, (u, x)) in Run::new(law, p, c, e).enumerate() {
                for (acc, &o) in err.iter_mut().zip(outputs) {
                    let (y, s) = match o {
                        OutputKind::Force => (gain * e.command[k], gain * u),
                        OutputKind::Position => (e.position[k], x),
                    };
                    *acc += (y - s).powi(2);
                }
            }
            let outs =
                outputs.iter().zip(err).map(|(&o, err)| (o, score_of(o, e, gain, err))).collect();
            ExperimentScore { name: e.name.clone(), outputs: outs }
        })
        .collect()
}

/// [`score`](super::score::score) of output `o` of `e` from Σ (measured − simulated)² =
/// `err_ss`, with the measured signal's sums taken as `score` takes them (same order, so the
/// same numbers).
fn score_of(o: OutputKind, e: &Experiment, gain: f64, err_ss: f64) -> Score {
    let meas = || -> Box<dyn Iterator<Item = f64> + '_> {
        match o {
            OutputKind::Force => Box::new(e.command.iter().map(move |u| gain * u)),
            OutputKind::Position => Box::new(e.position.iter().copied()),
        }
    };
    let n = e.len().max(1) as f64;
    let mean = meas().sum::<f64>() / n;
    let err = err_ss.sqrt();
    let norm = meas().map(|y| y * y).sum::<f64>().sqrt();
    let spread = meas().map(|y| (y - mean).powi(2)).sum::<f64>().sqrt();
    Score {
        rel_error: 100.0 * err / norm,
        rmse: err / n.sqrt(),
        fit_percent: 100.0 * (1.0 - err / spread),
    }
}

/// Each weighted residual (simulated − measured)/noise of every experiment, sample and
/// output, in that order, and with `T = Dual` its derivatives, as the simulation runs.
fn residuals<'a, T: Scalar + 'a>(
    spec: &'a FitSpec,
    p: &'a [T],
    experiments: &'a [Experiment],
) -> impl Iterator<Item = T> + 'a {
    experiments.iter().flat_map(move |e| {
        Run::new(spec.law, p, &spec.controller, e).enumerate().flat_map(move |(k, (u, x))| {
            spec.outputs.iter().map(move |&(o, sigma)| match o {
                OutputKind::Force => (u * spec.gain - spec.gain * e.command[k]) / sigma,
                OutputKind::Position => (x - e.position[k]) / sigma,
            })
        })
    })
}

/// The parameters as duals: free parameter `free_idx[slot]` differentiated as slot `slot`.
fn duals<const N: usize>(p: &[f64], free_idx: &[usize]) -> Vec<Dual<N>> {
    (0..p.len())
        .map(|k| match free_idx.iter().position(|&f| f == k) {
            Some(slot) => Dual::var(p[k], slot),
            None => Dual::cst(p[k]),
        })
        .collect()
}

/// Visit each residual at `p` with its Jacobian row (∂r/∂ the free parameters `free_idx`,
/// at most N of them) from one simulation in `Dual<N>`; `probe`, when given, is run beside
/// it in `f64` and its residual handed over too.
fn visit<const N: usize>(
    spec: &FitSpec,
    p: &[f64],
    free_idx: &[usize],
    experiments: &[Experiment],
    probe: Option<&[f64]>,
    each: &mut dyn FnMut(f64, &[f64], f64),
) {
    let pd = duals::<N>(p, free_idx);
    let k = free_idx.len();
    match probe {
        None => residuals(spec, &pd, experiments).for_each(|d| each(d.v, &d.d[..k], 0.0)),
        Some(q) => residuals(spec, &pd, experiments)
            .zip(residuals(spec, q, experiments))
            .for_each(|(d, rp)| each(d.v, &d.d[..k], rp)),
    }
}

/// The fit as a least-squares problem in its free parameters: every evaluation a fresh
/// simulation whose residuals are summed as they come.
struct Problem<'a> {
    spec: &'a FitSpec,
    experiments: &'a [Experiment],
    free_idx: Vec<usize>,
}

impl Problem<'_> {
    /// Every parameter, the free ones at `x`.
    fn full(&self, x: &[f64]) -> Vec<f64> {
        let mut p = self.spec.start.clone();
        for (slot, &k) in self.free_idx.iter().enumerate() {
            p[k] = x[slot];
        }
        p
    }

    /// [`visit`] with the smallest derivative count that holds the free parameters.
    fn visit(&self, x: &[f64], probe: Option<&[f64]>, each: &mut dyn FnMut(f64, &[f64], f64)) {
        let (p, f, e) = (self.full(x), &self.free_idx[..], self.experiments);
        let probe = probe.map(|q| self.full(q));
        let probe = probe.as_deref();
        match f.len() {
            k if k <= SIZES[0] => visit::<{ SIZES[0] }>(self.spec, &p, f, e, probe, each),
            k if k <= SIZES[1] => visit::<{ SIZES[1] }>(self.spec, &p, f, e, probe, each),
            _ => visit::<{ SIZES[2] }>(self.spec, &p, f, e, probe, each),
        }
    }

    /// R of the Jacobian's QR factorisation at `x` (built in blocks), the number of
    /// residuals and Σr², or `None` where a residual is not finite.
    fn factor(&self, x: &[f64]) -> Option<(nalgebra::DMatrix<f64>, usize, f64)> {
        let k = self.free_idx.len();
        let mut qr = StreamingQr::new(k);
        let (mut n, mut cost, mut finite) = (0usize, 0.0, true);
        self.visit(x, None, &mut |r, j, _| {
            finite &= r.is_finite();
            cost += r * r;
            n += 1;
            if k > 0 {
                qr.push(j);
            }
        });
        let r = if k > 0 { qr.finish() } else { nalgebra::DMatrix::zeros(0, 0) };
        finite.then_some((r, n, cost))
    }
}

impl LeastSquares for Problem<'_> {
    fn normal(&self, x: &[f64]) -> Result<Normal, FitError> {
        let mut acc = Accumulator::new(self.free_idx.len());
        self.visit(x, None, &mut |r, j, _| acc.push(r, j));
        acc.finish()
    }

    fn cost(&self, x: &[f64]) -> Result<f64, FitError> {
        let p = self.full(x);
        let (mut cost, mut finite) = (0.0, true);
        residuals(self.spec, &p, self.experiments).for_each(|r| {
            finite &= r.is_finite();
            cost += r * r;
        });
        if finite { Ok(cost) } else { Err(not_finite()) }
    }

    fn curvature(&self, x: &[f64], v: &DVector<f64>, h: f64) -> Option<DVector<f64>> {
        let probe: Vec<f64> = x.iter().zip(v.iter()).map(|(a, d)| a + h * d).collect();
        let mut out = DVector::zeros(self.free_idx.len());
        let mut finite = true;
        self.visit(x, Some(&probe), &mut |r, j, rp| {
            let jv: f64 = j.iter().zip(v.iter()).map(|(a, b)| a * b).sum();
            let rvv = (2.0 / h) * ((rp - r) / h - jv);
            finite &= rvv.is_finite();
            for (o, a) in out.iter_mut().zip(j) {
                *o += a * rvv;
            }
        });
        finite.then_some(out)
    }
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
    let problem = Problem { spec, experiments, free_idx: free_idx.clone() };
    let x0: Vec<f64> = free_idx.iter().map(|&k| spec.start[k]).collect();
    let lo: Vec<f64> = free_idx.iter().map(|&k| spec.lower[k]).collect();
    let hi: Vec<f64> = free_idx.iter().map(|&k| spec.upper[k]).collect();
    let LmOutcome { x, cost, iterations, failed_trials, termination, .. } =
        minimise(&problem, &x0, &pairs(&lo, &hi), &spec.settings, progress).map_err(|_| {
            FitError::Optimiser(format!(
                "the {} drive cannot be simulated at the start values",
                spec.law.name()
            ))
        })?;
    let values = problem.full(&x);
    let (r_factor, n, _) = problem
        .factor(&x)
        .ok_or_else(|| FitError::Optimiser("the fitted drive cannot be simulated".into()))?;
    let k = free_idx.len();
    let bic = crate::criteria::bic(cost, n, k);
    let free_names: Vec<&str> = free_idx.iter().map(|&k| names[k]).collect();
    let free_values: Vec<f64> = free_idx.iter().map(|&k| values[k]).collect();
    let det = determination_r(&r_factor, n, cost, &free_names, &free_values);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::identifiability::determination;
    use crate::drive::score::score;
    use crate::drive::simulate::simulate;
    use crate::drive::tests::{TRUTH, controller, record};
    use nalgebra::DMatrix;
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;

    /// Counts the heap bytes live on each thread and their peak, so that a test can see
    /// what one call holds at most (other test threads do not disturb it).
    struct Counting;

    thread_local! {
        static LIVE: Cell<isize> = const { Cell::new(0) };
        static PEAK: Cell<isize> = const { Cell::new(0) };
    }

    fn track(delta: isize) {
        let _ = LIVE.try_with(|l| {
            l.set(l.get() + delta);
            let _ = PEAK.try_with(|p| p.set(p.get().max(l.get())));
        });
    }

    // SAFETY: every call is handed to the system allocator unchanged; only counted.
    unsafe impl GlobalAlloc for Counting {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            // SAFETY: the caller's layout, as GlobalAlloc::alloc requires.
            let p = unsafe { System.alloc(layout) };
            if !p.is_null() {
                track(layout.size() as isize);
            }
            p
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            // SAFETY: ptr was allocated by System with this layout.
            unsafe { System.dealloc(ptr, layout) };
            track(-(layout.size() as isize));
        }
        unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
            // SAFETY: ptr was allocated by System with this layout.
            let p = unsafe { System.realloc(ptr, layout, new_size) };
            if !p.is_null() {
                track(new_size as isize - layout.size() as isize);
            }
            p
        }
    }

    #[global_allocator]
    static COUNTING: Counting = Counting;

    /// Peak heap bytes `f` holds above what was live when it started [B].
    fn peak_bytes<R>(f: impl FnOnce() -> R) -> (R, isize) {
        let base = LIVE.with(Cell::get);
        PEAK.with(|p| p.set(base));
        let r = f();
        (r, PEAK.with(Cell::get) - base)
    }

    fn spec(law: FrictionLaw, start: &[f64], max_iterations: usize) -> FitSpec {
        let n = start.len();
        let mut free = vec![true; n];
        free[n - 1] = false;
        FitSpec {
            law,
            controller: controller(1),
            gain: start[n - 1],
            outputs: vec![(OutputKind::Force, 0.1), (OutputKind::Position, 1e-6)],
            start: start.to_vec(),
            free,
            lower: vec![f64::NEG_INFINITY; n],
            upper: vec![f64::INFINITY; n],
            settings: LmOptions { max_iterations, ..LmOptions::drive() },
        }
    }

    /// The fit's working storage does not grow with the record: a fit of 40 000 samples
    /// holds at most a few kB more at its peak than one of 4 000 (holding the residuals
    /// and the Jacobian would take 36 000 × 2 × (1 + 4) × 8 B = 2.9 MB more; the
    /// simulation's dual columns another 3.5 MB).
    #[test]
    fn working_storage_does_not_grow_with_the_record() {
        let start: Vec<f64> = TRUTH.iter().map(|v| v * 1.1).collect();
        let s = spec(FrictionLaw::CoulombViscous, &start, 3);
        let peak = |n: usize| {
            let e = record(FrictionLaw::CoulombViscous, &TRUTH, 1, n);
            let (fit, bytes) = peak_bytes(|| fit_drive(&s, std::slice::from_ref(&e), &|_, _| {}));
            assert!(fit.is_ok(), "{fit:?}");
            bytes
        };
        let (short, long) = (peak(4_000), peak(40_000));
        assert!(long - short < 4_096, "peak {short} B at 4 000 samples, {long} B at 40 000");
        assert!(long < 200_000, "peak {long} B");
    }

    /// The normal equations, the cost and the verdict from the streamed passes equal those
    /// of the whole residual vector and Jacobian (rounding only), and the scores from
    /// running sums equal [`score`](super::super::score::score) of the simulated columns
    /// exactly.
    #[test]
    fn streamed_passes_match_whole_columns() {
        let law = FrictionLaw::CoulombViscous;
        let e = record(law, &TRUTH, 1, 6_000);
        let start: Vec<f64> = TRUTH.iter().map(|v| v * 1.05).collect();
        let s = spec(law, &start, 1);
        let free_idx: Vec<usize> = (0..4).collect();
        let experiments = std::slice::from_ref(&e);
        let problem = Problem { spec: &s, experiments, free_idx: free_idx.clone() };
        let x = &start[..4];
        // The whole columns, as the fit held them before.
        let pd = duals::<4>(&start, &free_idx);
        let sim = simulate(law, &pd, &s.controller, &e);
        let mut rows: Vec<(f64, [f64; 4])> = Vec::new();
        for &(o, sigma) in &s.outputs {
            let meas = o.measured(&e, s.gain);
            let col = if o == OutputKind::Force { &sim.command } else { &sim.position };
            for (v, y) in col.iter().zip(&meas) {
                let d = match o {
                    OutputKind::Force => (*v * s.gain - *y) / sigma,
                    OutputKind::Position => (*v - *y) / sigma,
                };
                rows.push((d.v, d.d));
            }
        }
        let j = DMatrix::from_fn(rows.len(), 4, |i, c| rows[i].1[c]);
        let r = DVector::from_iterator(rows.len(), rows.iter().map(|x| x.0));
        let normal = problem.normal(x).unwrap();
        let (jtj, jtr) = (j.transpose() * &j, j.transpose() * &r);
        let rel = (&normal.jtj - &jtj).norm() / jtj.norm();
        assert!(rel <= 1e-11, "JᵀJ {rel:e}");
        let rel = (&normal.jtr - &jtr).norm() / jtr.norm();
        assert!(rel <= 1e-11, "Jᵀr {rel:e}");
        let cost = r.norm_squared();
        assert!((normal.cost - cost).abs() <= 1e-13 * cost);
        assert!((problem.cost(x).unwrap() - cost).abs() <= 1e-13 * cost);
        let (rf, n, _) = problem.factor(x).unwrap();
        assert_eq!(n, rows.len());
        let names = ["M", "Fv", "Fc", "offset"];
        let a = determination(&j, cost, &names, x);
        let b = determination_r(&rf, n, cost, &names, x);
        for (p, q) in a.std_errors.iter().zip(&b.std_errors) {
            let (p, q) = (p.unwrap(), q.unwrap());
            assert!((p - q).abs() <= 1e-10 * p, "{p} vs {q}");
        }
        assert_eq!(a.sentences.len(), b.sentences.len());
        let outputs = [OutputKind::Force, OutputKind::Position];
        let got = score_all(law, &start, &s.controller, s.gain, experiments, &outputs);
        let plain = simulate(law, &start, &s.controller, &e);
        let force: Vec<f64> = plain.command.iter().map(|u| s.gain * u).collect();
        assert_eq!(got[0].outputs[0].1, score(&OutputKind::Force.measured(&e, s.gain), &force));
        assert_eq!(got[0].outputs[1].1, score(&e.position, &plain.position));
    }
}
