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

/// θz, θj and i [rad, rad, A] over `steps` communication steps of `h` [s] with the host
/// holding a 24 V, 50 Hz sine over each step (its value at the step's start).
fn sine_run(mut inst: Instance, h: f64, steps: usize) -> Vec<[f64; 3]> {
    let vr = |name: &str| inst.vars.iter().find(|v| v.name == name).unwrap().vr;
    let outs = [vr("theta_z"), vr("theta_j"), vr("i")];
    let mut rows = Vec::with_capacity(steps);
    for k in 0..steps {
        let t = k as f64 * h;
        inst.set_reals(&[VR_U], &[24.0 * (2.0 * std::f64::consts::PI * 50.0 * t).sin()]).unwrap();
        inst.do_step(t, h).unwrap();
        let mut v = [0.0; 3];
        inst.get_reals(&outs, &mut v).unwrap();
        rows.push(v);
    }
    rows
}

/// The largest difference of each output between two runs, over the output's RMS [–].
fn worst(a: &[[f64; 3]], b: &[[f64; 3]]) -> [f64; 3] {
    std::array::from_fn(|j| {
        let rms = (b.iter().map(|r| r[j] * r[j]).sum::<f64>() / b.len() as f64).sqrt();
        a.iter().zip(b).map(|(x, y)| (x[j] - y[j]).abs()).fold(0.0, f64::max) / rms
    })
}

/// The fixed step ([`Instance::with_fixed_substeps`]) against the adaptive solve of the
/// same FMU (rtol 1e-10) on the seed drive under a held 24 V sine at 10 kHz communication:
/// θz, θj and i agree to 1e-6 of their RMS at 4 substeps (measured 1.06e-7, 1.06e-7,
/// 1.7e-8), and doubling the substeps cuts every difference at least 2.5-fold (measured
/// 5.3, 5.3 and 4.8: the bristle's kinks at each reversal hold the method below its fourth
/// order, as the fits' accuracy check measures, `hd_ident::drive::compliant::accuracy`).
#[test]
fn a_fixed_step_matches_the_adaptive_solve_and_converges() {
    let (h, steps) = (1e-4, 1000);
    let mut tight = SimConfig::default();
    tight.solver.rtol = 1e-10;
    tight.solver.atol = 1e-13;
    let reference = sine_run(stepping(tight), h, steps);
    let fixed = |m| {
        let mut inst = Instance::new(SimConfig::default()).with_fixed_substeps(Some(m)).unwrap();
        inst.enter_initialization().unwrap();
        inst.exit_initialization().unwrap();
        sine_run(inst, h, steps)
    };
    let (e4, e8) = (worst(&fixed(4), &reference), worst(&fixed(8), &reference));
    for j in 0..3 {
        assert!(e4[j] < 1e-6, "output {j}: {e4:?}");
        assert!(e8[j] < e4[j] / 2.5, "output {j}: 4 substeps {e4:?}, 8 substeps {e8:?}");
    }
}

/// A drive the fixed-step assembly cannot stand for is refused at instantiation, each
/// setting named; a fixed step past the method's stability fails the step, naming it.
#[test]
fn a_fixed_step_refuses_what_it_cannot_integrate() {
    let mut cfg = sampled(1e-3);
    cfg.params.l = 1e-3;
    let e = Instance::new(cfg).with_fixed_substeps(Some(4)).unwrap_err();
    assert!(e.starts_with("fixed_substeps = 4: "), "{e}");
    assert!(e.contains("[controller]") && e.contains("L = 1e-3"), "{e}");
    let mut inst = Instance::new(SimConfig::default()).with_fixed_substeps(Some(1)).unwrap();
    inst.enter_initialization().unwrap();
    inst.exit_initialization().unwrap();
    inst.set_reals(&[VR_U], &[24.0]).unwrap();
    let e = (0..100).find_map(|k| inst.do_step(k as f64 * 0.02, 0.02).err()).unwrap();
    assert!(e.contains("not finite after 1 fixed substeps of 2.000e-2 s"), "{e}");
    assert_eq!(inst.phase, Phase::Failed);
}

/// The other gear laws through the fixed step: a Bouc–Wen element (carried by the
/// simulator as its torque α·h, by the assembly as h) and ten Maxwell-slip elements (their
/// offsets in the simulator's slots) follow the adaptive solve at 8 substeps as the seed's
/// law does: within 3e-7 of each output's RMS (measured 2.0e-8 and 3.0e-8 at most).
#[test]
fn a_fixed_step_carries_every_gear_law_state() {
    use hd_model::HystLaw;
    let (h, steps) = (1e-4, 1000);
    for law in [HystLaw::BoucWen, HystLaw::MaxwellSlip] {
        let mut cfg = SimConfig { stiffness: law, ..SimConfig::default() };
        if law == HystLaw::MaxwellSlip {
            cfg.params.set("ms_n", 10.0).unwrap();
        }
        let mut tight = cfg.clone();
        tight.solver.rtol = 1e-10;
        tight.solver.atol = 1e-13;
        let reference = sine_run(stepping(tight), h, steps);
        let mut inst = Instance::new(cfg).with_fixed_substeps(Some(8)).unwrap();
        inst.enter_initialization().unwrap();
        inst.exit_initialization().unwrap();
        let e = worst(&sine_run(inst, h, steps), &reference);
        assert!(e.iter().all(|&x| x < 3e-7), "{law:?}: {e:?}");
    }
}
