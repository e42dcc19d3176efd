//! The friction fit as a whole: the static stage, the dynamic stage, or both in order,
//! with one report over every parameter involved.

use super::joint::{FrictionOptions, JointSettings, fit_joint_with};
use super::propagate::{Propagated, propagate};
use super::steady::{LOAD_PARAMS, STATIC_PARAMS, SteadyOptions, SteadyProblem};
use super::transient::{DYNAMIC_PARAMS, TransientProblem};
use crate::data::{SteadyData, TransientData};
use crate::error::FitError;
use crate::fix::Fixed;
use crate::report::{Correlation, FitReport, Parameters, REL_SE_LIMIT};
use crate::separable::{SeparableFit, fit_separable};
use hd_model::laws::friction::{LoadFactors, LuGre};
use hd_model::registry::{REGISTRY, lookup};
use std::time::Instant;

/// All six LuGre parameters (registry order).
pub const FRICTION_PARAMS: [&str; 6] = ["sigma0", "sigma1", "sigma2", "Tc", "Ts", "ws"];
/// The LuGre parameters of an asymmetric fit.
pub const ASYMMETRIC_PARAMS: [&str; 8] =
    ["sigma0", "sigma1", "sigma2", "Tc", "Ts", "ws", "Tc_neg", "Ts_neg"];

/// Outcome of [`fit_friction`].
#[derive(Clone, Debug, PartialEq)]
pub struct FrictionFit {
    /// The report over every parameter involved (with each stage's own report inside
    /// when both stages ran).
    pub report: FitReport,
    /// The static stage, when a steady-state sweep was given.
    pub steady: Option<SeparableFit>,
    /// The dynamic stage, when a time series was given.
    pub transient: Option<SeparableFit>,
    /// The LuGre law with the final values (σ0, σ1 at their registry defaults when no
    /// time series was given).
    pub law: LuGre,
}

fn default_of(name: &str) -> f64 {
    lookup(name).map_or(0.0, |i| i.default_value())
}

/// Fit the symmetric friction law without offset: see [`fit_friction_with`].
pub fn fit_friction(
    steady: Option<&SteadyData>,
    transient: Option<&TransientData>,
    fixed: &Fixed,
) -> Result<FrictionFit, FitError> {
    fit_friction_with(steady, transient, fixed, FrictionOptions::default())
}

/// Fit the friction parameters: with `steady` alone the static stage (Tc, Ts, ωs, σ2);
/// with `transient` alone every parameter jointly from the one series ([`fit_joint`]);
/// with both, the static stage and then the dynamic stage (σ0, σ1) holding the static
/// parameters at its result, the static stage's uncertainty carried into the dynamic
/// stage's errors. `opts` adds direction-dependent levels and a torque offset (with one
/// data set). Parameters in `fixed` are held.
pub fn fit_friction_with(
    steady: Option<&SteadyData>,
    transient: Option<&TransientData>,
    fixed: &Fixed,
    opts: FrictionOptions,
) -> Result<FrictionFit, FitError> {
    fit_friction_settings(steady, transient, fixed, opts, JointSettings::default())
}

