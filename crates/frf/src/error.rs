//! The one error type of `chatter-frf`.

use std::path::PathBuf;

/// What can go wrong reading, writing or fitting a measured FRF.
#[derive(Debug, thiserror::Error)]
pub enum FrfError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// A file's content does not follow its format.
    #[error("{path}: line {line}: {message}")]
    Parse {
        /// The file concerned.
        path: PathBuf,
        /// 1-based line number (0 when not tied to a line).
        line: usize,
        /// What was found and what was expected.
        message: String,
    },
    /// An input value is outside its valid range.
    #[error("invalid `{field}`: {value} ({expected})")]
    InvalidValue {
        /// The input, in the caller's words.
        field: String,
        /// The offending value.
        value: f64,
        /// What was expected.
        expected: String,
    },
    /// A fit could not be made (too few points, no stable pole in the band).
    #[error("modal fit: {0}")]
    Fit(String),
    /// A model file or its measured FRFs are invalid.
    #[error(transparent)]
    Dynamics(#[from] chatter_dynamics::DynamicsError),
}

impl FrfError {
    pub(crate) fn parse(path: &std::path::Path, line: usize, message: impl Into<String>) -> Self {
        Self::Parse {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    pub(crate) fn value(field: impl Into<String>, value: f64, expected: impl Into<String>) -> Self {
        Self::InvalidValue {
            field: field.into(),
            value,
            expected: expected.into(),
        }
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, FrfError>;
