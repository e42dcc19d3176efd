//! A misfit below the doubt ratio that the input explains. A fit whose residuals on an output
//! stay clearly above that output's noise level ([`ABOVE_NOISE`]), and follow the test voltage
//! (their cross-correlation with it is outside the 99 % bounds of white noise at more lags
//! than chance allows, the residual analysis's own test, [`crate::drive::residual_analysis`]),
//! has model error left there. That is a local optimum or a model that lacks something, not
//! noise, so the standard errors, which take the residuals for the noise, do not hold.
//!
//! The ratio alone does not decide it: 1.2 times an encoder's count/√12 is well within what a
//! real encoder's other errors give. The input's trace in the residuals alone does not decide
//! it either: a fit at the noise has none to speak of. Both together do. Records in a loop
//! are not judged here, because their input is the reference, not the voltage.

use super::fit::{CompliantFit, CompliantSpec, Signal, simulate_on_zeros};
use super::record::VoltageRecord;
use crate::drive::residual_analysis::{DEFAULT_LAGS, analyse};

/// Ratio of an output's residual RMS to its noise level above which its residuals are tested
/// for the input's trace [–]: 10 % above the level, ten times the spread of that ratio for a
/// record of a thousand samples of white noise (1/√2000 ≈ 0.022), and below the doubt ratio
/// ([`super::determined::MISFIT_RATIO`]) at which the fit is in doubt anyway.
pub const ABOVE_NOISE: f64 = 1.1;

/// One sentence per output of a voltage test in `records` whose residuals at `fit`'s values
/// are above [`ABOVE_NOISE`] times the noise and cross-correlated with the voltage beyond
/// what chance allows.
pub fn structured_misfit(
    spec: &CompliantSpec,
    fit: &CompliantFit,
    records: &[VoltageRecord],
) -> Vec<String> {
    let d = spec.drive(fit.values);
    let mut out = Vec::new();
    for (k, (rec, score)) in records.iter().zip(&fit.scores).enumerate() {
        if rec.closed.is_some() {
            continue;
        }
        let above: Vec<(Signal, f64)> = score
            .outputs
            .iter()
            .filter(|(o, _, _, ratio)| *o != Signal::Command && *ratio > ABOVE_NOISE)
            .map(|(o, _, _, ratio)| (*o, *ratio))
            .collect();
        if above.is_empty() {
            continue;
        }
        let (sim, _, _) = simulate_on_zeros(spec, &d, rec);
        for (o, ratio) in above {
            let Some(meas) = o.measured(rec) else { continue };
            let e: Vec<f64> = o.simulated(&sim).iter().zip(meas).map(|(s, m)| s - m).collect();
            let a = analyse(&rec.u, &e, DEFAULT_LAGS, "voltage");
            let allowed =
                crate::drive::residual_analysis::allowed_outside(a.cross_correlation.lags.len());
            if a.cross_outside.len() <= allowed {
                continue;
            }
            let level = spec.outputs.iter().find(|(s, _)| *s == o).map_or(f64::NAN, |x| x.1[k]);
            out.push(format!(
                "The fit leaves model error on {}'s {}: its residual RMS is {ratio:.2} times the noise level {level:.3e}, and the residuals follow the voltage (their cross-correlation with it is outside the 99 % bounds at {} of {} lags, where chance allows {allowed}). That is a local optimum or a model that lacks something, not noise: every value below, determined or not, is in doubt. Try other starts, or validate the fit on another record.",
                rec.name,
                o.name(),
                a.cross_outside.len(),
                a.cross_correlation.lags.len()
            ));
        }
    }
    out
}
