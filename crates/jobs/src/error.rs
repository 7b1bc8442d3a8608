//! The one error type of `chatter-jobs`.

/// What can go wrong in a job: its inputs, or the science crate it calls.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// A request field is out of range or inconsistent.
    #[error("{field} {value}: expected {expected}")]
    Invalid {
        /// The field: the Python keyword, the CLI option `--field` with hyphens.
        field: &'static str,
        /// The value as given.
        value: String,
        /// What was expected.
        expected: String,
    },
    /// An option given where the chosen kind does not use it.
    #[error("{field} is not used {context}; it is for {used_by}")]
    Unused {
        /// The field (Python keyword; the CLI option with hyphens).
        field: &'static str,
        /// When it is not used (`with kind geometric`).
        context: String,
        /// What uses it.
        used_by: String,
    },
    /// An input the job needs was not given.
    #[error("{needed_by} needs {what}")]
    Missing {
        /// What is missing ("a parameter distribution").
        what: &'static str,
        /// What needs it (`` `kind` perturbation ``).
        needed_by: String,
    },
    /// A name that is not one of the known ones.
    #[error("{what} `{value}` is not one of {known:?}")]
    NotOneOf {
        /// What is named ("coordinate").
        what: &'static str,
        /// The name given.
        value: String,
        /// The names known.
        known: Vec<String>,
    },
    /// Two fields that exclude each other, or a combination the job cannot do.
    #[error("{0}")]
    Refused(String),
    /// The cost guard: a discretization would need more than
    /// [`crate::checks::MAX_STEPS_PER_DELAY`] steps per delay at the slowest speed.
    #[error(
        "{field}: at {speed_rpm} rpm one delay needs {steps} steps of the discretization (at \
         most {max}): give speeds of at least {lowest_rpm} rpm, or use `method` zoa where the \
         job offers it",
        max = crate::checks::MAX_STEPS_PER_DELAY
    )]
    TooManySteps {
        /// Where the speeds came from (`speeds`, `speed_rpm`, an observations file).
        field: String,
        /// The slowest speed as written.
        speed_rpm: String,
        /// Steps per delay it needs.
        steps: usize,
        /// The lowest speed within the limit, as written.
        lowest_rpm: String,
    },
    /// A file could not be read.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// Model or observations.
    #[error(transparent)]
    Dynamics(#[from] chatter_dynamics::DynamicsError),
    /// Stability.
    #[error(transparent)]
    Stability(#[from] chatter_stability::StabilityError),
    /// Updating and planning.
    #[error(transparent)]
    Updating(#[from] chatter_updating::UpdatingError),
    /// Uncertainty bands.
    #[error(transparent)]
    Uncertainty(#[from] chatter_uncertainty::UncertaintyError),
    /// Gap diagnosis.
    #[error(transparent)]
    Gap(#[from] chatter_gap::GapError),
    /// Measured FRFs and modal fits.
    #[error(transparent)]
    Frf(#[from] chatter_frf::FrfError),
    /// Receptance coupling of an assembly.
    #[error(transparent)]
    Rcsa(#[from] chatter_rcsa::RcsaError),
    /// Operational modal analysis and chatter detection.
    #[error(transparent)]
    Oma(#[from] chatter_oma::OmaError),
    /// The caller's observer asked to stop (`chatter_progress::Observer::cancelled`).
    #[error(transparent)]
    Cancelled(#[from] chatter_progress::Cancelled),
    /// A signal record of an observations file cannot be used.
    #[error("{record}: {message}")]
    Record {
        /// The record, `signals[i]` with its file where known.
        record: String,
        /// What is wrong.
        message: String,
    },
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, JobError>;

/// `value` of `field` when `min <= value <= max`, else [`JobError::Invalid`].
pub fn count(
    field: &'static str,
    value: usize,
    min: usize,
    max: usize,
    what: &str,
) -> Result<usize> {
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(JobError::Invalid {
            field,
            value: value.to_string(),
            expected: format!("{what} from {min} to {max}"),
        })
    }
}
