//! The Maxwell-slip fit. For fixed yield deflections δᵢ the torque
//! `a·θ³ + b·θ² + c·θ (+ offset) + Σ kᵢ·eᵢ(θ; δᵢ)` is linear in the spring coefficients and
//! the stiffnesses kᵢ ≥ 0, where eᵢ is the deflection of a unit-stiffness element run along
//! the measured θ by hd-model's [`SlipElement::step`]: non-negative least squares gives the
//! exact optimum ([`crate::nnls`]). The δᵢ start log-spaced over the record's own
//! reversal excursions and are then refined by Levenberg–Marquardt over ln δᵢ, each trial
//! solved by NNLS again (variable projection).

use super::report::{Entry, OFFSET_REMARK, Work, build, spring_entries};
use super::{LawFit, LawOptions};
use crate::data::HysteresisData;
use crate::error::FitError;
use crate::lm::{Formed, LmOptions, Normal, minimise, silent};
use crate::nnls::nnls;
use crate::report::{Estimate, Explanation};
use crate::varpro::{Moving, projected_jacobian};
use hd_model::laws::maxwell_slip::{MaxwellSlip, SlipElement};
use hd_model::laws::stiffness::CubicSpring;
use std::time::Instant;

/// Elements fitted unless told otherwise.
pub const DEFAULT_ELEMENTS: usize = 8;
/// The largest starting yield deflection, as a share of half the largest excursion
/// between reversals (an element yielding beyond that never slips: it is c·θ again).
pub const TOP_SHARE: f64 = 0.9;
/// Decades the starting yield deflections span below the largest.
pub const DECADES: f64 = 2.0;

/// Starting yield deflections [rad]: `m` values log-spaced over [`DECADES`] up to
/// [`TOP_SHARE`] of half the largest excursion between reversals of θ.
pub fn yield_grid(theta: &[f64], m: usize) -> Vec<f64> {
    let rev = super::cycles::reversals(theta);
    let mut marks: Vec<f64> = rev.iter().map(|&k| theta[k]).collect();
    marks.insert(0, theta[0]);
    marks.push(theta[theta.len() - 1]);
    let excursion = marks.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max);
    let top = TOP_SHARE * 0.5 * excursion;
    let m = m.max(1);
    (0..m)
        .map(|i| {
            let share = if m == 1 { 0.0 } else { 1.0 - i as f64 / (m - 1) as f64 };
            top * 10f64.powf(-DECADES * share)
        })
        .collect()
}

/// Deflection of a unit-stiffness element yielding at `delta` run along θ from rest [rad],
/// and its exact sensitivity to `delta` [–] ([`SlipElement::step_grad`]).
fn element_column(theta: &[f64], delta: f64) -> (Vec<f64>, Vec<f64>) {
    let el = SlipElement::from_yield(1.0, delta);
    let (mut e, mut de) = (0.0, 0.0);
    let mut prev = theta[0];
    theta
        .iter()
        .map(|&th| {
            (e, de) = el.step_grad(e, de, th - prev);
            prev = th;
            (e, de)
        })
        .unzip()
}

struct Problem<'a> {
    theta: &'a [f64],
    y: &'a [f64],
    spring: Vec<Vec<f64>>,
}

/// The exact linear solve at yield deflections `deltas`: spring coefficients (and offset),
/// then the stiffnesses.
struct Solved {
    beta: Vec<f64>,
    k: Vec<f64>,
    elements: Vec<Vec<f64>>,
    /// ∂element/∂δ per element.
    d_elements: Vec<Vec<f64>>,
}

