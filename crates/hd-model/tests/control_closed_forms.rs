//! Closed-loop control against closed forms (docs/model.md §6.8): with a stiff linear gear
//! and no friction the drive is a rigid body `J·θ̈ + c·θ̇ = b·u − T_L` in load
//! coordinates, with `J = Jj·N² + Jz`, `c = N²·(Km·Ke/R + Cj) + Cz` and `b = N·Km/R`.

use hd_model::control::{Compensation, ControllerConfig, Feedback, Reference};
use hd_model::laws::input::{Input, Profile};
use hd_model::laws::load::LoadTorque;
use hd_model::solver::SolverOptions;
use hd_model::{Params, SimConfig, Variant, simulate};
use nalgebra::{Complex, DMatrix};

/// Seed parameters with a gear so stiff that the rigid-body model holds to ~1e-7.
fn stiff() -> Params {
    Params { kbar: 1e9, ..Params::default() }
}

/// (J, c, b) of the rigid drive in load coordinates.
fn rigid(p: &Params) -> (f64, f64, f64) {
    let n2 = p.n * p.n;
    (p.jj * n2 + p.jz, n2 * (p.km * p.ke / p.r + p.cj) + p.cz, p.n * p.km / p.r)
}

fn controller(kp: f64, ki: f64, kd: f64, reference: Reference) -> ControllerConfig {
    ControllerConfig {
        kp,
        ki,
        kd,
        tau_d: 2e-3,
        u_max: 1e6,
        feedback: Feedback::Load,
        compensation: Compensation::None,
        reference,
        ..Default::default()
    }
}

fn run(p: Params, ctl: ControllerConfig, load: LoadTorque, t_end: f64) -> hd_model::Trace {
    let cfg = SimConfig {
        params: p,
        variant: Variant::Linear,
        t_end,
        dt_out: 1e-3,
        solver: SolverOptions { rtol: 1e-9, atol: 1e-13, ..Default::default() },
        load_torque: load,
        controller: Some(ctl),
        ..SimConfig::default()
    };
    simulate(&cfg).unwrap().trace.unwrap()
}

/// Polynomial with real coefficients, highest power first.
fn eval(c: &[f64], s: Complex<f64>) -> Complex<f64> {
    c.iter().fold(Complex::new(0.0, 0.0), |acc, &a| acc * s + a)
}

fn derivative(c: &[f64]) -> Vec<f64> {
    let n = c.len() - 1;
    c[..n].iter().enumerate().map(|(k, &a)| a * (n - k) as f64).collect()
}

fn mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

fn add(a: &[f64], b: &[f64]) -> Vec<f64> {
    let n = a.len().max(b.len());
    let pad = |c: &[f64]| [vec![0.0; n - c.len()], c.to_vec()].concat();
    pad(a).iter().zip(pad(b)).map(|(x, y)| x + y).collect()
}

/// Roots of a polynomial (companion-matrix eigenvalues).
fn roots(c: &[f64]) -> Vec<Complex<f64>> {
    let n = c.len() - 1;
    let mut m = DMatrix::<f64>::zeros(n, n);
    for k in 0..n {
        m[(0, k)] = -c[k + 1] / c[0];
    }
    for k in 1..n {
        m[(k, k - 1)] = 1.0;
    }
    m.complex_eigenvalues().iter().copied().collect()
}

