//! Loading the user's files with errors that name them.

use anyhow::{Context, Result};
use chatter_dynamics::{ModalModel, Observations, SignalRecord};
use chatter_oma::signals::Signals;
use std::path::Path;

/// Read and validate a model file.
pub fn model(path: &Path) -> Result<ModalModel> {
    ModalModel::from_path(path).context("reading the model file")
}

/// Read and validate an observations file (JSON or cuts CSV).
pub fn observations(path: &Path) -> Result<Observations> {
    Observations::from_path(path).context("reading the observations file")
}

/// The record's channels: CSV at the entry's rate, WAV or MP3 at their own.
pub fn signal_record(i: usize, record: &SignalRecord) -> Result<Signals> {
    let extension = record
        .file
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    Ok(match extension.as_deref() {
        Some("wav") => Signals::from_wav(&record.file, None)?,
        Some("mp3") => Signals::from_mp3(&record.file)?,
        _ => {
            let fs = record.sample_rate_hz.with_context(|| {
                format!(
                    "`signals[{i}].sample_rate_hz` is missing: a CSV record needs its sample rate"
                )
            })?;
            Signals::from_csv(&record.file, fs)?
        }
    })
}
