//! What an encoder's rounding alone does to the estimates. Where a shaft creeps, the rounding
//! error is a staircase fixed by the true angle, not noise: a parameter whose effect is a
//! fraction of a count (the bristle's pre-sliding deflection) can be fitted to the
//! staircase, and its linearised standard error, which takes every sample's error as
//! independent, says it is determined when the record says nothing of it (measured on a
//! 2–200 Hz chirp of the seed drive: σ0 at 2.9e4 ± 7.6e3, truth 1.2e5; the same record with
//! white noise of the same RMS in place of the rounding leaves σ0 undetermined).
//!
//! The check redraws the rounding. The fitted drive is run on each record (in closed loop,
//! its controller's output becomes the record's command), its
//! encoder angles are rounded to the record's own count lattice at a random phase (where
//! the record's readings lie on one; white noise of the encoder's level otherwise), the
//! current gets fresh noise of its level, and the fit is run again from the fitted values
//! on [`REPLICATES`] such records: a parametric bootstrap of the rounding and the noise. A
//! parameter whose estimates spread by [`SPREAD_RATIO`] times its linearised standard error
//! or more is set by the rounding more than by the record's information: the spread becomes
//! its standard error, and a sentence says so.

use super::fit::{CompliantFit, CompliantSpec, Report, Signal, optimise, simulate_on_zeros};
use super::model::{NAMES, P};
use super::record::VoltageRecord;
use crate::lm::LmOptions;
use rayon::prelude::*;

/// Number of re-rounded records the fit is repeated on [–].
pub const REPLICATES: usize = 4;

/// Iteration budget of each refit [–]: they start at the fitted values.
const REFIT_ITERATIONS: usize = 60;

/// A refit stops when a step lowers its cost by less than this share [–]: a cost of n/2
/// changes by far less than one standard error's worth (1/2) below it.
const REFIT_TOLERANCE: f64 = 1e-6;

/// Ratio of a parameter's spread over the refits to its linearised standard error from
/// which the spread is taken as its standard error [–]. Four refits estimate a spread to
/// within a factor 1.8 at 95 % (χ² with 3 degrees of freedom); a ratio of 2.5 arises by
/// chance with probability 3e-4.
const SPREAD_RATIO: f64 = 2.5;

/// Share of an encoder's sample-to-sample steps that must be whole multiples of its
/// smallest step for its readings to count as lying on a lattice [–].
const ON_LATTICE: f64 = 0.99;

/// The count [rad] of an encoder whose readings `x` lie on a lattice: the smallest non-zero
/// step between samples, when at least [`ON_LATTICE`] of the steps are whole multiples of
/// it (to 1e-6 of a count) and some samples repeat; None for readings that do not.
pub fn lattice(x: &[f64]) -> Option<f64> {
    let steps: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    let scale = x.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-300);
    let floor = 1e-12 * scale;
    let q = steps.iter().copied().filter(|&s| s > floor).fold(f64::INFINITY, f64::min);
    if !q.is_finite() {
        return None;
    }
    // Rounding of the readings themselves (a scale applied to counts) is far below 1e-6.
    let whole = steps
        .iter()
        .filter(|&&s| {
            let m = s / q;
            (m - m.round()).abs() <= 1e-6 * m.max(1.0)
        })
        .count();
    let repeats = steps.iter().any(|&s| s <= floor);
    (repeats && whole as f64 >= ON_LATTICE * steps.len() as f64).then_some(q)
}

/// A small deterministic generator (splitmix64), so a check gives the same answer twice.
struct Draws(u64);

