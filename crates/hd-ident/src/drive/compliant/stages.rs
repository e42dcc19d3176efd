//! How the compliant fit gets to its optimum, and how it checks what that optimum means.
//!
//! 1. **Motor pass.** The motor's own parameters (R, Km, Ke, Jj, Cj; with direction-dependent
//!    friction, the two Coulomb levels too) fitted to the current and the motor encoder. These see the motor without the gear's ringing (the current alone
//!    would leave the speed's scale free: Ke·s, Jj·s², Cj·s² give the same current).
//! 2. **Load pass.** The load's and the gear's parameters (Cz, TL, c, mem_A, mem_B or bw_*; Jz
//!    too when the stiffness is fixed) fitted to the load encoder, the motor's held. With the
//!    friction on the load, twice: once with its levels, once with its whole law and Jz. The load's
//!    ringing makes this cost many-valleyed in the resonance frequency, so it starts from
//!    the spring and memory stiffness scaled by [`super::passes::STIFFNESS_SCALES`] (in parallel); ends
//!    that predict the same load motion count once.
//!    Both passes integrate at half the full fit's substeps ([`super::passes`]).
//! 3. **Full fits** from the load pass's better starts, each [`settle`]d: a free parameter
//!    the records leave undetermined (no standard error) is held at its start value and the
//!    rest fitted again.
//! 4. **Split.** With friction on both sides, one more full fit: from the best with the
//!    weaker friction law held at its start until the rest has settled, then freed
//!    ([`super::split`]); it joins the fits.
//! 5. **Bounds.** A parameter of the best that ran to its bound is held at its start value
//!    and the fit run again. That fit is reported unless freeing the parameter lowers the cost by at
//!    least BIC's price, ln n per parameter (in units of the cost per degree of freedom);
//!    the other fit is a rival.
//! 6. **Nested law.** With direction-dependent friction, the symmetric law's own fit (these
//!    same stages) joins the fits, as a point of the directional law and as the start of one
//!    more full fit, so the directional fit never ends above it.
//! 7. **Agreement.** The best full fit is reported. Another full fit whose cost is within the
//!    95 % threshold of the best (Δcost ≤ χ²₉₅(m)·s², m the number of parameters on which
//!    the two differ by more than twice the best fit's standard error, s² the best fit's
//!    cost per degree of freedom) is as good an explanation of the records; a parameter on
//!    which the two differ that much is not determined, whatever its linearised standard
//!    error says (the cost's valley bends away from the tangent).

use super::determined::{not_determined_by_agreement, refine_fit};
use super::fit::{CompliantFit, CompliantSpec, Progress, Report, Signal, cost_at, fit_stage};
use super::model::{NAMES, P, ix::*};
use super::passes::staged_starts;
use super::record::VoltageRecord;
use rayon::prelude::*;

/// χ² quantiles at 95 % for 1 to 16 degrees of freedom [–].
const CHI2_95: [f64; 16] = [
    3.84, 5.99, 7.81, 9.49, 11.07, 12.59, 14.07, 15.51, 16.92, 18.31, 19.68, 21.03, 22.36, 23.68,
    25.00, 26.30,
];

/// Whether `rival` explains the records as well as `best` at 95 %: its cost is within the
/// χ² quantile for as many degrees of freedom as parameters on which the two differ by
/// more than twice the best fit's standard error (at least one), times s² (the best fit's
/// cost per degree of freedom). Fits that move several parameters together are compared
/// on that many.
fn as_good(best: &CompliantFit, rival: &CompliantFit) -> bool {
    let dof = (best.n as f64 - best.free.iter().filter(|&&f| f).count() as f64).max(1.0);
    let apart = (0..NAMES.len())
        .filter(|&k| {
            best.std_errors[k].is_some_and(|se| (rival.values[k] - best.values[k]).abs() > 2.0 * se)
        })
        .count();
    let q = CHI2_95[apart.clamp(1, CHI2_95.len()) - 1];
    rival.cost - best.cost <= q * best.cost / dof
}

