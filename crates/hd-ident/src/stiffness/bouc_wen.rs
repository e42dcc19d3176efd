//! The Bouc–Wen fit. With A held at 1 (the law's scale redundancy), the torque
//! `a·θ³ + b·θ² + c·θ (+ offset) + α·w(θ; β, γ, n)` is linear in a, b, c, α for given
//! (β, γ, n); w runs along the measured θ with hd-model's [`BoucWen::step`]. The three
//! shape constants are searched as (ln w_u, atanh(γ/β), ln n), with w_u = (β + γ)^(−1/n) the
//! saturation deflection: a grid over w_u (from the record's excursions) and n, then
//! Levenberg–Marquardt from the best grid points, the linear part solved at every trial.
//! The Jacobian is exact: w's derivatives in (β, γ, n) come with w from hd-model's
//! [`BoucWen::step_sensitive`] (the RK4 map differentiated), the chain rule takes them to the
//! search coordinates, and [`projected_jacobian`] adds the linear part's response.

use super::report::{Entry, OFFSET_REMARK, Work, build, spring_entries};
use super::{LawFit, LawOptions};
use crate::data::HysteresisData;
use crate::error::FitError;
use crate::linear::least_squares;
use crate::lm::{Formed, LmOptions, Normal, minimise, silent};
use crate::report::{Estimate, Explanation};
use crate::varpro::{Moving, projected_jacobian};
use hd_model::laws::bouc_wen::{BoucWen, BoucWenStiffness};
use hd_model::laws::stiffness::CubicSpring;
use rayon::prelude::*;
use std::time::Instant;

/// A shape constant in the report: name, unit, value, what it does.
type ShapeParam<'a> = (&'a str, &'static str, f64, &'a str);

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

/// ∂(β, γ, n)/∂(ln w_u, s, ln n) at the search point `x` (rows: β, γ, n).
fn shape_chain(x: &[f64], el: &BoucWen) -> [[f64; 3]; 3] {
    let r = x[1].tanh();
    let sum = el.beta + el.gamma;
    let (n, ln_wu) = (el.n, x[0]);
    // β + γ = w_u^(−n) = e^(−n·ln w_u); β = (β + γ)/(1 + r), γ = r·β.
    let d_beta_dr = -sum / ((1.0 + r) * (1.0 + r));
    let dr_ds = 1.0 - r * r;
    [
        [-n * el.beta, d_beta_dr * dr_ds, -ln_wu * n * el.beta],
        [-n * el.gamma, -d_beta_dr * dr_ds, -ln_wu * n * el.gamma],
        [0.0, 0.0, n],
    ]
}

fn element_law(el: BoucWen) -> BoucWenStiffness {
    BoucWenStiffness { spring: CubicSpring { a: 0.0, b: 0.0, c: 0.0 }, element: el }
}

fn state(theta: &[f64], el: BoucWen) -> Vec<f64> {
    element_law(el).state_along(theta)
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

    /// Residuals and the exact Jacobian (∂model/∂x, x the search coordinates) at `x`.
    fn residuals_exact(&self, x: &[f64]) -> Result<(Vec<f64>, Vec<Vec<f64>>), FitError> {
        let el = shape(x).ok_or_else(|| FitError::Optimiser("shape outside its range".into()))?;
        let (w, dw) = element_law(el).state_sensitive_along(self.theta);
        let cols: Vec<&[f64]> =
            self.spring.iter().map(Vec::as_slice).chain(std::iter::once(w.as_slice())).collect();
        let beta = least_squares(&cols, self.y);
        let r: Vec<f64> = (0..self.y.len())
            .map(|i| self.y[i] - cols.iter().zip(&beta).map(|(c, b)| c[i] * b).sum::<f64>())
            .collect();
        let alpha = beta[cols.len() - 1];
        let chain = shape_chain(x, &el);
        let dx: Vec<Vec<f64>> = (0..3)
            .map(|k| {
                (0..w.len()).map(|i| (0..3).map(|q| dw[q][i] * chain[q][k]).sum::<f64>()).collect()
            })
            .collect();
        let moving = dx
            .iter()
            .map(|d| Moving {
                d: d.iter().map(|v| alpha * v).collect(),
                column: Some((cols.len() - 1, d.as_slice())),
            })
            .collect();
        let jac = projected_jacobian(&cols, &r, moving);
        Ok((r, jac))
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
    let model =
        |x: &[f64]| problem.residuals_exact(x).map(|(r, j)| Normal::from_model_columns(&j, &r));
    let mut best: Option<crate::lm::LmOutcome> = None;
    let (mut iterations, mut evaluations, mut failed) = (0, starts.len(), 0);
    // The two best grid points refined in parallel.
    let outs: Vec<_> = scored
        .iter()
        .take(2)
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|(_, x0)| minimise(&Formed(model), x0, &[], &lm_opts, &silent))
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
    // ∂model/∂(β, γ, n) at fixed linear coefficients: α·∂w/∂(β, γ, n), exact.
    let (_, dw) = element_law(el).state_sensitive_along(theta);
    let params: [ShapeParam; 3] = [
        ("bw_beta", "rad^-n", el.beta, "the shape constant β"),
        ("bw_gamma", "rad^-n", el.gamma, "the shape constant γ"),
        ("bw_n", "-", el.n, "the smoothness exponent n"),
    ];
    for ((name, unit, value, effect), d) in params.into_iter().zip(dw) {
        entries.push(Entry::Free {
            name: name.into(),
            unit,
            value,
            column: d.into_iter().map(|v| alpha * v).collect(),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_projected_jacobian_matches_central_differences() {
        // A spring with a Bouc–Wen loop along two decaying cycles, fitted from a shape
        // away from the truth (so the residual is not small).
        let truth = BoucWen { alpha: 3e4, a: 1.0, beta: 4e5, gamma: 1.5e5, n: 1.4 };
        let theta: Vec<f64> = (0..800)
            .map(|k| {
                let t = k as f64 / 800.0;
                1e-3 * (std::f64::consts::TAU * 2.0 * t).sin() * (1.0 - 0.3 * t)
            })
            .collect();
        let spring = CubicSpring { a: 1e9, b: 0.0, c: 6e4 };
        let law = BoucWenStiffness { spring, element: truth };
        let y = law.torque_along(&theta);
        let problem =
            Problem { theta: &theta, y: &y, spring: super::super::spring_columns(&theta, true) };
        let x = [(-2.0e3f64).abs().ln() - 10.0, 0.3, 0.9f64.ln()];
        let (r, jac) = problem.residuals_exact(&x).unwrap();
        assert!(r.iter().map(|v| v * v).sum::<f64>() > 1e-6, "the point is not off the optimum");
        let mut worst: f64 = 0.0;
        for k in 0..3 {
            // Central differences' own error here: 1.4e-8 at h = 1e-4 (rounding grows as
            // 1/h: 1.3e-7 at 1e-5, 2.7e-6 at 1e-6), so the Jacobian is exact to that.
            let h = 1e-4;
            let (mut up, mut down) = (x, x);
            up[k] += h;
            down[k] -= h;
            let (ru, rd) = (problem.residuals(&up).unwrap(), problem.residuals(&down).unwrap());
            let scale = jac[k].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..r.len() {
                // model = y − r.
                let fd = -(ru[i] - rd[i]) / (2.0 * h);
                worst = worst.max((fd - jac[k][i]).abs() / scale);
            }
        }
        assert!(worst < 1.5e-7, "worst relative deviation {worst:e}");
    }
}
