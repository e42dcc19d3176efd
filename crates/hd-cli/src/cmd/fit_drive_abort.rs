//! What `hdw fit drive` leaves behind when it is aborted (SIGABRT: an allocation that
//! failed under a memory cap, an `abort()`, `kill -ABRT`). An interrupt (SIGINT, SIGTERM,
//! SIGHUP) or an error is handled by [`hd_io::pending`]; an abort cannot be, since the
//! process dies as the handler returns. So before the fit starts, the paths to clean are
//! set aside ([`arm`]) and a handler that only calls `unlink` and `rmdir`
//! (async-signal-safe) removes them: the fit's lock file, and the `--out` folder and the
//! parents the fit created, each only if empty. A folder that existed before keeps its
//! content; outputs land together (at the end) or not at all, so an abort before then
//! leaves no `--out` folder the fit created.

#[cfg(unix)]
mod imp {
    use std::ffi::{CString, c_char, c_int};
    use std::os::unix::ffi::OsStrExt;
    use std::path::Path;
    use std::sync::OnceLock;

    /// SIGABRT's number (6 on Linux and the BSDs).
    const SIGABRT: c_int = 6;
    /// `SIG_DFL`.
    const SIG_DFL: usize = 0;

    unsafe extern "C" {
        fn signal(signum: c_int, handler: usize) -> usize;
        fn raise(sig: c_int) -> c_int;
        fn unlink(path: *const c_char) -> c_int;
        fn rmdir(path: *const c_char) -> c_int;
    }

    /// The lock file, then the folders created (deepest first).
    static PATHS: OnceLock<(CString, Vec<CString>)> = OnceLock::new();

    extern "C" fn on_abort(_: c_int) {
        if let Some((lock, dirs)) = PATHS.get() {
            // SAFETY: NUL-terminated paths that live as long as the process; unlink and
            // rmdir are async-signal-safe and fail harmlessly on a path that is not there
            // or a folder that is not empty.
            unsafe {
                unlink(lock.as_ptr());
                for d in dirs {
                    rmdir(d.as_ptr());
                }
            }
        }
        // SAFETY: the default action again, then the signal again: the process ends by
        // SIGABRT as it would have (for abort() the re-raise is what it does anyway).
        unsafe {
            signal(SIGABRT, SIG_DFL);
            raise(SIGABRT);
        }
    }

    pub fn arm(lock: &Path, created: &[&Path]) {
        let c = |p: &Path| CString::new(p.as_os_str().as_bytes()).ok();
        let Some(lock) = c(lock) else { return };
        let dirs: Vec<CString> = created.iter().rev().filter_map(|d| c(d)).collect();
        if PATHS.set((lock, dirs)).is_ok() {
            let handler: extern "C" fn(c_int) = on_abort;
            // SAFETY: installs a handler that touches only the paths set above (a
            // OnceLock read, no allocation) and async-signal-safe calls.
            unsafe {
                signal(SIGABRT, handler as usize);
            }
        }
    }
}

/// The folders `dir` and its parents that do not exist yet (outermost first).
pub fn missing_folders(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut missing = Vec::new();
    let mut cur = Some(dir);
    while let Some(d) = cur.filter(|d| !d.as_os_str().is_empty()) {
        if d.exists() {
            break;
        }
        missing.push(d.to_path_buf());
        cur = d.parent();
    }
    missing.reverse();
    missing
}

/// On an abort from now on, remove `lock` and then each folder of `created` (outermost
/// first, as [`missing_folders`] lists them) that is empty. Once per process.
pub fn arm(lock: &std::path::Path, created: &[std::path::PathBuf]) {
    #[cfg(unix)]
    {
        let dirs: Vec<&std::path::Path> = created.iter().map(|p| p.as_path()).collect();
        imp::arm(lock, &dirs);
    }
    #[cfg(not(unix))]
    let _ = (lock, created);
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::os::unix::process::ExitStatusExt;
    use std::path::Path;

    /// Set in the child process of [`an_abort_leaves_no_folder_it_made`]: the folder
    /// under which it makes its `--out` folder.
    const CHILD: &str = "HDW_TEST_ABORT_CHILD";

    /// The child: make `out/a/b`, hold a lock in it, arm, abort. Does nothing unless
    /// started by the parent test.
    #[test]
    fn abort_child() {
        let Some(base) = std::env::var_os(CHILD) else { return };
        let base = Path::new(&base);
        for out in [base.join("new").join("a").join("b"), base.join("kept")] {
            let created = missing_folders(&out);
            std::fs::create_dir_all(&out).unwrap();
            let lock = out.join(".hdw-fit.lock");
            std::fs::write(&lock, "pid = 1\n").unwrap();
            if out.ends_with("b") {
                arm(&lock, &created);
            }
        }
        std::process::abort();
    }

    /// A run aborted after it made its `--out` folder (and a parent) and took its lock
    /// leaves neither; a folder that held something keeps it.
    #[test]
    fn an_abort_leaves_no_folder_it_made() {
        if std::env::var_os(CHILD).is_some() {
            return;
        }
        let base = std::env::temp_dir().join(format!("hdw-abort-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        std::fs::create_dir_all(base.join("new")).unwrap();
        let exe = std::env::current_exe().unwrap();
        let status = std::process::Command::new(exe)
            .args(["--exact", "cmd::fit_drive::abort::tests::abort_child", "--test-threads=1"])
            .env(CHILD, &base)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status()
            .unwrap();
        assert_eq!(status.signal(), Some(6), "{status:?}");
        assert!(!base.join("new").join("a").exists(), "the folders made are removed");
        assert!(base.join("new").exists(), "a folder that was there stays");
        // The other folder was not armed: the abort leaves it as it was.
        assert!(base.join("kept").join(".hdw-fit.lock").exists());
        let _ = std::fs::remove_dir_all(&base);
    }
}
