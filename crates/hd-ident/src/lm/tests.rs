//! Tests of [`super`]: closed-form optima, failing trials, bounds held and reached
//! exactly, a paused run resumed bit for bit, and the streamed normal equations.

use super::*;
use crate::error::FitError;
use nalgebra::{DMatrix, DVector};

/// y − a·e^{−k·t} and its model columns, over logarithms (ln a, ln k).
fn decay(t: &[f64], y: &[f64], x: &[f64]) -> Normal {
    let (a, k) = (x[0].exp(), x[1].exp());
    let r: Vec<f64> = t.iter().zip(y).map(|(&t, &y)| y - a * (-k * t).exp()).collect();
    let j0: Vec<f64> = t.iter().map(|&t| a * (-k * t).exp()).collect();
    let j1: Vec<f64> = t.iter().map(|&t| -a * k * t * (-k * t).exp()).collect();
    Normal::from_model_columns(&[j0, j1], &r)
}

#[test]
fn fits_an_exponential_decay() {
    // y = 3·e^{−0.7 t}: parameters (ln 3, ln 0.7) from a poor start.
    let t: Vec<f64> = (0..50).map(|k| 0.1 * k as f64).collect();
    let y: Vec<f64> = t.iter().map(|&t| 3.0 * (-0.7 * t).exp()).collect();
    let problem = Formed(|x: &[f64]| Ok(decay(&t, &y, x)));
    let out = minimise(&problem, &[0.0, 1.0], &[], &LmOptions::default(), &silent).unwrap();
    let (a, k) = (out.x[0].exp(), out.x[1].exp());
    assert!((a - 3.0).abs() < 1e-6 && (k - 0.7).abs() < 1e-6, "{out:?}");
}

#[test]
fn failing_trials_are_rejected_steps() {
    // The model fails for x > 2.5; the optimum is at x = 2, and the saturating residual
    // makes the first Gauss–Newton step overshoot into the failing region.
    let problem = Formed(|x: &[f64]| {
        if x[0] > 2.5 {
            return Err(FitError::Optimiser("diverged".into()));
        }
        let c = (x[0] - 2.0).tanh();
        Ok(Normal::from_model_columns(&[vec![-(1.0 - c * c)]], &[c]))
    });
    let opts = LmOptions { max_step: 10.0, ..Default::default() };
    let out = minimise(&problem, &[-6.0], &[], &opts, &silent).unwrap();
    assert!((out.x[0] - 2.0).abs() < 1e-6, "{out:?}");
    assert!(out.failed_trials > 0, "{out:?}");
}

#[test]
fn a_failing_start_is_an_error_naming_the_cause() {
    let problem = Formed(|_: &[f64]| Err(FitError::Optimiser("no such drive".into())));
    let err = minimise(&problem, &[1.0], &[], &LmOptions::drive(), &silent).unwrap_err();
    assert!(err.to_string().contains("no such drive"), "{err}");
}

#[test]
fn an_optimum_on_a_bound_is_reached_exactly() {
    // y = −0.5 + 2 t with the intercept bounded below by 0: the constrained optimum is
    // the intercept at exactly 0 and the slope Σty/Σt² (least squares through the
    // origin), where the gradient pushes the intercept below its bound (KKT).
    let t: Vec<f64> = (0..40).map(|k| 0.05 * k as f64).collect();
    let y: Vec<f64> = t.iter().map(|&t| -0.5 + 2.0 * t).collect();
    let model = |x: &[f64]| {
        let r: Vec<f64> = t.iter().zip(&y).map(|(&t, &y)| y - x[0] - x[1] * t).collect();
        Normal::from_model_columns(&[vec![1.0; t.len()], t.clone()], &r)
    };
    let problem = Formed(|x: &[f64]| Ok(model(x)));
    let opts = LmOptions::default();
    let out = minimise(&problem, &[1.0, 0.5], &[(0.0, 10.0)], &opts, &silent).unwrap();
    let slope =
        t.iter().zip(&y).map(|(t, y)| t * y).sum::<f64>() / t.iter().map(|t| t * t).sum::<f64>();
    assert_eq!(out.x[0], 0.0, "{out:?}");
    assert!((out.x[1] - slope).abs() <= 1e-9 * slope, "{out:?}");
    assert!(model(&out.x).jtr[0] >= 0.0, "the bound is binding");
    assert!(out.iterations <= 10, "{out:?}");
    // The slope bounded above by 1: it ends on 1 and the intercept at the mean of y − t,
    // where the gradient pushes the slope above its bound.
    let b = [(f64::NEG_INFINITY, f64::INFINITY), (f64::NEG_INFINITY, 1.0)];
    let out = minimise(&problem, &[1.0, 0.5], &b, &opts, &silent).unwrap();
    let intercept = t.iter().zip(&y).map(|(t, y)| y - t).sum::<f64>() / t.len() as f64;
    assert_eq!(out.x[1], 1.0, "{out:?}");
    assert!((out.x[0] - intercept).abs() <= 1e-9 * intercept.abs(), "{out:?} vs {intercept}");
    assert!(model(&out.x).jtr[1] <= 0.0, "the upper bound is binding");
}

