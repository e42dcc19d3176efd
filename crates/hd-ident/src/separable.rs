//! The fit driver shared by every identification problem. Each problem's model is linear
//! in all its parameters but one (variable projection): for a trial value q of the
//! nonlinear parameter, the best linear parameters come from a bounded linear least-squares
//! solve, which leaves a one-dimensional profile cost RSS(q). [`crate::search`] minimises
//! it globally over ln q; the Jacobian at the optimum then gives the uncertainty.

use crate::data::require_samples;
use crate::error::FitError;
use crate::fix::{Fixed, fitted_info};
use crate::linear::bounded_least_squares;
use crate::report::free_estimate;
use crate::report::{
    Correlation, Estimate, Explanation, FitReport, Judgement, Parameters, SearchSummary,
};
use crate::search::{GRID_POINTS, search_log};
use crate::uncertainty::{Covariance, covariance, covariance_rows};
use hd_model::registry::lookup;
use std::time::Instant;

/// The model's pieces at one value of the nonlinear parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Basis {
    /// One column per linear parameter: the model output for a unit value of that
    /// parameter (and zero for the others).
    pub columns: Vec<Vec<f64>>,
    /// The part of the output that scales with no linear parameter, if any.
    pub offset: Option<Vec<f64>>,
}

/// An identification problem whose output is `offset(q) + Σ β_j·column_j(q)`.
pub trait Separable: Sync {
    /// The fit's name, e.g. `hysteresis`.
    fn fit_name(&self) -> &'static str;
    /// Registry names of the linear parameters, in column order.
    fn linear_names(&self) -> &'static [&'static str];
    /// Registry name of the nonlinear parameter.
    fn nonlinear_name(&self) -> &'static str;
    /// Practical search range of the nonlinear parameter, from the data [registry unit].
    fn search_range(&self) -> (f64, f64);
    /// The measured output [N·m].
    fn measured(&self) -> &[f64];
    /// Columns and offset at nonlinear value `q`.
    fn basis(&self, q: f64) -> Result<Basis, FitError>;
    /// The model output for linear parameters `beta` and nonlinear `q`, computed by the
    /// hd-model law itself (the prediction the report and plots show).
    fn predict(&self, beta: &[f64], q: f64) -> Result<Vec<f64>, FitError>;
    /// What parameter `name` does and which data would reveal it, given the fitted
    /// `values` (all parameters, in [`Separable::names`] order).
    fn explain(&self, name: &str, values: &[(&'static str, f64)]) -> Explanation;
    /// RSS(q) [N·m²], the linear parameters at q within `[lo, hi]` and which of them sit
    /// at a bound, by a shortcut that holds no column (one streaming pass), when the
    /// problem has one; `None` (the default, or where the shortcut is unsafe): the full
    /// bounded solve.
    /// Not used when a linear parameter is fixed.
    fn profile(&self, _q: f64, _lo: &[f64], _hi: &[f64]) -> Option<(f64, Vec<f64>, Vec<bool>)> {
        None
    }
    /// The exact derivative of [`Separable::predict`] with respect to q at fixed `beta`
    /// [N·m per unit of q], when the problem carries its state's sensitivity; `None`
    /// (the default) falls back to a central difference in ln q.
    fn predict_dq(&self, _beta: &[f64], _q: f64) -> Option<Result<Vec<f64>, FitError>> {
        None
    }
    /// Whether [`Separable::stream_rows`] gives the Jacobian (default false).
    fn streams_rows(&self) -> bool {
        false
    }
    /// The Jacobian at the optimum row by row, for records too long to hold its columns:
    /// hands `f` each sample's values of the linear columns whose `free` entry is set (in
    /// column order) followed, with `with_q`, by ∂prediction/∂q at `beta` (as
    /// [`Separable::predict_dq`]). `None` (the default): the columns are built instead.
    fn stream_rows(
        &self,
        _beta: &[f64],
        _q: f64,
        _free: &[bool],
        _with_q: bool,
        _f: &mut dyn FnMut(&[f64]),
    ) -> Option<Result<(), FitError>> {
        None
    }
    /// Relative step in ln q for the finite-difference sensitivity to q.
    fn fd_step(&self) -> f64 {
        1e-4
    }
    /// All parameter names in report order (linear, then nonlinear).
    fn names(&self) -> Vec<&'static str> {
        let mut v = self.linear_names().to_vec();
        v.push(self.nonlinear_name());
        v
    }
}

/// The result of a separable fit.
#[derive(Clone, Debug, PartialEq)]
pub struct SeparableFit {
    /// The report.
    pub report: FitReport,
    /// Every parameter's value, in [`Separable::names`] order.
    pub values: Vec<(&'static str, f64)>,
    /// Model output at the optimum [N·m].
    pub fitted: Vec<f64>,
    /// Measured minus fitted [N·m].
    pub residuals: Vec<f64>,
    /// Names of the free parameters, in Jacobian column order.
    pub free: Vec<&'static str>,
    /// Sensitivity of the prediction to each free parameter at the optimum, one column
    /// per name in `free` [N·m per registry unit]; empty where the problem streams its
    /// rows instead ([`Separable::stream_rows`]: the hysteresis fit, whose records may
    /// hold millions of samples).
    pub jacobian: Vec<Vec<f64>>,
    /// The covariance summary behind the report's errors.
    pub covariance: Covariance,
}

impl SeparableFit {
    /// The value of `name`.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.values.iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
    }
}

/// The inner solve: best linear parameters at `q`, with fixed ones held.
struct Inner {
    beta: Vec<f64>,
    at_bound: Vec<bool>,
    rss: f64,
    /// The columns at q, when the solve built them.
    basis: Option<Basis>,
}

fn solve_inner<P: Separable>(
    p: &P,
    q: f64,
    fixed: &[Option<f64>],
    lo: &[f64],
    hi: &[f64],
) -> Result<Inner, FitError> {
    let basis = p.basis(q)?;
    let y = p.measured();
    let mut target: Vec<f64> = match &basis.offset {
        Some(off) => y.iter().zip(off).map(|(a, b)| a - b).collect(),
        None => y.to_vec(),
    };
    let mut free = Vec::new();
    for (j, col) in basis.columns.iter().enumerate() {
        match fixed[j] {
            Some(v) => target.iter_mut().zip(col).for_each(|(t, c)| *t -= v * c),
            None => free.push(j),
        }
    }
    let cols: Vec<&[f64]> = free.iter().map(|&j| basis.columns[j].as_slice()).collect();
    let flo: Vec<f64> = free.iter().map(|&j| lo[j]).collect();
    let fhi: Vec<f64> = free.iter().map(|&j| hi[j]).collect();
    let sol = bounded_least_squares(&cols, &target, &flo, &fhi);
    let mut beta: Vec<f64> = fixed.iter().map(|v| v.unwrap_or(0.0)).collect();
    let mut at_bound = vec![false; beta.len()];
    for (f, &j) in free.iter().enumerate() {
        beta[j] = sol.coef[f];
        at_bound[j] = sol.at_bound[f];
    }
    Ok(Inner { beta, at_bound, rss: sol.rss, basis: Some(basis) })
}

/// Fit `problem`, holding the parameters in `fixed` (all of which must belong to it).
pub fn fit_separable<P: Separable>(problem: &P, fixed: &Fixed) -> Result<SeparableFit, FitError> {
    let start = Instant::now();
    let names = problem.names();
    fixed.check_allowed(problem.fit_name(), &names)?;
    let lin = problem.linear_names();
    let qname = problem.nonlinear_name();
    let lin_fixed: Vec<Option<f64>> = lin.iter().map(|n| fixed.get(n)).collect();
    let q_fixed = fixed.get(qname);
    let free_names: Vec<&str> = names.iter().copied().filter(|n| fixed.get(n).is_none()).collect();
    if free_names.is_empty() {
        return Err(FitError::NothingFree { fit: problem.fit_name() });
    }
    let y = problem.measured();
    let n = y.len();
    let sample_warning = require_samples(n, &free_names)?;
    let infos: Vec<_> = lin.iter().map(|nm| fitted_info(nm)).collect::<Result<_, _>>()?;
    let lo: Vec<f64> = infos.iter().map(|i| i.1).collect();
    let hi: Vec<f64> = infos.iter().map(|i| i.2).collect();
    let qinfo = lookup(qname)?;

    let any_fixed = lin_fixed.iter().any(Option::is_some);
    let quick = |q: f64| if any_fixed { None } else { problem.profile(q, &lo, &hi) };

    // Global stage over ln q, or the closed form when q is fixed.
    let (q, outcome) = match q_fixed {
        Some(q) => (q, None),
        None => {
            let (mut a, mut b) = problem.search_range();
            a = a.max(qinfo.min).max(f64::MIN_POSITIVE);
            b = b.min(qinfo.max);
            let cost = |q: f64| match quick(q) {
                Some((rss, _, _)) => Ok(rss),
                None => solve_inner(problem, q, &lin_fixed, &lo, &hi).map(|s| s.rss),
            };
            let out = search_log(&cost, a, b)?;
            (out.value, Some(out))
        }
    };
    let inner = match quick(q) {
        Some((rss, beta, at_bound)) => Inner { at_bound, beta, rss, basis: None },
        None => solve_inner(problem, q, &lin_fixed, &lo, &hi)?,
    };
    let _ = inner.rss;
    let beta = inner.beta.clone();
    let fitted = problem.predict(&beta, q)?;
    let residuals: Vec<f64> = y.iter().zip(&fitted).map(|(a, b)| a - b).collect();
    let rss: f64 = residuals.iter().map(|r| r * r).sum();
    let mean = y.iter().sum::<f64>() / n as f64;
    let sst: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();

    // Jacobian of the prediction over the free parameters: streamed by row where the
    // problem can, else built as columns.
    let mut jac: Vec<Vec<f64>> = Vec::new();
    let mut jac_names: Vec<&'static str> =
        lin.iter().enumerate().filter(|(j, _)| lin_fixed[*j].is_none()).map(|(_, n)| *n).collect();
    if q_fixed.is_none() {
        jac_names.push(qname);
    }
    let at_bound = inner.at_bound;
    let free_mask: Vec<bool> = lin_fixed.iter().map(Option::is_none).collect();
    let cov = if problem.streams_rows() {
        let mut rows = |f: &mut dyn FnMut(&[f64])| {
            problem.stream_rows(&beta, q, &free_mask, q_fixed.is_none(), f).unwrap_or(Ok(()))
        };
        covariance_rows(jac_names.len(), n, rss, &mut rows)?
    } else {
        let basis = match inner.basis {
            Some(b) => b,
            None => problem.basis(q)?,
        };
        for (j, col) in basis.columns.into_iter().enumerate() {
            if lin_fixed[j].is_none() {
                jac.push(col);
            }
        }
        if q_fixed.is_none() {
            let column = match problem.predict_dq(&beta, q) {
                Some(col) => col?,
                None => {
                    let h = problem.fd_step();
                    let up = problem.predict(&beta, q * h.exp())?;
                    let down = problem.predict(&beta, q * (-h).exp())?;
                    let dq = q * (h.exp() - (-h).exp());
                    up.iter().zip(&down).map(|(u, d)| (u - d) / dq).collect()
                }
            };
            jac.push(column);
        }
        covariance(&jac, rss)
    };

    // Assemble the estimates.
    let mut params = Parameters::default();
    let values: Vec<(&'static str, f64)> = names
        .iter()
        .enumerate()
        .map(|(j, &nm)| (nm, if j < lin.len() { beta[j] } else { q }))
        .collect();
    for (j, &(name, value)) in values.iter().enumerate() {
        let (unit, _, _) = fitted_info(name)?;
        let Some(k) = jac_names.iter().position(|n| *n == name) else {
            params.0.push((name.to_string(), Estimate::held(value, unit, "fixed")));
            continue;
        };
        let col_rms = cov.column_norms[k] / (n as f64).sqrt();
        let nonlinear = j >= lin.len();
        let contribution = if nonlinear { 0.01 * q * col_rms } else { value.abs() * col_rms };
        let strongest = (0..jac_names.len())
            .filter(|&o| o != k)
            .filter_map(|o| cov.correlation[k][o].map(|r| (jac_names[o], r)))
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
        let explanation = problem.explain(name, &values);
        let at_edge = match (&outcome, nonlinear) {
            (Some(o), true) if o.at_edge => Some((o.lo, o.hi)),
            _ => None,
        };
        let at_bound = (!nonlinear && at_bound[j]).then_some(value);
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
    let report = FitReport {
        fit: problem.fit_name().to_string(),
        law: None,
        data: Vec::new(),
        parameters: params,
        rms: (rss / n as f64).sqrt(),
        r2: if sst > 0.0 { 1.0 - rss / sst } else { f64::NAN },
        iterations: outcome.as_ref().map_or(0, |o| o.iterations),
        termination: outcome.as_ref().map_or_else(
            || format!("{qname} fixed: the linear parameters follow in closed form (linear least squares)"),
            |o| o.termination.clone(),
        ),
        correlation: Correlation {
            names: jac_names.iter().map(|s| s.to_string()).collect(),
            matrix: cov.correlation.clone(),
        },
        samples: n,
        dof: cov.dof,
        noise_std: cov.sigma,
        evaluations: outcome.as_ref().map_or(1, |o| o.evaluations) + 3,
        search: outcome.as_ref().map(|o| SearchSummary {
            parameter: qname.to_string(),
            range: [o.lo, o.hi],
            grid_points: GRID_POINTS,
            starts: o.starts,
        }),
        stages: Vec::new(),
        remarks: sample_warning.into_iter().collect(),
        wall_time_s: start.elapsed().as_secs_f64(),
        loop_energy: Vec::new(),
        refinement_starts: Vec::new(),
        refinement_ends: Vec::new(),
        nested: None,
    };
    Ok(SeparableFit {
        report,
        values,
        fitted,
        residuals,
        free: jac_names,
        jacobian: jac,
        covariance: cov,
    })
}
