//! The output-error fit of the compliant drive: every record's motor angle, load angle and
//! current simulated under its voltage and compared, each divided by its noise level;
//! Levenberg–Marquardt within bounds on the exact Jacobian (the simulation run on dual
//! numbers, [`crate::drive::dual`]); standard errors, correlations and the combinations the
//! records leave undetermined ([`crate::drive::identifiability`]).

use super::model::ix::{BW_ALPHA, C, CJ, CZ, JJ, JZ, KE, KM, MEM_A, MS_K, R};
use super::model::{Compliant, NAMES, P};
use super::record::{Between, VoltageRecord};
use super::simulate::{Outputs, on_current_zero, on_encoder_zeros, simulate};
use crate::drive::dual::Scalar;
use crate::drive::identifiability::{Determination, determination};
use crate::drive::score::{Score, score};
use crate::lm::{Columns, LmOptions, LmOutcome, minimise, pairs};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Called after each iteration with (iteration, cost); fits may run in parallel.
pub type Progress<'a> = &'a (dyn Fn(usize, f64) + Sync);

/// Called as [`super::stages::fit_compliant`] goes with (stage, iteration, cost): the stage
/// names what runs (the motor pass, one of the load pass's starts, a full fit, a refit of
/// the checks), the iteration and cost are its optimiser's. Stages may run in parallel.
pub type Report<'a> = &'a (dyn Fn(&str, usize, f64) + Sync);

/// Largest (fastest rate × substep) of a substep count taken without measuring its
/// integration error [–] (`hdw fit drive` measures it: [`super::accuracy`]).
pub(super) const RATE_STEP: f64 = 0.1;

/// Long-run variance ratio from which a sentence says an output's residuals are
/// correlated [–].
const CORRELATED_KAPPA: f64 = 1.5;

/// The residual blocks of `spec` on `records`, in the order of [`residuals_at`]: (record,
/// output, range).
pub(crate) fn blocks(
    spec: &CompliantSpec,
    records: &[VoltageRecord],
) -> Vec<(usize, Signal, std::ops::Range<usize>)> {
    let mut out = Vec::new();
    let mut at = 0;
    for (k, r) in records.iter().enumerate() {
        for (o, _) in &spec.outputs {
            if o.measured(r).is_some() {
                out.push((k, *o, at..at + r.len()));
                at += r.len();
            }
        }
    }
    out
}

/// One of the compared outputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Signal {
    /// Motor encoder [rad].
    Motor,
    /// Load encoder [rad].
    Load,
    /// Armature current [A].
    Current,
    /// Closed loop: the controller's output [V or A].
    Command,
}

impl Signal {
    /// Every output, in report order.
    pub const ALL: [Signal; 4] = [Signal::Motor, Signal::Load, Signal::Current, Signal::Command];

    /// Its name in configurations and reports.
    pub fn name(self) -> &'static str {
        match self {
            Signal::Motor => "motor",
            Signal::Load => "load",
            Signal::Current => "current",
            Signal::Command => "command",
        }
    }

    /// Its unit.
    pub fn unit(self) -> &'static str {
        match self {
            Signal::Current => "A",
            Signal::Command => "V or A",
            _ => "rad",
        }
    }

    /// Parse a name.
    pub fn parse(s: &str) -> Option<Signal> {
        Signal::ALL.into_iter().find(|o| o.name() == s)
    }

    /// The recorded signal (None: the record has no current).
    pub fn measured(self, r: &VoltageRecord) -> Option<&[f64]> {
        match self {
            Signal::Motor => Some(&r.theta_m),
            Signal::Load => Some(&r.theta_l),
            Signal::Current => r.current.as_deref(),
            Signal::Command => r.closed.is_some().then_some(&r.u[..]),
        }
    }

    /// The simulated signal.
    pub fn simulated<T>(self, o: &Outputs<T>) -> &[T] {
        match self {
            Signal::Motor => &o.theta_m,
            Signal::Load => &o.theta_l,
            Signal::Current => &o.current,
            Signal::Command => &o.command,
        }
    }
}

