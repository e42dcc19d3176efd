//! Why a compliant fit does not reach the noise: the cheap alternatives tried, and the one
//! that fits named. Each is a short pass from the fit's end (at most the passes' iteration
//! budget), compared with the same pass under the configuration as given:
//!
//! - the voltage read the other way between samples (`voltage_between`: `hold` against
//!   `linear`), on the motor pass (current and motor encoder; the motor's parameters and
//!   the friction levels free, from the configuration's start);
//! - the current read at the other instant (`current_sampled`: `after` against `before`), on
//!   the motor pass;
//! - direction-dependent friction (Tc_neg, Ts_neg their own) where the fit was symmetric,
//!   on every output with the motor's parameters and the friction levels free.
//!
//! An alternative is named when it lowers that pass's cost below [`BETTER`] times the
//! configuration's. Scale mistakes of the current and the command are checked before the
//! fit ([`super::scale_check`]).

use super::fit::{CompliantFit, CompliantSpec, Signal, optimise};
use super::model::ix::*;
use super::passes::pass;
use super::record::{Between, VoltageRecord};
use rayon::prelude::*;

/// An alternative is named when its pass's cost is below this share of the configuration's
/// [–].
pub const BETTER: f64 = 0.5;

/// How the motor-pass trials are run, in the sentence that names one.
const MOTOR_PASS: &str = "the current and the motor encoder, the motor's parameters and the friction levels free, from the configuration's start";

/// One alternative: what it is, in the configuration's words, and its pass.
struct Trial {
    what: String,
    how: &'static str,
    spec: CompliantSpec,
    records: Vec<VoltageRecord>,
}

/// The cost of `spec` (already a pass) on `records`, fitted from its start; None when it
/// cannot be fitted.
fn cost(spec: &CompliantSpec, records: &[VoltageRecord]) -> Option<f64> {
    let quiet = |_: usize, _: f64| {};
    optimise(spec, records, &quiet).ok().map(|f| f.cost)
}

/// Sentences naming the likely causes of `best`'s misfit under `spec` on `records`: the
/// alternatives that fit better, or, where none does, the causes left to check.
pub fn diagnose(
    spec: &CompliantSpec,
    records: &[VoltageRecord],
    best: &CompliantFit,
) -> Vec<String> {
    let start = best.values;
    let motor_outputs: Vec<_> =
        spec.outputs.iter().filter(|(s, _)| *s != Signal::Load).cloned().collect();
    // From the configuration's start, as the fit's own motor pass: the fit's end has
    // already bent the friction to absorb the wrong reading. The friction levels are free,
    // as that absorption is what the alternative must undo.
    let motor_set = [R, KM, KE, JJ, CJ, TC, TS, TC_NEG, TS_NEG];
    let base_motor = pass(spec, &motor_set, motor_outputs.clone(), spec.start);
    let in_loop = records.iter().any(|r| r.closed.is_some());
    let has_current = spec.outputs.iter().any(|(o, _)| *o == Signal::Current);
    let mut trials: Vec<(Trial, &CompliantSpec)> = Vec::new();
    if !in_loop && !motor_outputs.is_empty() {
        let other = if spec.between == Between::Hold { Between::Linear } else { Between::Hold };
        trials.push((
            Trial {
                what: format!(
                    "`voltage_between = \"{}\"` (the fit read the voltage as `{}`)",
                    other.name(),
                    spec.between.name()
                ),
                how: MOTOR_PASS,
                spec: CompliantSpec { between: other, ..base_motor.clone() },
                records: records.to_vec(),
            },
            &base_motor,
        ));
    }
    if has_current {
        let now = records[0].current_sampled;
        let other = now.other();
        trials.push((
            Trial {
                what: format!(
                    "`current_sampled = \"{}\"` (the fit read the current as sampled {} the new voltage)",
                    other.name(),
                    now.name()
                ),
                how: MOTOR_PASS,
                spec: base_motor.clone(),
                records: records.iter().map(|r| r.clone().with_current_sampled(other)).collect(),
            },
            &base_motor,
        ));
    }
    let friction_set = [R, KM, KE, JJ, CJ, TC, TS, TC_NEG, TS_NEG];
    let base_friction = pass(spec, &friction_set, spec.outputs.clone(), start);
    if spec.symmetric_friction && (spec.free[TC] || spec.free[TS]) {
        let directional = CompliantSpec { symmetric_friction: false, ..spec.clone() };
        trials.push((
            Trial {
                what: "`directional_friction = true` (Tc_neg and Ts_neg their own: the friction differs by direction)".into(),
                how: "every output, the motor's parameters and the friction levels free, from this fit's end",
                spec: pass(&directional, &friction_set, spec.outputs.clone(), start),
                records: records.to_vec(),
            },
            &base_friction,
        ));
    }
    // Each baseline once, then the alternatives, in parallel.
    let bases: Vec<&CompliantSpec> = {
        let mut b: Vec<&CompliantSpec> = Vec::new();
        for (_, base) in &trials {
            if !b.iter().any(|x| std::ptr::eq(*x, *base)) {
                b.push(base);
            }
        }
        b
    };
    let base_costs: Vec<Option<f64>> = bases.par_iter().map(|b| cost(b, records)).collect();
    let alt_costs: Vec<Option<f64>> =
        trials.par_iter().map(|(t, _)| cost(&t.spec, &t.records)).collect();
    let mut named = Vec::new();
    for ((t, base), alt) in trials.iter().zip(alt_costs) {
        let k = bases.iter().position(|x| std::ptr::eq(*x, *base)).unwrap_or(0);
        let (Some(b), Some(a)) = (base_costs[k], alt) else { continue };
        if a < BETTER * b {
            named.push((a / b, t.what.clone(), t.how));
        }
    }
    named.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut out: Vec<String> = named
        .iter()
        .map(|(ratio, what, how)| {
            format!(
                "Likely cause: {what} fits this record better: a short refit with it ({how}) ends at {ratio:.3} times the cost of the same refit as configured. Set it and fit again."
            )
        })
        .collect();
    if out.is_empty() {
        out.push(format!(
            "None of the cheap alternatives tried ({}) fits this record much better. Check the scales (voltage_scale, current_scale, motor_scale, load_scale, and N), a start nearer the drive, more parameters free, and the noise levels given.",
            trials.iter().map(|(t, _)| t.what.split(' ').next().unwrap_or("").trim_matches('`')).collect::<Vec<_>>().join(", ")
        ));
    }
    out
}
