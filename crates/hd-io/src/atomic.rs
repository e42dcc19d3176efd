//! Atomic file writes: the data goes to a temporary file beside the target, which is then
//! renamed over it (tempfile's `persist`), so a reader never sees a half-written file and a
//! killed writer leaves the old file intact.

use crate::error::IoError;
use std::fs::File;
use std::path::Path;

/// Create a temporary file beside `path`, let `write` fill it, then move it to `path`.
pub fn write_atomically<T>(
    path: &Path,
    write: impl FnOnce(&mut File) -> Result<T, IoError>,
) -> Result<T, IoError> {
    let dir = match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => {
            std::fs::create_dir_all(dir).map_err(|e| IoError::fs(dir, e))?;
            dir
        }
        None => Path::new("."),
    };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    // Hidden and marked `.tmp`, so folder readers skip it while it is being written.
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!(".{name}.tmp-"))
        .tempfile_in(dir)
        .map_err(|e| IoError::fs(dir, e))?;
    let out = write(tmp.as_file_mut())?;
    tmp.as_file().sync_all().map_err(|e| IoError::fs(tmp.path(), e))?;
    tmp.persist(path).map_err(|e| IoError::fs(path, e.error))?;
    Ok(out)
}
