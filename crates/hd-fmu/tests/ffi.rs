//! The FMI 2 and FMI 3 C functions called as a host calls them: instantiation from a
//! resources folder, stepping, errors reported by status and logger, never a panic.

use hd_fmu::ffi::Status;
use hd_fmu::fmi2::*;
use hd_fmu::fmi3::*;
use hd_fmu::variables::variables;
use hd_model::{Input, Profile, SimConfig, simulate};
use std::ffi::{CStr, CString, c_char, c_void};
use std::sync::Mutex;

/// Messages the loggers received, with their status.
static LOG: Mutex<Vec<(i32, String)>> = Mutex::new(Vec::new());

/// An FMI 2 logger reading the format's one argument (this library always logs "%s").
extern "C" fn logger2(
    _env: *mut c_void,
    _name: *const c_char,
    status: i32,
    _category: *const c_char,
    format: *const c_char,
    message: *const c_char,
) {
    // SAFETY: the library passes NUL-terminated strings.
    let (format, message) = unsafe { (CStr::from_ptr(format), CStr::from_ptr(message)) };
    assert_eq!(format.to_str().unwrap(), "%s");
    LOG.lock().unwrap().push((status, message.to_string_lossy().into_owned()));
}

extern "C" fn logger3(
    _env: *mut c_void,
    status: i32,
    _category: *const c_char,
    message: *const c_char,
) {
    // SAFETY: the library passes NUL-terminated strings.
    let message = unsafe { CStr::from_ptr(message) };
    LOG.lock().unwrap().push((status, message.to_string_lossy().into_owned()));
}

fn logged(needle: &str) -> bool {
    LOG.lock().unwrap().iter().any(|(s, m)| *s == Status::Error as i32 && m.contains(needle))
}

/// A resources folder holding the configuration of `cfg`, and its token.
fn resources(cfg: &SimConfig) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    let text = hd_fmu::config::to_toml(cfg).unwrap();
    std::fs::write(dir.path().join(hd_fmu::CONFIG_FILE), &text).unwrap();
    (dir, hd_fmu::config::token(&text))
}

fn vr(cfg: &SimConfig, name: &str) -> u32 {
    variables(cfg).iter().find(|v| v.name == name).unwrap().vr
}

fn instantiate2(dir: &std::path::Path, token: &str) -> *mut c_void {
    let uri = CString::new(format!("file://{}", dir.display())).unwrap();
    let token = CString::new(token).unwrap();
    // SAFETY: test-only: on x86-64 a variadic callee reads its first variadic argument
    // where a sixth fixed argument sits, so this non-variadic logger stands in for one.
    let logger: Fmi2Logger = unsafe { std::mem::transmute(logger2 as *const ()) };
    let functions = Box::leak(Box::new(Fmi2CallbackFunctions {
        logger: Some(logger),
        allocate_memory: std::ptr::null(),
        free_memory: std::ptr::null(),
        step_finished: std::ptr::null(),
        component_environment: std::ptr::null_mut(),
    }));
    // SAFETY: valid strings and callbacks.
    unsafe { fmi2Instantiate(c"test".as_ptr(), 1, token.as_ptr(), uri.as_ptr(), functions, 0, 0) }
}

use hd_fmu::ffi::Fmi2Logger;

fn instantiate3(dir: &std::path::Path, token: &str) -> *mut c_void {
    let path = CString::new(format!("{}/", dir.display())).unwrap();
    let token = CString::new(token).unwrap();
    // SAFETY: valid strings and callback.
    unsafe {
        fmi3InstantiateCoSimulation(
            c"test3".as_ptr(),
            token.as_ptr(),
            path.as_ptr(),
            false,
            false,
            false,
            false,
            std::ptr::null(),
            0,
            std::ptr::null_mut(),
            Some(logger3),
            std::ptr::null(),
        )
    }
}