/// Fit `spec` to `records` (see the module's steps); `report(stage, iteration, cost)` is
/// called as the fits go (several may run at once).
pub fn fit_compliant(
    spec: &CompliantSpec,
    records: &[VoltageRecord],
    report: Report<'_>,
) -> Result<CompliantFit, String> {
    let mut clock = Stages::default();
    let nested = nested_symmetric(spec, records, report);
    clock.lap("symmetric law's fit (nested)", nested.is_some());
    let starts = staged_starts(spec, records, report);
    clock.lap("motor and load passes", true);
    let count = starts.len();
    let mut fits: Vec<Result<CompliantFit, String>> = starts
        .par_iter()
        .enumerate()
        .map(|(j, s)| {
            let stage = format!("full fit from start {} of {count}", j + 1);
            settle(spec, *s, records, &|it, c| report(&stage, it, c))
        })
        .collect();
    clock.lap("full fits", true);
    let mut spent: usize = fits.iter().flatten().map(|f| f.iterations).sum();
    let mut failed: usize = fits.iter().flatten().map(|f| f.failed_trials).sum();
    // Noise levels estimated from the records (third differences) overstate a signal whose
    // own content reaches the Nyquist band. Where they were estimated, the best fit's
    // residual RMS replaces them (the maximum-likelihood level of each output), and the best
    // fit is settled again from where it ended, with those weights. The other fits keep
    // their ends, costed with the new weights: a rival's cost can only fall further if it
    // were refitted, so the agreement check below stays on the safe side.
    let weighed = reweigh(spec, &fits);
    if let Some(new) = &weighed {
        fits.sort_by(|a, b| match (a, b) {
            (Ok(a), Ok(b)) => a.cost.total_cmp(&b.cost),
            (Ok(_), Err(_)) => std::cmp::Ordering::Less,
            (Err(_), Ok(_)) => std::cmp::Ordering::Greater,
            _ => std::cmp::Ordering::Equal,
        });
        if let Some(Ok(best)) = fits.first() {
            let progress = |it, c| report("best fit again with the residuals' noise levels", it, c);
            let again = settle(new, best.values, records, &progress);
            if let Ok(f) = &again {
                spent += f.iterations;
                failed += f.failed_trials;
            }
            fits[0] = again;
        }
        for f in fits.iter_mut().skip(1).flatten() {
            f.cost = cost_at(new, &f.values, records).unwrap_or(f64::INFINITY);
        }
    }
    clock.lap("noise levels re-estimated, best refitted", weighed.is_some());
    let mut ok: Vec<CompliantFit> = Vec::new();
    let mut last_error = String::from("no start could be fitted");
    for f in fits {
        match f {
            Ok(f) => ok.push(f),
            Err(e) => last_error = e,
        }
    }
    ok.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    let used = weighed.as_ref().unwrap_or(spec);
    // Friction on both sides: one more fit, from the best with the weaker law held at its
    // start until the rest has settled, then freed (super::split); it joins the fits.
    if let Some(weak) = ok.first().and_then(|f| super::split::weaker_law(used, &f.values)) {
        let mut held = used.clone();
        let mut from = ok[0].values;
        for &k in &weak {
            held.free[k] = false;
            from[k] = used.start[k];
        }
        let progress = |it, c| report("split: the weaker friction law held, then freed", it, c);
        let end = settle(&held, held.tied(from), records, &progress).and_then(|h| {
            spent += h.iterations;
            settle(used, h.values, records, &progress)
        });
        if let Ok(end) = end {
            spent += end.iterations;
            failed += end.failed_trials;
            ok.push(end);
            ok.sort_by(|a, b| a.cost.total_cmp(&b.cost));
        }
        clock.lap("split (friction on both sides)", true);
    }
    // Nested laws stay nested: the symmetric law's own fit joins the fits as a point of this
    // law (the negative-side levels equal to the positive ones), costed with this fit's
    // weights, and as the start of one more full fit; the directional fit's cost is then
    // never above the symmetric one's.
    if let Some(n) = &nested {
        let from = used.tied(n.values);
        let mut at = used.clone();
        at.start = from;
        at.settings.max_iterations = 0;
        let progress = |it, c| report("full fit from the symmetric law's optimum", it, c);
        if let Ok(point) = fit_stage(&at, records, &progress) {
            ok.push(point);
        }
        if let Ok(end) = settle(used, from, records, &progress) {
            spent += end.iterations;
            failed += end.failed_trials;
            ok.push(end);
        }
        spent += n.iterations;
        ok.sort_by(|a, b| a.cost.total_cmp(&b.cost));
        clock.lap("full fit from the symmetric law's optimum", true);
    }
    let mut best = if ok.is_empty() { return Err(last_error) } else { ok.remove(0) };
    // A parameter on its bound: the fit again with it held at its start is reported unless
    // freeing it lowers the cost by at least BIC's price of the parameters it frees
    // (ln n each, in units of the cost per degree of freedom); the other one is a rival.
    let bounded = on_bound(used, &best);
    if !bounded.is_empty() {
        let at_bound: Vec<f64> = bounded.iter().map(|&k| best.values[k]).collect();
        let mut held = used.clone();
        let mut start = best.values;
        for &k in &bounded {
            held.free[k] = false;
            start[k] = used.start[k];
        }
        let mut gap = f64::NAN;
        let best_cost = best.cost;
        // The free fit the held one is weighed against (the first, or its run again).
        let mut free_cost = best_cost;
        let mut kept_held = false;
        let progress = |it, c| report("bounds: refit with the bounded parameters held", it, c);
        let mut freed_again = false;
        if let Ok(mut alt) = settle(&held, start, records, &progress) {
            spent += alt.iterations;
            failed += alt.failed_trials;
            alt.free = used.free;
            alt.held.extend(bounded.iter().copied());
            // A fit with more parameters free can always do at least as well as one it
            // contains: a full fit that ended above the held refit was stuck on its way
            // (a bound it ran into, a ridge), not at an optimum. It runs once more from the
            // held refit's end with everything free, and that end replaces it where lower.
            if alt.cost < best.cost {
                let progress = |it, c| report("bounds: full fit again from the held refit", it, c);
                if let Ok(again) = settle(used, alt.values, records, &progress) {
                    spent += again.iterations;
                    failed += again.failed_trials;
                    if again.cost < best.cost {
                        ok.push(std::mem::replace(&mut best, again));
                        freed_again = true;
                    }
                }
            }
            gap = alt.cost - best.cost;
            free_cost = best.cost;
            let dof = (best.n as f64 - best.free.iter().filter(|&&f| f).count() as f64).max(1.0);
            let price = bounded.len() as f64 * (best.n as f64).ln() * best.cost / dof;
            if gap < price {
                std::mem::swap(&mut best, &mut alt);
                kept_held = true;
            }
            ok.push(alt);
        }
        let still = on_bound(used, &best);
        for (&k, v) in bounded.iter().zip(at_bound) {
            if freed_again && !kept_held && !still.contains(&k) {
                best.determination.sentences.push(format!(
                    "{} ran to its bound ({v:.4e}) in the first full fits, which ended above a refit with it held at its start value {:.4e}; the full fit run again from that refit's end, with it free, ends lower (cost {:.4e}, first {best_cost:.4e}) with {} at {:.4e}, off its bound.",
                    NAMES[k], used.start[k], best.cost, NAMES[k], best.values[k]
                ));
                continue;
            }
            best.determined[k] = false;
            let verdict = if kept_held {
                "the record does not justify freeing it (BIC), so it is held there"
            } else {
                "the record asks for the bound; widen [bounds] if such values are physical"
            };
            best.determination.sentences.push(format!(
                "{} ran to its bound ({v:.4e}); held at its start value {:.4e} instead, the fit's cost changes by {gap:+.3e} ({:+.2} % of the best fit's {:.4e}): {verdict}.",
                NAMES[k], used.start[k], 100.0 * gap / free_cost, free_cost
            ));
        }
    }
    clock.lap("bounds: held refit", !bounded.is_empty());
    let rivals: Vec<&CompliantFit> = ok.iter().filter(|f| as_good(&best, f)).collect();
    not_determined_by_agreement(&mut best, &rivals);
    super::requantised::widen_by_rounding(used, &mut best, records, report);
    clock.lap("rounding check (refits of re-rounded records)", true);
    refine_fit(&mut best, spec.n);
    let given = |s: Signal| {
        spec.outputs
            .iter()
            .enumerate()
            .any(|(j, (o, _))| *o == s && !spec.noise_estimated.get(j).copied().unwrap_or(false))
    };
    let has_current = used.outputs.iter().any(|(o, _)| *o == Signal::Current);
    super::sentences::group_pairs(&mut best.determination.sentences, has_current);
    let mut misfit = super::determined::misfit_sentences(&best, given);
    if misfit.is_empty() {
        misfit = super::structured::structured_misfit(used, &best, records);
    }
    if !misfit.is_empty() {
        let mut doubt = misfit;
        report("misfit diagnosis: fitting the alternatives", 0, f64::NAN);
        doubt.extend(super::diagnose::diagnose(used, records, &best));
        super::determined::put_in_doubt(&mut best, doubt);
        clock.lap("misfit diagnosis", true);
    }
    best.stage_seconds = clock.done;
    best.iterations = spent;
    best.failed_trials = failed;
    best.starts = starts.len();
    Ok(best)
}

