//! The joint fit's pipeline: starts, refinement, the bound stage, the nested law's
//! guarantee and the report.
//!
//! Two guarantees a user can leave the fit to:
//! - **nested laws stay nested**: the asymmetric law contains the symmetric one (equal
//!   levels on both sides), so the asymmetric fit first fits the symmetric law and starts
//!   (among its starts) from that optimum with its levels copied to both sides; its final
//!   cost is then never above the symmetric fit's;
//! - **optima on a bound are reachable**: the levels are refined by their logarithms, which
//!   can only approach 0, above a floor kept as an active-set bound
//!   ([`super::LEVEL_FLOOR`]), so a start drawn to Tc = 0 lands on the floor in a few
//!   steps. A level that ends there is held at exactly 0 and the rest refined; the bound
//!   stage also holds each Coulomb level at 0 from the best fit and from
//!   Stribeck-dominated starts (valleys the free starts did not enter). Where a level ends
//!   on 0 either way it is reported on its bound, after a polish that frees it from just
//!   above 0 with no floor (an optimum just above 0 is not lost to the floor).

use super::race::{Refined, refine_starts};
use super::sigma0_pass::Sigma0Pass;
use super::start::{speed_range, static_start};
use super::{
    EXTRA_STARTS, FrictionOptions, JointProblem, MAX_ITERATIONS, NONLINEAR_ALL, OFFSET,
    START_FACTOR, finish::finish,
};
use crate::data::{TransientData, require_samples};
use crate::error::FitError;
use crate::fix::Fixed;
use crate::lm::{LmOptions, hit_budget};
use crate::report::SearchSummary;
use crate::search::{GRID_POINTS, search_log};
use crate::separable::SeparableFit;
use std::time::Instant;

/// How the joint fit treats its starts. The default takes every shortcut; each shortcut is
/// checked against [`JointSettings::exhaustive`] on a corpus of records with different
/// valleys (crates/hd-ident/tests/joint_corpus.rs, and the repository's real recordings in
/// the CLI suite): none changes the optimum there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JointSettings {
    /// Stop starts far above the others early ([`super::DROP_FACTOR`]); false runs every
    /// start to its end.
    pub race: bool,
    /// The bound stage for a Coulomb level runs only where some start ended, in a valley
    /// comparable with the best, with that level small ([`BOUND_GATE`] of its side's larger
    /// level) or the nested fit had it on its bound: a valley whose optimum lies on Tc = 0
    /// draws the free refinement from the Stribeck-dominated starts towards it. False runs
    /// the bound stage for every free Coulomb level.
    ///
    /// (Reusing the symmetric fit's σ0 search in the asymmetric fit, and leaving out its
    /// perturbed starts, was tried as a shortcut too: on the real tribometer recording the
    /// asymmetric fit then ended at RMS 0.2330 against 0.2049, so it is not taken.)
    pub shortcuts: bool,
}

impl Default for JointSettings {
    fn default() -> Self {
        Self { race: true, shortcuts: true }
    }
}

impl JointSettings {
    /// No shortcut: every start runs to its end, every start set and stage is run.
    pub fn exhaustive() -> Self {
        Self { race: false, shortcuts: false }
    }
}

/// A Coulomb level whose free refinement ended below this share of its side's larger
/// level (in some start) opens the bound stage for it, with [`JointSettings::shortcuts`]
/// [–].
pub const BOUND_GATE: f64 = 0.1;

/// The Coulomb levels the bound stage may hold at 0, in the order it tries them.
const BOUND_LEVELS: [&str; 2] = ["Tc", "Tc_neg"];

/// Share of its side's static level from which a Coulomb level on 0 is freed by its
/// logarithm in the polish [–] (above the law's floor,
/// [`hd_model::laws::friction::LEVEL_FLOOR_SHARE`]).
const POLISH_SHARE: f64 = 1e-6;

/// Share of the largest level a Stribeck-dominated start gives the Coulomb level [–].
const STRIBECK_START_SHARE: f64 = 0.02;

/// Fit every free LuGre parameter (and, by `opts`, the negative-side levels and the
/// offset) to one time series.
pub fn fit_joint(
    data: &TransientData,
    fixed: &Fixed,
    opts: FrictionOptions,
) -> Result<SeparableFit, FitError> {
    fit_joint_with(data, fixed, opts, JointSettings::default())
}

