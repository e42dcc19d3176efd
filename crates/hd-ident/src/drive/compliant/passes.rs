//! The motor and load passes of the compliant fit ([`super::stages`], steps 1 and 2): the
//! cheap fits on one side of the gear at a time that choose the full fits' starts.

use super::fit::{CompliantSpec, Report, Signal, optimise};
use super::model::{P, has_load_law, ix::*};
use super::record::VoltageRecord;
use crate::lm::LmOptions;
use rayon::prelude::*;

/// Stiffness scales of the load pass's starts: the gear's resonance at 0.5, 0.71, 1, 1.41
/// and 2 times the start's.
pub const STIFFNESS_SCALES: [f64; 5] = [0.25, 0.5, 1.0, 2.0, 4.0];

/// Load-pass starts go on to a full fit while their load-pass cost is within this factor of
/// the best one's.
const LOAD_COST_FACTOR: f64 = 2.0;

/// Iteration budget of each motor and load pass [–]: the passes only choose the full fits'
/// starts, and a pass that crawls along a valley (friction on the load, whose stick and
/// slip make its cost ridged) would otherwise spend the full fit's budget there.
const PASS_ITERATIONS: usize = 100;

/// Relative cost change per iteration below which a motor or load pass stops [–]. A pass
/// only chooses the full fits' starts, and its ends are told apart by their load predictions
/// ([`SAME_PREDICTION`]): a change of 1e-6 of a pass's noise-weighted cost (~10⁴ squares) is
/// a few hundredths of one, a move of the prediction far below that resolution. A pass held
/// by a motor or load its other half mis-states crawls on at such rates: on a 50:1 drive
/// with a stiff gear, 100 iterations on each of five starts, with 1e-8 (the full fit's).
/// Looser, at 1e-5, ends that would have met stayed apart and ran as five full fits
/// instead of three.
const PASS_COST_TOLERANCE: f64 = 1e-6;

/// RMS difference of two load-pass results' load residuals, as a share of the noise, below
/// which they count as one start [–].
const SAME_PREDICTION: f64 = 0.02;

