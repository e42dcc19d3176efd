//! Atomic file writes: write to a temporary sibling, then rename over the target, so a
//! reader never sees a half-written file and a killed writer leaves the old file intact.

use crate::error::IoError;
use std::fs::File;
use std::path::{Path, PathBuf};

/// Create a temporary file beside `path`, let `write` fill it, then rename it to `path`.
pub fn write_atomically<T>(
    path: &Path,
    write: impl FnOnce(&mut File) -> Result<T, IoError>,
) -> Result<T, IoError> {
    let tmp = temp_sibling(path);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| IoError::fs(dir, e))?;
    }
    let mut file = File::create(&tmp).map_err(|e| IoError::fs(&tmp, e))?;
    let out = match write(&mut file) {
        Ok(v) => v,
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            return Err(e);
        }
    };
    file.sync_all().map_err(|e| IoError::fs(&tmp, e))?;
    drop(file);
    std::fs::rename(&tmp, path).map_err(|e| IoError::fs(path, e))?;
    Ok(out)
}

fn temp_sibling(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp-{}", std::process::id()))
}
