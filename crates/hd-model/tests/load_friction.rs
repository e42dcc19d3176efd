//! Load-dependent LuGre levels (docs/model.md §2.3): the steady friction at a constant
//! transmitted torque is the raised Stribeck level, and the energy balance still closes.

use hd_model::laws::friction::{FrictionLaw, LoadFactors, LuGre};
use hd_model::laws::input::Input;
use hd_model::laws::load::LoadTorque;
use hd_model::solver::{Method, OdeSystem, SolverOptions, solve};
use hd_model::state::*;
use hd_model::{SimConfig, simulate};
use nalgebra::{SMatrix, SVector};

/// The bristle state at a constant speed v [rad/s] and transmitted torque tb [N·m].
struct Held {
    law: LuGre,
    v: f64,
    tb: f64,
}

impl OdeSystem<1> for Held {
    fn rhs(&self, _t: f64, y: &SVector<f64, 1>) -> SVector<f64, 1> {
        SVector::from([self.law.eval_loaded(self.v, y[0], self.tb).w_rate])
    }
    fn jacobian(&self, _t: f64, y: &SVector<f64, 1>) -> (SMatrix<f64, 1, 1>, SVector<f64, 1>) {
        let e = self.law.eval_loaded(self.v, y[0], self.tb);
        (SMatrix::from([[e.w_rate_d_w]]), SVector::zeros())
    }
}

fn loaded_law() -> LuGre {
    let mut law = LuGre::symmetric(1.2e5, 0.8, 0.01, 0.15, 0.25, 0.01);
    law.mu = LoadFactors { c_fwd: 0.03, s_fwd: 0.05, c_back: 0.06, s_back: 0.09 };
    law
}

#[test]
fn steady_friction_under_a_held_torque_is_the_raised_stribeck_level() {
    let law = loaded_law();
    let opts =
        SolverOptions { method: Method::Rodas4, rtol: 1e-10, atol: 1e-14, ..Default::default() };
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for v in [3e-3f64, -3e-3, 0.02, -0.02, 1.0, -1.0] {
        for tb in [0.0f64, 4.0, -4.0, 25.0, -25.0] {
            // Written out on its own: forward when Tb·v > 0, back-driven when Tb·v < 0.
            let (mc, ms) = if tb * v < 0.0 { (0.06, 0.09) } else { (0.03, 0.05) };
            let (tc, ts) = (0.15 + mc * tb.abs(), 0.25 + ms * tb.abs());
            let expected =
                v.signum() * (tc + (ts - tc) * (-(v / 0.01f64).powi(2)).exp()) + 0.01 * v;
            let t_end = 1000.0 * ts / (1.2e5 * v.abs());
            let sys = Held { law, v, tb };
            let (y, _) =
                solve(&sys, 0.0, SVector::zeros(), t_end, &[], &opts, &mut |_| {}).unwrap();
            let tf = law.eval_loaded(v, y[0], tb).torque;
            let rel = (tf - expected).abs() / expected.abs();
            worst = worst.max(rel);
            // Measured 1.4e-16.
            assert!(rel < 2e-15, "v = {v} rad/s, Tb = {tb} N·m: Tf = {tf}, expected {expected}");
            let st = law.steady_torque_loaded(v, tb);
            assert!((st - expected).abs() < 1e-14 * expected.abs(), "steady_torque_loaded {st}");
            checked += 1;
        }
    }
    eprintln!("raised Stribeck level: {checked} cases, max relative error {worst:.2e}");
    assert_eq!(checked, 30);
}

#[test]
fn zero_factors_leave_the_law_unchanged() {
    let law = LuGre::symmetric(1.2e5, 0.8, 0.01, 0.15, 0.25, 0.01);
    for (v, w, tb) in [(0.01, 0.1, 30.0), (-0.3, -0.12, 5.0), (0.0, 0.05, -2.0)] {
        assert_eq!(law.eval_loaded(v, w, tb), law.eval(v, w), "v = {v}, w = {w}, Tb = {tb}");
    }
}