impl Problem<'_> {
    fn solve(&self, deltas: &[f64]) -> Solved {
        let (elements, d_elements): (Vec<Vec<f64>>, Vec<Vec<f64>>) =
            deltas.iter().map(|&d| element_column(self.theta, d)).unzip();
        let cols: Vec<&[f64]> = self.spring.iter().chain(&elements).map(Vec::as_slice).collect();
        let nonneg: Vec<bool> = (0..cols.len()).map(|j| j >= self.spring.len()).collect();
        let sol = nnls(&cols, self.y, &nonneg);
        let ns = self.spring.len();
        Solved { beta: sol.coef[..ns].to_vec(), k: sol.coef[ns..].to_vec(), elements, d_elements }
    }

    /// Residuals at ln δ = `u` and their exact Jacobian (∂model/∂ln δᵢ): an element at
    /// k = 0 moves nothing; one with k > 0 moves its own column ([`crate::varpro`]).
    fn residuals_and_jacobian(&self, u: &[f64]) -> Result<(Vec<f64>, Vec<Vec<f64>>), FitError> {
        let deltas: Vec<f64> = u.iter().map(|v| v.exp()).collect();
        let s = self.solve(&deltas);
        let r: Vec<f64> = self.y.iter().zip(self.predict(&s)).map(|(a, b)| a - b).collect();
        let mut active: Vec<&[f64]> = self.spring.iter().map(Vec::as_slice).collect();
        let mut slot = vec![None; deltas.len()];
        for (i, el) in s.elements.iter().enumerate() {
            if s.k[i] > 0.0 {
                slot[i] = Some(active.len());
                active.push(el);
            }
        }
        let scaled: Vec<Vec<f64>> = s
            .d_elements
            .iter()
            .zip(&deltas)
            .map(|(c, d)| c.iter().map(|x| x * d).collect())
            .collect();
        let params = (0..deltas.len())
            .map(|i| Moving {
                d: scaled[i].iter().map(|x| s.k[i] * x).collect(),
                column: slot[i].map(|k| (k, scaled[i].as_slice())),
            })
            .collect();
        Ok((r.clone(), projected_jacobian(&active, &r, params)))
    }

    fn predict(&self, s: &Solved) -> Vec<f64> {
        (0..self.y.len())
            .map(|i| {
                let spring: f64 = self.spring.iter().zip(&s.beta).map(|(c, b)| c[i] * b).sum();
                spring + s.elements.iter().zip(&s.k).map(|(c, k)| c[i] * k).sum::<f64>()
            })
            .collect()
    }
}