#[test]
fn a_paused_run_resumes_exactly() {
    // y = 3·e^{−0.7 t} + 0.5·e^{−4 t} with the secant model on: paused after 3
    // iterations and resumed, the run ends bit for bit where the uninterrupted one does.
    let t: Vec<f64> = (0..80).map(|k| 0.05 * k as f64).collect();
    let y: Vec<f64> = t.iter().map(|&t| 3.0 * (-0.7 * t).exp() + 0.5 * (-4.0 * t).exp()).collect();
    let problem = Formed(|x: &[f64]| Ok(decay(&t, &y, x)));
    let opts = LmOptions { secant: true, ..Default::default() };
    let whole = minimise(&problem, &[0.0, 1.0], &[], &opts, &silent).unwrap();
    let LmStep::Paused(paused) = minimise_paused(&problem, &[0.0, 1.0], &[], &opts, 3).unwrap()
    else {
        panic!("ended before 3 iterations");
    };
    assert_eq!(paused.iterations(), 3);
    assert!(paused.cost() > whole.cost);
    let resumed = resume(&problem, paused, &[], &opts).unwrap();
    assert_eq!(resumed, whole);
    assert!(whole.iterations > 3, "{whole:?}");
    // One iteration at a time, as a frame such as argmin's would drive it.
    let mut step = minimise_paused(&problem, &[0.0, 1.0], &[], &opts, 0).unwrap();
    let mut pauses = 0;
    while let LmStep::Paused(p) = step {
        pauses += 1;
        let next = p.iterations() + 1;
        step = resume_until(&problem, p, &[], &opts, Some(next)).unwrap();
    }
    let LmStep::Done(stepped) = step else { unreachable!() };
    assert_eq!(stepped, whole);
    assert_eq!(pauses, whole.iterations);
}

/// y = a·e^{−k·t} in whole columns from a poor start, with k bounded above the
/// optimum's side: the unbounded fit recovers (3, 0.7); bounded to k ≤ 0.5 it stops on
/// the bound. With the geodesic acceleration it reaches the same optimum.
#[test]
fn columns_with_and_without_a_bound() {
    let t: Vec<f64> = (0..60).map(|k| 0.1 * k as f64).collect();
    let y: Vec<f64> = t.iter().map(|&t| 3.0 * (-0.7 * t).exp()).collect();
    let res = |x: &[f64]| -> Option<Vec<f64>> {
        Some(t.iter().zip(&y).map(|(&t, &y)| x[0] * (-x[1] * t).exp() - y).collect())
    };
    let jac = |x: &[f64]| {
        let r = res(x)?;
        let j = DMatrix::from_fn(t.len(), 2, |i, c| {
            let e = (-x[1] * t[i]).exp();
            if c == 0 { e } else { -x[0] * t[i] * e }
        });
        Some((r, j))
    };
    let problem = Columns::new(&jac, &res);
    for geodesic in [false, true] {
        let s = LmOptions { geodesic, ..LmOptions::drive() };
        let b = pairs(&[0.0, 0.0], &[10.0, 10.0]);
        let out = minimise(&problem, &[1.0, 0.1], &b, &s, &silent).unwrap();
        assert!((out.x[0] - 3.0).abs() < 1e-7 && (out.x[1] - 0.7).abs() < 1e-7, "{out:?}");
        let b = pairs(&[0.0, 0.0], &[10.0, 0.5]);
        let out = minimise(&problem, &[1.0, 0.1], &b, &s, &silent).unwrap();
        assert_eq!(out.x[1], 0.5, "{out:?}");
    }
}

/// r = (x0 − 2, x1 + 1, x0 + x1 − 0.5) with x1 ≥ 0: the optimum puts x1 on its bound and
/// x0 = 1.25 (the mean of 2 and 0.5). With the bound held out of the step, the other
/// parameter reaches it in a few iterations, not by ever smaller projected steps.
#[test]
fn an_active_bound_is_held_and_the_rest_converges() {
    let res = |x: &[f64]| Some(vec![x[0] - 2.0, x[1] + 1.0, x[0] + x[1] - 0.5]);
    let jac = |x: &[f64]| {
        let j = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
        Some((res(x)?, j))
    };
    let problem = Columns::new(&jac, &res);
    let b = [(f64::NEG_INFINITY, f64::INFINITY), (0.0, f64::INFINITY)];
    let out = minimise(&problem, &[5.0, 3.0], &b, &LmOptions::drive(), &silent).unwrap();
    assert!((out.x[0] - 1.25).abs() < 5e-8 && out.x[1] == 0.0, "{out:?}");
    assert!(out.iterations <= 10, "{out:?}");
}

/// The accumulated normal equations equal JᵀJ and Jᵀr of the whole matrix (rows over
/// several blocks), and the accumulator holds the same numbers for 10 rows as for 5000.
#[test]
fn accumulated_normal_equations_match_and_do_not_grow() {
    let row = |i: usize| [1.0, (i as f64 * 0.01).sin(), 1e-3 * (i as f64).sqrt()];
    let res = |i: usize| (i as f64 * 0.7).cos();
    let n = 5000;
    let mut acc = Accumulator::new(3);
    let small = {
        let mut a = Accumulator::new(3);
        (0..10).for_each(|i| a.push(res(i), &row(i)));
        a.storage()
    };
    (0..n).for_each(|i| acc.push(res(i), &row(i)));
    assert_eq!(acc.storage(), small);
    assert_eq!(acc.rows(), n);
    let j = DMatrix::from_fn(n, 3, |i, c| row(i)[c]);
    let r = DVector::from_fn(n, |i, _| res(i));
    let got = acc.finish().unwrap();
    let (jtj, jtr) = (j.transpose() * &j, j.transpose() * &r);
    assert!((&got.jtj - &jtj).norm() <= 1e-12 * jtj.norm(), "{}", got.jtj);
    assert!((&got.jtr - &jtr).norm() <= 1e-12 * jtr.norm(), "{}", got.jtr);
    assert!((got.cost - r.norm_squared()).abs() <= 1e-12 * got.cost);
    let mut bad = Accumulator::new(1);
    bad.push(f64::NAN, &[1.0]);
    assert!(bad.finish().is_err());
}
