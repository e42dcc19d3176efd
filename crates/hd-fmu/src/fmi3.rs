//! The FMI 3.0 co-simulation functions (fmi3Functions.h). Like the FMI 2 layer, every
//! instance function runs under [`guarded`] (a null, freed or unknown handle answers
//! `fmi3Error` without being read); model exchange, scheduled execution, event
//! mode, clocks, FMU state and derivatives are declared off and answer `fmi3Error`.
//! The FMU's variables are all Float64, so the other types' getters and setters accept
//! only empty lists.

use crate::ffi::{Fmi3Logger, Logger, Status, free, guarded, instantiate, slices, text};
use std::ffi::{c_char, c_void};

fn unsupported(c: *mut c_void, what: &str) -> Status {
    guarded(c, |comp| {
        comp.log(Status::Error, "logStatusError", &format!("{what} is not supported by this FMU"));
        Status::Error
    })
}

/// `"3.0"`.
#[unsafe(no_mangle)]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

/// Create a co-simulation instance from the FMU's resources; null (with a logged reason)
/// on failure.
///
/// # Safety
/// Strings are null or NUL-terminated; the logger and environment stay valid for the
/// instance's life.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instance_name: *const c_char,
    token: *const c_char,
    resource_path: *const c_char,
    _visible: bool,
    logging_on: bool,
    _event_mode_used: bool,
    _early_return_allowed: bool,
    _required_intermediate: *const u32,
    _n_required_intermediate: usize,
    environment: *mut c_void,
    log_message: Option<Fmi3Logger>,
    _intermediate_update: *const c_void,
) -> *mut c_void {
    // SAFETY: as the caller promises.
    let (name, token, resources) =
        unsafe { (text(instance_name), text(token), text(resource_path)) };
    let logger = log_message.map_or(Logger::None, |l| Logger::Fmi3(l, environment));
    instantiate(&name, &token, &resources, logger, logging_on)
}

/// Model exchange is not offered: null.
#[unsafe(no_mangle)]
pub extern "C" fn fmi3InstantiateModelExchange() -> *mut c_void {
    std::ptr::null_mut()
}

/// Scheduled execution is not offered: null.
#[unsafe(no_mangle)]
pub extern "C" fn fmi3InstantiateScheduledExecution() -> *mut c_void {
    std::ptr::null_mut()
}

/// Free an instance from [`fmi3InstantiateCoSimulation`]; a null handle, one freed already or one
/// this library did not make is ignored (nothing behind it is read).
#[unsafe(no_mangle)]
pub extern "C" fn fmi3FreeInstance(c: *mut c_void) {
    free(c)
}

/// Switch debug logging on or off.
#[unsafe(no_mangle)]
pub extern "C" fn fmi3SetDebugLogging(
    c: *mut c_void,
    logging_on: bool,
    _n_categories: usize,
    _categories: *const *const c_char,
) -> Status {
    guarded(c, |comp| {
        comp.logging_on = logging_on;
        Status::Ok
    })
}

/// Enter initialisation mode; the start time becomes the model's time 0, the tolerance is
/// the exported solver's.
#[unsafe(no_mangle)]
pub extern "C" fn fmi3EnterInitializationMode(
    c: *mut c_void,
    _tolerance_defined: bool,
    _tolerance: f64,
    start_time: f64,
    _stop_time_defined: bool,
    _stop_time: f64,
) -> Status {
    guarded(c, |comp| {
        let r =
            comp.inst.set_start_time(start_time).and_then(|()| comp.inst.enter_initialization());
        comp.report(r)
    })
}

/// Leave initialisation mode (into step mode): the parameters are checked and the drive
/// assembled at rest.
#[unsafe(no_mangle)]
pub extern "C" fn fmi3ExitInitializationMode(c: *mut c_void) -> Status {
    guarded(c, |comp| {
        let r = comp.inst.exit_initialization();
        comp.report(r)
    })
}

/// Already in step mode after initialisation (no event mode): nothing to do.
#[unsafe(no_mangle)]
pub extern "C" fn fmi3EnterStepMode(c: *mut c_void) -> Status {
    guarded(c, |_| Status::Ok)
}

/// Terminate.
#[unsafe(no_mangle)]
pub extern "C" fn fmi3Terminate(c: *mut c_void) -> Status {
    guarded(c, |comp| {
        let r = comp.inst.terminate();
        comp.report(r)
    })
}

/// Back to the instantiated state with the start values.
#[unsafe(no_mangle)]
pub extern "C" fn fmi3Reset(c: *mut c_void) -> Status {
    guarded(c, |comp| {
        comp.inst.reset();
        Status::Ok
    })
}

/// Read Float64 variables (`time` has value reference 0).
///
/// # Safety
/// `vr` points to `nvr` and `values` to `n_values` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFloat64(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    values: *mut f64,
    n_values: usize,
) -> Status {
    // SAFETY: as the caller promises.
    let (vr, values) = unsafe { slices(vr, values, nvr.min(n_values)) };
    guarded(c, |comp| {
        let r = comp.inst.get_reals(vr, values);
        comp.report(r)
    })
}

