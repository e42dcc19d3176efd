//! The bounds of one communication step: non-finite points, the step budget, and a sampled
//! controller's run split at its instants exactly as the run splits it itself.

use super::*;
use hd_model::control::ControllerConfig;

/// An instance of `cfg` in step mode.
fn stepping(cfg: SimConfig) -> Instance {
    let mut inst = Instance::new(cfg);
    inst.enter_initialization().unwrap();
    inst.exit_initialization().unwrap();
    inst
}

fn sampled(period: f64) -> SimConfig {
    SimConfig {
        controller: Some(ControllerConfig { period, ..ControllerConfig::default() }),
        ..SimConfig::default()
    }
}

#[test]
fn non_finite_points_and_steps_are_refused_before_any_work() {
    let mut inst = stepping(SimConfig::default());
    for (t, h, needle) in [
        (f64::NAN, 1e-3, "t = NaN"),
        (f64::INFINITY, 1e-3, "t = inf"),
        (f64::NEG_INFINITY, 1e-3, "t = -inf"),
        (0.0, f64::NAN, "step size = NaN"),
        (0.0, f64::INFINITY, "step size = inf"),
        (0.0, -1e-3, "step size = -0.001"),
    ] {
        let e = inst.do_step(t, h).unwrap_err();
        assert!(e.contains(needle), "{e}");
    }
    // Refused, not failed: the instance is where it was and steps on.
    assert_eq!(inst.time(), 0.0);
    assert_eq!(inst.phase, Phase::Stepping);
    inst.do_step(0.0, 1e-3).unwrap();
    assert_eq!(inst.time(), 1e-3);
    // An end time beyond the largest number.
    let mut late = stepping(SimConfig::default());
    late.set_start_time(1.5e308).unwrap();
    let e = late.do_step(1.5e308, 1.5e308).unwrap_err();
    assert!(e.contains("overflows"), "{e}");
}

#[test]
fn a_step_longer_than_the_budget_allows_fails_with_a_reason() {
    let mut inst = stepping(SimConfig::default());
    inst.set_reals(&[VR_U], &[24.0]).unwrap();
    inst.set_step_budget(2_000);
    let start = std::time::Instant::now();
    let e = inst.do_step(0.0, 1e6).unwrap_err();
    assert!(start.elapsed().as_secs_f64() < 5.0);
    assert!(e.contains("more than the 2000 solver steps"), "{e}");
    assert_eq!(inst.phase, Phase::Failed);
    // A bounded solver step makes the refusal immediate: h / h_max steps at least.
    let mut cfg = SimConfig::default();
    cfg.solver.h_max = 1e-4;
    let mut inst = stepping(cfg);
    let e = inst.do_step(0.0, 1e6).unwrap_err();
    assert!(e.contains("needs at least 1.000e10 solver steps"), "{e}");
    assert_eq!(inst.time(), 0.0);
}

#[test]
fn a_sampled_controller_steps_as_its_run_does_and_is_bounded_by_its_instants() {
    let cfg = sampled(1e-4);
    let mut inst = stepping(cfg.clone());
    // The first step (the solver's own first step size, as below), across 52 instants
    // and part of an interval.
    inst.do_step(0.0, 0.00525).unwrap();
    let mut run = Stepper::new(&cfg).unwrap();
    run.advance(0.00525, &cfg.breakpoints(), &cfg.solver, &mut |_, _| {}).unwrap();
    let y = inst.run.as_ref().unwrap().y;
    assert_eq!(y, run.y, "split at the instants, the same run to the bit");
    inst.do_step(0.00525, 0.00475).unwrap();
    // 1e7 sampling instants in one step: more than the budget, refused at once.
    let e = inst.do_step(0.01, 1e3).unwrap_err();
    assert!(e.contains("needs at least 1.000e7 solver steps"), "{e}");
    // And the budget bounds the instants' steps together.
    let mut inst = stepping(cfg);
    inst.set_step_budget(10_000);
    let e = inst.do_step(0.0, 1.0).unwrap_err();
    assert!(e.contains("more than the 10000 solver steps"), "{e}");
}

#[test]
fn communication_points_that_round_onto_an_instant_step_on() {
    // 1e-4 communication steps over a 1e-3 controller: 0.0109 + 1e-4 and 11·1e-3 differ in
    // their last bits; every step must still land on its end (was "step size too small"
    // with a remainder of 1.7e-18 s at t = 0.011 s).
    let mut inst = stepping(sampled(1e-3));
    let h = 1e-4;
    for k in 0..300 {
        let t = k as f64 * h;
        inst.do_step(t, h).unwrap_or_else(|e| panic!("step {k} at t = {t}: {e}"));
    }
    assert!((inst.time() - 0.03).abs() < 1e-12, "{}", inst.time());
}