/// [`fit_friction_with`] with explicit settings of the joint fit (a time series alone):
/// [`JointSettings::exhaustive`] takes none of its shortcuts.
pub fn fit_friction_settings(
    steady: Option<&SteadyData>,
    transient: Option<&TransientData>,
    fixed: &Fixed,
    opts: FrictionOptions,
    settings: JointSettings,
) -> Result<FrictionFit, FitError> {
    let start = Instant::now();
    let base: &[&str] = if opts.asymmetric { &ASYMMETRIC_PARAMS } else { &FRICTION_PARAMS };
    let mut allowed = base.to_vec();
    let loaded = steady.is_some_and(|d| d.load().is_some());
    if loaded {
        allowed.extend(LOAD_PARAMS);
    }
    fixed.check_allowed("friction", &allowed)?;
    if loaded && transient.is_some() {
        return Err(FitError::Setting {
            field: "--load-column",
            value: "with both --steady and --transient".into(),
            expected: "a steady-state table alone: the load factors are fitted from the steady-state levels".into(),
        });
    }
    if steady.is_none() && transient.is_none() {
        return Err(FitError::NoData);
    }
    if steady.is_some() && transient.is_some() && (opts.asymmetric || opts.offset) {
        return Err(FitError::Setting {
            field: "--asymmetric / --offset",
            value: "with both --steady and --transient".into(),
            expected: "one data set: the direction-dependent levels and the offset are fitted from a time series alone (every parameter jointly) or from a steady-state table alone".into(),
        });
    }
    if let (None, Some(d)) = (steady, transient) {
        let joint = fit_joint_with(d, fixed, opts, settings)?;
        return Ok(single(joint, fixed, opts, false));
    }
    if let (Some(d), None) = (steady, transient) {
        let problem = SteadyProblem::with_options(
            d,
            SteadyOptions { asymmetric: opts.asymmetric, offset: opts.offset },
        );
        let s1 = fit_separable(&problem, fixed)?;
        return Ok(single(s1, fixed, opts, true));
    }
    // Both data sets: the static stage, then the dynamic stage holding its result.
    let (Some(sd), Some(d)) = (steady, transient) else {
        unreachable!("one data set is handled above")
    };
    let s1 = fit_separable(&SteadyProblem::new(sd), &fixed.restricted_to(&STATIC_PARAMS))?;
    let static_value = |name: &str| fixed.get(name).or_else(|| s1.value(name));
    let mut statics = [0.0; 4];
    for (s, name) in statics.iter_mut().zip(["Tc", "Ts", "ws", "sigma2"]) {
        *s = static_value(name).unwrap_or_else(|| default_of(name));
    }
    let problem = TransientProblem::new(d, statics[0], statics[1], statics[2], statics[3]);
    let mut s2 = fit_separable(&problem, &fixed.restricted_to(&DYNAMIC_PARAMS))?;
    let value = |name: &str| {
        s2.value(name)
            .or_else(|| s1.value(name))
            .or_else(|| fixed.get(name))
            .unwrap_or_else(|| default_of(name))
    };
    let law = LuGre::symmetric(
        value("sigma0"),
        value("sigma1"),
        value("sigma2"),
        value("Tc"),
        value("Ts"),
        value("ws"),
    );
    let prop = propagate(&s1, &s2, d, statics)?;
    if let Some(p) = &prop {
        widen(&mut s2, p);
    }
    let mut report = combine(&s1, &s2, prop.as_ref(), start);
    report.parameters.0.sort_by_key(|(n, _)| order_key(n));
    Ok(FrictionFit { report, steady: Some(s1), transient: Some(s2), law })
}

/// The outcome of a fit on one data set (`steady` tells which kind): its law, with the
/// parameters it did not estimate at their fixed or default values.
fn single(fit: SeparableFit, fixed: &Fixed, opts: FrictionOptions, steady: bool) -> FrictionFit {
    let value = |name: &str| {
        fit.value(name).or_else(|| fixed.get(name)).unwrap_or_else(|| default_of(name))
    };
    let (tc, ts) = (value("Tc"), value("Ts"));
    let law = LuGre {
        sigma0: value("sigma0"),
        sigma1: value("sigma1"),
        sigma2: value("sigma2"),
        tc,
        ts,
        ws: value("ws"),
        tc_neg: if opts.asymmetric { value("Tc_neg") } else { tc },
        ts_neg: if opts.asymmetric { value("Ts_neg") } else { ts },
        mu: LoadFactors {
            c_fwd: value("mu_c_fwd"),
            s_fwd: value("mu_s_fwd"),
            c_back: value("mu_c_back"),
            s_back: value("mu_s_back"),
        },
    };
    let mut report = fit.report.clone();
    report.parameters.0.sort_by_key(|(n, _)| order_key(n));
    if steady {
        FrictionFit { report, steady: Some(fit), transient: None, law }
    } else {
        FrictionFit { report, steady: None, transient: Some(fit), law }
    }
}

/// Report order: registry order, the offset last.
fn order_key(name: &str) -> usize {
    REGISTRY.iter().position(|p| p.name == name).unwrap_or(usize::MAX)
}

