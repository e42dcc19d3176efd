//! Writing a figure: the backend is chosen by the file extension (`.svg` → SVG, `.png` →
//! PNG), the parent folder is created, and the file is drawn under a temporary name in the
//! same folder and renamed into place, so a reader never sees half a plot.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::error::PlotError;
use crate::font;

/// A drawing failure reported by plotters, as text (its error types are backend-generic).
#[derive(Debug)]
pub(crate) struct DrawError(pub String);

impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for DrawError {
    fn from(err: DrawingAreaErrorKind<E>) -> Self {
        DrawError(err.to_string())
    }
}

/// Something that can be drawn on any plotters backend.
pub(crate) trait Figure {
    /// Canvas width and height [px].
    fn size(&self) -> (u32, u32);

    /// Draw onto `root`, which is already filled white.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError>;
}

/// The output formats, named by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Svg,
    Png,
}

/// The format named by the extension of `path` (case-insensitive).
fn format_of(path: &Path) -> Result<Format, PlotError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("svg") => Ok(Format::Svg),
        Some("png") => Ok(Format::Png),
        _ => Err(PlotError::UnsupportedFormat { path: path.to_path_buf() }),
    }
}

/// Check that `path` names a supported format, before any work is done.
pub(crate) fn check_path(path: &Path) -> Result<(), PlotError> {
    format_of(path).map(|_| ())
}

/// Draw `figure` into the file at `path`.
pub(crate) fn render<F: Figure>(path: &Path, figure: &F) -> Result<(), PlotError> {
    let format = format_of(path)?;
    font::ensure_registered()
        .map_err(|message| PlotError::Font { path: path.to_path_buf(), message })?;
    let dir = match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => dir,
        None => Path::new("."),
    };
    std::fs::create_dir_all(dir)
        .map_err(|source| PlotError::CreateDir { path: path.to_path_buf(), source })?;
    let size = figure.size();
    let draw = |target: &Path| match format {
        Format::Svg => draw_on(&SVGBackend::new(target, size).into_drawing_area(), figure),
        Format::Png => draw_on(&BitMapBackend::new(target, size).into_drawing_area(), figure),
    };
    let failed = |DrawError(message)| PlotError::Draw { path: path.to_path_buf(), message };
    // A hidden target is already the caller's temporary (a run's outputs are staged and
    // renamed together): drawn in place.
    if path.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.')) {
        return draw(path).map_err(failed);
    }
    // Drawn into a hidden temporary file beside the target, then moved over it (tempfile's
    // persist), so a reader never sees half a plot. It keeps the extension because the PNG
    // encoder picks its format from it; it is removed if drawing fails. Mode 0666 less
    // the umask, like any other file (tempfile's default, 0600, made plots private).
    let ext = path.extension().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let suffix = format!(".{ext}");
    let mut builder = tempfile::Builder::new();
    builder.prefix(".plot.tmp-").suffix(&suffix);
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let tmp = builder
        .tempfile_in(dir)
        .map_err(|source| PlotError::Write { path: path.to_path_buf(), source })?;
    draw(tmp.path()).map_err(failed)?;
    tmp.persist(path)
        .map(|_| ())
        .map_err(|e| PlotError::Write { path: path.to_path_buf(), source: e.error })
}

/// Fill white, draw, and flush to the file.
fn draw_on<DB: DrawingBackend, F: Figure>(
    root: &DrawingArea<DB, Shift>,
    figure: &F,
) -> Result<(), DrawError> {
    root.fill(&WHITE)?;
    figure.draw(root)?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_follows_extension() {
        assert_eq!(format_of(Path::new("a/b.svg")).unwrap(), Format::Svg);
        assert_eq!(format_of(Path::new("b.PNG")).unwrap(), Format::Png);
        assert!(format_of(Path::new("b.pdf")).is_err());
        assert!(format_of(Path::new("b")).is_err());
    }
}