/// The starts of the full fits: `spec.start` alone, or, when the records carry the load
/// encoder beside the current or the motor encoder, the motor and load passes' results.
pub(super) fn staged_starts(
    spec: &CompliantSpec,
    records: &[VoltageRecord],
    report: Report<'_>,
) -> Vec<[f64; P]> {
    let has = |s: Signal| spec.outputs.iter().any(|(o, _)| *o == s);
    let first_outputs: Vec<_> =
        spec.outputs.iter().filter(|(s, _)| *s != Signal::Load).cloned().collect();
    if !has(Signal::Load) || first_outputs.is_empty() {
        return vec![spec.start];
    }
    // Levels that differ by direction act on the motor as a torque that flips with the
    // direction, which the motor's own parameters would absorb from a wrong start (a 5 s
    // multisine with Tc_neg, Ts_neg 30 % off then ended with the load's resonance at half
    // its frequency): the motor pass fits the two Coulomb levels too. A symmetric level's
    // error is absorbed without harm, and fitting it there only costs time.
    // Friction on the load is the load pass's, with the constant load torque.
    let levels = !spec.symmetric_friction;
    let on_load = spec.friction_velocity == hd_model::FrictionVelocity::Load;
    let motor_set: &[usize] =
        if !levels || on_load { &[R, KM, KE, JJ, CJ] } else { &[R, KM, KE, JJ, CJ, TC, TC_NEG] };
    let coarse = CompliantSpec { substeps: pass_substeps(spec, records), ..spec.clone() };
    let spec = &coarse;
    let motor = start_pass(spec, motor_set, first_outputs, spec.start);
    let values = optimise(&motor, records, &|it, c| report("motor pass", it, c))
        .map_or(spec.start, |f| f.values);
    let load_outputs: Vec<_> =
        spec.outputs.iter().filter(|(s, _)| *s == Signal::Load).cloned().collect();
    // Jz, Cz and the stiffness scaled together move the load alike (the load's rates are
    // ratios to Jz): with the stiffness free, Jz waits for the full fit, which alone can see
    // that scale (through the motor), and the load pass does not crawl along it.
    let stiffness_free = [C, MEM_A, BW_ALPHA, MS_K, CAT_K1].iter().any(|&k| spec.free[k]);
    let gear = [
        C, MEM_A, MEM_B, BW_ALPHA, BW_A, BW_BETA, BW_GAMMA, BW_N, MS_K, MS_DELTA, CAT_K1, CAT_K2,
        CAT_K3, CAT_T1, CAT_T2,
    ];
    // Friction on the load is the load's to explain: held at a wrong start, the gear's
    // constants absorb it. How much of it the load pass should take has no one answer: on
    // one 2–200 Hz chirp only its levels (Jz waiting, as above) led the full fit to the
    // truth, on another only the whole law with Jz did, each variant ending at 7–10 times
    // the noise-level cost where the other succeeded. Both are run, and the better ends of
    // each go on to full fits.
    // The load-side law beside the gear's (friction on both sides) is the load's too, in
    // the same two variants.
    let base: Vec<usize> = if stiffness_free { vec![CZ] } else { vec![JZ, CZ] };
    let load_law = has_load_law(&spec.start);
    let variants: Vec<Vec<usize>> = if on_load || load_law {
        let (level_set, law_set): (&[usize], &[usize]) = if on_load {
            (&[TC, TS, TC_NEG, TS_NEG], &[TC, TS, WS, SIGMA0, SIGMA1, SIGMA2, TC_NEG, TS_NEG])
        } else {
            (&[TC_L, TS_L, TC_NEG_L, TS_NEG_L], &super::model::LOAD_LAW)
        };
        let levels = base.iter().copied().chain(gear).chain([TL]).chain(level_set.iter().copied());
        let whole = [JZ, CZ].into_iter().chain(gear).chain([TL]).chain(law_set.iter().copied());
        vec![levels.collect(), whole.collect()]
    } else {
        vec![base.into_iter().chain(gear).chain([TL]).collect()]
    };
    let mut kept: Vec<([f64; P], Option<Vec<f64>>)> = Vec::new();
    for (v, load_set) in variants.iter().enumerate() {
        let load = start_pass(spec, load_set, load_outputs.clone(), values);
        if !load.free.iter().any(|&f| f) {
            continue;
        }
        let which = if variants.len() > 1 {
            format!(" {} of {}", v + 1, variants.len())
        } else {
            String::new()
        };
        let progress = |stage: &str, it, c| report(&format!("load pass{which}, {stage}"), it, c);
        kept_ends(&load, values, records, &mut kept, &progress);
    }
    if kept.is_empty() {
        return vec![values];
    }
    kept.into_iter().map(|(v, _)| v).collect()
}

