//! Errors of the drive identification: a bad configuration, a bad record, a failed fit.
//! Each names the file and the field it is about.

use thiserror::Error;

/// Something wrong found while setting up or running a drive fit.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DriveError {
    /// The configuration is invalid: `where_` names the file and key.
    #[error("{where_}: {message}")]
    Config {
        /// File and key, e.g. `fit.toml, [controller] kp`.
        where_: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A record cannot be used: `source` names the file (and column).
    #[error("{file}: {message}")]
    Data {
        /// The record's file (and experiment name).
        file: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// The fit could not be carried out.
    #[error("{0}")]
    Fit(String),
}

impl DriveError {
    /// A configuration error at `where_`.
    pub fn config(where_: impl Into<String>, message: impl Into<String>) -> Self {
        DriveError::Config { where_: where_.into(), message: message.into() }
    }

    /// A data error in `source`.
    pub fn data(source: impl Into<String>, message: impl Into<String>) -> Self {
        DriveError::Data { file: source.into(), message: message.into() }
    }
}