/// Fit the Maxwell-slip law with `opts.elements` elements.
pub fn fit(data: &HysteresisData, opts: &LawOptions) -> Result<LawFit, FitError> {
    let started = Instant::now();
    if opts.elements == 0 || opts.elements > 40 {
        return Err(FitError::Setting {
            field: "elements",
            value: opts.elements.to_string(),
            expected: "between 1 and 40 Maxwell-slip elements".into(),
        });
    }
    let (theta, y) = (data.theta(), data.torque());
    let spring = super::spring_columns(theta, opts.offset);
    let problem = Problem { theta, y, spring };
    let start = yield_grid(theta, opts.elements);
    let model = Formed(|u: &[f64]| {
        problem.residuals_and_jacobian(u).map(|(r, j)| Normal::from_model_columns(&j, &r))
    });
    let u0: Vec<f64> = start.iter().map(|d| d.ln()).collect();
    let lm_opts = LmOptions {
        max_iterations: 100,
        max_step: 0.7,
        cost_tolerance: 1e-10,
        ..Default::default()
    };
    let out = minimise(&model, &u0, &[], &lm_opts, &silent)?;
    let mut deltas: Vec<f64> = out.x.iter().map(|v| v.exp()).collect();
    deltas.sort_by(f64::total_cmp);
    let s = problem.solve(&deltas);
    let active: Vec<usize> = (0..deltas.len()).filter(|&i| s.k[i] > 0.0).collect();
    let law = MaxwellSlip {
        spring: CubicSpring { a: s.beta[0], b: s.beta[1], c: s.beta[2] },
        elements: active.iter().map(|&i| SlipElement::from_yield(s.k[i], deltas[i])).collect(),
    };
    let offset = if opts.offset { s.beta[3] } else { 0.0 };
    // The prediction from the law itself (equal to the basis sum, to rounding).
    let fitted: Vec<f64> = law.torque_along(theta).iter().map(|t| t + offset).collect();
    let residuals: Vec<f64> = y.iter().zip(&fitted).map(|(a, b)| a - b).collect();

    let mut entries = spring_entries(theta, &s.beta, opts.offset);
    for (num, &i) in active.iter().enumerate() {
        let (k, d) = (s.k[i], deltas[i]);
        // ∂prediction/∂δ at fixed k (exact), then the chain rule to (k, F = k·δ).
        let j_delta: Vec<f64> = s.d_elements[i].iter().map(|de| k * de).collect();
        let col_k: Vec<f64> =
            s.elements[i].iter().zip(&j_delta).map(|(e, jd)| e - jd * d / k).collect();
        let col_f: Vec<f64> = j_delta.iter().map(|jd| jd / k).collect();
        let what = format!("element {} (yield deflection {d:.3e} rad)", num + 1);
        let remedy = format!(
            "cycles whose excursions pass 2δ = {:.3e} rad, some above and some below it, would reveal it",
            2.0 * d
        );
        entries.push(Entry::Free {
            name: format!("ms_k{}", num + 1),
            unit: "N·m/rad",
            value: k,
            column: col_k,
            nonlinear: false,
            explanation: Explanation {
                effect: format!("the stiffness of {what}"),
                remedy: remedy.clone(),
            },
        });
        entries.push(Entry::Free {
            name: format!("ms_f{}", num + 1),
            unit: "N·m",
            value: k * d,
            column: col_f,
            nonlinear: true,
            explanation: Explanation { effect: format!("the slip torque of {what}"), remedy },
        });
    }
    let mut remarks = vec![format!(
        "{} elements started from yield deflections log-spaced over {DECADES} decades up to {:.3e} rad ({TOP_SHARE} × half the largest excursion between reversals), refined by Levenberg–Marquardt with the stiffnesses solved exactly by non-negative least squares at every trial; {} kept a positive stiffness and are reported (ms_k1, ms_f1, … by increasing yield deflection), the others are at their bound 0 and left out",
        opts.elements,
        start.last().copied().unwrap_or(0.0),
        active.len()
    )];
    if crate::lm::hit_budget(&out.termination) {
        remarks.push(format!(
            "warning: the yield deflections' refinement stopped on its iteration budget ({}) before converging; the fit may improve further",
            lm_opts.max_iterations
        ));
    }
    if out.failed_trials > 0 {
        remarks.push(format!("{} trial(s) failed and were rejected", out.failed_trials));
    }
    if opts.offset {
        remarks.push(OFFSET_REMARK.into());
    }
    if active.is_empty() {
        entries.push(Entry::Held(
            "ms_k1".into(),
            Estimate::held(
                0.0,
                "N·m/rad",
                "every element's stiffness is at its bound 0: the data show no slip hysteresis",
            ),
        ));
    }
    let report = build(
        entries,
        y,
        &fitted,
        Work {
            iterations: out.iterations as u64,
            evaluations: out.evaluations as u64,
            termination: out.termination,
            remarks,
            started,
        },
    );
    Ok(LawFit {
        law: super::Law::MaxwellSlip,
        report,
        fitted,
        residuals,
        charged: 3 + opts.offset as usize + 2 * active.len(),
        c: s.beta[2],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact Jacobian over ln δ against central differences of the projected
    /// residual, at a point where every element keeps a positive stiffness.
    #[test]
    fn exact_jacobian_matches_central_differences() {
        let theta: Vec<f64> = (0..4000)
            .map(|i| {
                let t = i as f64 * 1e-3;
                1e-3 * (t * (1.0 + 0.3 * t)).sin() * (1.0 + 0.5 * (0.7 * t).cos())
            })
            .collect();
        let truth = [(2e4, 5e-5), (1.5e4, 2e-4), (1e4, 6e-4)];
        let law = MaxwellSlip {
            spring: CubicSpring { a: 0.0, b: 0.0, c: 3e4 },
            elements: truth.iter().map(|&(k, d)| SlipElement::from_yield(k, d)).collect(),
        };
        let y: Vec<f64> = law
            .torque_along(&theta)
            .iter()
            .enumerate()
            .map(|(i, t)| t + 0.01 * (1.7 * i as f64).sin())
            .collect();
        let problem =
            Problem { theta: &theta, y: &y, spring: super::super::spring_columns(&theta, false) };
        let u: Vec<f64> = truth.iter().map(|&(_, d)| (1.2 * d).ln()).collect();
        assert!(problem.solve(&[6e-5, 2.4e-4, 7.2e-4]).k.iter().all(|k| *k > 0.0));
        let (_, jac) = problem.residuals_and_jacobian(&u).unwrap();
        let h = 1e-6;
        for j in 0..u.len() {
            let at = |dx: f64| {
                let mut uj = u.clone();
                uj[j] += dx;
                problem.residuals_and_jacobian(&uj).unwrap().0
            };
            let (up, down) = (at(h), at(-h));
            let scale = jac[j].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = (0..y.len())
                .map(|i| (-(up[i] - down[i]) / (2.0 * h) - jac[j][i]).abs())
                .fold(0.0, f64::max);
            println!("∂/∂ln δ{j}: {worst:.1e} of {scale:.3e}");
            assert!(scale > 0.0 && worst <= 1e-6 * scale, "δ{j}: {worst:e} of {scale:e}");
        }
    }
}