impl Draws {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller).
    fn normal(&mut self) -> f64 {
        let u = self.uniform().max(1e-300);
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// Record `rec` as the drive at `values` would log it, with the rounding redrawn: encoder
/// angles rounded to the record's lattice at a random phase (or white noise of `spec`'s
/// level), the current with fresh noise of its level, and in closed loop the command as
/// the fitted drive's controller gives it, with fresh noise of its level.
fn redrawn(
    spec: &CompliantSpec,
    values: &[f64; P],
    rec: &VoltageRecord,
    k: usize,
    draws: &mut Draws,
) -> VoltageRecord {
    let d = spec.drive(*values);
    let (sim, _, _) = simulate_on_zeros(spec, &d, rec);
    let level = |s: Signal| spec.outputs.iter().find(|(o, _)| *o == s).map(|(_, n)| n[k]);
    let mut encoder = |sim: &[f64], measured: &[f64], s: Signal| -> Vec<f64> {
        match lattice(measured) {
            Some(q) => {
                let phase = draws.uniform();
                sim.iter().map(|x| q * ((x / q + phase).round() - phase)).collect()
            }
            None => {
                let sigma = level(s).unwrap_or(0.0);
                sim.iter().map(|x| x + sigma * draws.normal()).collect()
            }
        }
    };
    let theta_m = encoder(&sim.theta_m, &rec.theta_m, Signal::Motor);
    let theta_l = encoder(&sim.theta_l, &rec.theta_l, Signal::Load);
    let current = rec.current.as_ref().map(|_| {
        let sigma = level(Signal::Current).unwrap_or(0.0);
        sim.current.iter().map(|i| i + sigma * draws.normal()).collect()
    });
    // In its loop the record's command is the controller's output: the fitted drive's,
    // with fresh noise of the command's level where it is compared.
    let u = if rec.closed.is_some() && !sim.command.is_empty() {
        let sigma = level(Signal::Command).unwrap_or(0.0);
        sim.command.iter().map(|c| c + sigma * draws.normal()).collect()
    } else {
        rec.u.clone()
    };
    VoltageRecord { theta_m, theta_l, current, u, ..rec.clone() }
}

/// The spread (standard deviation over [`REPLICATES`] refits on re-rounded records) of each
/// parameter of `fit` ([`NAMES`] order; None where not free or where too few refits
/// converged), or None when no record has a quantised encoder.
pub fn rounding_spread(
    spec: &CompliantSpec,
    fit: &CompliantFit,
    records: &[VoltageRecord],
    report: Report<'_>,
) -> Option<[Option<f64>; P]> {
    let quantised =
        |r: &VoltageRecord| lattice(&r.theta_m).is_some() || lattice(&r.theta_l).is_some();
    if !records.iter().any(quantised) {
        return None;
    }
    let mut free = spec.free;
    for &k in &fit.held {
        free[k] = false;
    }
    let settings = LmOptions {
        max_iterations: REFIT_ITERATIONS,
        cost_tolerance: REFIT_TOLERANCE,
        ..spec.settings.clone()
    };
    let refit = CompliantSpec { free, start: fit.values, settings, ..spec.clone() };
    let ends: Vec<[f64; P]> = (0..REPLICATES)
        .into_par_iter()
        .filter_map(|j| {
            let mut draws = Draws(0x5EED_0000 + j as u64);
            let recs: Vec<VoltageRecord> = records
                .iter()
                .enumerate()
                .map(|(k, r)| redrawn(spec, &fit.values, r, k, &mut draws))
                .collect();
            let stage = format!("rounding check: refit {} of {REPLICATES}", j + 1);
            let f = optimise(&refit, &recs, &|it, c| report(&stage, it, c)).ok()?;
            Some(f.values)
        })
        .collect();
    if ends.len() < 3 {
        return Some([None; P]);
    }
    let mut out = [None; P];
    for (k, slot) in out.iter_mut().enumerate().take(NAMES.len()) {
        if !free[k] || spec.follows(k) {
            continue;
        }
        let m = ends.len() as f64;
        let mean = ends.iter().map(|e| e[k]).sum::<f64>() / m;
        let var = ends.iter().map(|e| (e[k] - mean).powi(2)).sum::<f64>() / (m - 1.0);
        *slot = Some(var.sqrt());
    }
    Some(out)
}

/// Take the rounding spread ([`rounding_spread`]) as the standard error of each parameter
/// of `fit` where it is [`SPREAD_RATIO`] times the linearised one or more, with one sentence
/// per parameter so widened.
pub fn widen_by_rounding(
    spec: &CompliantSpec,
    fit: &mut CompliantFit,
    records: &[VoltageRecord],
    report: Report<'_>,
) {
    let Some(spread) = rounding_spread(spec, fit, records, report) else { return };
    for k in 0..NAMES.len() {
        let (Some(se), Some(s)) = (fit.std_errors[k], spread[k]) else { continue };
        if s < SPREAD_RATIO * se {
            continue;
        }
        fit.std_errors[k] = Some(s);
        fit.determination.sentences.push(format!(
            "{}'s estimate moves by ± {s:.3e} when the encoders' rounding and the noise are redrawn ({REPLICATES} refits), {:.1} times its linearised standard error {se:.3e}: the rounding, not the record's information, sets much of it; its standard error is taken as {s:.3e}.",
            NAMES[k], s / se
        ));
    }
    // A follower shown with its leader (Km with Ke) keeps its leader's standard error.
    for (f, l) in spec.ties() {
        if fit.std_errors[f].is_some() {
            fit.std_errors[f] = fit.std_errors[l];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Readings rounded to a count lie on a lattice of that count; readings with noise do
    /// not.
    #[test]
    fn lattice_of_rounded_readings() {
        let q = std::f64::consts::TAU / 4096.0;
        let x: Vec<f64> = (0..500).map(|k| ((0.02 * k as f64).sin() * 40.0).round() * q).collect();
        let found = lattice(&x).expect("a lattice");
        assert!((found - q).abs() < 1e-12 * q, "{found} vs {q}");
        let noisy: Vec<f64> =
            (0..500).map(|k| (0.02 * k as f64).sin() + 1e-7 * (k as f64).cos()).collect();
        assert!(lattice(&noisy).is_none());
    }

    /// A redrawn record of the seed drive lies on the record's lattices, its encoders' errors
    /// against the drive's own motion have the RMS of a count's rounding (count/√12, within
    /// 10 % over 2 000 samples of a moving shaft) and its current the noise level asked for
    /// (within 10 %); two replicates round at different phases.
    #[test]
    fn redrawn_records_round_as_the_encoders_do() {
        use super::super::tests::{chirp_reference, quantise, seed, test_spec};
        use hd_model::Params;
        let [t, u, tj, tz, i] = chirp_reference(2.0, 1e-3, 12.0, 60.0);
        let (qm, ql) = (std::f64::consts::TAU / 4096.0, std::f64::consts::TAU / 1048576.0);
        let rec = VoltageRecord::new(
            "chirp",
            "test",
            t,
            u,
            quantise(&tj, qm),
            quantise(&tz, ql),
            Some(i),
        )
        .unwrap();
        let sigma_i = 0.02;
        let outputs = vec![
            (Signal::Motor, vec![qm / 12f64.sqrt()]),
            (Signal::Load, vec![ql / 12f64.sqrt()]),
            (Signal::Current, vec![sigma_i]),
        ];
        let n = Params::default().n;
        let spec = test_spec(n, seed(), outputs, 40);
        let (sim, _, _) = simulate_on_zeros(&spec, &spec.drive(seed()), &rec);
        let mut draws = Draws(1);
        let a = redrawn(&spec, &seed(), &rec, 0, &mut draws);
        let b = redrawn(&spec, &seed(), &rec, 0, &mut draws);
        let rms_diff = |x: &[f64], y: &[f64]| {
            (x.iter().zip(y).map(|(p, q)| (p - q).powi(2)).sum::<f64>() / x.len() as f64).sqrt()
        };
        for (got, simulated, q) in [(&a.theta_m, &sim.theta_m, qm), (&a.theta_l, &sim.theta_l, ql)]
        {
            let found = lattice(got).expect("on a lattice");
            assert!((found / q - 1.0).abs() < 1e-9, "lattice {found} vs {q}");
            let e = rms_diff(got, simulated) / (q / 12f64.sqrt());
            println!("rounding RMS / (count/√12) = {e:.3}");
            assert!((e - 1.0).abs() < 0.1, "{e}");
        }
        let e = rms_diff(a.current.as_ref().unwrap(), &sim.current) / sigma_i;
        assert!((e - 1.0).abs() < 0.1, "current noise ratio {e}");
        assert!(a.theta_m != b.theta_m, "the phase is redrawn");
    }
}
