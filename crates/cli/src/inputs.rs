//! Loading the user's files with errors that name them.

use anyhow::{Context, Result, bail};
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

/// Parse `MIN:MAX:N` speeds (rpm).
pub fn speeds(spec: &str) -> Result<Vec<f64>> {
    let (min, max, n) = range("--speeds", spec)?;
    Ok(chatter_stability::boundary::speed_range(min, max, n)?)
}

/// Parse a `MIN:MAX:N` grid of `flag` with `floor <= MIN < MAX` and `N >= 2`.
pub fn grid(flag: &str, spec: &str, floor: f64) -> Result<Vec<f64>> {
    let (min, max, n) = range(flag, spec)?;
    if !(min >= floor && max > min && n >= 2) {
        bail!("{flag} `{spec}`: expected {floor} <= MIN < MAX and N >= 2");
    }
    Ok((0..n)
        .map(|i| min + (max - min) * i as f64 / (n - 1) as f64)
        .collect())
}

fn range(flag: &str, spec: &str) -> Result<(f64, f64, usize)> {
    let parts: Vec<&str> = spec.split(':').collect();
    if parts.len() != 3 {
        bail!("{flag} `{spec}`: expected MIN:MAX:N, e.g. 3000:15000:200");
    }
    let min: f64 = parts[0]
        .parse()
        .with_context(|| format!("{flag} MIN `{}`", parts[0]))?;
    let max: f64 = parts[1]
        .parse()
        .with_context(|| format!("{flag} MAX `{}`", parts[1]))?;
    let n: usize = parts[2]
        .parse()
        .with_context(|| format!("{flag} N `{}`", parts[2]))?;
    Ok((min, max, n))
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
