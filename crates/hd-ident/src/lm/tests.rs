//! Tests of [`super`]: closed-form optima, failing trials, bounds and a paused run.

use super::*;

#[test]
fn fits_an_exponential_decay() {
    // y = 3·e^{−0.7 t}: parameters (ln 3, ln 0.7) from a poor start.
    let t: Vec<f64> = (0..50).map(|k| 0.1 * k as f64).collect();
    let y: Vec<f64> = t.iter().map(|&t| 3.0 * (-0.7 * t).exp()).collect();
    let res = |x: &[f64]| -> Result<Vec<f64>, FitError> {
        Ok(t.iter().zip(&y).map(|(&t, &y)| y - x[0].exp() * (-x[1].exp() * t).exp()).collect())
    };
    let out = levenberg_marquardt(&res, &[0.0, 1.0], &LmOptions::default()).unwrap();
    let (a, k) = (out.x[0].exp(), out.x[1].exp());
    println!("a = {a}, k = {k}, cost {:e}, {} iterations", out.cost, out.iterations);
    assert!((a - 3.0).abs() < 1e-6 && (k - 0.7).abs() < 1e-6, "{out:?}");
}

#[test]
fn failing_trials_are_rejected_steps() {
    // The model fails for x > 2.5; the optimum is at x = 2, and the saturating
    // residual makes the first Gauss–Newton step overshoot into the failing region.
    let res = |x: &[f64]| -> Result<Vec<f64>, FitError> {
        if x[0] > 2.5 {
            return Err(FitError::Optimiser("diverged".into()));
        }
        Ok(vec![(x[0] - 2.0).tanh()])
    };
    let opts = LmOptions { max_step: 10.0, ..Default::default() };
    let out = levenberg_marquardt(&res, &[-6.0], &opts).unwrap();
    assert!((out.x[0] - 2.0).abs() < 1e-6, "{out:?}");
    assert!(out.failed_trials > 0, "{out:?}");
}

#[test]
fn an_optimum_on_a_bound_is_reached_exactly() {
    // y = −0.5 + 2 t with the intercept bounded below by 0: the constrained optimum
    // is the intercept at exactly 0 and the slope Σty/Σt² (least squares through the
    // origin), where the gradient pushes the intercept below its bound (KKT).
    let t: Vec<f64> = (0..40).map(|k| 0.05 * k as f64).collect();
    let y: Vec<f64> = t.iter().map(|&t| -0.5 + 2.0 * t).collect();
    let model = |x: &[f64]| -> Result<(f64, Normal), FitError> {
        let r: Vec<f64> = t.iter().zip(&y).map(|(&t, &y)| y - x[0] - x[1] * t).collect();
        let j0 = vec![1.0; t.len()];
        Ok((cost_of(&r), Normal::from_columns(&[j0, t.clone()], &r)))
    };
    let out =
        levenberg_marquardt_normal(&model, &[1.0, 0.5], &[(0.0, 10.0)], &LmOptions::default())
            .unwrap();
    let slope =
        t.iter().zip(&y).map(|(t, y)| t * y).sum::<f64>() / t.iter().map(|t| t * t).sum::<f64>();
    println!("{out:?}, slope {slope}");
    assert_eq!(out.x[0], 0.0, "{out:?}");
    assert!((out.x[1] - slope).abs() <= 1e-9 * slope, "{out:?}");
    let (_, n) = model(&out.x).unwrap();
    assert!(n.jtr[0] <= 0.0, "the bound is binding: {n:?}");
    assert!(out.iterations <= 10, "{out:?}");
    // The slope bounded above by 1: it ends on 1 and the intercept at the mean of
    // y − t, where the gradient pushes the slope above its bound.
    let out = levenberg_marquardt_normal(
        &model,
        &[1.0, 0.5],
        &[(f64::NEG_INFINITY, f64::INFINITY), (f64::NEG_INFINITY, 1.0)],
        &LmOptions::default(),
    )
    .unwrap();
    let intercept = t.iter().zip(&y).map(|(t, y)| y - t).sum::<f64>() / t.len() as f64;
    assert_eq!(out.x[1], 1.0, "{out:?}");
    assert!((out.x[0] - intercept).abs() <= 1e-9 * intercept.abs(), "{out:?} vs {intercept}");
    let (_, n) = model(&out.x).unwrap();
    assert!(n.jtr[1] >= 0.0, "the upper bound is binding: {n:?}");
}

#[test]
fn a_paused_run_resumes_exactly() {
    // y = 3·e^{−0.7 t} + 0.5·e^{−4 t} with the secant model on: paused after 3
    // iterations and resumed, the run ends bit for bit where the uninterrupted one does.
    let t: Vec<f64> = (0..80).map(|k| 0.05 * k as f64).collect();
    let y: Vec<f64> = t.iter().map(|&t| 3.0 * (-0.7 * t).exp() + 0.5 * (-4.0 * t).exp()).collect();
    let model = |x: &[f64]| -> Result<(f64, Normal), FitError> {
        let (a, k) = (x[0].exp(), x[1].exp());
        let r: Vec<f64> = t.iter().zip(&y).map(|(&t, &y)| y - a * (-k * t).exp()).collect();
        let j0: Vec<f64> = t.iter().map(|&t| a * (-k * t).exp()).collect();
        let j1: Vec<f64> = t.iter().map(|&t| -a * k * t * (-k * t).exp()).collect();
        Ok((cost_of(&r), Normal::from_columns(&[j0, j1], &r)))
    };
    let opts = LmOptions { secant: true, ..Default::default() };
    let whole = levenberg_marquardt_normal(&model, &[0.0, 1.0], &[], &opts).unwrap();
    let LmStep::Paused(paused) = lm_normal_paused(&model, &[0.0, 1.0], &[], &opts, 3).unwrap()
    else {
        panic!("ended before 3 iterations");
    };
    assert_eq!(paused.iterations(), 3);
    assert!(paused.cost() > whole.cost);
    let resumed = lm_normal_resume(&model, paused, &[], &opts).unwrap();
    assert_eq!(resumed, whole);
    assert!(whole.iterations > 3, "{whole:?}");
}