/// A finished fit of the nested (symmetric) law, as a start of the richer one.
struct Nested {
    values: [f64; 6],
    /// Part of the first torque that is not bristle torque at its optimum [N·m].
    bias: f64,
    rss: f64,
    on_bound: Vec<&'static str>,
    /// Its report, carried into the richer fit's (`FitReport::nested`).
    report: crate::report::FitReport,
}

/// [`fit_joint`] with explicit settings.
pub fn fit_joint_with(
    data: &TransientData,
    fixed: &Fixed,
    opts: FrictionOptions,
    settings: JointSettings,
) -> Result<SeparableFit, FitError> {
    let started = Instant::now();
    let mut remarks = Vec::new();
    let nested =
        if opts.asymmetric && (fixed.get("Tc_neg").is_none() || fixed.get("Ts_neg").is_none()) {
            nested_fit(data, fixed, opts, settings)
        } else {
            None
        };
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
        let pass = Sigma0Pass::new(&problem, problem.law(&base));
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

    let starts = start_set(&problem, base, nested.as_ref());
    let lm = LmOptions { max_iterations: MAX_ITERATIONS, secant: true, ..Default::default() };
    let race = refine_starts(&problem, &starts, &lm, settings.race, f64::INFINITY);
    let mut iterations = race.iterations;
    evaluations += race.evaluations;
    failed += race.failed;
    let mut ends = race.ends;
    let Some(mut best) = race.best else {
        return Err(FitError::Optimiser(format!(
            "no start of the joint refinement could be evaluated ({})",
            race.start_failures.join("; ")
        )));
    };
    if race.dropped > 0 {
        remarks.push(format!(
            "{} of {} starts stopped after {} iterations, their RSS over {} × the lowest any start had reached then (fit.json refinement_ends)",
            race.dropped,
            starts.len(),
            super::RACE_ITERATIONS,
            super::DROP_FACTOR
        ));
    }
    if !race.start_failures.is_empty() {
        remarks.push(format!(
            "{} of {} starts could not be evaluated and were skipped",
            race.start_failures.len(),
            starts.len()
        ));
    }

    // The bound stage: each free Coulomb level held at exactly 0.
    for name in BOUND_LEVELS {
        if !problem.nonlinear.contains(&name) {
            continue;
        }
        if settings.shortcuts && problem.on_floor(name, &best.values) {
            ends.push(format!(
                "{name} held at 0: not tried here (the free refinement ended on its floor: held at 0 below)"
            ));
            continue;
        }
        if settings.shortcuts && !bound_stage_needed(name, &race.end_values, nested.as_ref()) {
            ends.push(format!(
                "{name} held at 0: not tried (no start ended with {name} below {BOUND_GATE} of its side's larger level)"
            ));
            continue;
        }
        let candidate = bound_candidate(&problem, fixed, opts, &best, name, &lm, settings.race);
        let Some((held, refined, tried)) = candidate else {
            continue;
        };
        iterations += tried.iterations;
        evaluations += tried.evaluations;
        ends.extend(tried.ends.iter().map(|e| format!("{name} held at 0: {e}")));
        if refined.rss < best.rss {
            remarks.push(format!(
                "{name} is best on its bound 0: held there, the RSS is {:.6e} against {:.6e} with it free (bound stage)",
                refined.rss, best.rss
            ));
            problem = held;
            best = refined;
        }
    }
    // A level the free refinement brought to its floor: held at exactly 0 and the rest
    // refined from there; kept where that is no worse, so that it is reported on its bound
    // and the covariance leaves it out.
    let reached: Vec<&'static str> =
        BOUND_LEVELS.into_iter().filter(|name| problem.on_floor(name, &best.values)).collect();
    if !reached.is_empty() {
        let mut on_bound = problem.on_bound.clone();
        on_bound.extend(&reached);
        let mut at_zero = best.values;
        for name in &reached {
            at_zero[if *name == "Tc" { 0 } else { 4 }] = 0.0;
        }
        if !opts.asymmetric {
            at_zero[4] = at_zero[0];
        }
        let mut held = held_problem(data, fixed, opts, &at_zero, &on_bound)?;
        held.first_bias = problem.first_bias;
        if let Ok(out) = held.refine(&held.x_of(&at_zero), &lm) {
            iterations += out.iterations;
            evaluations += out.evaluations;
            ends.push(format!(
                "{} from the floor to 0: RSS {:.6e} after {} iterations ({})",
                reached.join(" and "),
                out.cost,
                out.iterations,
                out.termination
            ));
            if out.cost <= best.rss {
                remarks.push(format!(
                    "{} reached the floor of the free refinement; held at 0 (on its bound): RSS {:.6e}",
                    reached.join(" and "),
                    out.cost
                ));
                best = Refined::from_outcome(&held, out);
                problem = held;
            }
        }
    }
    // The polish of a level on 0: the law holds a level below a share of the static one at
    // that floor, so the one-sided slope at 0 can hide an optimum just above it. The levels
    // on 0, freed and moved by their logarithms from just above it with no floor, show
    // whether there is one.
    if !problem.on_bound.is_empty() {
        let mut start = best.values;
        for name in &problem.on_bound {
            let (c, st) = if *name == "Tc" { (0, 1) } else { (4, 5) };
            start[c] = POLISH_SHARE * start[st];
        }
        if !opts.asymmetric {
            start[4] = start[0];
        }
        let named: Vec<(&'static str, f64)> =
            NONLINEAR_ALL.iter().copied().zip(start.iter().copied()).collect();
        let mut polish = JointProblem::new(data, fixed, opts, &named);
        polish.level_floor = 0.0;
        polish.first_bias = problem.first_bias;
        if let Ok(out) = polish.refine(&polish.x_of(&start), &lm) {
            iterations += out.iterations;
            evaluations += out.evaluations;
            ends.push(format!(
                "{} freed from just above 0: RSS {:.6e} after {} iterations ({})",
                problem.on_bound.join(" and "),
                out.cost,
                out.iterations,
                out.termination
            ));
            if out.cost < best.rss {
                remarks.push(format!(
                    "{} just above 0 fit better than on it: RSS {:.6e} against {:.6e}",
                    problem.on_bound.join(" and "),
                    out.cost,
                    best.rss
                ));
                best = Refined::from_outcome(&polish, out);
                problem = polish;
            }
        }
    }
    if failed > 0 {
        remarks.push(format!("{failed} trial parameter sets failed to integrate or gave non-finite torques; each counted as a rejected trial"));
    }

    // The bristle state starts from the first torque less the offset and viscous term,
    // which are only known now: refine once more with that start (a fixed point in one
    // step: the start's effect on the optimum is second order).
    let bias = bias_at(&problem, &best.values)?;
    if bias != 0.0 {
        problem.first_bias = bias;
        let x0 = problem.x_of(&best.values);
        if let Ok(out) = problem.refine(&x0, &lm) {
            iterations += out.iterations;
            evaluations += out.evaluations;
            best = Refined::from_outcome(&problem, out);
        }
    }

    // The nested law's guarantee: never above its optimum.
    if let Some(n) = &nested
        && n.rss < best.rss
    {
        let mut held = held_problem(data, fixed, opts, &n.values, &n.on_bound)?;
        held.first_bias = n.bias;
        if let Ok(out) = held.refine(&held.x_of(&n.values), &lm) {
            iterations += out.iterations;
            evaluations += out.evaluations;
            remarks.push(format!(
                "the symmetric law's optimum (RSS {:.6e}) was below the asymmetric fit's ({:.6e}); refined from it: RSS {:.6e}",
                n.rss, best.rss, out.cost
            ));
            best = Refined::from_outcome(&held, out);
            problem = held;
        }
    }
    if hit_budget(&best.termination) {
        remarks.push(format!(
            "warning: the best start's refinement stopped on its iteration budget ({MAX_ITERATIONS}) before converging; the optimum may lie further on (try --fix on a poorly determined parameter)"
        ));
    }
    let mut fit = finish(
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
    if let Some(n) = nested {
        fit.report.remarks.push(nested_comparison(&fit.report, &n.report));
        fit.report.nested = Some(Box::new(n.report));
    }
    Ok(fit)
}

/// BIC of a reported fit ([`crate::criteria::bic`]): RSS = n·rms², k = n − dof free
/// parameters [–].
fn bic(r: &crate::report::FitReport) -> f64 {
    let n = r.samples;
    crate::criteria::bic(n as f64 * r.rms * r.rms, n, n.saturating_sub(r.dof))
}

/// The richer law against the nested one it started from, in one sentence.
fn nested_comparison(rich: &crate::report::FitReport, nested: &crate::report::FitReport) -> String {
    let delta = bic(nested) - bic(rich);
    let verdict = if delta > 10.0 {
        "the direction-dependent levels are strongly supported"
    } else if delta > 2.0 {
        "the direction-dependent levels are supported"
    } else {
        "the record does not support direction-dependent levels: prefer the symmetric law"
    };
    format!(
        "nested symmetric law (levels equal on both sides, same offset; fit.json `nested`): RMS {:.6e} against {:.6e}; BIC(symmetric) − BIC(asymmetric) = {delta:.1}: {verdict}",
        nested.rms, rich.rms
    )
}

/// The symmetric law's fit, for the asymmetric one to start from (None where it fails:
/// the richer fit then goes on from its own starts).
fn nested_fit(
    data: &TransientData,
    fixed: &Fixed,
    opts: FrictionOptions,
    settings: JointSettings,
) -> Option<Nested> {
    let sym = FrictionOptions { asymmetric: false, ..opts };
    let held = fixed.restricted_to(&["Tc", "Ts", "ws", "sigma0", "sigma1", "sigma2", OFFSET]);
    let fit = fit_joint_with(data, &held, sym, settings).ok()?;
    let get = |name: &str| fit.values.iter().find(|(n, _)| *n == name).map(|v| v.1);
    let (tc, ts) = (get("Tc")?, get("Ts")?);
    let values = [tc, ts, get("ws")?, get("sigma0")?, tc, ts];
    let bias = get(OFFSET).unwrap_or(0.0) + get("sigma2").unwrap_or(0.0) * data.omega()[0];
    let rss = fit.residuals.iter().map(|r| r * r).sum();
    let on_bound = fit
        .report
        .parameters
        .0
        .iter()
        .filter(|(n, e)| n == "Tc" && e.value == 0.0 && !e.fixed)
        .flat_map(|_| ["Tc", "Tc_neg"])
        .collect();
    Some(Nested { values, bias, rss, on_bound, report: fit.report })
}

/// The part of the first measured torque that is not bristle torque at `v` [N·m].
fn bias_at(problem: &JointProblem, v: &[f64; 6]) -> Result<f64, FitError> {
    let proj = problem.project(v)?;
    let beta = |name: &str| {
        problem.linear.iter().position(|(n, _)| *n == name).map_or(0.0, |j| proj.beta[j])
    };
    Ok(beta(OFFSET) + beta("sigma2") * problem.data.omega()[0])
}

/// Whether the bound stage for the Coulomb level `name` can find anything: some start
/// ended in a valley comparable with the best (RSS within [`super::DROP_FACTOR`] of the
/// lowest, the race's own measure) with that level below [`BOUND_GATE`] of its side's
/// larger level, or the nested fit has it on its bound.
fn bound_stage_needed(name: &str, ends: &[([f64; 6], f64)], nested: Option<&Nested>) -> bool {
    let (c, s) = if name == "Tc" { (0, 1) } else { (4, 5) };
    let lowest = ends.iter().map(|e| e.1).fold(f64::INFINITY, f64::min);
    let small = |(v, rss): &&([f64; 6], f64)| {
        *rss <= super::DROP_FACTOR * lowest && v[c] <= BOUND_GATE * v[c].max(v[s])
    };
    ends.iter().any(|e| small(&e)) || nested.is_some_and(|n| n.on_bound.contains(&name))
}

/// The refinement's starts: the searched one, ωs and σ0 moved each way, two
/// Stribeck-dominated ones (the Coulomb level small, the static level the largest, ωs as
/// found and in the middle of the record's speeds), and the nested law's optimum.
fn start_set(problem: &JointProblem, base: [f64; 6], nested: Option<&Nested>) -> Vec<[f64; 6]> {
    let mut starts = vec![base];
    for (k, factor) in
        [(2, START_FACTOR), (2, 1.0 / START_FACTOR), (3, START_FACTOR), (3, 1.0 / START_FACTOR)]
    {
        if problem.nonlinear.contains(&NONLINEAR_ALL[k]) && starts.len() <= EXTRA_STARTS {
            let mut v = base;
            v[k] *= factor;
            starts.push(v);
        }
    }
    if problem.nonlinear.contains(&"Tc") && problem.nonlinear.contains(&"Ts") {
        let (lo, hi) = speed_range(problem.data.omega());
        let mid = (lo * hi).sqrt();
        for ws in [base[2], mid] {
            if !(ws.is_finite() && ws > 0.0) || !problem.nonlinear.contains(&"ws") && ws != base[2]
            {
                continue;
            }
            starts.push(stribeck_dominated(&base, ws));
        }
    }
    if let Some(n) = nested {
        // A level on its bound in the nested fit enters the free refinement on its floor.
        starts.push(n.values.map(|v| v.max(problem.level_floor)));
    }
    starts
}

/// `v` with each side's Coulomb level at [`STRIBECK_START_SHARE`] of its larger level, the
/// static level at that larger level, and ωs at `ws`.
fn stribeck_dominated(v: &[f64; 6], ws: f64) -> [f64; 6] {
    let mut s = *v;
    for (c, st) in [(0, 1), (4, 5)] {
        let top = v[c].max(v[st]);
        s[c] = STRIBECK_START_SHARE * top;
        s[st] = top;
    }
    s[2] = ws;
    s
}

/// A problem with the levels `on_bound` held at exactly 0 (and reported so), the other
/// free parameters starting from `values`.
fn held_problem<'a>(
    data: &'a TransientData,
    fixed: &Fixed,
    opts: FrictionOptions,
    values: &[f64; 6],
    on_bound: &[&'static str],
) -> Result<JointProblem<'a>, FitError> {
    let mut held = fixed.clone();
    for name in on_bound {
        if opts.asymmetric || !name.ends_with("_neg") {
            held.insert(name, 0.0)?;
        }
    }
    let start: Vec<(&'static str, f64)> =
        NONLINEAR_ALL.iter().copied().zip(values.iter().copied()).collect();
    let mut problem = JointProblem::new(data, &held, opts, &start);
    problem.on_bound = on_bound.to_vec();
    Ok(problem)
}

/// The best refinement with `name` held at 0 on top of `problem`'s own bounds: from the
/// best fit with that level at 0 and from Stribeck-dominated starts (raced as the main
/// starts are, with `race`). None where the held problem cannot be set up or no start
/// could be evaluated.
fn bound_candidate<'a>(
    problem: &JointProblem<'a>,
    fixed: &Fixed,
    opts: FrictionOptions,
    best: &Refined,
    name: &'static str,
    lm: &LmOptions,
    race: bool,
) -> Option<(JointProblem<'a>, Refined, super::race::RaceOutcome)> {
    let mut on_bound = problem.on_bound.clone();
    on_bound.push(name);
    let k = NONLINEAR_ALL.iter().position(|n| *n == name)?;
    let mut at_zero = best.values;
    at_zero[k] = 0.0;
    if !opts.asymmetric {
        at_zero[4] = 0.0;
    }
    let held = held_problem(problem.data, fixed, opts, &at_zero, &on_bound).ok()?;
    let mut starts = vec![at_zero];
    let (lo, hi) = speed_range(problem.data.omega());
    for ws in [best.values[2], (lo * hi).sqrt()] {
        if ws.is_finite() && ws > 0.0 && (ws == best.values[2] || held.nonlinear.contains(&"ws")) {
            let mut s = stribeck_dominated(&best.values, ws);
            s[k] = 0.0;
            if !opts.asymmetric {
                s[4] = 0.0;
            }
            for (i, held_name) in NONLINEAR_ALL.iter().enumerate() {
                if on_bound.contains(held_name) {
                    s[i] = 0.0;
                }
            }
            starts.push(s);
        }
    }
    // The held problem is the free one restricted to a bound (same objective): its starts
    // race against the free optimum's cost too.
    let tried = refine_starts(&held, &starts, lm, race, best.rss);
    let refined = tried.best.as_ref().map(|b| Refined {
        values: b.values,
        rss: b.rss,
        iterations: b.iterations,
        evaluations: b.evaluations,
        failed: b.failed,
        termination: b.termination.clone(),
        dropped: false,
    })?;
    Some((held, refined, tried))
}