/// What to fit.
#[derive(Clone, Debug, PartialEq)]
pub struct CompliantSpec {
    /// Gear ratio N [–].
    pub n: f64,
    /// How the voltage runs between samples.
    pub between: Between,
    /// Start values, [`NAMES`] order.
    pub start: [f64; P],
    /// Which parameters are free.
    pub free: [bool; P],
    /// Lower bounds.
    pub lower: [f64; P],
    /// Upper bounds.
    pub upper: [f64; P],
    /// The outputs compared, each with its noise level per record [rad or A]
    /// (`noise[record]`).
    pub outputs: Vec<(Signal, Vec<f64>)>,
    /// Per output (the order of `outputs`): whether its noise levels were estimated from the
    /// records, to be replaced by the residuals' RMS of the best fit ([`super::stages`]).
    pub noise_estimated: Vec<bool>,
    /// Whether the torque constant Km [N·m/A] is the back-EMF constant Ke [V·s/rad] (in SI
    /// units they are one constant of an ideal DC motor; Km then follows Ke).
    pub km_is_ke: bool,
    /// Whether the friction is the same in both directions: Tc_neg and Ts_neg then follow
    /// Tc and Ts ([`CompliantSpec::ties`]).
    pub symmetric_friction: bool,
    /// Whether the load-side law is the same in both directions: Tc_neg_load and
    /// Ts_neg_load then follow Tc_load and Ts_load.
    pub symmetric_load_friction: bool,
    /// Whether each record's current sensor offset is fitted as a constant (projected out
    /// of the current's residuals, as the encoder zeros are).
    pub current_offset: bool,
    /// Where the gear's friction law acts ([`Compliant::friction_velocity`]).
    pub friction_velocity: hd_model::FrictionVelocity,
    /// Runge–Kutta substeps per sample (fixed for the whole fit, so the objective is smooth).
    pub substeps: usize,
    /// Optimiser settings.
    pub settings: LmOptions,
}

impl CompliantSpec {
    /// The parameters that follow another, as (follower, leader) in [`NAMES`] indices: Km
    /// follows Ke when `km_is_ke`, Tc_neg and Ts_neg follow Tc and Ts when the friction is
    /// symmetric, and the load-side law's likewise. A follower is never an optimisation
    /// variable: it takes its leader's value and its derivative flows into its leader's.
    pub fn ties(&self) -> Vec<(usize, usize)> {
        use super::model::ix::*;
        let mut t = Vec::new();
        if self.km_is_ke {
            t.push((KM, KE));
        }
        if self.symmetric_friction {
            t.extend([(TC_NEG, TC), (TS_NEG, TS)]);
        }
        if self.symmetric_load_friction {
            t.extend([(TC_NEG_L, TC_L), (TS_NEG_L, TS_L)]);
        }
        t
    }

    /// The drive at parameters `p` ([`NAMES`] order; followers take their leaders' values).
    pub fn drive<T: Scalar>(&self, p: [T; P]) -> Compliant<T> {
        Compliant::new(self.tied(p), self.n).with_friction_velocity(self.friction_velocity)
    }

    /// Whether parameter `k` follows another ([`CompliantSpec::ties`]).
    pub fn follows(&self, k: usize) -> bool {
        self.ties().iter().any(|&(f, _)| f == k)
    }

    /// `p` with every follower set to its leader's value.
    pub fn tied<S: Copy>(&self, mut p: [S; P]) -> [S; P] {
        for (f, l) in self.ties() {
            p[f] = p[l];
        }
        p
    }
}

/// Substeps per sample of `h` [s] for the drive at `p`: enough that its fastest non-stiff
/// rate times the substep stays below [`RATE_STEP`], at least 2, at most 512.
pub fn substeps_for(p: &[f64; P], n: f64, h: f64) -> usize {
    substeps_of(&Compliant::new(*p, n), h)
}