/// The wall time of each stage of [`fit_compliant`], as [`CompliantFit::stage_seconds`].
struct Stages {
    since: std::time::Instant,
    done: Vec<(&'static str, f64)>,
}

impl Default for Stages {
    fn default() -> Self {
        Self { since: std::time::Instant::now(), done: Vec::new() }
    }
}

impl Stages {
    /// End the stage `name`, recording its time where it `ran`.
    fn lap(&mut self, name: &'static str, ran: bool) {
        let now = std::time::Instant::now();
        if ran {
            self.done.push((name, (now - self.since).as_secs_f64()));
        }
        self.since = now;
    }
}

/// With direction-dependent friction on the gear (Tc_neg or Ts_neg free), the fit of the
/// symmetric law it contains, as [`fit_compliant`] gives it; None otherwise or where that
/// fit fails (the richer fit then goes on from its own starts).
fn nested_symmetric(
    spec: &CompliantSpec,
    records: &[VoltageRecord],
    report: Report<'_>,
) -> Option<CompliantFit> {
    if spec.symmetric_friction || !(spec.free[TC_NEG] || spec.free[TS_NEG]) {
        return None;
    }
    let symmetric = CompliantSpec { symmetric_friction: true, ..spec.clone() };
    fit_compliant(&symmetric, records, &|stage, it, c| {
        report(&format!("symmetric law (nested): {stage}"), it, c)
    })
    .ok()
}

/// The free parameters of `fit` that ended on a bound of `spec` (within 1e-9 of it,
/// relative).
fn on_bound(spec: &CompliantSpec, fit: &CompliantFit) -> Vec<usize> {
    let near = |v: f64, b: f64| b.is_finite() && (v - b).abs() <= 1e-9 * b.abs().max(1e-300);
    (0..NAMES.len())
        .filter(|&k| spec.free[k] && !fit.held.contains(&k))
        .filter(|&k| near(fit.values[k], spec.lower[k]) || near(fit.values[k], spec.upper[k]))
        .collect()
}

/// `spec` with every estimated noise level replaced by the best fit's residual RMS of that
/// output and record, or None when no level was estimated or none moves by 10 %.
fn reweigh(spec: &CompliantSpec, fits: &[Result<CompliantFit, String>]) -> Option<CompliantSpec> {
    let best = fits.iter().flatten().min_by(|a, b| a.cost.total_cmp(&b.cost))?;
    let mut out = spec.clone();
    let mut moved = false;
    for (j, (signal, levels)) in out.outputs.iter_mut().enumerate() {
        if !spec.noise_estimated.get(j).copied().unwrap_or(false) {
            continue;
        }
        for (k, level) in levels.iter_mut().enumerate() {
            let Some(score) = best.scores.get(k) else { continue };
            let Some(&(_, s, _, _)) = score.outputs.iter().find(|o| o.0 == *signal) else {
                continue;
            };
            // A residual far above the level the record itself shows (its third
            // differences, which if anything overstate the noise) is the misfit's, not the
            // sensor's: the record's level stays, so the report shows the misfit.
            if s.rmse > super::determined::MISFIT_RATIO * *level {
                continue;
            }
            if s.rmse > 0.0 && s.rmse.is_finite() {
                moved |= (s.rmse / *level - 1.0).abs() > 0.1;
                *level = s.rmse;
            }
        }
    }
    moved.then_some(out)
}

/// Fit `spec` from `start`; then, for each combination of parameters the records leave
/// undetermined (a near-null direction of the Jacobian), hold one of its members, the one
/// with the largest weight, at its value in `spec.start` (the user's), and fit the rest
/// again. A direction the records do not see would otherwise let its parameters drift
/// without bound; holding one member per direction removes the drift and leaves the
/// combinations the records do see free. The held ones are listed in `held`.
pub fn settle(
    spec: &CompliantSpec,
    start: [f64; P],
    records: &[VoltageRecord],
    progress: Progress<'_>,
) -> Result<CompliantFit, String> {
    let first = fit_stage(&CompliantSpec { start, ..spec.clone() }, records, progress)?;
    let mut unseen: Vec<usize> = Vec::new();
    for direction in &first.determination.null_directions {
        let mut members: Vec<(usize, f64)> = direction
            .iter()
            .map(|&(slot, w)| (first.jacobian_params[slot], w))
            .filter(|(k, _)| !spec.follows(*k))
            .collect();
        members.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        if members.iter().any(|(k, _)| unseen.contains(k)) {
            continue; // a member is held already: this direction is pinned too
        }
        if let Some(&(k, _)) = members.first() {
            unseen.push(k);
        }
    }
    if unseen.is_empty() {
        return Ok(first);
    }
    let mut free = spec.free;
    for &k in &unseen {
        free[k] = false;
    }
    // Held at the user's start value; where the drive cannot be simulated there with the
    // rest at the first fit's values (a stiff gear's resonance past the integrator's
    // reach), at the first fit's own value, which the record does not prefer either; where
    // that fails too, the first fit stands.
    let refit = |at: &[f64; P]| {
        let mut again = first.values;
        for &k in &unseen {
            again[k] = at[k];
        }
        fit_stage(&CompliantSpec { free, start: again, ..spec.clone() }, records, progress)
            .ok()
            .map(|f| (f, again))
    };
    let Some((mut fit, again)) = refit(&spec.start).or_else(|| refit(&first.values)) else {
        return Ok(first);
    };
    fit.iterations += first.iterations;
    fit.failed_trials += first.failed_trials;
    fit.free = spec.free;
    let held: Vec<String> = unseen
        .iter()
        .map(|&k| {
            let whose = if again[k] == spec.start[k] { "its start value" } else { "the value the fit reached" };
            format!(
                "{} is held at {whose} {:.4e}: the record leaves a combination of it with other parameters undetermined (below).",
                NAMES[k], again[k]
            )
        })
        .collect();
    fit.held = unseen;
    fit.determination.sentences.retain(|s| !s.starts_with("Every free parameter is determined"));
    fit.determination.sentences.splice(0..0, held);
    fit.determination.all_determined = false;
    Ok(fit)
}
