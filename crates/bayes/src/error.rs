//! The one error type of `chatter-bayes`.

/// What can go wrong in inference.
#[derive(Debug, thiserror::Error)]
pub enum BayesError {
    /// A distribution or option parameter is invalid.
    #[error("invalid `{field}`: {message}")]
    InvalidInput {
        /// Which input.
        field: &'static str,
        /// What was expected.
        message: String,
    },
    /// The sampler could not proceed (e.g. every likelihood is zero).
    #[error("{0}")]
    Degenerate(String),
    /// The caller's observer asked to stop (`chatter_progress::Observer::cancelled`).
    #[error(transparent)]
    Cancelled(#[from] chatter_progress::Cancelled),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, BayesError>;
