//! An open-loop record fitted by multiple shooting: a rigid drive's closed-loop record, its
//! controller forgotten, the recorded command driving the model and the simulation
//! restarted from the record every segment.

use super::controller::Controller;
use super::fit::{FitSpec, OutputKind, fit_drive};
use super::model::FrictionLaw;
use super::simulate::simulate;
use super::tests::{RIGID, TRUTH, record};
use crate::lm::LmOptions;

/// Without restarts a model error integrates into a drift off the record; with them each
/// segment starts on it, and the fit from a start 20 % off recovers the parameters to
/// the accuracy of the restart speeds (a zero-lag 40 Hz filter's derivative of the
/// position).
#[test]
fn multiple_shooting_recovers_a_drive_from_its_command_alone() {
    for law in RIGID {
        let truth: Vec<f64> = match law {
            FrictionLaw::CoulombViscous => TRUTH.to_vec(),
            _ => vec![95.0, 170.0, 20.0, 240.0, 21.0, 35.0],
        };
        let mut e = record(law, &truth, 0, 8000);
        e.estimate_speed(4, 40.0);
        let n = truth.len();
        let open = Controller::open(200, e.h);
        // The record's own model re-run from its segments' starts follows it closely.
        let s = simulate(law, &truth, &open, &e);
        let worst =
            s.position.iter().zip(&e.position).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        println!("{}: worst restart error {worst:.3e} m", law.name());
        assert!(worst < 3e-4, "{worst}");
        // With the viscous term 5 % off, one segment over the whole record drifts away from
        // it; restarts keep the error to what the term does within a segment.
        let mut off = truth.clone();
        off[1] *= 1.05;
        let err = |c: &Controller| {
            let s = simulate(law, &off, c, &e);
            s.position.iter().zip(&e.position).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
        };
        let (segmented, free_run) = (err(&open), err(&Controller::open(e.len(), e.h)));
        println!(
            "{}: Fv 5 % off: {segmented:.3e} m segmented, {free_run:.3e} m in one run",
            law.name()
        );
        assert!(free_run > 3.0 * segmented, "{free_run} against {segmented}");
        let mut start: Vec<f64> = truth.iter().map(|v| v * 1.2).collect();
        start[n - 1] = truth[n - 1];
        let mut free = vec![true; n];
        free[n - 1] = false; // the gain
        let spec = FitSpec {
            law,
            controller: open,
            gain: truth[n - 1],
            outputs: vec![(OutputKind::Position, 1e-6)],
            start,
            free,
            lower: vec![f64::NEG_INFINITY; n],
            upper: vec![f64::INFINITY; n],
            settings: LmOptions::drive(),
        };
        let fit = fit_drive(&spec, std::slice::from_ref(&e), &|_, _| {}).unwrap();
        for (k, truth_k) in truth.iter().enumerate().take(n - 1) {
            let rel = (fit.values[k] - truth_k).abs() / truth_k.abs();
            println!("{} {}: {} vs {truth_k} ({rel:.2e})", law.name(), fit.names[k], fit.values[k]);
            assert!(
                rel < 2e-2,
                "{}: {} {} vs {}",
                law.name(),
                fit.names[k],
                fit.values[k],
                truth_k
            );
        }
    }
}
