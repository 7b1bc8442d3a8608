//! The one error type of `chatter-dynamics`.

use std::path::PathBuf;

/// Everything that can go wrong when building, perturbing, reading or simulating a model.
#[derive(Debug, thiserror::Error)]
pub enum DynamicsError {
    /// A value is outside its physical range.
    #[error("invalid value for `{field}`: {} (expected {expected})", crate::limits::written(*value))]
    InvalidValue {
        /// The field, in the file format's words (e.g. `modes[1].damping_ratio`).
        field: String,
        /// The offending value.
        value: f64,
        /// What was expected.
        expected: String,
    },
    /// A structural problem that is not a single number (missing choice, unknown name).
    #[error("invalid `{field}`: {message}")]
    Invalid {
        /// The field concerned.
        field: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// A file could not be parsed (JSON or CSV syntax, unknown or missing field, wrong type).
    #[error("{}: {message}", path.display())]
    Parse {
        /// The file concerned.
        path: PathBuf,
        /// Parser message, naming the field and line where possible.
        message: String,
    },
    /// A file parsed but its content is invalid.
    #[error("{}: {error}", path.display())]
    InFile {
        /// The file concerned.
        path: PathBuf,
        /// The validation error.
        error: Box<DynamicsError>,
    },
    /// The caller's observer asked to stop (`chatter_progress::Observer::cancelled`).
    #[error(transparent)]
    Cancelled(#[from] chatter_progress::Cancelled),
}

impl DynamicsError {
    /// Shorthand for [`DynamicsError::InvalidValue`].
    pub fn value(field: impl Into<String>, value: f64, expected: impl Into<String>) -> Self {
        Self::InvalidValue {
            field: field.into(),
            value,
            expected: expected.into(),
        }
    }

    /// Shorthand for [`DynamicsError::Invalid`].
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    /// Attach the file name to a validation error.
    pub fn in_file(self, path: impl Into<PathBuf>) -> Self {
        Self::InFile {
            path: path.into(),
            error: Box::new(self),
        }
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, DynamicsError>;

/// Check that `value` is finite and strictly positive.
pub(crate) fn positive(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(DynamicsError::value(field, value, "a finite number > 0"))
    }
}

/// Check that `value` is finite and non-negative.
pub(crate) fn non_negative(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(DynamicsError::value(field, value, "a finite number >= 0"))
    }
}

/// Check that `value` is finite.
pub(crate) fn finite(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(DynamicsError::value(field, value, "a finite number"))
    }
}
