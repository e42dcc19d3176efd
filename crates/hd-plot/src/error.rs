//! The one error type of the crate.

use std::path::PathBuf;

/// Why a plot could not be written. Every variant names the output file it was meant for
/// and says what was wrong; no variant leaves a partial file behind.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The file name does not end in `.svg` or `.png`.
    #[error("{}: unsupported plot format; the file name must end in .svg or .png", path.display())]
    UnsupportedFormat {
        /// The requested output file.
        path: PathBuf,
    },
    /// An input that must hold data is empty.
    #[error("{}: nothing to plot: {what} is empty", path.display())]
    EmptyInput {
        /// The requested output file.
        path: PathBuf,
        /// Which input was empty.
        what: String,
    },
    /// Every value of an input is NaN or infinite.
    #[error("{}: nothing to plot: {what} has no finite values", path.display())]
    NoFiniteData {
        /// The requested output file.
        path: PathBuf,
        /// Which input had no finite values.
        what: String,
    },
    /// A logarithmic axis was asked for, but no finite value on it is positive.
    #[error("{}: cannot use a log axis: {what} has no positive finite values", path.display())]
    NoPositiveData {
        /// The requested output file.
        path: PathBuf,
        /// Which input lacked positive values.
        what: String,
    },
    /// Two inputs that must have the same length do not.
    #[error("{}: {what}: expected {expected} values, found {found}", path.display())]
    LengthMismatch {
        /// The requested output file.
        path: PathBuf,
        /// Which input had the wrong length.
        what: String,
        /// The length it should have.
        expected: usize,
        /// The length it has.
        found: usize,
    },
    /// A heatmap grid axis is not finite and strictly increasing.
    #[error("{}: invalid grid: {what} {reason}", path.display())]
    InvalidGrid {
        /// The requested output file.
        path: PathBuf,
        /// Which grid axis is invalid.
        what: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The folder that should hold the plot could not be created.
    #[error("{}: cannot create the output folder", path.display())]
    CreateDir {
        /// The requested output file.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The embedded font could not be registered with plotters.
    #[error("{}: font setup failed: {message}", path.display())]
    Font {
        /// The requested output file.
        path: PathBuf,
        /// What failed.
        message: String,
    },
    /// Plotters failed while drawing or encoding the figure.
    #[error("{}: drawing failed: {message}", path.display())]
    Draw {
        /// The requested output file.
        path: PathBuf,
        /// Plotters' description of the failure.
        message: String,
    },
    /// The finished figure could not be moved into place.
    #[error("{}: cannot write the plot", path.display())]
    Write {
        /// The requested output file.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
}