#[test]
fn one_fmi2_step_is_hdw_simulate_to_the_bit() {
    let cfg = SimConfig::default();
    let (dir, token) = resources(&cfg);
    let c = instantiate2(dir.path(), &token);
    assert!(!c.is_null());
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
    assert_eq!(fmi2EnterInitializationMode(c), Status::Ok);
    assert_eq!(fmi2ExitInitializationMode(c), Status::Ok);
    let (u, thz) = (vr(&cfg, "u"), vr(&cfg, "theta_z"));
    // SAFETY: one reference, one value.
    unsafe { assert_eq!(fmi2SetReal(c, &u, 1, &12.0), Status::Ok) };
    assert_eq!(fmi2DoStep(c, 0.0, 0.01, 1), Status::Ok);
    let mut got = f64::NAN;
    // SAFETY: one reference, one value.
    unsafe { assert_eq!(fmi2GetReal(c, &thz, 1, &mut got), Status::Ok) };
    let mut t = f64::NAN;
    // SAFETY: one value.
    unsafe { assert_eq!(fmi2GetRealStatus(c, 2, &mut t), Status::Ok) };
    assert_eq!(t, 0.01);
    let reference = SimConfig {
        input: Input::Constant { amplitude: 12.0 },
        t_end: 0.01,
        record_trace: true,
        ..SimConfig::default()
    };
    let out = simulate(&reference).unwrap();
    assert_eq!(got, *out.trace.unwrap().theta_z.last().unwrap());
    fmi2FreeInstance(c);
}

#[test]
fn errors_are_statuses_with_a_message_naming_the_cause() {
    let cfg = SimConfig::default();
    let (dir, token) = resources(&cfg);
    assert!(instantiate2(dir.path(), "{not-this-one}").is_null());
    assert!(logged("does not match"));
    let c = instantiate2(dir.path(), &token);
    let sigma0 = vr(&cfg, "sigma0");
    // SAFETY: one reference, one value.
    unsafe { assert_eq!(fmi2SetReal(c, &sigma0, 1, &-1.0), Status::Error) };
    assert!(logged("'sigma0' = -1"));
    let mut v = 0.0;
    // SAFETY: one reference, one value.
    unsafe { assert_eq!(fmi2GetReal(c, &99_999, 1, &mut v), Status::Error) };
    assert!(logged("unknown value reference 99999"));
    assert_eq!(fmi2DoStep(c, 0.0, 1e-3, 1), Status::Error, "not initialised");
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
    assert_eq!(fmi2EnterInitializationMode(c), Status::Ok);
    assert_eq!(fmi2ExitInitializationMode(c), Status::Ok);
    assert_eq!(fmi2DoStep(c, 0.5, 1e-3, 1), Status::Error);
    assert!(logged("doStep from t = 0.5 s"));
    assert_eq!(fmi2DoStep(std::ptr::null_mut(), 0.0, 1e-3, 1), Status::Error);
    assert_eq!(fmi2GetFMUstate(c), Status::Error);
    fmi2FreeInstance(c);
}

#[test]
fn fmi3_steps_and_reports_time() {
    let cfg = SimConfig::default();
    let (dir, token) = resources(&cfg);
    let c = instantiate3(dir.path(), &token);
    assert!(!c.is_null());
    assert_eq!(fmi3EnterInitializationMode(c, false, 0.0, 1.0, false, 0.0), Status::Ok);
    assert_eq!(fmi3ExitInitializationMode(c), Status::Ok);
    let (mut ev, mut term, mut early, mut last) = (true, true, true, 0.0);
    for k in 0..10 {
        let t = 1.0 + k as f64 * 1e-3;
        // SAFETY: valid out-pointers.
        let s = unsafe { fmi3DoStep(c, t, 1e-3, true, &mut ev, &mut term, &mut early, &mut last) };
        assert_eq!(s, Status::Ok);
    }
    assert!(!ev && !term && !early);
    assert!((last - 1.01).abs() < 1e-12);
    let mut time = 0.0;
    // SAFETY: one reference, one value.
    unsafe { assert_eq!(fmi3GetFloat64(c, &0, 1, &mut time, 1), Status::Ok) };
    assert!((time - 1.01).abs() < 1e-12);
    let ms_n = vr(&cfg, "ms_n");
    // SAFETY: one reference, one value.
    unsafe { assert_eq!(fmi3SetFloat64(c, &ms_n, 1, &40.0, 1), Status::Error) };
    assert!(logged("'ms_n' = 40"));
    fmi3FreeInstance(c);
}

