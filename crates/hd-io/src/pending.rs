//! Files that must not outlive an interrupted process: temporaries being written and the
//! lock of a running study. Each is registered here while it exists; on SIGINT, SIGTERM
//! or SIGHUP the handler of [`remove_on_signal`] deletes every registered file and exits
//! with 128 + the signal number (130 for Ctrl-C, 143 for `kill`).
//!
//! A group of temporaries is renamed into place while the registry is locked
//! ([`with_registry`]), so a signal arrives either before the group's renames (all
//! temporaries removed, earlier results untouched) or after them (all new files in place),
//! never between two of them.
//!
//! Folders the process creates for its outputs ([`create_dir_all`]) are registered too: on
//! an interrupt, and on a failed command ([`remove_empty_created_dirs`]), those still empty
//! are removed, so a run that produced nothing leaves no empty `--out` folder behind.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// The registered files.
static REGISTRY: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The registry, locked (a panic elsewhere while it was held does not make it unusable).
pub(crate) fn with_registry<T>(f: impl FnOnce(&mut Vec<PathBuf>) -> T) -> T {
    let mut guard: MutexGuard<'_, Vec<PathBuf>> =
        REGISTRY.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    f(&mut guard)
}

/// Folders this process created, in creation order (parents before children).
static CREATED_DIRS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Create `dir` and its missing parents, remembering each folder created here, so that
/// an interrupted or failed command can remove the ones it left empty.
pub fn create_dir_all(dir: &Path) -> std::io::Result<()> {
    let mut missing = Vec::new();
    let mut cur = Some(dir);
    while let Some(d) = cur.filter(|d| !d.as_os_str().is_empty()) {
        if d.exists() {
            break;
        }
        missing.push(d.to_path_buf());
        cur = d.parent();
    }
    std::fs::create_dir_all(dir)?;
    let mut created = CREATED_DIRS.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    for d in missing.into_iter().rev() {
        if !created.contains(&d) {
            created.push(d);
        }
    }
    Ok(())
}

/// Remove the folders this process created that are still empty (children first); returns
/// how many were removed. A folder holding anything is kept.
pub fn remove_empty_created_dirs() -> usize {
    let mut created = CREATED_DIRS.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let mut removed = 0;
    while let Some(d) = created.pop() {
        if std::fs::remove_dir(&d).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Register `path` for removal if the process is interrupted.
pub fn register(path: &Path) {
    with_registry(|r| r.push(path.to_path_buf()));
}

/// Forget `path` (it was renamed into place or removed).
pub fn unregister(path: &Path) {
    with_registry(|r| {
        if let Some(k) = r.iter().rposition(|p| p == path) {
            r.swap_remove(k);
        }
    });
}

/// Install the handler that removes every registered file on SIGINT, SIGTERM or SIGHUP,
/// then exits with 128 + the signal number. Call once, at the start of `main`.
pub fn remove_on_signal() -> std::io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new().name("hdw-signals".into()).spawn(move || {
        if let Some(sig) = signals.forever().next() {
            // Held until the process ends: no rename of a group can start after this.
            let mut guard = REGISTRY.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
            let removed = guard.drain(..).filter(|p| std::fs::remove_file(p).is_ok()).count();
            remove_empty_created_dirs();
            let name = match sig {
                SIGINT => "SIGINT",
                SIGTERM => "SIGTERM",
                _ => "SIGHUP",
            };
            eprintln!(
                "\ninterrupted ({name}): removed {removed} unfinished file(s); results committed earlier are kept"
            );
            std::process::exit(128 + sig);
        }
    })?;
    Ok(())
}

/// A file removed when this guard is dropped or the process is interrupted (a lock file).
#[derive(Debug)]
pub struct RemoveOnDrop(PathBuf);

impl RemoveOnDrop {
    /// Take charge of the existing file `path`.
    pub fn new(path: &Path) -> Self {
        register(path);
        RemoveOnDrop(path.to_path_buf())
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for RemoveOnDrop {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
        unregister(&self.0);
    }
}
