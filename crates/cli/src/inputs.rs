//! Loading the user's files with errors that name them.

use anyhow::{Context, Result};
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
