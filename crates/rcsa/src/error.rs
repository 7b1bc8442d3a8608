//! The one error type of `chatter-rcsa`.

use std::path::PathBuf;

/// What can go wrong building or coupling substructures.
#[derive(Debug, thiserror::Error)]
pub enum RcsaError {
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// An assembly file is not valid JSON or does not follow the format.
    #[error("{path}: {message}")]
    Parse {
        /// The file concerned.
        path: PathBuf,
        /// What was found and what was expected.
        message: String,
    },
    /// An input value is outside its valid range.
    #[error("invalid `{field}`: {value} ({expected})")]
    InvalidValue {
        /// The input, in the file's words (with its position, e.g. `tool[1].length_mm`).
        field: String,
        /// The value as written.
        value: f64,
        /// What was expected.
        expected: String,
    },
    /// A coupling or decoupling step met a singular matrix (a frequency where a substructure
    /// has no unique response, e.g. 0 Hz for a free-free beam).
    #[error("{what} is singular at {frequency_hz} Hz")]
    Singular {
        /// Which matrix.
        what: &'static str,
        /// Where.
        frequency_hz: f64,
    },
    /// A measured FRF could not be read or interpolated.
    #[error(transparent)]
    Frf(#[from] chatter_frf::FrfError),
}

impl RcsaError {
    pub(crate) fn value(field: impl Into<String>, value: f64, expected: impl Into<String>) -> Self {
        Self::InvalidValue {
            field: field.into(),
            value,
            expected: expected.into(),
        }
    }
}

/// Result with [`RcsaError`].
pub type Result<T> = std::result::Result<T, RcsaError>;
