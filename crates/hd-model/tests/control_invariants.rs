//! Closed-loop invariants on the full model: the energy balance still closes with a
//! controller, a load torque and a sampled controller; friction compensation with the
//! exact model halves the tracking error of the issue's case.

use hd_model::control::{Compensation, ControllerConfig, Reference};
use hd_model::laws::input::Input;
use hd_model::laws::load::LoadTorque;
use hd_model::solver::SolverOptions;
use hd_model::{Params, SimConfig, simulate};

/// The issue's case: PID kp 2000, ki 20 000 on the load angle, 1 mrad sine at 0.2 Hz,
/// LuGre torques ×10 (Tc = 1.5, Ts = 2.5 N·m).
fn issue_case(compensation: Compensation, t_end: f64) -> SimConfig {
    SimConfig {
        params: Params { tc: 1.5, ts: 2.5, ..Params::default() },
        t_end,
        record_trace: false,
        controller: Some(ControllerConfig {
            kp: 2000.0,
            ki: 20_000.0,
            kd: 0.0,
            compensation,
            reference: Reference::Sine { amplitude: 1e-3, freq: 0.2 },
            ..Default::default()
        }),
        ..SimConfig::default()
    }
}

#[test]
fn energy_balance_closes_in_closed_loop() {
    let tight = SolverOptions { rtol: 1e-9, atol: 1e-12, ..Default::default() };
    let load = LoadTorque::new(Input::Sine { amplitude: 3.0, freq: 1.0 });
    for period in [0.0, 1e-3] {
        let mut cfg = issue_case(Compensation::FrictionCompliance, 1.5);
        cfg.solver = tight;
        cfg.load_torque = load.clone();
        if let Some(c) = cfg.controller.as_mut() {
            c.period = period;
            c.kd = 5.0;
        }
        let m = simulate(&cfg).unwrap().metrics;
        eprintln!("period {period}: energy residual {:.2e}", m.energy_residual);
        assert!(m.energy_residual < 1e-6, "period {period}: {}", m.energy_residual);
    }
}

#[test]
fn friction_compensation_at_least_halves_the_tracking_error() {
    let none = simulate(&issue_case(Compensation::None, 12.0)).unwrap().metrics;
    let fric = simulate(&issue_case(Compensation::Friction, 12.0)).unwrap().metrics;
    eprintln!(
        "track_rms none {:.3e} friction {:.3e}; reversal_peak {:.3e} / {:.3e}; torque_est_rms {:.3e} (no friction model {:.3e})",
        none.track_rms,
        fric.track_rms,
        none.reversal_peak,
        fric.reversal_peak,
        none.torque_est_rms,
        none.torque_est_rms_nofric
    );
    assert!(fric.track_rms <= 0.5 * none.track_rms, "{} vs {}", fric.track_rms, none.track_rms);
}
