//! The one error type of `chatter-stability`.

/// What can go wrong in a stability computation.
#[derive(Debug, thiserror::Error)]
pub enum StabilityError {
    /// A cutting condition or option is outside its valid range.
    #[error("invalid `{field}`: {value} ({expected})")]
    InvalidInput {
        /// Which input.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What was expected.
        expected: &'static str,
    },
    /// An iterative solver did not converge.
    #[error("{solver} did not converge: {detail}")]
    NoConvergence {
        /// Which solver.
        solver: &'static str,
        /// Iterations, residual, condition.
        detail: String,
    },
    /// The method does not apply to this model (e.g. zero-order approximation for turning).
    #[error("{method} does not apply: {reason}")]
    Unsupported {
        /// Method name.
        method: &'static str,
        /// Why.
        reason: String,
    },
    /// The model could not be built or perturbed.
    #[error(transparent)]
    Dynamics(#[from] chatter_dynamics::DynamicsError),
    /// The caller's observer asked to stop (`chatter_progress::Observer::cancelled`).
    #[error(transparent)]
    Cancelled(#[from] chatter_progress::Cancelled),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, StabilityError>;

/// The [`StabilityError::InvalidInput`] of `field` at `value`, expected `expected`.
pub(crate) fn invalid<T>(field: &'static str, value: f64, expected: &'static str) -> Result<T> {
    Err(StabilityError::InvalidInput {
        field,
        value,
        expected,
    })
}

/// Check a spindle speed (rpm) and depth (m) and return them.
pub fn check_condition(speed_rpm: f64, depth_m: f64) -> Result<(f64, f64)> {
    if !(speed_rpm.is_finite() && speed_rpm > 0.0) {
        return Err(StabilityError::InvalidInput {
            field: "speed_rpm",
            value: speed_rpm,
            expected: "a spindle speed > 0",
        });
    }
    if !(depth_m.is_finite() && depth_m >= 0.0) {
        return Err(StabilityError::InvalidInput {
            field: "depth_m",
            value: depth_m,
            expected: "a depth >= 0",
        });
    }
    Ok((speed_rpm, depth_m))
}
