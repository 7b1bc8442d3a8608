//! The gap-diagnosis job (`chatter diagnose`, `chatter.diagnose`): the request's seed, samples
//! and held-out validation on [`chatter_gap::diagnose()`].
//!
//! [`diagnose_recordings`] starts from a shop's recordings: the observations file's `signals`
//! are judged by chatter detection and identified by OMA ([`crate::recordings`], the library
//! calls of `chatter detect` and `chatter oma`), the labelled cuts and identified poles join the
//! file's own, and the diagnosis runs on the result; every record's outcome is in the
//! [`RecordedDiagnosis::records`] table.

use crate::error::{JobError, Result, count};
use crate::recordings::{RecordRow, RecordVerdict, RecordsRequest, label_records};
use chatter_dynamics::{ModalModel, Observations};
use chatter_gap::{DiagnoseOptions, Diagnosis, Validation};
use chatter_progress::Observer;
use serde::Serialize;

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

/// A diagnosis made from an observations file with signal records: the diagnosis's fields and
/// the `records` table when serialized (`diagnosis.json`).
#[derive(Debug, Clone, Serialize)]
pub struct RecordedDiagnosis {
    /// The diagnosis of the file's cuts and poles with those made from the records.
    #[serde(flatten)]
    pub diagnosis: Diagnosis,
    /// One row per signal record: verdict, chatter frequency, evidence, pole or the reason
    /// there is none (empty when the file holds no `signals`).
    pub records: Vec<RecordRow>,
    /// The observations diagnosed: the file's cuts and poles, then the records' (no
    /// `signals`).
    #[serde(skip)]
    pub observations: Observations,
}

/// Diagnose an observations file that may hold signal records: the records are labelled and
/// identified first ([`label_records`] with `records`), then the request is checked against
/// the resulting cuts and poles and [`diagnose`] runs on them. Without `signals` this is
/// [`diagnose`] with an empty table. An error when no record gives a cut or a pole and the
/// file holds none either (the message lists every record's reason); a cancel by `observer`
/// stops the job at any step.
pub fn diagnose_recordings(
    model: &ModalModel,
    observations: &Observations,
    request: &DiagnoseRequest,
    records: &RecordsRequest,
    observer: &dyn Observer,
) -> Result<RecordedDiagnosis> {
    let (labelled, rows) = if observations.signals.is_empty() {
        (observations.clone(), Vec::new())
    } else {
        let r = label_records(observations, model, records, observer)?;
        (r.observations, r.records)
    };
    if labelled.cuts.is_empty() && labelled.poles.is_empty() {
        let reasons: Vec<String> = rows
            .iter()
            .map(|r| {
                format!(
                    "signals[{}] ({}): {}",
                    r.record,
                    r.file.display(),
                    r.reason.as_deref().unwrap_or("no cut")
                )
            })
            .collect();
        return Err(JobError::Invalid {
            field: "observations",
            value: format!(
                "no cuts and no poles, and none of the {} signal records judged",
                rows.len()
            ),
            expected: format!(
                "at least one record that chatter detection can judge; {}",
                reasons.join("; ")
            ),
        });
    }
    let diagnosis = diagnose(model, &labelled, request, observer)?;
    Ok(RecordedDiagnosis {
        diagnosis,
        records: rows,
        observations: labelled,
    })
}

impl RecordedDiagnosis {
    /// How many records were judged stable, chatter and not judged, and how many gave a pole.
    pub fn record_counts(&self) -> RecordCounts {
        let count = |v: RecordVerdict| self.records.iter().filter(|r| r.verdict == v).count();
        RecordCounts {
            stable: count(RecordVerdict::Stable),
            chatter: count(RecordVerdict::Chatter),
            not_judged: count(RecordVerdict::NotJudged),
            poles: self.records.iter().filter(|r| r.pole.is_some()).count(),
        }
    }
}

/// Counts of a [`RecordedDiagnosis`]'s records by outcome.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct RecordCounts {
    /// Records detection judged stable.
    pub stable: usize,
    /// Records detection judged chatter.
    pub chatter: usize,
    /// Records that could not be read or judged.
    pub not_judged: usize,
    /// Stable records OMA identified a pole from.
    pub poles: usize,
}
