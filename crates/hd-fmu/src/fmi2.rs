//! The FMI 2.0 co-simulation functions (fmi2Functions.h). Every function that takes an
//! instance runs under [`guarded`]: a handle that is null, freed or unknown answers
//! `fmi2Error` without being read, a failure is logged and returned as `fmi2Error`, a
//! panic as `fmi2Fatal`, and nothing unwinds into the host. Features the model description
//! does not declare (FMU state, directional derivatives, input derivatives) answer
//! `fmi2Error` with a message.

use crate::ffi::{Fmi2Logger, Logger, Status, free, guarded, instantiate, slices, text};
use std::ffi::{c_char, c_int, c_void};

/// fmi2CallbackFunctions.
#[repr(C)]
pub struct Fmi2CallbackFunctions {
    /// Logger.
    pub logger: Option<Fmi2Logger>,
    /// Allocator (unused: the library allocates with Rust's allocator).
    pub allocate_memory: *const c_void,
    /// Deallocator (unused).
    pub free_memory: *const c_void,
    /// Asynchronous step callback (unused).
    pub step_finished: *const c_void,
    /// The host's environment, passed back to the logger.
    pub component_environment: *mut c_void,
}

const CO_SIMULATION: c_int = 1;
/// fmi2StatusKind's fmi2LastSuccessfulTime.
const LAST_SUCCESSFUL_TIME: c_int = 2;
/// fmi2StatusKind's fmi2Terminated.
const TERMINATED: c_int = 3;

fn unsupported(c: *mut c_void, what: &str) -> Status {
    guarded(c, |comp| {
        comp.log(Status::Error, "logStatusError", &format!("{what} is not supported by this FMU"));
        Status::Error
    })
}

/// `"default"`.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `"2.0"`.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// Create an instance from the FMU's resources; null (with a logged reason) on failure.
///
/// # Safety
/// Strings are null or NUL-terminated; `functions` is null or valid for the instance's life.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resource_location: *const c_char,
    functions: *const Fmi2CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> *mut c_void {
    // SAFETY: as the caller promises.
    let (name, guid, resources) =
        unsafe { (text(instance_name), text(guid), text(resource_location)) };
    // SAFETY: as the caller promises.
    let logger = match unsafe { functions.as_ref() } {
        Some(f) => f.logger.map_or(Logger::None, |l| Logger::Fmi2(l, f.component_environment)),
        None => Logger::None,
    };
    if fmu_type != CO_SIMULATION {
        let cname = std::ffi::CString::new(name).unwrap_or_default();
        crate::ffi::log_to(
            logger,
            &cname,
            Status::Error,
            "logStatusError",
            "this FMU supports co-simulation only (fmuType = fmi2CoSimulation)",
        );
        return std::ptr::null_mut();
    }
    instantiate(&name, &guid, &resources, logger, logging_on != 0)
}

/// Free an instance from [`fmi2Instantiate`]; a null handle, one freed already or one
/// this library did not make is ignored (nothing behind it is read).
#[unsafe(no_mangle)]
pub extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    free(c)
}

/// Switch debug logging on or off.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    logging_on: c_int,
    _n_categories: usize,
    _categories: *const *const c_char,
) -> Status {
    guarded(c, |comp| {
        comp.logging_on = logging_on != 0;
        Status::Ok
    })
}

/// The start time becomes the model's time 0; the tolerance is the exported solver's.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    _tolerance_defined: c_int,
    _tolerance: f64,
    start_time: f64,
    _stop_time_defined: c_int,
    _stop_time: f64,
) -> Status {
    guarded(c, |comp| {
        let r = comp.inst.set_start_time(start_time);
        comp.report(r)
    })
}

/// Enter initialisation mode.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> Status {
    guarded(c, |comp| {
        let r = comp.inst.enter_initialization();
        comp.report(r)
    })
}

/// Leave initialisation mode: the parameters are checked and the drive assembled at rest.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Status {
    guarded(c, |comp| {
        let r = comp.inst.exit_initialization();
        comp.report(r)
    })
}

/// Terminate.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2Terminate(c: *mut c_void) -> Status {
    guarded(c, |comp| {
        let r = comp.inst.terminate();
        comp.report(r)
    })
}

/// Back to the instantiated state with the start values.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2Reset(c: *mut c_void) -> Status {
    guarded(c, |comp| {
        comp.inst.reset();
        Status::Ok
    })
}