/// Replace the dynamic stage's conditional errors by the propagated ones, and re-judge.
fn widen(s2: &mut SeparableFit, p: &Propagated) {
    let r = &mut s2.report;
    let t95 = s2.covariance.t95;
    for (i, name) in s2.free.iter().enumerate() {
        let se = p.dynamic[(i, i)].max(0.0).sqrt();
        let Some((_, est)) = r.parameters.0.iter_mut().find(|(n, _)| n == name) else { continue };
        if est.std_error.is_none() {
            continue;
        }
        est.std_error = Some(se);
        est.ci95 = Some([est.value - t95 * se, est.value + t95 * se]);
        let rse = se / est.value.abs();
        if est.determined && rse > REL_SE_LIMIT {
            est.determined = false;
            est.note = Some(format!(
                "relative standard error {:.3} % (limit {} %) once the static stage's uncertainty is carried over: \
                 the dynamic fit leans on Tc, Ts and ωs, which the steady-state sweep fixes too loosely; a denser or less noisy sweep would tighten it",
                100.0 * rse,
                100.0 * REL_SE_LIMIT
            ));
        }
    }
    for i in 0..s2.free.len() {
        for j in 0..s2.free.len() {
            if r.correlation.matrix[i][j].is_some() {
                let c = p.dynamic[(i, j)] / (p.dynamic[(i, i)] * p.dynamic[(j, j)]).sqrt();
                r.correlation.matrix[i][j] = Some(c.clamp(-1.0, 1.0));
            }
        }
    }
    r.remarks.push(
        "standard errors include the static stage's uncertainty, propagated to first order".into(),
    );
}

/// One report over both stages: all parameters, the dynamic stage's fit quality (its
/// model uses all six), and the correlation over all free parameters (the cross block
/// from the propagation, when available).
fn combine(
    s1: &SeparableFit,
    s2: &SeparableFit,
    prop: Option<&Propagated>,
    start: Instant,
) -> FitReport {
    let (r1, r2) = (&s1.report, &s2.report);
    let mut params = r1.parameters.0.clone();
    for (name, est) in &r2.parameters.0 {
        if !params.iter().any(|(n, _)| n == name) {
            params.push((name.clone(), est.clone()));
        }
    }
    let names: Vec<String> =
        r1.correlation.names.iter().chain(&r2.correlation.names).cloned().collect();
    let k1 = r1.correlation.names.len();
    let se = |k: usize| -> Option<f64> {
        if k < k1 {
            s1.covariance.std_error[k]
        } else {
            prop.map(|p| p.dynamic[(k - k1, k - k1)].sqrt())
        }
    };
    let cross = |i: usize, j: usize| -> Option<f64> {
        // i in stage 2, j in stage 1.
        let p = prop?;
        Some(p.cross[(i, j)] / (se(k1 + i)? * se(j)?))
    };
    let matrix = (0..names.len())
        .map(|i| {
            (0..names.len())
                .map(|j| match (i < k1, j < k1) {
                    (true, true) => r1.correlation.matrix[i][j],
                    (false, false) => r2.correlation.matrix[i - k1][j - k1],
                    (false, true) => cross(i - k1, j).map(|c| c.clamp(-1.0, 1.0)),
                    (true, false) => cross(j - k1, i).map(|c| c.clamp(-1.0, 1.0)),
                })
                .collect()
        })
        .collect();
    let mut remarks = r2.remarks.clone();
    remarks.push("rms, r2, samples and dof are those of the dynamic stage, whose model uses all six parameters".into());
    FitReport {
        fit: "friction".to_string(),
        law: None,
        data: Vec::new(),
        parameters: Parameters(params),
        rms: r2.rms,
        r2: r2.r2,
        iterations: r1.iterations + r2.iterations,
        termination: format!("static stage: {}; dynamic stage: {}", r1.termination, r2.termination),
        correlation: Correlation { names, matrix },
        samples: r2.samples,
        dof: r2.dof,
        noise_std: r2.noise_std,
        evaluations: r1.evaluations + r2.evaluations,
        search: None,
        stages: vec![r1.clone(), r2.clone()],
        remarks,
        wall_time_s: start.elapsed().as_secs_f64(),
        loop_energy: Vec::new(),
        refinement_starts: Vec::new(),
        refinement_ends: Vec::new(),
        nested: None,
    }
}
