//! What the FMI 2 and FMI 3 layers share: an instance with its host's logger, the guard
//! that turns a panic into an error status instead of unwinding into the host, the
//! registry of live instances, and the conversions of C strings and resource locations.
//!
//! **Handles.** Every pointer this library hands out is entered in a registry and removed
//! when the host frees it; every entry point looks the pointer up before touching it. A
//! handle freed already (a double free, a call after free), a null one or one this library
//! never made is answered with an error status (ignored by the free functions), without
//! reading the memory behind it. So that a stale handle does not reach a newer instance at
//! the same address, the memory of the last [`QUARANTINE`] freed instances is held back
//! from the allocator.

use crate::instance::Instance;
use std::collections::{BTreeSet, VecDeque};
use std::ffi::{CStr, CString, c_char, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

/// Freed instances whose memory is held back, so that their addresses are not reused by
/// the next instances [–].
pub const QUARANTINE: usize = 32;

/// The live handles, and the freed instances held back.
struct Registry {
    /// Addresses of the components the host holds.
    live: BTreeSet<usize>,
    /// Freed components, oldest first, kept allocated (their addresses are not live).
    retired: VecDeque<Box<Component>>,
}

// SAFETY: the retired components are never used again, only dropped; dropping one reads
// none of the host's pointers its logger holds, so it may happen on any thread.
unsafe impl Send for Registry {}

static REGISTRY: Mutex<Registry> =
    Mutex::new(Registry { live: BTreeSet::new(), retired: VecDeque::new() });

/// The registry, also after a panic while it was held (its sets stay consistent: every
/// change is one insert or remove).
fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Whether `c` is a handle this library returned and the host has not freed.
pub fn is_live(c: *const c_void) -> bool {
    !c.is_null() && registry().live.contains(&(c as usize))
}

/// Hand `comp` to the host: its handle, entered in the registry.
pub fn register(comp: Component) -> *mut c_void {
    let c = Box::into_raw(Box::new(comp)) as *mut c_void;
    registry().live.insert(c as usize);
    c
}

/// Status codes, numbered as both FMI versions number them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(i32)]
pub enum Status {
    /// All is well.
    Ok = 0,
    /// Something worth a look, the call went through.
    Warning = 1,
    /// The call was refused, the instance is usable.
    Discard = 2,
    /// The call failed; the instance must be reset or freed.
    Error = 3,
    /// The instance is unusable.
    Fatal = 4,
}

/// FMI 2's logger: `(environment, instance name, status, category, format, ...)`.
pub type Fmi2Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, i32, *const c_char, *const c_char, ...);
/// FMI 3's logger: `(environment, status, category, message)`.
pub type Fmi3Logger = unsafe extern "C" fn(*mut c_void, i32, *const c_char, *const c_char);

/// How an instance reports to its host.
#[derive(Clone, Copy, Debug)]
pub enum Logger {
    /// No logger given.
    None,
    /// FMI 2 logger with its component environment.
    Fmi2(Fmi2Logger, *mut c_void),
    /// FMI 3 logger with its instance environment.
    Fmi3(Fmi3Logger, *mut c_void),
}

/// An instance as the host holds it.
pub struct Component {
    /// The model.
    pub inst: Instance,
    /// The host's name for the instance.
    pub name: CString,
    /// The host's logger.
    pub logger: Logger,
    /// Whether the host asked for debug messages.
    pub logging_on: bool,
}

impl Component {
    /// Send `message` to the host's logger (information only when logging is on).
    pub fn log(&self, status: Status, category: &str, message: &str) {
        if status == Status::Ok && !self.logging_on {
            return;
        }
        log_to(self.logger, &self.name, status, category, message);
    }

    /// Report `result` (logging an error) as a status.
    pub fn report(&self, result: Result<(), String>) -> Status {
        match result {
            Ok(()) => Status::Ok,
            Err(e) => {
                self.log(Status::Error, "logStatusError", &e);
                Status::Error
            }
        }
    }
}

/// Send one message to a logger.
pub fn log_to(logger: Logger, name: &CStr, status: Status, category: &str, message: &str) {
    let category = CString::new(category).unwrap_or_default();
    let message = CString::new(message.replace('\0', " ")).unwrap_or_default();
    // SAFETY: the host gave these callbacks and environments for exactly this use; the
    // strings live until the call returns. FMI 2's message is a format: it is passed as
    // the argument of "%s" so that a '%' in it is printed as is.
    unsafe {
        match logger {
            Logger::None => {}
            Logger::Fmi2(f, env) => f(
                env,
                name.as_ptr(),
                status as i32,
                category.as_ptr(),
                c"%s".as_ptr(),
                message.as_ptr(),
            ),
            Logger::Fmi3(f, env) => f(env, status as i32, category.as_ptr(), message.as_ptr()),
        }
    }
}

/// Run `f` on the component behind `c`, turning a null, freed or unknown handle, an error
/// or a panic into an error status (logged when the component can still be reached).
pub fn guarded(c: *mut c_void, f: impl FnOnce(&mut Component) -> Status) -> Status {
    if !is_live(c) {
        return Status::Error;
    }
    // SAFETY: `c` is in the registry: a component this library made and the host has not
    // freed; the host calls one instance from one thread at a time (the FMI contract), so
    // it is not freed while `f` runs.
    let comp = unsafe { &mut *(c as *mut Component) };
    // The name stays where it is while `f` runs (only freeing moves the component).
    let (logger, name) = (comp.logger, comp.name.as_ptr());
    match catch_unwind(AssertUnwindSafe(|| f(comp))) {
        Ok(status) => status,
        Err(panic) => {
            let what = panic_message(&panic);
            log_to(
                logger,
                // SAFETY: the component's name, alive as said above.
                unsafe { CStr::from_ptr(name) },
                Status::Fatal,
                "logStatusFatal",
                &format!("internal error: {what}"),
            );
            Status::Fatal
        }
    }
}