#[test]
fn input_derivatives_ramp_the_voltage_over_the_step() {
    let cfg = SimConfig::default();
    let (dir, token) = resources(&cfg);
    let c = instantiate2(dir.path(), &token);
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
    assert_eq!(fmi2EnterInitializationMode(c), Status::Ok);
    assert_eq!(fmi2ExitInitializationMode(c), Status::Ok);
    let (u, thz) = (vr(&cfg, "u"), vr(&cfg, "theta_z"));
    // SAFETY: one reference, one order, one value.
    unsafe {
        assert_eq!(fmi2SetReal(c, &u, 1, &0.0), Status::Ok);
        assert_eq!(fmi2SetRealInputDerivatives(c, &u, 1, &1, &1200.0), Status::Ok);
        assert_eq!(fmi2SetRealInputDerivatives(c, &u, 1, &2, &0.0), Status::Error);
    }
    assert!(logged("order 2"));
    assert_eq!(fmi2DoStep(c, 0.0, 0.01, 1), Status::Ok);
    let mut got = f64::NAN;
    // SAFETY: one reference, one value.
    unsafe { assert_eq!(fmi2GetReal(c, &thz, 1, &mut got), Status::Ok) };
    // The same ramp, 0 → 12 V over 0.01 s, as a recorded input of hdw simulate.
    let ramp = Profile::new(vec![0.0, 0.01], vec![0.0, 12.0], "ramp").unwrap();
    let reference = SimConfig { input: Input::Recorded(ramp), t_end: 0.01, ..SimConfig::default() };
    let out = simulate(&reference).unwrap();
    assert_eq!(got, *out.trace.unwrap().theta_z.last().unwrap());
    fmi2FreeInstance(c);
}

/// Every FMI 2 instance function at `c`, each expected to answer `status`.
fn every_fmi2_call(c: *mut c_void, status: Status) {
    let (mut v, mut b, vr) = (0.0, 0, 1u32);
    // SAFETY: valid out-pointers; the handle is what is tested.
    unsafe {
        assert_eq!(fmi2SetReal(c, &vr, 1, &1.0), status);
        assert_eq!(fmi2GetReal(c, &vr, 1, &mut v), status);
        assert_eq!(fmi2GetRealStatus(c, 2, &mut v), status);
        assert_eq!(fmi2GetBooleanStatus(c, 3, &mut b), status);
    }
    assert_eq!(fmi2SetDebugLogging(c, 0, 0, std::ptr::null()), status);
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), status);
    assert_eq!(fmi2EnterInitializationMode(c), status);
    assert_eq!(fmi2ExitInitializationMode(c), status);
    assert_eq!(fmi2DoStep(c, 0.0, 1e-3, 1), status);
    assert_eq!(fmi2Terminate(c), status);
    assert_eq!(fmi2Reset(c), status);
}

#[test]
fn fmi2_handles_freed_twice_used_after_free_null_or_foreign_are_errors_not_crashes() {
    let cfg = SimConfig::default();
    let (dir, token) = resources(&cfg);
    let a = instantiate2(dir.path(), &token);
    assert!(!a.is_null());
    every_fmi2_call(a, Status::Ok);
    fmi2FreeInstance(a);
    fmi2FreeInstance(a); // the double free: ignored, the heap untouched
    every_fmi2_call(a, Status::Error);
    every_fmi2_call(std::ptr::null_mut(), Status::Error);
    fmi2FreeInstance(std::ptr::null_mut());
    // A pointer this library never made is neither read nor written.
    let mut foreign = [7u64; 64];
    let f = foreign.as_mut_ptr() as *mut c_void;
    every_fmi2_call(f, Status::Error);
    fmi2FreeInstance(f);
    assert!(foreign.iter().all(|&w| w == 7));
    // A new instance does not take the freed one's address: the stale handle stays dead.
    let b = instantiate2(dir.path(), &token);
    assert_ne!(a, b);
    every_fmi2_call(a, Status::Error);
    every_fmi2_call(b, Status::Ok);
    fmi2FreeInstance(a);
    every_fmi2_call(b, Status::Ok);
    fmi2FreeInstance(b);
}

#[test]
fn fmi3_handles_freed_twice_used_after_free_or_null_are_errors_not_crashes() {
    let cfg = SimConfig::default();
    let (dir, token) = resources(&cfg);
    let c = instantiate3(dir.path(), &token);
    assert!(!c.is_null());
    fmi3FreeInstance(c);
    fmi3FreeInstance(c);
    for h in [c, std::ptr::null_mut()] {
        let (mut v, mut flag, vr) = (0.0, false, 1u32);
        assert_eq!(fmi3EnterInitializationMode(h, false, 0.0, 0.0, false, 0.0), Status::Error);
        assert_eq!(fmi3ExitInitializationMode(h), Status::Error);
        assert_eq!(fmi3EnterStepMode(h), Status::Error);
        // SAFETY: valid pointers; the handle is what is tested.
        unsafe {
            assert_eq!(fmi3GetFloat64(h, &vr, 1, &mut v, 1), Status::Error);
            assert_eq!(fmi3SetFloat64(h, &vr, 1, &1.0, 1), Status::Error);
            let s = fmi3DoStep(h, 0.0, 1e-3, true, &mut flag, &mut flag, &mut flag, &mut v);
            assert_eq!(s, Status::Error);
        }
        assert_eq!(fmi3SetDebugLogging(h, true, 0, std::ptr::null()), Status::Error);
        assert_eq!(fmi3Terminate(h), Status::Error);
        assert_eq!(fmi3Reset(h), Status::Error);
        assert_eq!(fmi3GetFMUState(h), Status::Error);
    }
    fmi3FreeInstance(std::ptr::null_mut());
}