/// Set Float64 variables (inputs and parameters; a value outside a parameter's range is
/// an error naming it).
///
/// # Safety
/// `vr` points to `nvr` and `values` to `n_values` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFloat64(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    values: *const f64,
    n_values: usize,
) -> Status {
    // SAFETY: as the caller promises.
    let (vr, values) = unsafe { slices(vr, values as *mut f64, nvr.min(n_values)) };
    guarded(c, |comp| {
        let r = comp.inst.set_reals(vr, values);
        comp.report(r)
    })
}

/// Getters and setters of types the FMU has no variables of: only an empty list is fine.
macro_rules! no_variables_of_type {
    ($($name:ident),* $(,)?) => {$(
        /// The FMU has no variables of this type: any value reference is an error.
        #[unsafe(no_mangle)]
        pub extern "C" fn $name(c: *mut c_void, _vr: *const u32, nvr: usize) -> Status {
            guarded(c, |comp| {
                if nvr == 0 {
                    return Status::Ok;
                }
                comp.log(Status::Error, "logStatusError", concat!(stringify!($name), ": this FMU has only Float64 variables"));
                Status::Error
            })
        }
    )*};
}

no_variables_of_type!(
    fmi3GetFloat32,
    fmi3GetInt8,
    fmi3GetUInt8,
    fmi3GetInt16,
    fmi3GetUInt16,
    fmi3GetInt32,
    fmi3GetUInt32,
    fmi3GetInt64,
    fmi3GetUInt64,
    fmi3GetBoolean,
    fmi3GetString,
    fmi3GetBinary,
    fmi3GetClock,
    fmi3SetFloat32,
    fmi3SetInt8,
    fmi3SetUInt8,
    fmi3SetInt16,
    fmi3SetUInt16,
    fmi3SetInt32,
    fmi3SetUInt32,
    fmi3SetInt64,
    fmi3SetUInt64,
    fmi3SetBoolean,
    fmi3SetString,
    fmi3SetBinary,
    fmi3SetClock,
);

/// Advance by one communication step with the inputs held; never returns early, never
/// asks for event handling or termination.
///
/// # Safety
/// The flag and time pointers are null or point to one value each.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DoStep(
    c: *mut c_void,
    t: f64,
    h: f64,
    _no_set_prior: bool,
    event_handling_needed: *mut bool,
    terminate_simulation: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> Status {
    guarded(c, |comp| {
        let r = comp.inst.do_step(t, h);
        // SAFETY: as the caller promises.
        unsafe {
            for flag in [event_handling_needed, terminate_simulation, early_return] {
                if let Some(f) = flag.as_mut() {
                    *f = false;
                }
            }
            if let Some(last) = last_successful_time.as_mut() {
                *last = comp.inst.time();
            }
        }
        comp.report(r)
    })
}

/// Declared-off features: each answers fmi3Error with a message.
macro_rules! unsupported_fns {
    ($($name:ident),* $(,)?) => {$(
        /// Not supported (the model description declares it off).
        #[unsafe(no_mangle)]
        pub extern "C" fn $name(c: *mut c_void) -> Status {
            unsupported(c, stringify!($name))
        }
    )*};
}

unsupported_fns!(
    fmi3EnterEventMode,
    fmi3GetNumberOfVariableDependencies,
    fmi3GetVariableDependencies,
    fmi3GetFMUState,
    fmi3SetFMUState,
    fmi3FreeFMUState,
    fmi3SerializedFMUStateSize,
    fmi3SerializeFMUState,
    fmi3DeserializeFMUState,
    fmi3GetDirectionalDerivative,
    fmi3GetAdjointDerivative,
    fmi3EnterConfigurationMode,
    fmi3ExitConfigurationMode,
    fmi3GetIntervalDecimal,
    fmi3GetIntervalFraction,
    fmi3GetShiftDecimal,
    fmi3GetShiftFraction,
    fmi3SetIntervalDecimal,
    fmi3SetIntervalFraction,
    fmi3SetShiftDecimal,
    fmi3SetShiftFraction,
    fmi3EvaluateDiscreteStates,
    fmi3UpdateDiscreteStates,
    fmi3EnterContinuousTimeMode,
    fmi3CompletedIntegratorStep,
    fmi3SetTime,
    fmi3SetContinuousStates,
    fmi3GetContinuousStateDerivatives,
    fmi3GetEventIndicators,
    fmi3GetContinuousStates,
    fmi3GetNominalsOfContinuousStates,
    fmi3GetNumberOfEventIndicators,
    fmi3GetNumberOfContinuousStates,
    fmi3GetOutputDerivatives,
    fmi3ActivateModelPartition,
);
