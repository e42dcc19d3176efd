//! How many Runge–Kutta substeps a fit needs. The fastest rate of the drive says where the
//! search starts ([`first_substeps`]), but the error that matters is the one the fit sees: the
//! integration error of each output against that output's noise. A record with large motion
//! and a fine load encoder (2^20 counts: 1.7e-6 rad of noise on a load swinging by 1e-2 rad)
//! needs the simulated angle to 1e-4 of its RMS, and an error the fit sees is absorbed into
//! the parameters (on a 5 s, 1–100 Hz multisine of the seed drive, 18 substeps put the true
//! drive's cost 1 100 above its converged value, and the fit moved Tc by 7 standard errors
//! to follow it). So the count is raised from there until the noise-weighted sum of
//! squares of the difference between a run with m and with 2m substeps, an estimate of the
//! error at m (the method's error falls about sixfold per doubling), is below
//! [`ACCURACY_COST`]. `hdw fit drive` measures it again at the fitted values.
//!
//! The search starts where the fastest rate times the substep is [`SEARCH_RATE_STEP`]
//! (0.3), not at 0.1, the rule for a count used without measuring its error
//! ([`super::fit::substeps_of`]). On a 2 s, 5 kHz multisine of a 50:1 drive with a stiff
//! gear, 0.1 asked for 14 substeps, and 3 already met the budget at the start values (error
//! cost 0.08); 4 met it at the truth (0.02). On the seed drive it asked for 4, and 2 already
//! met the budget (0.22 at the start values, 0.04 at the truth).

use super::fit::{CompliantSpec, residuals_at};
use super::model::Compliant;
use super::record::VoltageRecord;

/// Largest noise-weighted sum of squares the integration error may add to the cost [–].
pub const ACCURACY_COST: f64 = 1.0;

/// Most substeps per sample.
pub const MAX_SUBSTEPS: usize = 512;

/// Largest (fastest rate × substep) the search for the count starts from, and the coarsest
/// the motor and load passes integrate at [–]: about a ninth of where the Runge–Kutta step's
/// stability ends (2.8), so that the difference between m and 2m substeps estimates the
/// error at m.
pub const SEARCH_RATE_STEP: f64 = 0.3;

/// Where the search for the substep count of drive `d` on samples of `h` [s] starts: the
/// fastest rate times the substep at most [`SEARCH_RATE_STEP`], at least 2 substeps.
pub fn first_substeps(d: &Compliant<f64>, h: f64) -> usize {
    super::fit::substeps_at(d, h, SEARCH_RATE_STEP)
}

/// Order of the integration error's amplitude in the substep, as measured on the seed
/// drive (doubling the substeps divides the differences to a reference by 6.2–6.9) [–].
const ORDER: f64 = 2.7;

/// The estimated cost of the integration error of `spec` at its start values on `records`
/// (noise-weighted squares): the sum of squares of the difference between runs at
/// `spec.substeps` and at twice as many. Infinite where either run fails.
pub fn integration_error(spec: &CompliantSpec, records: &[VoltageRecord]) -> f64 {
    let run = |m: usize| {
        residuals_at(&CompliantSpec { substeps: m, ..spec.clone() }, &spec.start, records)
    };
    let m = spec.substeps.max(1);
    match (run(m), run(2 * m)) {
        (Some(a), Some(b)) => a.iter().zip(&b).map(|(x, y)| (x - y) * (x - y)).sum(),
        _ => f64::INFINITY,
    }
}

/// The substep count for `spec` (from `spec.substeps` up) whose integration error at the
/// start values costs less than [`ACCURACY_COST`] on `records`, and that error's estimated
/// cost [–]. The error of a count m is estimated as the cost of the difference between runs
/// at m and 2m; above the budget, the next count is the one the error's order predicts for
/// half the budget (at least m + 1). A count whose run fails (a step past the method's
/// stability at the start values: a rate the floor's estimate does not see) is doubled.
/// Stops at [`MAX_SUBSTEPS`].
pub fn accurate_substeps(spec: &CompliantSpec, records: &[VoltageRecord]) -> (usize, f64) {
    raised_substeps(spec, records, None)
}

/// [`accurate_substeps`] where the error at `spec.substeps` may already be known
/// (`measured`, from [`integration_error`] at the same values and count): it is not run
/// again, and the counts tried and the result are the same.
pub fn raised_substeps(
    spec: &CompliantSpec,
    records: &[VoltageRecord],
    mut measured: Option<f64>,
) -> (usize, f64) {
    let mut m = spec.substeps.max(1);
    loop {
        if 2 * m > MAX_SUBSTEPS {
            return (m.min(MAX_SUBSTEPS), f64::NAN);
        }
        let err = measured.take().unwrap_or_else(|| {
            integration_error(&CompliantSpec { substeps: m, ..spec.clone() }, records)
        });
        if !err.is_finite() {
            m *= 2;
            continue;
        }
        if err < ACCURACY_COST {
            return (m, err);
        }
        // The cost falls as m^(−2·ORDER).
        let predicted = m as f64 * (err / (0.5 * ACCURACY_COST)).powf(0.5 / ORDER);
        m = (predicted.ceil() as usize).max(m + 1);
    }
}
