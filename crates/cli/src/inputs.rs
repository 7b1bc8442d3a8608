//! Loading the user's files with errors that name them.

use anyhow::{Context, Result, bail};
use chatter_dynamics::{ModalModel, Observations};
use std::path::Path;

/// Read and validate a model file.
pub fn model(path: &Path) -> Result<ModalModel> {
    ModalModel::from_path(path).context("reading the model file")
}

/// Read and validate an observations file (JSON or cuts CSV).
pub fn observations(path: &Path) -> Result<Observations> {
    Observations::from_path(path).context("reading the observations file")
}

/// Parse `MIN:MAX:N` speeds.
pub fn speeds(spec: &str) -> Result<Vec<f64>> {
    let parts: Vec<&str> = spec.split(':').collect();
    if parts.len() != 3 {
        bail!("--speeds `{spec}`: expected MIN:MAX:N, e.g. 3000:15000:200");
    }
    let min: f64 = parts[0]
        .parse()
        .with_context(|| format!("--speeds MIN `{}`", parts[0]))?;
    let max: f64 = parts[1]
        .parse()
        .with_context(|| format!("--speeds MAX `{}`", parts[1]))?;
    let n: usize = parts[2]
        .parse()
        .with_context(|| format!("--speeds N `{}`", parts[2]))?;
    Ok(chatter_stability::boundary::speed_range(min, max, n)?)
}
