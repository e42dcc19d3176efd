//! The Bouc–Wen fit. With A held at 1 (the law's scale redundancy), the torque
//! `a·θ³ + b·θ² + c·θ (+ offset) + α·w(θ; β, γ, n)` is linear in a, b, c, α for given
//! (β, γ, n); w runs along the measured θ with hd-model's [`BoucWen::step`]. The three
//! shape constants are searched as (ln w_u, atanh(γ/β), ln n), with w_u = (β + γ)^(−1/n) the
//! saturation deflection: a grid over w_u (from the record's excursions) and n, then
//! Levenberg–Marquardt from the best grid points, the linear part solved at every trial.

use super::report::{Entry, OFFSET_REMARK, Work, build, spring_entries};
use super::{LawFit, LawOptions};
use crate::data::HysteresisData;
use crate::error::FitError;
use crate::linear::least_squares;
use crate::lm::{LmOptions, levenberg_marquardt};
use crate::report::{Estimate, Explanation};
use hd_model::laws::bouc_wen::{BoucWen, BoucWenStiffness};
use hd_model::laws::stiffness::CubicSpring;
use rayon::prelude::*;
use std::time::Instant;

/// A shape constant in the report: name, unit, value, how to set it, what it does.
type ShapeParam<'a> = (&'a str, &'static str, f64, &'a dyn Fn(BoucWen, f64) -> BoucWen, &'a str);

/// Smallest and largest exponent n tried.
pub const N_RANGE: (f64, f64) = (0.3, 8.0);

/// The shape constants from the search coordinates (ln w_u, s, ln n), with A = 1.
fn shape(x: &[f64]) -> Option<BoucWen> {
    let (wu, r, n) = (x[0].exp(), x[1].tanh(), x[2].exp());
    if !(N_RANGE.0..=N_RANGE.1).contains(&n) || x[1].abs() > 6.0 {
        return None;
    }
    let sum = wu.powf(-n); // β + γ
    let beta = sum / (1.0 + r);
    Some(BoucWen { alpha: 1.0, a: 1.0, beta, gamma: beta * r, n })
}

fn state(theta: &[f64], el: BoucWen) -> Vec<f64> {
    let law = BoucWenStiffness { spring: CubicSpring { a: 0.0, b: 0.0, c: 0.0 }, element: el };
    law.state_along(theta)
}

struct Problem<'a> {
    theta: &'a [f64],
    y: &'a [f64],
    spring: Vec<Vec<f64>>,
}

impl Problem<'_> {
    /// Linear coefficients (spring, offset, α) and the prediction at shape `el`.
    fn solve(&self, el: BoucWen) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let w = state(self.theta, el);
        let cols: Vec<&[f64]> =
            self.spring.iter().map(Vec::as_slice).chain(std::iter::once(w.as_slice())).collect();
        let beta = least_squares(&cols, self.y);
        let pred = (0..self.y.len())
            .map(|i| cols.iter().zip(&beta).map(|(c, b)| c[i] * b).sum())
            .collect();
        (beta, pred, w)
    }

    fn residuals(&self, x: &[f64]) -> Result<Vec<f64>, FitError> {
        let el = shape(x).ok_or_else(|| FitError::Optimiser("shape outside its range".into()))?;
        let (_, pred, _) = self.solve(el);
        Ok(self.y.iter().zip(pred).map(|(a, b)| a - b).collect())
    }
}

