//! Wall time per simulated second of the FMU against `hdw simulate`'s, on the seed case
//! (full model, 24 V at 50 Hz, rtol 1e-6): the FMU is stepped through its FMI 2 functions,
//! as a host steps it, with the sine's value at each step's middle held over the step, once
//! with the adaptive solver and once per fixed substep count (`hdw export fmu
//! --fixed-substeps`).
//!
//! `cargo run --release -p hd-fmu --example fmu_speed`

use hd_fmu::ffi::Status;
use hd_fmu::fmi2::*;
use hd_fmu::variables::variables;
use hd_model::{SimConfig, simulate};
use std::ffi::CString;
use std::time::Instant;

/// Simulated time of one run [s] (the seed case's).
const T_END: f64 = 0.2;
/// Runs per measurement; the fastest is kept.
const REPEATS: usize = 5;

fn main() {
    let cfg = SimConfig { record_trace: false, ..SimConfig::default() };
    let best = (0..REPEATS)
        .map(|_| {
            let start = Instant::now();
            simulate(&cfg).expect("seed case");
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min);
    println!(
        "hdw simulate (library call, no trace): {:.2} ms per simulated second",
        best / T_END * 1e3
    );

    for fixed in [None, Some(1), Some(2), Some(4)] {
        fmu_runs(&cfg, fixed, best);
    }
}

/// The FMU of `cfg` stepped at 1e-5, 1e-4 and 1e-3 s, adaptive or in `fixed` substeps per
/// step; `best` is `hdw simulate`'s time [s].
fn fmu_runs(cfg: &SimConfig, fixed: Option<u32>, best: f64) {
    let dir = tempfile::tempdir().expect("temporary folder");
    let text = hd_fmu::config::to_toml_fixed(cfg, fixed).expect("configuration");
    std::fs::write(dir.path().join(hd_fmu::CONFIG_FILE), &text).expect("write resources");
    let uri = CString::new(format!("file://{}", dir.path().display())).expect("path");
    let token = CString::new(hd_fmu::config::token(&text)).expect("token");
    let u = variables(cfg).iter().find(|v| v.name == "u").expect("input u").vr;
    for h in [1e-5, 1e-4, 1e-3] {
        let n = (T_END / h).round() as usize;
        let mut fastest = f64::INFINITY;
        let mut failed = false;
        for _ in 0..REPEATS {
            // SAFETY: valid strings; no callbacks.
            let c = unsafe {
                fmi2Instantiate(
                    c"speed".as_ptr(),
                    1,
                    token.as_ptr(),
                    uri.as_ptr(),
                    std::ptr::null(),
                    0,
                    0,
                )
            };
            assert!(!c.is_null());
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
            assert_eq!(fmi2EnterInitializationMode(c), Status::Ok);
            assert_eq!(fmi2ExitInitializationMode(c), Status::Ok);
            let start = Instant::now();
            for k in 0..n {
                let t = k as f64 * h;
                let volts = 24.0 * (std::f64::consts::TAU * 50.0 * (t + h / 2.0)).sin();
                // SAFETY: one reference, one value.
                unsafe { assert_eq!(fmi2SetReal(c, &u, 1, &volts), Status::Ok) };
                if fmi2DoStep(c, t, h, 1) != Status::Ok {
                    failed = true;
                    break;
                }
            }
            fastest = fastest.min(start.elapsed().as_secs_f64());
            fmi2FreeInstance(c);
        }
        let what = fixed.map_or("adaptive".to_string(), |m| format!("{m} fixed substeps"));
        if failed {
            println!(
                "FMU ({what}), communication step {h:e} s: the step failed (past the fixed step's stability)"
            );
            continue;
        }
        println!(
            "FMU ({what}), communication step {h:e} s ({n} steps): {:.2} ms per simulated second ({:.1}× hdw simulate)",
            fastest / T_END * 1e3,
            fastest / best
        );
    }
}
