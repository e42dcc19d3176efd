//! Metrics of non-periodic runs are missing with a reason; a recorded sine is the sine.

use super::*;
use crate::laws::input::{Input, Profile};
use crate::simulate::{SimConfig, simulate};
use std::f64::consts::TAU;

fn run(cfg: &SimConfig) -> Metrics {
    simulate(&SimConfig { record_trace: false, ..cfg.clone() }).expect("run").metrics
}

fn reason<'a>(n: &'a Notes, name: &str) -> Option<&'a str> {
    n.undefined.iter().find(|(m, _)| *m == name).map(|(_, r)| r.as_str())
}

#[test]
fn a_step_run_has_no_amplitude_and_says_why() {
    let cfg = SimConfig {
        input: Input::Step { amplitude: 12.0, t0: 0.0 },
        t_end: 0.1,
        ..SimConfig::default()
    };
    let m = run(&cfg);
    assert!(m.thz_amp.is_nan());
    let n = notes(&cfg, &m);
    let why = reason(&n, "thz_amp").expect("thz_amp is undefined");
    assert!(why.contains("step") && why.contains("not periodic"), "{why}");
    assert!(reason(&n, "track_rms").unwrap().contains("open loop"));
    // A step response is defined where it rose.
    assert!(m.rise_time.is_finite() && reason(&n, "rise_time").is_none());
}

#[test]
fn a_recorded_sine_is_the_built_in_sine_and_neither_is_a_limit_cycle() {
    let builtin = SimConfig::default(); // 24 V, 50 Hz, 0.2 s
    let dt = 1e-5;
    let t: Vec<f64> = (0..=20_000).map(|k| k as f64 * dt).collect();
    let u: Vec<f64> = t.iter().map(|&t| 24.0 * (TAU * 50.0 * t).sin()).collect();
    let recorded = SimConfig {
        input: Input::Recorded(Profile::new(t, u, "test").unwrap()),
        ..SimConfig::default()
    };
    let (a, b) = (run(&builtin), run(&recorded));
    for m in [&a, &b] {
        assert!(m.limit_cycle != 1.0, "a forced response flagged as a limit cycle");
        assert_eq!(m.cycles_used, 5.0);
    }
    // Linear interpolation of the sine at 1e-5 s moves the input by ≤ 1.2e-6 of its
    // amplitude; the response follows to that order (measured: amplitude 8.2e-7 relative,
    // phase 4.6e-7°).
    let rel = (a.thz_amp - b.thz_amp).abs() / a.thz_amp;
    assert!(rel < 1e-5, "thz_amp {} vs {} ({rel:e})", a.thz_amp, b.thz_amp);
    let phase = (a.phase_deg - b.phase_deg).abs();
    assert!(phase < 5e-6, "phase {} vs {}", a.phase_deg, b.phase_deg);
    assert!(notes(&recorded, &b).warnings.is_empty());
}

#[test]
fn a_chirp_is_not_a_limit_cycle_and_a_short_window_warns() {
    let chirp = SimConfig {
        input: Input::Chirp { amplitude: 24.0, f0: 10.0, f1: 60.0, duration: 0.2 },
        t_end: 0.2,
        ..SimConfig::default()
    };
    let m = run(&chirp);
    assert!(m.limit_cycle.is_nan());
    let why = reason(&notes(&chirp, &m), "limit_cycle").unwrap().to_string();
    assert!(why.contains("varies") && why.contains("chirp"), "{why}");
    // Two cycles of 50 Hz: the five-cycle window shrinks to both, start-up included.
    let short = SimConfig { t_end: 0.04, ..SimConfig::default() };
    let m = run(&short);
    assert_eq!(m.cycles_used, 2.0);
    let n = notes(&short, &m);
    assert_eq!(n.warnings.len(), 1, "{:?}", n.warnings);
    assert!(n.warnings[0].contains("start-up"));
}
