//! Typed I/O errors; each names the file and, where it can, the column and row.

use std::path::PathBuf;
use thiserror::Error;

/// A problem reading or writing a workbench file.
#[derive(Debug, Error)]
pub enum IoError {
    /// The file could not be opened, created or renamed.
    #[error("{}", path.display())]
    Fs {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The file's format or content is not what was expected.
    #[error("{}: {message}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong and what was expected.
        message: String,
    },
    /// Polars could not read, combine or write the data; the polars error is the source.
    #[error("{}: {context}", path.display())]
    Polars {
        /// The file.
        path: PathBuf,
        /// What was being done.
        context: String,
        /// The polars error.
        source: polars::error::PolarsError,
    },
}

impl IoError {
    /// A format error for `path`.
    pub fn format(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        IoError::Format { path: path.into(), message: message.into() }
    }

    /// A converter of a polars error met while doing `context` on `path`, for `map_err`.
    pub fn polars(
        path: impl Into<PathBuf>,
        context: impl Into<String>,
    ) -> impl FnOnce(polars::error::PolarsError) -> IoError {
        let (path, context) = (path.into(), context.into());
        move |source| IoError::Polars { path, context, source }
    }

    /// A file-system error for `path`.
    pub fn fs(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        IoError::Fs { path: path.into(), source }
    }
}
