//! Pieces shared by several subcommands: parameter loading and output folders.

use anyhow::{Context, Result};
use hd_model::Params;
use hd_model::params_file::apply_params_toml;
use std::path::{Path, PathBuf};

/// Defaults, then the params file (if any), then each `--set NAME=VALUE` in order.
pub fn load_params(file: Option<&Path>, sets: &[String]) -> Result<Params> {
    let mut p = Params::default();
    if let Some(path) = file {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read params file {}", path.display()))?;
        apply_params_toml(&mut p, &text, &path.display().to_string())?;
    }
    for s in sets {
        p.apply_assignment(s).with_context(|| format!("--set {s}"))?;
    }
    Ok(p)
}

/// Create the output folder (and parents).
pub fn ensure_dir(dir: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create output folder {}", dir.display()))?;
    Ok(dir.to_path_buf())
}

/// Write a JSON value to `path` atomically.
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    hd_io::atomic::write_atomically(path, |f| {
        use std::io::Write;
        f.write_all(text.as_bytes()).map_err(|e| hd_io::IoError::fs(path, e))
    })?;
    Ok(())
}