/// Fit the Bouc–Wen law.
pub fn fit(data: &HysteresisData, opts: &LawOptions) -> Result<LawFit, FitError> {
    let started = Instant::now();
    let (theta, y) = (data.theta(), data.torque());
    let spring = super::spring_columns(theta, opts.offset);
    let problem = Problem { theta, y, spring };
    // Grid: saturation deflections over the record's excursions, n = 1 and 2, γ/β = 0, 0.5.
    let grid_wu = super::maxwell_slip::yield_grid(theta, 8);
    let starts: Vec<[f64; 3]> = grid_wu
        .iter()
        .flat_map(|wu| {
            [1.0f64, 2.0]
                .into_iter()
                .flat_map(move |n| [0.0f64, 0.55].into_iter().map(move |s| [wu.ln(), s, n.ln()]))
        })
        .collect();
    let cost = |x: &[f64]| problem.residuals(x).map(|r| r.iter().map(|v| v * v).sum::<f64>());
    let mut scored: Vec<(f64, [f64; 3])> =
        starts.par_iter().map(|x| (cost(x).unwrap_or(f64::INFINITY), *x)).collect();
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    let lm_opts = LmOptions { max_iterations: 40, max_step: 1.0, ..Default::default() };
    let res = |x: &[f64]| problem.residuals(x);
    let mut best: Option<crate::lm::LmOutcome> = None;
    let (mut iterations, mut evaluations, mut failed) = (0, starts.len(), 0);
    // The two best grid points refined in parallel.
    let outs: Vec<_> = scored
        .iter()
        .take(2)
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|(_, x0)| levenberg_marquardt(&res, x0, &lm_opts))
        .collect();
    for out in outs {
        let Ok(out) = out else { continue };
        iterations += out.iterations;
        evaluations += out.evaluations;
        failed += out.failed_trials;
        if best.as_ref().is_none_or(|b| out.cost < b.cost) {
            best = Some(out);
        }
    }
    let out =
        best.ok_or_else(|| FitError::Optimiser("no Bouc–Wen start could be evaluated".into()))?;
    let el = shape(&out.x).expect("the optimum lies inside the shape range");
    let (beta, _, w) = problem.solve(el);
    let ns = problem.spring.len();
    let alpha = beta[ns];
    let element = BoucWen { alpha, ..el };
    let law =
        BoucWenStiffness { spring: CubicSpring { a: beta[0], b: beta[1], c: beta[2] }, element };
    let offset = if opts.offset { beta[3] } else { 0.0 };
    let fitted: Vec<f64> = law.torque_along(theta).iter().map(|t| t + offset).collect();
    let residuals: Vec<f64> = y.iter().zip(&fitted).map(|(a, b)| a - b).collect();

    let mut entries = spring_entries(theta, &beta, opts.offset);
    let wu = el.saturation();
    let remedy = format!(
        "cycles with excursions from well below to well above the saturation deflection {wu:.3e} rad would reveal it"
    );
    entries.push(Entry::Free {
        name: "bw_alpha".into(),
        unit: "N·m/rad",
        value: alpha,
        column: w,
        nonlinear: false,
        explanation: Explanation {
            effect: "the hysteretic torque α·w".into(),
            remedy: remedy.clone(),
        },
    });
    entries.push(Entry::Held(
        "bw_A".into(),
        Estimate::held(1.0, "-", "the law's scale redundancy: w → s·w changes α, A, β, γ together"),
    ));
    let h = 1e-4;
    let shaped = |f: &dyn Fn(BoucWen, f64) -> BoucWen, v: f64| -> Vec<f64> {
        let dv = h * v.abs().max(1e-12);
        let up = state(theta, f(el, v + dv));
        let down = state(theta, f(el, v - dv));
        up.iter().zip(&down).map(|(u, d)| alpha * (u - d) / (2.0 * dv)).collect()
    };
    let params: [ShapeParam; 3] = [
        ("bw_beta", "rad^-n", el.beta, &|e, v| BoucWen { beta: v, ..e }, "the shape constant β"),
        ("bw_gamma", "rad^-n", el.gamma, &|e, v| BoucWen { gamma: v, ..e }, "the shape constant γ"),
        ("bw_n", "-", el.n, &|e, v| BoucWen { n: v, ..e }, "the smoothness exponent n"),
    ];
    for (name, unit, value, f, effect) in params {
        entries.push(Entry::Free {
            name: name.into(),
            unit,
            value,
            column: shaped(f, value),
            nonlinear: true,
            explanation: Explanation { effect: effect.into(), remedy: remedy.clone() },
        });
    }
    let mut remarks = vec![format!(
        "A held at 1; β, γ, n from a grid of {} starts (saturation deflection, n = 1 and 2, γ/β = 0 and 0.5) refined by Levenberg–Marquardt from the best two, a, b, c, α solved by linear least squares at every trial; saturation deflection {wu:.3e} rad, largest hysteretic torque α·w_u = {:.3e} N·m",
        starts.len(),
        alpha * wu
    )];
    if el.beta < el.gamma.abs() {
        remarks.push("warning: β < |γ|: the fitted loop dissipates negative power on part of its branches (not thermodynamically admissible)".into());
    }
    if failed > 0 {
        remarks.push(format!("{failed} trial(s) failed and were rejected"));
    }
    if crate::lm::hit_budget(&out.termination) {
        remarks.push(format!(
            "warning: the shape's refinement stopped on its iteration budget ({}) before converging; the fit may improve further",
            lm_opts.max_iterations
        ));
    }
    if opts.offset {
        remarks.push(OFFSET_REMARK.into());
    }
    let report = build(
        entries,
        y,
        &fitted,
        Work {
            iterations: iterations as u64,
            evaluations: evaluations as u64,
            termination: out.termination.clone(),
            remarks,
            started,
        },
    );
    Ok(LawFit {
        law: super::Law::BoucWen,
        report,
        fitted,
        residuals,
        charged: 3 + opts.offset as usize + 4,
        c: beta[2],
    })
}