/// Unit-step response of the loop PID(τd) × rigid drive, from the closed-loop
/// characteristic polynomial by partial fractions: `y(t) = Σ N(p)/(p·D'(p))·e^{pt}` over
/// the roots p of s·D(s), D the characteristic polynomial, N the loop numerator.
fn analytic_step(p: &Params, kp: f64, ki: f64, kd: f64, tau: f64) -> impl Fn(f64) -> f64 {
    let (j, c, b) = rigid(p);
    // C(s) = [(kp·τ + kd)s² + (kp + ki·τ)s + ki] / [s(τs + 1)], P(s) = b/[s(Js + c)].
    let mut num = vec![b * (kp * tau + kd), b * (kp + ki * tau), b * ki];
    let mut den = add(&mul(&mul(&[1.0, 0.0, 0.0], &[j, c]), &[tau, 1.0]), &num);
    if ki == 0.0 {
        // Both carry a factor s: cancel it.
        num.pop();
        den.pop();
    }
    let poles = roots(&den);
    let d_den = derivative(&den);
    let steady = num.last().unwrap() / den.last().unwrap();
    move |t: f64| {
        let sum: Complex<f64> =
            poles.iter().map(|&q| eval(&num, q) / (q * eval(&d_den, q)) * (q * t).exp()).sum();
        steady + sum.re
    }
}

#[test]
fn pd_and_pid_step_responses_match_the_characteristic_polynomial() {
    let p = stiff();
    let step = 1e-3;
    for (kp, ki, kd) in [(2000.0, 0.0, 20.0), (2000.0, 20_000.0, 10.0), (2000.0, 20_000.0, 0.0)] {
        let ctl = controller(kp, ki, kd, Reference::Step { amplitude: step, t0: 0.0 });
        let tr = run(p.clone(), ctl, LoadTorque::default(), 0.4);
        let y = analytic_step(&p, kp, ki, kd, 2e-3);
        let worst =
            tr.t.iter()
                .zip(&tr.theta_z)
                .map(|(&t, &th)| (th - step * y(t)).abs())
                .fold(0.0, f64::max);
        eprintln!(
            "kp {kp} ki {ki} kd {kd}: max |θz − closed form| = {:.2e} of the step",
            worst / step
        );
        assert!(worst < 1e-4 * step, "kp {kp} ki {ki} kd {kd}: {:.3e} of the step", worst / step);
    }
}

#[test]
fn type_one_loop_tracks_a_ramp_with_the_analytic_steady_error() {
    let p = stiff();
    let (_, c, b) = rigid(&p);
    let (kp, v) = (2000.0, 2e-3);
    let ramp = Profile::new(vec![0.0, 10.0], vec![0.0, 10.0 * v], "ramp").unwrap();
    let tr =
        run(p, controller(kp, 0.0, 0.0, Reference::Recorded(ramp)), LoadTorque::default(), 1.0);
    let expected = v * c / (b * kp);
    let measured = *tr.error.last().unwrap();
    eprintln!("ramp error {measured:.6e} rad against c·v/(b·kp) = {expected:.6e}");
    assert!((measured - expected).abs() < 1e-5 * expected, "{measured} vs {expected}");
}

#[test]
fn integral_action_removes_a_constant_load_torques_steady_error() {
    let p = stiff();
    let (_, _, b) = rigid(&p);
    let tl = 5.0;
    // Ramped in over 0.2 s: a sudden torque would ring the stiff, nearly undamped gear
    // mode (≈ 2e5 rad/s) at an amplitude of T_L/K̄ for the rest of the run.
    let ramp = Profile::new(vec![0.0, 0.2], vec![0.0, tl], "load").unwrap();
    let load = LoadTorque::new(Input::Recorded(ramp));
    let hold = Reference::Step { amplitude: 0.0, t0: 0.0 };
    let p_only = run(p.clone(), controller(2000.0, 0.0, 0.0, hold.clone()), load.clone(), 1.0);
    let pi = run(p, controller(2000.0, 20_000.0, 0.0, hold), load, 3.0);
    let expected = tl / (b * 2000.0);
    let e_p = *p_only.error.last().unwrap();
    let e_pi = *pi.error.last().unwrap();
    eprintln!("P: {e_p:.6e} rad (T_L/(b·kp) = {expected:.6e}); PI: {e_pi:.2e} rad");
    assert!((e_p - expected).abs() < 1e-5 * expected, "{e_p} vs {expected}");
    assert!(e_pi.abs() < 1e-6 * expected, "PI leaves {e_pi}");
}
