//! The one error type of `chatter-gap`.

/// What can go wrong in a gap diagnosis.
#[derive(Debug, thiserror::Error)]
pub enum GapError {
    /// An option or an input value is outside its valid range.
    #[error("invalid `{field}`: {value} ({expected})")]
    InvalidInput {
        /// Which input.
        field: String,
        /// Its value.
        value: f64,
        /// What was expected.
        expected: &'static str,
    },
    /// The observations cannot support a diagnosis (e.g. no cuts and no poles).
    #[error("observations: {0}")]
    Observations(String),
    /// The nominal model cannot be used (e.g. a mode with zero stiffness in both coordinates).
    #[error("model: {0}")]
    Model(String),
    /// A model class name that is not one of the candidates.
    #[error(
        "unknown model class `{0}`; expected parameter_error, process_damping, \
         speed_dependent_dynamics, extra_mode or drift"
    )]
    UnknownClass(String),
    /// The sampler failed for a model class.
    #[error("model class `{class}`: {source}")]
    Sampler {
        /// Which class.
        class: &'static str,
        /// The sampler's error.
        source: chatter_bayes::BayesError,
    },
    /// A model could not be built.
    #[error(transparent)]
    Dynamics(#[from] chatter_dynamics::DynamicsError),
    /// The caller's observer asked to stop (`chatter_progress::Observer::cancelled`).
    #[error(transparent)]
    Cancelled(#[from] chatter_progress::Cancelled),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, GapError>;

/// Check that `value` is finite and > 0.
pub(crate) fn positive(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(GapError::InvalidInput {
            field: field.to_string(),
            value,
            expected: "a finite value > 0",
        })
    }
}
