//! Every separable fit whose state runs along the record carries its sensitivity to the
//! nonlinear parameter exactly; these check it against central differences of the
//! prediction (1e-6 of each column's largest entry).

use hd_ident::friction::TransientProblem;
use hd_ident::hysteresis::HysteresisProblem;
use hd_ident::separable::Separable;
use hd_ident::{HysteresisData, TransientData};

fn check<P: Separable>(what: &str, p: &P, beta: &[f64], q: f64) {
    let exact = p.predict_dq(beta, q).expect("an exact derivative").unwrap();
    let h = 1e-6 * q;
    let up = p.predict(beta, q + h).unwrap();
    let down = p.predict(beta, q - h).unwrap();
    let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = (0..exact.len())
        .map(|k| ((up[k] - down[k]) / (2.0 * h) - exact[k]).abs())
        .fold(0.0, f64::max);
    println!("{what}: {worst:.1e} of {scale:.3e}");
    assert!(scale > 0.0 && worst <= 1e-6 * scale, "{what}: {worst:e} of {scale:e}");
}

#[test]
fn memory_law_derivative_in_b() {
    let t: Vec<f64> = (0..4000).map(|k| 25e-6 * k as f64).collect();
    let theta: Vec<f64> = t
        .iter()
        .map(|&t| 4e-4 * ((std::f64::consts::TAU * 15.0 * t).sin() + (400.0 * t).sin()))
        .collect();
    let torque: Vec<f64> = theta.iter().map(|th| 6e4 * th).collect();
    let d = HysteresisData::new(t, theta, torque).unwrap();
    let p = HysteresisProblem::new(&d);
    for b in [30.0, 300.0, 3e4] {
        check(&format!("memory, B = {b}"), &p, &[0.12, 0.56, 5.2e4, 4e4], b);
    }
}

#[test]
fn bristle_derivative_in_sigma0() {
    let t: Vec<f64> = (0..3000).map(|k| 2e-3 * k as f64).collect();
    let omega: Vec<f64> =
        t.iter().map(|&t| 0.02 * (std::f64::consts::TAU * 0.7 * t).sin() + 1e-3).collect();
    let torque: Vec<f64> = omega.iter().map(|w| 0.2 * w.signum()).collect();
    let d = TransientData::new(t, omega, torque).unwrap();
    let p = TransientProblem::new(&d, 0.2, 0.3, 0.01, 0.05);
    for sigma0 in [1e2, 1e4, 1e6] {
        check(&format!("bristle, σ0 = {sigma0:e}"), &p, &[0.7], sigma0);
    }
}