/// Run the load pass `load` from `values` with the stiffness scaled by each of
/// [`STIFFNESS_SCALES`] (or, with the stiffness held and Jz free, Jz divided by them; in
/// parallel), and add to `kept` each end whose cost is within
/// [`LOAD_COST_FACTOR`] of the best one's and whose load prediction differs from every end
/// kept so far (with its predicted load residuals).
fn kept_ends(
    load: &CompliantSpec,
    values: [f64; P],
    records: &[VoltageRecord],
    kept: &mut Vec<([f64; P], Option<Vec<f64>>)>,
    report: Report<'_>,
) {
    // The catalogue curve scaled whole (its rates with its corner torques: the corners'
    // deflections stay).
    let scaled = [C, MEM_A, BW_ALPHA, MS_K, CAT_K1, CAT_K2, CAT_K3, CAT_T1, CAT_T2];
    let stiffness = scaled.iter().any(|&k| load.free[k]);
    // A gear held at its datasheet's stiffness with the load's inertia free: the resonance
    // is moved by Jz instead (divided by the same scales), since from a start on the wrong
    // side of it the load pass can settle on a secondary optimum (a Bouc–Wen drive's Jz
    // 14 standard errors off, 15–34 above the truth's cost, from starts 25 % off).
    let inertia = !stiffness && load.free[JZ];
    let scales: &[f64] = if stiffness || inertia { &STIFFNESS_SCALES } else { &[1.0] };
    let mut tried: Vec<(f64, [f64; P])> = scales
        .par_iter()
        .filter_map(|&g| {
            let mut start = values;
            for k in scaled.into_iter().filter(|&k| load.free[k]) {
                start[k] *= g;
            }
            if inertia {
                start[JZ] /= g;
            }
            let s = CompliantSpec { start, ..load.clone() };
            let stage = if inertia {
                format!("start with Jz ÷ {g}")
            } else {
                format!("start with the stiffness × {g}")
            };
            optimise(&s, records, &|it, c| report(&stage, it, c)).ok().map(|f| (f.cost, f.values))
        })
        .collect();
    tried.sort_by(|a, b| a.0.total_cmp(&b.0));
    let Some(&(lowest, _)) = tried.first() else { return };
    // Starts that ended in the same place would give the same full fit: one of them is
    // kept. The same place is the same prediction: load residuals that differ by less
    // than SAME_PREDICTION of the noise, RMS over the samples (in a valley the parameters
    // of two such ends can still differ in their last digits).
    let predicted = |v: &[f64; P]| super::fit::residuals_at(load, v, records);
    for (cost, v) in tried {
        if cost > LOAD_COST_FACTOR * lowest {
            continue;
        }
        let r = predicted(&v);
        let same = |(_, w): &([f64; P], Option<Vec<f64>>)| match (&r, w) {
            (Some(a), Some(b)) => {
                let d2 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>();
                d2 <= SAME_PREDICTION * SAME_PREDICTION * a.len().max(1) as f64
            }
            _ => false,
        };
        if !kept.iter().any(same) {
            kept.push((v, r));
        }
    }
}

/// Largest (fastest rate × substep) of the motor and load passes [–]: the coarsest step the
/// fit integrates at ([`super::accuracy::SEARCH_RATE_STEP`]).
const PASS_RATE_STEP: f64 = super::accuracy::SEARCH_RATE_STEP;

/// Substeps per sample of the motor and load passes: half the full fit's (rounded up), not
/// below [`PASS_RATE_STEP`]'s floor at the start values nor above the full fit's. The passes
/// only choose the full fits' starts, which then run at the full count: halving the substep
/// multiplies the integration error's cost by about 2^5.4 ≈ 40 ([`super::accuracy`]), from
/// below one to tens of noise-weighted squares, against the passes' 10⁴ and more, and halves
/// their time.
fn pass_substeps(spec: &CompliantSpec, records: &[VoltageRecord]) -> usize {
    let h = records.iter().map(|r| r.h).fold(f64::INFINITY, f64::min);
    let rate = spec.drive(spec.start).fastest_rate();
    let floor = (rate * h / PASS_RATE_STEP).ceil();
    let floor = if floor.is_finite() { floor.max(1.0) as usize } else { spec.substeps };
    spec.substeps.div_ceil(2).max(floor).min(spec.substeps).max(1)
}

/// [`pass`] as the motor and load passes run it: stopping at [`PASS_COST_TOLERANCE`].
fn start_pass(
    spec: &CompliantSpec,
    which: &[usize],
    outputs: Vec<(Signal, Vec<f64>)>,
    start: [f64; P],
) -> CompliantSpec {
    let mut s = pass(spec, which, outputs, start);
    s.settings.cost_tolerance = s.settings.cost_tolerance.max(PASS_COST_TOLERANCE);
    s
}

/// `spec` with only `which` (where `spec` frees them) free, comparing `outputs`, from `start`.
pub(super) fn pass(
    spec: &CompliantSpec,
    which: &[usize],
    outputs: Vec<(Signal, Vec<f64>)>,
    start: [f64; P],
) -> CompliantSpec {
    let mut free = [false; P];
    for &k in which {
        free[k] = spec.free[k];
    }
    let settings = LmOptions {
        max_iterations: spec.settings.max_iterations.min(PASS_ITERATIONS),
        ..spec.settings.clone()
    };
    CompliantSpec { outputs, free, start, settings, ..spec.clone() }
}
