//! Pieces shared by several subcommands: parameter loading and output folders.

use anyhow::{Context, Result, bail};
use hd_model::Params;
use hd_model::params_file::apply_params_toml;
use hd_model::text_file::{MAX_SETTINGS_BYTES, read_text};
use std::path::{Path, PathBuf};

/// Defaults, then the params file (if any), then each `--set NAME=VALUE` in order. Two
/// `--set`s naming one parameter by two names (`A` and `mem_A`) are refused: which one
/// wins would be a matter of order.
pub fn load_params(file: Option<&Path>, sets: &[String]) -> Result<Params> {
    let mut p = Params::default();
    if let Some(path) = file {
        let text = read_params_text(path)?;
        apply_params_toml(&mut p, &text, &path.display().to_string())?;
    }
    let mut seen: Vec<(&str, &str)> = Vec::new();
    for s in sets {
        p.apply_assignment(s).with_context(|| format!("--set {s}"))?;
        let typed = s.split_once('=').map_or(s.as_str(), |(n, _)| n.trim());
        let name = hd_model::registry::canonical(typed);
        if let Some((_, first)) = seen.iter().find(|(n, t)| *n == name && *t != typed) {
            bail!(
                "--set {typed} and --set {first} are two names for one parameter ({name}): keep one"
            );
        }
        seen.push((name, typed));
    }
    Ok(p)
}

/// The text of a params file, refused by size and type before it is parsed.
pub fn read_params_text(path: &Path) -> Result<String> {
    read_text(path, "params file", MAX_SETTINGS_BYTES).map_err(anyhow::Error::msg)
}

/// Largest fit configuration read [bytes], as for params and study files.
pub const MAX_CONFIG_BYTES: u64 = MAX_SETTINGS_BYTES;

/// Refuse a data file (a record, a validation record) that cannot be one, before it is
/// opened: missing, a folder, or not a regular file (`/dev/zero`, a pipe) is one line
/// naming `what` and the path. Records may be large: there is no size cap here.
pub fn check_data_file(path: &Path, what: &str) -> Result<()> {
    let at = || format!("{what} {}", path.display());
    let meta = std::fs::metadata(path).map_err(|e| anyhow::anyhow!("cannot read {}: {e}", at()))?;
    if meta.is_dir() {
        bail!("{} is a folder: expected a data file (CSV, Parquet or MAT)", at());
    }
    if !meta.is_file() {
        bail!("{} is not a regular file (a device or pipe?): expected a data file", at());
    }
    Ok(())
}

/// Default of `--max-output-values`: about 1.6 GB of numbers before compression [–].
pub const DEFAULT_MAX_OUTPUT_VALUES: u64 = 200_000_000;

/// Refuse a run whose output, `rows` × `columns` values, is estimated above `limit`
/// (0: no limit), before anything is computed or written.
pub fn check_output_size(rows: f64, columns: usize, limit: u64) -> Result<()> {
    let values = rows * columns as f64;
    if limit > 0 && !rows.is_finite() {
        bail!(
            "the trace would have no end ({rows} samples: --t-end over the sampling interval): raise --dt-out, shorten --t-end or pass --no-trace"
        );
    }
    if limit > 0 && (values.is_nan() || values > limit as f64) {
        bail!(
            "the trace would hold about {values:.3e} values ({rows:.3e} samples × {columns} columns), over the limit of {limit}: raise --dt-out, shorten --t-end, pass --no-trace, or lift the limit with --max-output-values N (0 = none)"
        );
    }
    Ok(())
}

/// Create the output folder (and parents); a failed or interrupted command removes the
/// folders it created here if they are still empty.
pub fn ensure_dir(dir: &Path) -> Result<PathBuf> {
    hd_io::pending::create_dir_all(dir)
        .with_context(|| format!("cannot create output folder {}", dir.display()))?;
    Ok(dir.to_path_buf())
}

/// Draw a plot into a hidden temporary beside `dest` and rename it into place, with the
/// rest of the outputs when called inside [`hd_io::atomic::group`].
pub fn staged_plot(
    dest: &Path,
    draw: impl FnOnce(&Path) -> std::result::Result<(), hd_plot::PlotError>,
) -> Result<()> {
    let staged = hd_io::atomic::Staged::new(dest)?;
    draw(staged.path()).with_context(|| format!("drawing {}", dest.display()))?;
    hd_io::atomic::finish(staged)?;
    Ok(())
}

/// Write a JSON value to `path` atomically.
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    hd_io::atomic::commit(vec![stage_json(path, value)?], &[])?;
    Ok(())
}

/// A JSON value written to a temporary beside `path`, to be committed with its siblings.
pub fn stage_json(path: &Path, value: &serde_json::Value) -> Result<hd_io::atomic::Staged> {
    let text = serde_json::to_string_pretty(value)?;
    let mut staged = hd_io::atomic::Staged::new(path)?;
    staged.write_with(|f| {
        use std::io::Write;
        f.write_all(text.as_bytes()).map_err(|e| hd_io::IoError::fs(path, e))
    })?;
    Ok(staged)
}

/// The outputs an earlier run left in a folder (files a command writes, with the identity
/// of each: inode and modification time), to remove those the next run did not replace:
/// a new fit must not leave the earlier fit's plots beside its own fit.json.
#[derive(Debug)]
pub struct EarlierOutputs {
    files: Vec<(PathBuf, Option<(u64, std::time::SystemTime)>)>,
}

/// Identity of a file: inode (0 where unknown) and modification time.
fn identity(path: &Path) -> Option<(u64, std::time::SystemTime)> {
    let meta = std::fs::symlink_metadata(path).ok()?;
    #[cfg(unix)]
    let ino = std::os::unix::fs::MetadataExt::ino(&meta);
    #[cfg(not(unix))]
    let ino = 0;
    Some((ino, meta.modified().ok()?))
}

impl EarlierOutputs {
    /// The regular files of `dir` whose names `is_output` claims, when `dir` holds an
    /// earlier run's `fit.json` (a folder without one is left alone: its files are not
    /// known to be a fit's).
    pub fn scan(dir: &Path, is_output: fn(&str) -> bool) -> Self {
        let mut files = Vec::new();
        if dir.join("fit.json").is_file()
            && let Ok(entries) = std::fs::read_dir(dir)
        {
            for e in entries.flatten() {
                let name = e.file_name().to_string_lossy().to_string();
                if is_output(&name) && e.file_type().is_ok_and(|t| t.is_file()) {
                    files.push((e.path(), identity(&e.path())));
                }
            }
        }
        EarlierOutputs { files }
    }

    /// Remove the earlier outputs the run did not write again (same inode and time);
    /// returns how many were removed.
    pub fn remove_stale(self) -> usize {
        let mut removed = 0;
        for (path, before) in self.files {
            if before.is_some() && identity(&path) == before && std::fs::remove_file(&path).is_ok()
            {
                removed += 1;
            }
        }
        removed
    }
}

/// Worker threads when `--threads` is not given: `RAYON_NUM_THREADS` where the environment
/// sets it (as batch schedulers' job scripts and users do to share a machine), else every
/// core. Rayon's global pool reads the variable the same way.
pub fn default_threads() -> usize {
    std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.trim().parse::<usize>().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}