/// Read real variables.
///
/// # Safety
/// `vr` and `value` point to `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    value: *mut f64,
) -> Status {
    // SAFETY: as the caller promises.
    let (vr, value) = unsafe { slices(vr, value, nvr) };
    guarded(c, |comp| {
        let r = comp.inst.get_reals(vr, value);
        comp.report(r)
    })
}

/// Set real variables (inputs and parameters; a value outside a parameter's range is an
/// error naming it).
///
/// # Safety
/// `vr` and `value` point to `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    value: *const f64,
) -> Status {
    // SAFETY: as the caller promises.
    let (vr, value) = unsafe { slices(vr, value as *mut f64, nvr) };
    guarded(c, |comp| {
        let r = comp.inst.set_reals(vr, value);
        comp.report(r)
    })
}

/// Integer, Boolean and String variables: the FMU has none, so any reference is unknown.
macro_rules! no_variables_of_type {
    ($($name:ident: $t:ty),* $(,)?) => {$(
        /// The FMU has no variables of this type: any value reference is an error.
        #[unsafe(no_mangle)]
        pub extern "C" fn $name(c: *mut c_void, _vr: *const u32, nvr: usize, _value: $t) -> Status {
            guarded(c, |comp| {
                if nvr == 0 {
                    return Status::Ok;
                }
                comp.log(Status::Error, "logStatusError", concat!(stringify!($name), ": this FMU has only Real variables"));
                Status::Error
            })
        }
    )*};
}

no_variables_of_type!(
    fmi2GetInteger: *mut c_int,
    fmi2GetBoolean: *mut c_int,
    fmi2GetString: *mut *const c_char,
    fmi2SetInteger: *const c_int,
    fmi2SetBoolean: *const c_int,
    fmi2SetString: *const *const c_char,
);

/// First derivatives of the inputs over the next step (the FMU interpolates them
/// linearly; higher orders are an error).
///
/// # Safety
/// `vr`, `order` and `value` point to `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    order: *const c_int,
    value: *const f64,
) -> Status {
    // SAFETY: as the caller promises.
    let (vr, value) = unsafe { slices(vr, value as *mut f64, nvr) };
    let orders: &[c_int] = if nvr == 0 || order.is_null() {
        &[]
    } else {
        // SAFETY: as the caller promises.
        unsafe { std::slice::from_raw_parts(order, nvr) }
    };
    guarded(c, |comp| {
        let r = comp.inst.set_input_rates(vr, orders, value);
        comp.report(r)
    })
}

/// Advance by one communication step with the inputs held.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2DoStep(c: *mut c_void, t: f64, h: f64, _no_set_prior: c_int) -> Status {
    guarded(c, |comp| {
        let r = comp.inst.do_step(t, h);
        comp.report(r)
    })
}

/// Steps run synchronously: there is nothing to cancel.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2CancelStep(c: *mut c_void) -> Status {
    unsupported(c, "fmi2CancelStep (steps are synchronous)")
}

/// Status queries of an asynchronous step: steps are synchronous.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetStatus(c: *mut c_void, _kind: c_int, _value: *mut c_int) -> Status {
    guarded(c, |_| Status::Discard)
}

/// The last successful time (the time reached).
///
/// # Safety
/// `value` is null or points to one real.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, kind: c_int, value: *mut f64) -> Status {
    guarded(c, |comp| {
        if kind != LAST_SUCCESSFUL_TIME || value.is_null() {
            return Status::Discard;
        }
        // SAFETY: as the caller promises.
        unsafe { *value = comp.inst.time() };
        Status::Ok
    })
}

/// Integer status: none.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetIntegerStatus(c: *mut c_void, _kind: c_int, _value: *mut c_int) -> Status {
    guarded(c, |_| Status::Discard)
}

/// Whether the FMU asks to stop (never).
///
/// # Safety
/// `value` is null or points to one fmi2Boolean.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: *mut c_void,
    kind: c_int,
    value: *mut c_int,
) -> Status {
    guarded(c, |_| {
        if kind != TERMINATED || value.is_null() {
            return Status::Discard;
        }
        // SAFETY: as the caller promises.
        unsafe { *value = 0 };
        Status::Ok
    })
}

/// String status: none.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetStringStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut *const c_char,
) -> Status {
    guarded(c, |_| Status::Discard)
}

/// Declared-off features: each answers fmi2Error with a message.
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
    fmi2GetFMUstate,
    fmi2SetFMUstate,
    fmi2FreeFMUstate,
    fmi2SerializedFMUstateSize,
    fmi2SerializeFMUstate,
    fmi2DeSerializeFMUstate,
    fmi2GetDirectionalDerivative,
    fmi2GetRealOutputDerivatives,
);
