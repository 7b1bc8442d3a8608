//! The one error type of `chatter-uncertainty`.

/// What can go wrong when building uncertainty bands.
#[derive(Debug, thiserror::Error)]
pub enum UncertaintyError {
    /// An input is outside its valid range.
    #[error("invalid `{field}`: {message}")]
    InvalidInput {
        /// Which input.
        field: &'static str,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A stability computation failed.
    #[error(transparent)]
    Stability(#[from] chatter_stability::StabilityError),
    /// A sampled boundary could not be built (`chatter_updating::sampled`).
    #[error(transparent)]
    Updating(#[from] chatter_updating::UpdatingError),
    /// The caller's observer asked to stop (`chatter_progress::Observer::cancelled`).
    #[error(transparent)]
    Cancelled(#[from] chatter_progress::Cancelled),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, UncertaintyError>;