/// The text of a caught panic.
pub fn panic_message(panic: &Box<dyn std::any::Any + Send>) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panic".to_string())
}

/// A C string argument as text (empty for null).
///
/// # Safety
/// `s` is null or a NUL-terminated string valid for the call.
pub unsafe fn text(s: *const c_char) -> String {
    if s.is_null() {
        return String::new();
    }
    // SAFETY: as the caller promises.
    unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned()
}

/// A resource location as a folder: a `file:` URI (FMI 2; `file:///p`, `file://localhost/p`
/// or `file:/p`, percent-encoded) or a plain path (FMI 3).
pub fn resource_dir(location: &str) -> PathBuf {
    let Some(rest) = location.strip_prefix("file:") else {
        return PathBuf::from(location);
    };
    let path = rest
        .strip_prefix("//localhost")
        .or_else(|| rest.strip_prefix("//").filter(|p| p.starts_with('/')))
        .unwrap_or(rest);
    PathBuf::from(percent_decode(path))
}

fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Build a component for a host, or report why not to its logger: the configuration is
/// read from the resources folder and its token compared with the host's.
pub fn instantiate(
    name: &str,
    token: &str,
    resources: &str,
    logger: Logger,
    logging_on: bool,
) -> *mut c_void {
    let cname = CString::new(name.replace('\0', " ")).unwrap_or_default();
    let built = catch_unwind(|| -> Result<Component, String> {
        let dir = resource_dir(resources);
        let path = dir.join(crate::config::CONFIG_FILE);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        let expected = crate::config::token(&text);
        if !token.is_empty() && token != expected {
            return Err(format!(
                "token {token} does not match this FMU's {expected} (modelDescription.xml and resources/ are from different exports)"
            ));
        }
        let source = path.display().to_string();
        let cfg = crate::config::from_toml(&text, &source)?;
        let fixed = crate::config::fixed_substeps(&text, &source)?;
        let inst = Instance::new(cfg).with_fixed_substeps(fixed)?;
        Ok(Component { inst, name: cname.clone(), logger, logging_on })
    });
    match built {
        Ok(Ok(comp)) => register(comp),
        Ok(Err(e)) => {
            log_to(logger, &cname, Status::Error, "logStatusError", &e);
            std::ptr::null_mut()
        }
        Err(panic) => {
            let what = panic_message(&panic);
            log_to(
                logger,
                &cname,
                Status::Fatal,
                "logStatusFatal",
                &format!("internal error: {what}"),
            );
            std::ptr::null_mut()
        }
    }
}

/// Free a component made by [`instantiate`]; a null, freed or unknown handle is ignored.
/// The component is dropped at once; its memory is released once [`QUARANTINE`] later
/// frees have passed.
pub fn free(c: *mut c_void) {
    let mut reg = registry();
    if !reg.live.remove(&(c as usize)) {
        return;
    }
    // SAFETY: `c` was live: a component made by `register` from a Box, freed only here,
    // once (it has just left the registry).
    let comp = unsafe { Box::from_raw(c as *mut Component) };
    reg.retired.push_back(comp);
    let released = if reg.retired.len() > QUARANTINE { reg.retired.pop_front() } else { None };
    drop(reg);
    drop(released);
}

/// The slices behind a value-reference array and a value array of `n` entries (empty for
/// n = 0 or null pointers).
///
/// # Safety
/// Non-null pointers point to at least `n` elements, valid for the call.
pub unsafe fn slices<'a, T>(vr: *const u32, values: *mut T, n: usize) -> (&'a [u32], &'a mut [T]) {
    if n == 0 || vr.is_null() || values.is_null() {
        return (&[], &mut []);
    }
    // SAFETY: as the caller promises.
    unsafe { (std::slice::from_raw_parts(vr, n), std::slice::from_raw_parts_mut(values, n)) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_a_fatal_status_not_an_unwind_into_the_host() {
        let comp = Component {
            inst: Instance::new(hd_model::SimConfig::default()),
            name: CString::new("p").unwrap(),
            logger: Logger::None,
            logging_on: false,
        };
        let c = register(comp);
        assert_eq!(guarded(c, |_| panic!("boom")), Status::Fatal);
        assert_eq!(guarded(c, |_| Status::Ok), Status::Ok);
        assert_eq!(guarded(std::ptr::null_mut(), |_| Status::Ok), Status::Error);
        free(c);
        assert_eq!(guarded(c, |_| Status::Ok), Status::Error, "freed");
        free(c);
        let mut unknown = 0u64;
        let stranger = &mut unknown as *mut u64 as *mut c_void;
        assert_eq!(guarded(stranger, |_| Status::Ok), Status::Error, "never made here");
        free(stranger);
        assert_eq!(unknown, 0, "an unknown handle is not written through");
    }

    #[test]
    fn resource_uris_become_folders() {
        assert_eq!(
            resource_dir("file:///tmp/a%20b/resources"),
            PathBuf::from("/tmp/a b/resources")
        );
        assert_eq!(resource_dir("file://localhost/x/resources/"), PathBuf::from("/x/resources/"));
        assert_eq!(resource_dir("file:/x/resources"), PathBuf::from("/x/resources"));
        assert_eq!(resource_dir("/plain/path/"), PathBuf::from("/plain/path/"));
    }
}
