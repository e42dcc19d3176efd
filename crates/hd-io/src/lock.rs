//! A lock file that keeps two processes from running the same sweep into one folder (each
//! would run every run again, doubling the work). The file holds the holder's pid, host and
//! start time; a lock whose process is gone on this host is stale and taken over; one held
//! from another host (a shared folder on a cluster) is reported with its holder.

use crate::error::IoError;
use crate::pending::RemoveOnDrop;
use std::io::Write;
use std::path::Path;

/// A held lock; dropping it (or an interrupt) removes the file.
#[derive(Debug)]
pub struct FolderLock {
    _file: RemoveOnDrop,
}

/// This machine's name (empty if unknown).
fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .map(|s| s.trim().to_string())
        .unwrap_or_default()
}

/// Whether process `pid` runs on this machine.
fn alive(pid: u32) -> bool {
    pid == std::process::id() || Path::new(&format!("/proc/{pid}")).exists()
}

/// Take the lock file `path` for what `purpose` says ("the study"). Refused, naming the
/// holder, while another live process holds it.
pub fn lock_folder(path: &Path, purpose: &str) -> Result<FolderLock, IoError> {
    let me = host();
    let started = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let content = format!("pid = {}\nhost = \"{me}\"\nstarted = {started}\n", std::process::id());
    for _ in 0..3 {
        match std::fs::OpenOptions::new().write(true).create_new(true).open(path) {
            Ok(mut f) => {
                let guard = RemoveOnDrop::new(path);
                f.write_all(content.as_bytes()).map_err(|e| IoError::fs(path, e))?;
                return Ok(FolderLock { _file: guard });
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let text = std::fs::read_to_string(path).unwrap_or_default();
                let field = |k: &str| {
                    text.lines()
                        .find_map(|l| l.strip_prefix(k)?.trim_start().strip_prefix('='))
                        .map(|v| v.trim().trim_matches('"').to_string())
                };
                let pid = field("pid").and_then(|p| p.parse::<u32>().ok());
                let holder_host = field("host").unwrap_or_default();
                let same_host = holder_host == me;
                match pid {
                    Some(pid) if same_host && !alive(pid) => {
                        // Stale: its process is gone (killed without cleaning up).
                        let _ = std::fs::remove_file(path);
                    }
                    Some(pid) => {
                        let on =
                            if same_host { String::new() } else { format!(" on {holder_host}") };
                        return Err(IoError::format(
                            path,
                            format!(
                                "{purpose} in this folder is running already (pid {pid}{on}): wait for it, or remove this file if that process is gone"
                            ),
                        ));
                    }
                    None => {
                        // Being written by a process that has just created it, or damaged.
                        std::thread::sleep(std::time::Duration::from_millis(50));
                        let again = std::fs::read_to_string(path).unwrap_or_default();
                        if again.trim().is_empty() {
                            let _ = std::fs::remove_file(path);
                        }
                    }
                }
            }
            Err(e) => return Err(IoError::fs(path, e)),
        }
    }
    Err(IoError::format(
        path,
        format!("cannot take the lock of {purpose}: remove this file if no hdw is running"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_lock_refused_stale_taken_over_released_on_drop() {
        let dir = std::env::temp_dir().join(format!("hd-io-lock-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(".lock");
        let held = lock_folder(&path, "the study").unwrap();
        let err = lock_folder(&path, "the study").unwrap_err().to_string();
        assert!(err.contains(&format!("pid {}", std::process::id())), "{err}");
        drop(held);
        assert!(!path.exists());
        // A lock left by a process that no longer exists (pid beyond pid_max).
        std::fs::write(&path, format!("pid = 4294967294\nhost = \"{}\"\n", host())).unwrap();
        let taken = lock_folder(&path, "the study").unwrap();
        assert!(std::fs::read_to_string(&path).unwrap().contains(&std::process::id().to_string()));
        drop(taken);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