#[test]
fn non_finite_communication_points_are_errors_at_once_in_both_versions() {
    let cfg = SimConfig::default();
    let (dir, token) = resources(&cfg);
    let c = instantiate2(dir.path(), &token);
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
    assert_eq!(fmi2EnterInitializationMode(c), Status::Ok);
    assert_eq!(fmi2ExitInitializationMode(c), Status::Ok);
    let start = std::time::Instant::now();
    assert_eq!(fmi2DoStep(c, f64::NAN, 1e-3, 1), Status::Error);
    assert!(logged("doStep at communication point t = NaN"));
    assert_eq!(fmi2DoStep(c, f64::INFINITY, 1e-3, 1), Status::Error);
    assert!(logged("doStep at communication point t = inf"));
    assert_eq!(fmi2DoStep(c, 0.0, f64::NAN, 1), Status::Error);
    assert_eq!(fmi2DoStep(c, 0.0, f64::INFINITY, 1), Status::Error);
    assert!(logged("communication step size = inf"));
    assert!(start.elapsed().as_secs_f64() < 1.0, "refused before any work");
    assert_eq!(fmi2DoStep(c, 0.0, 1e-3, 1), Status::Ok, "the instance steps on");
    fmi2FreeInstance(c);

    let c = instantiate3(dir.path(), &token);
    assert_eq!(fmi3EnterInitializationMode(c, false, 0.0, 0.0, false, 0.0), Status::Ok);
    assert_eq!(fmi3ExitInitializationMode(c), Status::Ok);
    let (mut flag, mut last) = (false, -1.0);
    let start = std::time::Instant::now();
    for (t, h) in [(f64::NAN, 1e-3), (f64::INFINITY, 1e-3), (0.0, f64::NAN), (0.0, f64::INFINITY)] {
        // SAFETY: valid out-pointers.
        let s = unsafe { fmi3DoStep(c, t, h, true, &mut flag, &mut flag, &mut flag, &mut last) };
        assert_eq!(s, Status::Error, "t = {t}, h = {h}");
        assert_eq!(last, 0.0, "nothing advanced");
    }
    assert!(start.elapsed().as_secs_f64() < 1.0, "refused before any work");
    fmi3FreeInstance(c);
}

#[test]
fn an_absurd_communication_step_is_an_error_in_bounded_time() {
    // h_max bounds the solver's step: a step of 1e6 s needs 1e10 of them, refused at once.
    let mut cfg = SimConfig::default();
    cfg.solver.h_max = 1e-4;
    let (dir, token) = resources(&cfg);
    let start = std::time::Instant::now();
    let c = instantiate2(dir.path(), &token);
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
    assert_eq!(fmi2EnterInitializationMode(c), Status::Ok);
    assert_eq!(fmi2ExitInitializationMode(c), Status::Ok);
    assert_eq!(fmi2DoStep(c, 0.0, 1e6, 1), Status::Error);
    assert!(logged("needs at least 1.000e10 solver steps"));
    fmi2FreeInstance(c);
    let c = instantiate3(dir.path(), &token);
    assert_eq!(fmi3EnterInitializationMode(c, false, 0.0, 0.0, false, 0.0), Status::Ok);
    assert_eq!(fmi3ExitInitializationMode(c), Status::Ok);
    let (mut flag, mut last) = (false, -1.0);
    // SAFETY: valid out-pointers.
    let s = unsafe { fmi3DoStep(c, 0.0, 1e6, true, &mut flag, &mut flag, &mut flag, &mut last) };
    assert_eq!(s, Status::Error);
    assert!(start.elapsed().as_secs_f64() < 2.0, "refused before any work");
    fmi3FreeInstance(c);
}
