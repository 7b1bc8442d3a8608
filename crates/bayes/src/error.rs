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
    /// The likelihood is zero (or its computation failed) at every draw from the prior: the
    /// data rule out the prior's support, or nothing could be evaluated.
    #[error("the likelihood is zero at every prior sample")]
    ZeroLikelihood,
    /// The sampler could not proceed (a singular covariance, no end of the tempering).
    #[error("{0}")]
    Degenerate(String),
    /// The caller's observer asked to stop (`chatter_progress::Observer::cancelled`).
    #[error(transparent)]
    Cancelled(#[from] chatter_progress::Cancelled),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, BayesError>;
