//! The joint fit's report at the optimum: sensitivities, covariance, estimates.

use super::{JointProblem, NONLINEAR_ALL, unit_of};
use crate::error::FitError;
use crate::report::free_estimate;
use crate::report::{Correlation, Estimate, FitReport, Judgement, Parameters, SearchSummary};
use crate::separable::SeparableFit;
use crate::uncertainty::covariance;
use std::time::Instant;

/// Estimates, covariance and report at the optimum `v`.
#[allow(clippy::too_many_arguments)]
pub(super) fn finish(
    problem: &JointProblem,
    v: &[f64; 6],
    started: Instant,
    remarks: Vec<String>,
    search: Option<SearchSummary>,
    iterations: usize,
    evaluations: usize,
    termination: &str,
    starts: &[[f64; 6]],
    ends: Vec<String>,
) -> Result<SeparableFit, FitError> {
    let proj = problem.project_with(v, true)?;
    let y = problem.data.torque();
    let n = y.len();
    let fitted: Vec<f64> = y.iter().zip(&proj.residuals).map(|(a, r)| a - r).collect();
    let rss: f64 = proj.residuals.iter().map(|r| r * r).sum();

    // Sensitivities of the full prediction: the nonlinear parameters' exact columns (the
    // bristle run's carried sensitivities, linear parameters held), the linear ones their
    // columns.
    let mut names: Vec<&'static str> = problem.nonlinear.clone();
    let mut jac: Vec<Vec<f64>> =
        problem.nonlinear_columns(&proj).into_iter().map(|(d, _)| d).collect();
    for (j, (name, fixed)) in problem.linear.iter().enumerate() {
        if fixed.is_none() {
            names.push(name);
            jac.push(proj.pieces.columns[j].clone());
        }
    }
    let cov = covariance(&jac, rss);

    let mut all: Vec<(&'static str, f64, bool)> = Vec::new(); // name, value, nonlinear
    let nl_count = if problem.asymmetric { 6 } else { 4 };
    for (k, name) in NONLINEAR_ALL.iter().enumerate().take(nl_count) {
        all.push((name, v[k], true));
    }
    for (j, (name, _)) in problem.linear.iter().enumerate() {
        all.push((name, proj.beta[j], false));
    }
    let mut params = Parameters::default();
    for &(name, value, nonlinear) in &all {
        let unit = unit_of(name);
        let Some(k) = names.iter().position(|n| *n == name) else {
            let estimate = if problem.on_bound.contains(&name) {
                Estimate::on_bound(name, value, unit)
            } else {
                Estimate::held(value, unit, "fixed")
            };
            params.0.push((name.to_string(), estimate));
            continue;
        };
        let col_rms = (jac[k].iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
        let contribution =
            if nonlinear { 0.01 * value.abs() * col_rms } else { value.abs() * col_rms };
        let strongest = (0..names.len())
            .filter(|&o| o != k)
            .filter_map(|o| cov.correlation[k][o].map(|r| (names[o], r)))
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
        let at_bound = if nonlinear {
            None
        } else {
            let j = problem.linear.iter().position(|(n, _)| *n == name).unwrap();
            proj.at_bound[j].then_some(value)
        };
        let at_edge = match (&search, name) {
            (Some(s), "sigma0") if value <= s.range[0] * 1.0001 || value >= s.range[1] * 0.9999 => {
                Some((s.range[0], s.range[1]))
            }
            _ => None,
        };
        let explanation = problem.explain(name, v);
        let judgement = Judgement {
            name,
            unit,
            value,
            std_error: cov.std_error[k],
            singular: cov.singular[k],
            at_bound,
            at_edge,
            contribution,
            nonlinear,
            noise: cov.sigma,
            output_unit: "N·m",
            strongest,
            explanation: &explanation,
        };
        params.0.push((name.to_string(), free_estimate(&judgement, unit, cov.t95)));
    }
    let mean = y.iter().sum::<f64>() / n as f64;
    let sst: f64 = y.iter().map(|x| (x - mean).powi(2)).sum();
    let values: Vec<(&'static str, f64)> = all.iter().map(|&(n, v, _)| (n, v)).collect();
    let mut remarks = remarks;
    remarks.push(format!(
        "joint refinement: Levenberg–Marquardt over ln of {} from {} starts; {} by bounded linear least squares at every trial",
        problem.nonlinear.join(", "),
        starts.len(),
        problem.linear.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
    ));
    let report = FitReport {
        fit: "friction".into(),
        law: None,
        data: Vec::new(),
        parameters: params,
        rms: (rss / n as f64).sqrt(),
        r2: if sst > 0.0 { 1.0 - rss / sst } else { f64::NAN },
        iterations: iterations as u64,
        termination: termination.to_string(),
        correlation: Correlation {
            names: names.iter().map(|s| s.to_string()).collect(),
            matrix: cov.correlation.clone(),
        },
        samples: n,
        dof: cov.dof,
        noise_std: cov.sigma,
        evaluations: evaluations as u64,
        search,
        stages: Vec::new(),
        remarks,
        wall_time_s: started.elapsed().as_secs_f64(),
        loop_energy: Vec::new(),
        refinement_starts: starts
            .iter()
            .map(|s| {
                problem
                    .nonlinear
                    .iter()
                    .map(|name| {
                        let k = NONLINEAR_ALL.iter().position(|n| n == name).expect("a name");
                        (name.to_string(), s[k])
                    })
                    .collect()
            })
            .collect(),
        refinement_ends: ends,
        nested: None,
    };
    Ok(SeparableFit {
        report,
        values,
        fitted,
        residuals: proj.residuals,
        free: names,
        jacobian: jac,
        covariance: cov,
    })
}