/// [`substeps_for`] of drive `d`.
pub fn substeps_of(d: &Compliant<f64>, h: f64) -> usize {
    substeps_at(d, h, RATE_STEP)
}

/// Substeps per sample of `h` [s] that keep drive `d`'s fastest rate times the substep at
/// most `rate_step` [–]: at least 2, at most 512.
pub(super) fn substeps_at(d: &Compliant<f64>, h: f64, rate_step: f64) -> usize {
    ((d.fastest_rate() * h / rate_step).ceil() as usize).clamp(2, 512)
}

/// Scores of one record.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordScore {
    /// The record's name.
    pub name: String,
    /// Per output: the output, its score, its noise level and RMS residual / noise [–].
    pub outputs: Vec<(Signal, Score, f64, f64)>,
    /// The constants added to the simulated motor and load angles to put them on the
    /// record's encoder zeros ([`on_encoder_zeros`]) [rad].
    pub encoder_offsets: [f64; 2],
    /// The current sensor's offset, where fitted ([`CompliantSpec::current_offset`]) [A].
    pub current_offset: Option<f64>,
}

/// Run drive `d` on record `rec` as `spec` says, with the outputs put on the record's zeros
/// (the encoders' always, the current sensor's when `spec.current_offset`); returns the
/// outputs, the encoder offsets and the current offset.
pub fn simulate_on_zeros<T: Scalar>(
    spec: &CompliantSpec,
    d: &Compliant<T>,
    rec: &VoltageRecord,
) -> (Outputs<T>, [T; 2], Option<T>) {
    let mut sim = simulate(d, rec, spec.between, spec.substeps);
    let enc = on_encoder_zeros(rec, &mut sim);
    let cur = if spec.current_offset { on_current_zero(rec, &mut sim) } else { None };
    (sim, enc, cur)
}

