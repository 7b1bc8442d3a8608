//! Loading the user's files with errors that name them.

use anyhow::{Context, Result};
use chatter_dynamics::{ModalModel, Observations};
use chatter_frf::MeasuredModel;
use chatter_jobs::lobes::{Dynamics, uses_measured_frf};
use chatter_stability::Method;
use chatter_updating::joint_prior::{JointNormal, PriorFile};
use chatter_updating::update::PriorOverrides;
use std::path::Path;

/// Read and validate a model file.
pub fn model(path: &Path) -> Result<ModalModel> {
    ModalModel::from_path(path).context("reading the model file")
}

/// Read a model file as the dynamics `method` runs on: its measured FRFs for the zero-order
/// method when it has `measured_frf` (`chatter_jobs::lobes::uses_measured_frf`), else its
/// modes.
pub fn dynamics(path: &Path, method: Method) -> Result<Dynamics> {
    if let Ok(file) = chatter_frf::read_model_file(path)
        && uses_measured_frf(&file, method, &path.display().to_string())
            .map_err(crate::job_error)?
    {
        return Ok(Dynamics::Measured(
            MeasuredModel::from_path(path).context("reading the measured FRFs")?,
        ));
    }
    Ok(Dynamics::Modal(model(path)?))
}

/// Read and validate an observations file (JSON or cuts CSV).
pub fn observations(path: &Path) -> Result<Observations> {
    Observations::from_path(path).context("reading the observations file")
}

/// Read an observations file and, when given, a model file checked to match it (the model's
/// operation against the observations' geometry; `crate::validate::observations_match`).
pub fn observations_with_model(
    observations_path: &Path,
    model_path: Option<&Path>,
) -> Result<(Observations, Option<ModalModel>)> {
    let observations = observations(observations_path)?;
    let model = model_path.map(model).transpose()?;
    if let (Some(m), Some(path)) = (&model, model_path) {
        crate::validate::observations_match(m, &observations, observations_path, path)?;
    }
    Ok((observations, model))
}

/// Read a priors file (`--priors` of `update` and `plan`): marginals by name, or one correlated
/// normal `{"parameter_names", "mean", "covariance"}`; without a file, neither.
pub fn priors(path: Option<&Path>) -> Result<(PriorOverrides, Option<JointNormal>)> {
    let Some(path) = path else {
        return Ok((PriorOverrides::new(), None));
    };
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading the priors file {}", path.display()))?;
    let file = PriorFile::from_json_str(&text).with_context(|| {
        format!(
            "{}: invalid priors file (expected marginals by name, or \
             {{\"parameter_names\", \"mean\", \"covariance\"}})",
            path.display()
        )
    })?;
    Ok(match file {
        PriorFile::Marginals(m) => (m, None),
        PriorFile::Joint(j) => (PriorOverrides::new(), Some(j)),
    })
}
