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