/// A fitted compliant drive.
#[derive(Clone, Debug, PartialEq)]
pub struct CompliantFit {
    /// Every parameter's value, [`NAMES`] order.
    pub values: [f64; P],
    /// Which were free.
    pub free: [bool; P],
    /// Standard error of each free parameter (None where undetermined or fixed).
    pub std_errors: [Option<f64>; P],
    /// Σ (residual/noise)².
    pub cost: f64,
    /// Number of residuals.
    pub n: usize,
    /// Jacobian evaluations.
    pub iterations: usize,
    /// Trials that could not be evaluated.
    pub failed_trials: usize,
    /// Why the optimiser stopped.
    pub termination: String,
    /// Standard errors, correlations and what is undetermined, over the free parameters.
    pub determination: Determination,
    /// Scores on the fitted records.
    pub scores: Vec<RecordScore>,
    /// Free parameters the records left undetermined, held at their start values ([`NAMES`]
    /// indices).
    pub held: Vec<usize>,
    /// The Jacobian of the residuals at the optimum, one column per parameter of
    /// `jacobian_params` (the last fit's free ones) [1 per parameter unit].
    pub jacobian: DMatrix<f64>,
    /// The parameters ([`NAMES`] indices) of the Jacobian's columns.
    pub jacobian_params: Vec<usize>,
    /// The outputs with the noise levels the reported fit weighed them by [rad or A].
    pub noise: Vec<(Signal, Vec<f64>)>,
    /// Starts the full fit was run from (the best is reported).
    pub starts: usize,
    /// Per parameter: free and determined by the records (a standard error, and in no
    /// undetermined combination or inseparable pair).
    pub determined: [bool; P],
    /// Why the fit is in doubt, said before anything else (the fit does not reach the
    /// noise, a scale or the controller check fails; [`super::diagnose`]); empty when it
    /// is not. Where it is not empty, no parameter's `determined` should be trusted.
    pub doubt: Vec<String>,
    /// Wall time of each stage of [`super::stages::fit_compliant`] that ran, in order
    /// (name, seconds [s]): where a fit's time goes.
    pub stage_seconds: Vec<(&'static str, f64)>,
}

/// Score every output of every record with parameters `p` ([`NAMES`] order), against the
/// noise levels of `spec` where the record is one of the fitted ones (`noise_of` gives the
/// level of output `o` for record `k`).
pub fn score_records(
    spec: &CompliantSpec,
    p: &[f64; P],
    records: &[VoltageRecord],
    noise_of: &(dyn Fn(Signal, usize) -> f64 + Sync),
) -> Vec<RecordScore> {
    let d = spec.drive(*p);
    records
        .par_iter()
        .enumerate()
        .map(|(k, r)| {
            let (sim, encoder_offsets, current_offset) = simulate_on_zeros(spec, &d, r);
            let outputs = spec
                .outputs
                .iter()
                .filter_map(|(o, _)| {
                    let meas = o.measured(r)?;
                    let s = score(meas, o.simulated(&sim));
                    let sigma = noise_of(*o, k);
                    Some((*o, s, sigma, s.rmse / sigma))
                })
                .collect();
            RecordScore { name: r.name.clone(), outputs, encoder_offsets, current_offset }
        })
        .collect()
}

/// Residuals (simulated − measured)/noise of every record and output, with parameters of
/// arithmetic `T`.
pub(super) fn residuals_of<T: Scalar + Send + Sync>(
    spec: &CompliantSpec,
    p: [T; P],
    records: &[VoltageRecord],
) -> Vec<T> {
    let d = spec.drive(p);
    let parts: Vec<Vec<T>> = records
        .par_iter()
        .enumerate()
        .map(|(k, r)| {
            let (sim, _, _) = simulate_on_zeros(spec, &d, r);
            let mut out = Vec::new();
            for (o, noise) in &spec.outputs {
                let Some(meas) = o.measured(r) else { continue };
                let inv = 1.0 / noise[k];
                out.extend(o.simulated(&sim).iter().zip(meas).map(|(&s, &m)| (s - m) * inv));
            }
            out
        })
        .collect();
    parts.concat()
}

/// The residuals (simulated − measured)/noise at parameters `p`, or None where one is not
/// finite.
pub fn residuals_at(
    spec: &CompliantSpec,
    p: &[f64; P],
    records: &[VoltageRecord],
) -> Option<Vec<f64>> {
    let r = residuals_of(spec, *p, records);
    r.iter().all(|v| v.is_finite()).then_some(r)
}

/// Σ (residual/noise)² at parameters `p`, or None where a residual is not finite.
pub fn cost_at(spec: &CompliantSpec, p: &[f64; P], records: &[VoltageRecord]) -> Option<f64> {
    residuals_at(spec, p, records).map(|r| r.iter().map(|v| v * v).sum())
}

pub use super::jacobian::residuals_and_jacobian;

/// Parameters fitted as they are, not by their logarithm, even when positive: the
/// motor's constants, the inertias, the viscous dampings and the gear's stiffness
/// constants. Each enters the drive's equations of motion as a coefficient, and a record
/// that sees only a combination of them sees a sum or a ratio: the load's resonance fixes
/// (c + A·ω²/(B² + ω²))/Jz, the motor's current Ke·ωj/R, the reflected inertia
/// Jj + Jz/N². Those valleys are flat planes in the parameters themselves and bend in
/// their logarithms, where the optimiser's steps overshoot them: on a 2 s multisine of the
/// seed drive the full fit took 34 iterations with these logged and 12 without (same
/// optimum to 1e-9 of the cost). The friction law's constants keep their logarithms (its
/// level and bristle stiffness span decades between drives). Their bounds (the user's, by
/// default start/1000) keep them positive.
const LINEAR: [usize; 11] = [R, KM, KE, JJ, JZ, CJ, CZ, C, MEM_A, BW_ALPHA, MS_K];

/// Where one Levenberg–Marquardt fit ends, without the analysis of its optimum: what the
/// stages that only choose starts or collect ends (the motor and load passes, the rounding
/// check's refits, the diagnosis's trials) need.
pub(super) struct Optimum {
    /// Every parameter at the end, [`NAMES`] order.
    pub values: [f64; P],
    /// Σ (residual/noise)² at `values` [–].
    pub cost: f64,
    /// Iterations taken [–].
    pub iterations: usize,
    /// Trial points that could not be simulated [–].
    pub failed_trials: usize,
    /// Why the optimiser stopped.
    pub termination: String,
    /// The free parameters ([`NAMES`] indices), the Jacobian's columns.
    free_idx: Vec<usize>,
}

/// One Levenberg–Marquardt fit of `spec` from its start, to its end only ([`Optimum`]).
pub(super) fn optimise(
    spec: &CompliantSpec,
    records: &[VoltageRecord],
    progress: Progress<'_>,
) -> Result<Optimum, String> {
    let free_idx: Vec<usize> =
        (0..NAMES.len()).filter(|&k| spec.free[k] && !spec.follows(k)).collect();
    // Parameters that are positive at the start and bounded below by zero are fitted by
    // their logarithm (relative steps: a step cannot reach zero or below, and a parameter
    // the record barely sees drifts by factors, not into the bound), except the
    // [`LINEAR`] ones; others as they are.
    let logged: Vec<bool> = free_idx
        .iter()
        .map(|&k| spec.start[k] > 0.0 && spec.lower[k] >= 0.0 && !LINEAR.contains(&k))
        .collect();
    let full = |x: &[f64]| {
        let mut p = spec.start;
        for (slot, &k) in free_idx.iter().enumerate() {
            p[k] = if logged[slot] { x[slot].exp() } else { x[slot] };
        }
        spec.tied(p)
    };
    let finite = |r: &[f64]| r.iter().all(|v| v.is_finite());
    let plain = |x: &[f64]| {
        let r = residuals_of(spec, full(x), records);
        finite(&r).then_some(r)
    };
    // ∂r/∂ln p = p·∂r/∂p.
    let with_jac = |x: &[f64]| {
        let p = full(x);
        let (r, mut j) = residuals_and_jacobian(spec, &p, &free_idx, records);
        for (slot, &k) in free_idx.iter().enumerate() {
            if logged[slot] {
                j.column_mut(slot).scale_mut(p[k]);
            }
        }
        finite(&r).then_some((r, j))
    };
    let to_x = |slot: usize, v: f64| if logged[slot] { v.max(f64::MIN_POSITIVE).ln() } else { v };
    let x0: Vec<f64> = free_idx.iter().enumerate().map(|(s, &k)| to_x(s, spec.start[k])).collect();
    let lo: Vec<f64> = free_idx.iter().enumerate().map(|(s, &k)| to_x(s, spec.lower[k])).collect();
    let hi: Vec<f64> = free_idx.iter().enumerate().map(|(s, &k)| to_x(s, spec.upper[k])).collect();
    let problem = Columns::new(&with_jac, &plain);
    let LmOutcome { x, cost, iterations, failed_trials, termination, .. } =
        minimise(&problem, &x0, &pairs(&lo, &hi), &spec.settings, progress).map_err(
            |_| "the drive cannot be simulated at the start values (a residual is not finite)",
        )?;
    Ok(Optimum { values: full(&x), cost, iterations, failed_trials, termination, free_idx })
}

/// One Levenberg–Marquardt fit of `spec` from its start, with its optimum's analysis: the
/// exact Jacobian there, what the records determine and the scores.
pub(super) fn fit_stage(
    spec: &CompliantSpec,
    records: &[VoltageRecord],
    progress: Progress<'_>,
) -> Result<CompliantFit, String> {
    let Optimum { values, cost, iterations, failed_trials, termination, free_idx } =
        optimise(spec, records, progress)?;
    let (r, jac) = residuals_and_jacobian(spec, &values, &free_idx, records);
    let free_names: Vec<&str> = free_idx.iter().map(|&k| NAMES[k]).collect();
    let free_values: Vec<f64> = free_idx.iter().map(|&k| values[k]).collect();
    // Correlated residuals hold fewer independent samples than they have
    // ([`super::correlated`]): each output's rows are weighed down by its κ.
    let blocks = blocks(spec, records);
    let mut widened = jac.clone();
    let kappas = super::correlated::widen(
        &mut widened,
        &r,
        &blocks.iter().map(|b| b.2.clone()).collect::<Vec<_>>(),
    );
    let mut det = determination(&widened, cost, &free_names, &free_values);
    for ((record, signal, _), (kappa, lag)) in blocks.iter().zip(&kappas) {
        if *kappa >= CORRELATED_KAPPA {
            det.sentences.push(format!(
                "The {} residuals of {} are correlated over about {lag} samples: the standard errors count that record's {} as {:.0} independent samples, not {} (κ = {kappa:.1}).",
                signal.name(), records[*record].name, signal.name(),
                records[*record].len() as f64 / kappa, records[*record].len()
            ));
        }
    }
    let mut std_errors = [None; P];
    let mut determined = [false; P];
    for (slot, &k) in free_idx.iter().enumerate() {
        std_errors[k] = det.std_errors[slot];
        determined[k] = det.determined[slot];
    }
    // Information from samples where an encoder creeps is a quantisation staircase, not
    // noise ([`super::creeping`]).
    let masks = super::creeping::masks(spec, records, |o| o != Signal::Current);
    let shares = super::creeping::creeping_share(&widened, &masks);
    for (slot, &k) in free_idx.iter().enumerate() {
        if determined[k] && shares[slot] > super::creeping::CREEPING_SHARE {
            determined[k] = false;
            det.sentences.push(format!(
                "{} is not determined by this record: {:.0} % of what it says of {} comes from samples where an encoder moves less than a count, where its rounding error is a staircase the fit can follow rather than noise; add an experiment that moves it further.",
                NAMES[k],
                100.0 * shares[slot],
                NAMES[k]
            ));
        }
    }
    let corr = |a: usize, b: usize| {
        let (sa, sb) =
            (free_idx.iter().position(|&k| k == a)?, free_idx.iter().position(|&k| k == b)?);
        det.correlation[sa][sb]
    };
    // Km, shown beside Ke, carries Ke's verdict; the symmetric fit's negative-side levels are
    // not reported, so they carry none and no rule below speaks of them.
    for (f, l) in spec.ties().into_iter().filter(|&(f, _)| f == super::model::ix::KM) {
        std_errors[f] = std_errors[l];
        determined[f] = determined[l];
    }
    super::determined::refine(
        &mut det.sentences,
        &values,
        &std_errors,
        &mut determined,
        spec.n,
        &corr,
    );
    det.all_determined = free_idx.iter().all(|&k| determined[k]);
    let noise_of = |o: Signal, k: usize| {
        spec.outputs.iter().find(|(s, _)| *s == o).map_or(f64::NAN, |(_, n)| n[k])
    };
    Ok(CompliantFit {
        values,
        free: spec.free,
        std_errors,
        cost,
        n: r.len(),
        iterations,
        failed_trials,
        termination,
        determination: det,
        scores: score_records(spec, &values, records, &noise_of),
        held: Vec::new(),
        jacobian: jac,
        jacobian_params: free_idx.clone(),
        noise: spec.outputs.clone(),
        starts: 1,
        determined,
        doubt: Vec::new(),
        stage_seconds: Vec::new(),
    })
}
