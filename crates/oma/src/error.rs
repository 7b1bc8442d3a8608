//! The one error type of `chatter-oma`.

use std::path::PathBuf;

/// What can go wrong in operational modal analysis.
#[derive(Debug, thiserror::Error)]
pub enum OmaError {
    /// A signal file could not be read.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong, with line or column where known.
        message: String,
    },
    /// An input or option is invalid.
    #[error("invalid `{field}`: {message}")]
    InvalidInput {
        /// Which input.
        field: &'static str,
        /// What was expected.
        message: String,
    },
    /// No pole satisfied the identification criteria.
    #[error("no pole identified: {0}")]
    NoPole(String),
    /// A least-squares or eigenvalue problem failed.
    #[error("{0}")]
    Numerical(String),
    /// The caller's observer asked to stop (`chatter_progress::Observer::cancelled`).
    #[error(transparent)]
    Cancelled(#[from] chatter_progress::Cancelled),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, OmaError>;
