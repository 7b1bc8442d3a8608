//! The one error type of `chatter-updating`.

/// What can go wrong when setting up or evaluating a chatter likelihood.
#[derive(Debug, thiserror::Error)]
pub enum UpdatingError {
    /// The observations do not fit the likelihood (none, wrong operation, bad values).
    #[error("invalid observations: {0}")]
    Observations(String),
    /// A parameter vector or option is invalid.
    #[error("invalid `{field}`: {message}")]
    InvalidInput {
        /// Which input.
        field: &'static str,
        /// What was expected.
        message: String,
    },
    /// The model could not be built or perturbed.
    #[error(transparent)]
    Dynamics(#[from] chatter_dynamics::DynamicsError),
    /// A sampler failed.
    #[error(transparent)]
    Bayes(#[from] chatter_bayes::BayesError),
    /// A stability computation failed.
    #[error(transparent)]
    Stability(#[from] chatter_stability::StabilityError),
    /// The caller's observer asked to stop (`chatter_progress::Observer::cancelled`).
    #[error(transparent)]
    Cancelled(#[from] chatter_progress::Cancelled),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, UpdatingError>;