#[test]
fn energy_balance_closes_with_load_dependent_friction_and_a_load_torque() {
    let mut cfg = SimConfig {
        record_trace: false,
        t_end: 0.2,
        solver: SolverOptions { rtol: 1e-9, atol: 1e-12, ..Default::default() },
        load_torque: LoadTorque::new(Input::Sine { amplitude: 10.0, freq: 7.0 }),
        ..SimConfig::default()
    };
    cfg.params.mu_c_fwd = 0.03;
    cfg.params.mu_s_fwd = 0.05;
    cfg.params.mu_c_back = 0.06;
    cfg.params.mu_s_back = 0.09;
    let out = simulate(&cfg).unwrap();
    let sys = cfg.system().unwrap();
    let y = out.final_state;
    let e_in = y[Q_ELEC];
    let accounted = sys.stored_energy(&y) + y[Q_DISS] + y[Q_FRIC] + y[Q_LOAD];
    let rel = (e_in - accounted).abs() / e_in.abs();
    eprintln!("energy balance with μ > 0 and a load torque: {e_in:.6} J in, residual {rel:.2e}");
    // Measured 8.0e-15.
    assert!(e_in > 0.0 && rel < 1e-13, "in {e_in} J, accounted {accounted} J, rel {rel:e}");
}

#[test]
fn steady_efficiency_is_the_torque_ratio_with_the_raised_levels() {
    // Constant voltage against a constant load torque: in steady running the output power
    // is Tb·ωz and the wave generator takes (Tb + Tf)/N·ωj with ωj/N = ωz, so the
    // efficiency is Tb/(Tb + Tf) with Tf the raised Stribeck level at v = ωj/N.
    let mut cfg = SimConfig {
        record_trace: false,
        t_end: 0.4,
        input: Input::Constant { amplitude: 24.0 },
        load_torque: LoadTorque::new(Input::Constant { amplitude: 30.0 }),
        ..SimConfig::default()
    };
    cfg.metrics.final_fraction = 0.2;
    cfg.params.mu_c_fwd = 0.08;
    cfg.params.mu_s_fwd = 0.12;
    cfg.params.sigma2 = 0.5;
    let out = simulate(&cfg).unwrap();
    let y = out.final_state;
    let p = &cfg.params;
    let wz = y[OMEGA_Z];
    let tb = 30.0 + p.cz * wz;
    let tf = LuGre::from_params(p).steady_torque_loaded(y[OMEGA_J] / p.n, tb);
    let expected = tb / (tb + tf);
    let got = out.metrics.efficiency;
    eprintln!(
        "steady efficiency {got:.9}, Tb/(Tb + Tf) = {expected:.9}, {:.1e} apart",
        (got - expected).abs()
    );
    // Measured 4.5e-11 apart.
    assert!((got - expected).abs() < 5e-10, "efficiency {got}, expected {expected}");
}

#[test]
fn stribeck_curve_is_the_closed_form_at_every_speed_far_beyond_the_stribeck_speed_too() {
    // Far above ωs the factor e^{−(v/ωs)²} underflows; the law must still give exactly the
    // Coulomb level there (and the closed form everywhere below), without a slow path.
    let (tc, ts, ws, s2) = (0.15, 0.25, 0.01, 0.02);
    let law = LuGre::symmetric(1.2e5, 0.8, s2, tc, ts, ws);
    let mut worst: f64 = 0.0;
    for k in 0..=4000 {
        let v = 1e-4 * 1.005f64.powi(k); // 1e-4 … 4.8e4 rad/s
        for v in [v, -v] {
            let r = v / ws;
            let want = v.signum() * (tc + (ts - tc) * (-(r * r)).exp()) + s2 * v;
            let got = law.steady_torque(v);
            worst = worst.max((got - want).abs() / want.abs());
        }
    }
    assert!(worst < 1e-14, "largest relative deviation from the closed form {worst:e}");
}

/// The friction torque read back from the bristle rate is the torque the law gives, for
/// load-raised levels, both directions, stick and slide, and bristles loaded past the
/// level (measured: 2.1e-16 of the torque).
#[test]
fn torque_from_the_bristle_rate_is_the_laws_torque() {
    let law = loaded_law();
    let mut worst: f64 = 0.0;
    for v in [-3.0, -0.02, -1e-4, 0.0, 1e-5, 0.007, 0.5, 40.0] {
        for w in [-0.6, -0.2, 0.0, 0.05, 0.3, 0.9] {
            for tb in [-80.0, -1.0, 0.0, 2.5, 120.0] {
                let e = law.eval_loaded(v, w, tb);
                let got = law.torque_with_rate(v, w, e.w_rate);
                worst = worst.max((got - e.torque).abs() / e.torque.abs().max(1e-3));
            }
        }
    }
    assert!(worst < 2e-15, "largest relative difference {worst:e}");
}
