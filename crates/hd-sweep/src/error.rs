//! Study-file errors: each names the file, the line and the key.

use thiserror::Error;

/// A problem found while reading or checking a study file.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{file}:{line}: {key}: {message}")]
pub struct StudyError {
    /// The study file.
    pub file: String,
    /// 1-based line of the offending key (1 when unknown).
    pub line: usize,
    /// The key or item concerned, e.g. `axis.name` or `set.sigma0`.
    pub key: String,
    /// What is wrong and what was expected.
    pub message: String,
}

/// Where in a study file an item sits: the file name and its text, for line numbers.
#[derive(Clone, Copy, Debug)]
pub struct Source<'a> {
    /// File name for messages.
    pub file: &'a str,
    /// The file's text.
    pub text: &'a str,
}

impl Source<'_> {
    /// An error at byte offset `pos`.
    pub fn error(
        &self,
        pos: usize,
        key: impl Into<String>,
        message: impl Into<String>,
    ) -> StudyError {
        StudyError {
            file: self.file.to_string(),
            line: hd_model::params_file::line_of(self.text, pos),
            key: key.into(),
            message: message.into(),
        }
    }
}
