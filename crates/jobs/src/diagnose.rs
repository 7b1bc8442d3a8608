//! The gap-diagnosis job (`chatter diagnose`, `chatter.diagnose`): the request's seed, samples
//! and held-out validation on [`chatter_gap::diagnose()`].

use crate::error::{JobError, Result, count};
use chatter_dynamics::{ModalModel, Observations};
use chatter_gap::{DiagnoseOptions, Diagnosis, Validation};
use chatter_progress::Observer;

/// Default samples per model class.
pub const DEFAULT_SAMPLES: usize = 120;
/// Default folds or speed bands of the validation.
pub const DEFAULT_FOLDS: usize = 3;

/// What a diagnosis was asked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiagnoseRequest {
    /// Seed of the samplers and the folds.
    pub seed: u64,
    /// iTMCMC samples per class (40 to 100 000).
    pub samples: usize,
    /// Held-out validation.
    pub validation: Validation,
    /// Every class's prior draws and pointwise log-likelihood too (for ArviZ).
    pub pointwise: bool,
}

impl DiagnoseRequest {
    /// 120 samples per class, 3-fold validation.
    pub fn new(seed: u64) -> Self {
        Self {
            seed,
            samples: DEFAULT_SAMPLES,
            validation: Validation::KFold {
                folds: DEFAULT_FOLDS,
            },
            pointwise: false,
        }
    }

    /// Folds or bands of the validation (0 when off).
    pub fn folds(&self) -> usize {
        match self.validation {
            Validation::KFold { folds } => folds,
            Validation::SpeedBands { bands } => bands,
            Validation::Off => 0,
        }
    }
}

/// Check the request against the observations and diagnose.
pub fn diagnose(
    model: &ModalModel,
    observations: &Observations,
    request: &DiagnoseRequest,
    observer: &dyn Observer,
) -> Result<Diagnosis> {
    check(observations, request)?;
    let options = DiagnoseOptions {
        seed: request.seed,
        samples: request.samples,
        validation: request.validation,
        pointwise: request.pointwise,
        ..DiagnoseOptions::default()
    };
    Ok(chatter_gap::diagnose(
        model,
        observations,
        &options,
        observer,
    )?)
}

/// The folds fit the observations (k-fold splits the entries, speed bands the distinct
/// speeds) and the samples are in range.
pub fn check(observations: &Observations, request: &DiagnoseRequest) -> Result<()> {
    let (available, what) = match request.validation {
        Validation::KFold { .. } => (
            observations.cuts.len() + observations.poles.len(),
            "cuts and poles",
        ),
        Validation::SpeedBands { .. } => {
            let mut distinct = observations.speeds_rpm();
            distinct.sort_by(f64::total_cmp);
            distinct.dedup();
            (distinct.len(), "distinct speeds")
        }
        Validation::Off => (usize::MAX, ""),
    };
    let folds = request.folds();
    if available > 0 && folds > available {
        return Err(JobError::Invalid {
            field: "folds",
            value: folds.to_string(),
            expected: format!(
                "at most one fold per entry: the observations hold {available} {what}"
            ),
        });
    }
    count(
        "samples",
        request.samples,
        40,
        100_000,
        "samples per model class",
    )?;
    Ok(())
}
