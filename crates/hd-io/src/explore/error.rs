//! The error type of the explore engine: every variant says what was asked and what was
//! expected, so the command line can print it as is.

use crate::error::IoError;
use crate::explore::filter::FilterError;
use thiserror::Error;

/// Why a query on a result table could not be answered.
#[derive(Debug, Error)]
pub enum ExploreError {
    /// A file could not be read.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A `--filter` expression could not be parsed or does not fit the table.
    #[error(transparent)]
    Filter(#[from] FilterError),
    /// The source names no readable Parquet file, or mixes kinds of files.
    #[error("{source_name}: {message}")]
    Source {
        /// The file, folder or pattern as given.
        source_name: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A column named in an option is not in the table.
    #[error("{context}: no column '{name}'{hint} (columns: {available})")]
    UnknownColumn {
        /// The option that named it, e.g. `--group-by`.
        context: String,
        /// The name as given.
        name: String,
        /// ` (did you mean 'x'?)` or empty.
        hint: String,
        /// The columns present, comma-separated.
        available: String,
    },
    /// An option's value is malformed or does not fit the data.
    #[error("{option}: {message}")]
    Usage {
        /// The option, e.g. `--pivot`.
        option: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// Polars failed while running the query.
    #[error("query failed: {0}")]
    Query(String),
}

impl ExploreError {
    /// A usage error for `option`.
    pub fn usage(option: &str, message: impl Into<String>) -> Self {
        ExploreError::Usage { option: option.to_string(), message: message.into() }
    }

    /// A source error for `source_name`.
    pub fn source(source_name: &str, message: impl Into<String>) -> Self {
        ExploreError::Source { source_name: source_name.to_string(), message: message.into() }
    }
}

impl From<polars::prelude::PolarsError> for ExploreError {
    fn from(e: polars::prelude::PolarsError) -> Self {
        ExploreError::Query(e.to_string())
    }
}
