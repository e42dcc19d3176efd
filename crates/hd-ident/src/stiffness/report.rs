//! The report of a stiffness-law fit whose parameters are not registry parameters: the
//! same covariance, intervals and verdicts as every other fit, from the Jacobian columns
//! the law's fit supplies.

use crate::report::free_estimate;
use crate::report::{Correlation, Estimate, Explanation, FitReport, Judgement, Parameters};
use crate::uncertainty::covariance;
use std::time::Instant;

/// One parameter of the report.
pub(crate) enum Entry {
    /// A fitted parameter with its sensitivity column ∂prediction/∂parameter [N·m per unit].
    Free {
        name: String,
        unit: &'static str,
        value: f64,
        column: Vec<f64>,
        nonlinear: bool,
        explanation: Explanation,
    },
    /// A parameter held (at a bound, or by a redundancy), with its estimate.
    Held(String, Estimate),
}

/// What the optimiser did.
pub(crate) struct Work {
    pub iterations: u64,
    pub evaluations: u64,
    pub termination: String,
    pub remarks: Vec<String>,
    pub started: Instant,
}

/// Assemble the report from the entries, the measured torque and the fitted torque.
pub(crate) fn build(entries: Vec<Entry>, y: &[f64], fitted: &[f64], work: Work) -> FitReport {
    let n = y.len();
    let rss: f64 = y.iter().zip(fitted).map(|(a, b)| (a - b).powi(2)).sum();
    let mean = y.iter().sum::<f64>() / n as f64;
    let sst: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
    let jac: Vec<Vec<f64>> = entries
        .iter()
        .filter_map(|e| match e {
            Entry::Free { column, .. } => Some(column.clone()),
            Entry::Held(..) => None,
        })
        .collect();
    let names: Vec<String> = entries
        .iter()
        .filter_map(|e| match e {
            Entry::Free { name, .. } => Some(name.clone()),
            Entry::Held(..) => None,
        })
        .collect();
    let cov = covariance(&jac, rss);
    let mut params = Parameters::default();
    let mut k = 0;
    for e in entries {
        match e {
            Entry::Held(name, est) => params.0.push((name, est)),
            Entry::Free { name, unit, value, column, nonlinear, explanation } => {
                let col_rms = (column.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
                let contribution =
                    if nonlinear { 0.01 * value.abs() * col_rms } else { value.abs() * col_rms };
                let strongest = (0..names.len())
                    .filter(|&o| o != k)
                    .filter_map(|o| cov.correlation[k][o].map(|r| (names[o].as_str(), r)))
                    .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
                let judgement = Judgement {
                    name: &name,
                    unit,
                    value,
                    std_error: cov.std_error[k],
                    singular: cov.singular[k],
                    at_bound: None,
                    at_edge: None,
                    contribution,
                    nonlinear,
                    noise: cov.sigma,
                    output_unit: "N·m",
                    strongest,
                    explanation: &explanation,
                };
                let estimate = free_estimate(&judgement, unit, cov.t95);
                params.0.push((name, estimate));
                k += 1;
            }
        }
    }
    FitReport {
        fit: "hysteresis".into(),
        law: None,
        data: Vec::new(),
        parameters: params,
        rms: (rss / n as f64).sqrt(),
        r2: if sst > 0.0 { 1.0 - rss / sst } else { f64::NAN },
        iterations: work.iterations,
        termination: work.termination,
        correlation: Correlation { names, matrix: cov.correlation.clone() },
        samples: n,
        dof: cov.dof,
        noise_std: cov.sigma,
        evaluations: work.evaluations,
        search: None,
        stages: Vec::new(),
        remarks: work.remarks,
        wall_time_s: work.started.elapsed().as_secs_f64(),
        loop_energy: Vec::new(),
        refinement_starts: Vec::new(),
        refinement_ends: Vec::new(),
        nested: None,
    }
}

/// The spring's and the offset's entries: columns θ³, θ², θ (and 1).
pub(crate) fn spring_entries(theta: &[f64], beta: &[f64], offset: bool) -> Vec<Entry> {
    let range = theta.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut out = Vec::new();
    for (j, (name, unit, pow)) in
        [("a", "N·m/rad³", 3), ("b", "N·m/rad²", 2), ("c", "N·m/rad", 1)].into_iter().enumerate()
    {
        out.push(Entry::Free {
            name: name.into(),
            unit,
            value: beta[j],
            column: theta.iter().map(|t| t.powi(pow)).collect(),
            nonlinear: false,
            explanation: Explanation {
                effect: format!("{name}·θ^{pow}"),
                remedy: format!(
                    "data over a wider deflection range than max |θ| = {range:.2e} rad would reveal it"
                ),
            },
        });
    }
    if offset {
        out.push(Entry::Free {
            name: crate::fix::OFFSET.into(),
            unit: "N·m",
            value: beta[3],
            column: vec![1.0; theta.len()],
            nonlinear: false,
            explanation: Explanation {
                effect: "the torque offset".into(),
                remedy: "a record whose deflection swings symmetrically about zero would separate it from b·θ²".into(),
            },
        });
    }
    out
}

/// The remark every rate-independent fit with offsets carries.
pub(crate) const OFFSET_REMARK: &str = "offsets: the torque offset is fitted as `offset`; a deflection offset θ0 is absorbed exactly by b, c and the torque offset (f(θ − θ0) is again a cubic in θ, and the hysteretic states see only increments of θ), so b and c describe the spring about the recorded zero of θ";
