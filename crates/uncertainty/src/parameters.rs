//! Parameter distributions that feed the bands: a mean and covariance of named theta parameters
//! (from a covariance file or a posterior's `summary.json`), optionally with posterior samples.
//!
//! Files (the toolkit's own, written by `chatter update` or by hand):
//! - covariance file: `{"parameter_names": ["theta_omega_2", ...], "covariance": [[...], ...],
//!   "mean": [...]}` (`mean` optional, zero by default);
//! - posterior folder: `summary.json` ([`PosteriorSummary`]: `parameter_names`,
//!   `posterior_mean` and `posterior_covariance`), and optionally `posterior.csv` whose header names the parameters and
//!   whose rows are samples.
//!
//! The names are those of `chatter update` (`chatter_updating::parameters::ModelParameter`):
//! relative modal perturbations `theta_omega_N`, ... and the absolute process parameters
//! `kt_n_per_mm2`, `kn_n_per_mm2` (cutting-force coefficients) and `c_n_per_m`. Every one of them
//! is sampled by the Monte Carlo maps. The error variances of a posterior (names starting with
//! `sigma_`) are not model parameters and are dropped with their rows and columns; any other
//! name is an error, never silently left out. The absolute parameters need a `mean`.

use crate::error::{Result, UncertaintyError};
use crate::montecarlo::gaussian_draws;
use chatter_dynamics::{ModalModel, Parameter};
use chatter_updating::parameters::{ModelParameter, Parameterization};
use chatter_updating::update::PosteriorSummary;
use nalgebra::DMatrix;
use std::path::Path;

/// A distribution of named model parameters: relative perturbations theta (000 Eq. 12-13:
/// omega(1 + theta) etc.) and absolute process parameters (cutting coefficients in N/mm^2).
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterDistribution {
    /// The parameters.
    pub parameters: Vec<ModelParameter>,
    /// Mean of theta.
    pub mean: Vec<f64>,
    /// Covariance of theta.
    pub covariance: DMatrix<f64>,
    /// Samples of theta (rows), when a posterior provides them.
    pub samples: Option<Vec<Vec<f64>>>,
}

fn invalid(path: &Path, message: String) -> UncertaintyError {
    UncertaintyError::InvalidInput {
        field: "parameter distribution",
        message: format!("{}: {message}", path.display()),
    }
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CovarianceFile {
    parameter_names: Vec<String>,
    covariance: Vec<Vec<f64>>,
    #[serde(default)]
    mean: Option<Vec<f64>>,
}

impl ParameterDistribution {
    /// Validate shapes and keep the model parameters among `names` (dropping only `sigma_*`).
    pub fn new(
        names: &[String],
        mean: Vec<f64>,
        covariance: Vec<Vec<f64>>,
        samples: Option<Vec<Vec<f64>>>,
        source: &Path,
    ) -> Result<Self> {
        let d = names.len();
        if mean.len() != d {
            return Err(invalid(
                source,
                format!("{d} parameter names but {} mean values", mean.len()),
            ));
        }
        if covariance.len() != d || covariance.iter().any(|r| r.len() != d) {
            return Err(invalid(
                source,
                format!("the covariance must be a {d} x {d} matrix (one row per parameter)"),
            ));
        }
        // a covariance is symmetric: an asymmetric matrix is a typo, not a distribution (the
        // Cholesky factor would silently read one triangle only); relative tolerance 1e-9 for
        // values printed with ten significant digits
        for (i, row) in covariance.iter().enumerate() {
            for (j, column) in covariance.iter().enumerate().take(i) {
                let (a, b) = (row[j], column[i]);
                if !(a.is_finite() && b.is_finite()) || (a - b).abs() > 1e-9 * a.abs().max(b.abs())
                {
                    return Err(invalid(
                        source,
                        format!(
                            "covariance[{i}][{j}] = {a:?} but covariance[{j}][{i}] = {b:?}: a \
                             covariance matrix is symmetric"
                        ),
                    ));
                }
            }
        }
        if let Some(bad) = samples
            .as_ref()
            .and_then(|s| s.iter().find(|r| r.len() != d))
        {
            return Err(invalid(
                source,
                format!("a sample has {} values, expected {d}", bad.len()),
            ));
        }
        let mut keep: Vec<(usize, ModelParameter)> = Vec::new();
        for (i, n) in names.iter().enumerate() {
            if n.starts_with("sigma_") {
                continue;
            }
            let p = n.parse::<ModelParameter>().map_err(|_| {
                invalid(
                    source,
                    format!(
                        "`{n}` is not a parameter that can be sampled (theta_omega_N, \
                         theta_zeta_N, theta_phi_N, theta_k_N, kt_n_per_mm2, kn_n_per_mm2, \
                         c_n_per_m; sigma_* error variances are dropped)"
                    ),
                )
            })?;
            if keep.iter().any(|k| k.1 == p) {
                return Err(invalid(source, format!("`{n}` is listed twice")));
            }
            keep.push((i, p));
        }
        if keep.is_empty() {
            return Err(invalid(
                source,
                format!("none of the names {names:?} is a model parameter"),
            ));
        }
        let idx: Vec<usize> = keep.iter().map(|k| k.0).collect();
        let covariance = DMatrix::from_fn(idx.len(), idx.len(), |a, b| covariance[idx[a]][idx[b]]);
        if covariance.clone().cholesky().is_none() {
            return Err(invalid(
                source,
                "the covariance is not symmetric positive definite".into(),
            ));
        }
        Ok(Self {
            parameters: keep.iter().map(|k| k.1).collect(),
            mean: idx.iter().map(|&i| mean[i]).collect(),
            covariance,
            samples: samples.map(|s| {
                s.iter()
                    .map(|r| idx.iter().map(|&i| r[i]).collect())
                    .collect()
            }),
        })
    }

    /// Read a covariance file (see the module docs).
    pub fn from_covariance_file(path: &Path) -> Result<Self> {
        let text = read(path)?;
        let f: CovarianceFile =
            serde_json::from_str(&text).map_err(|e| invalid(path, e.to_string()))?;
        let mean = match f.mean {
            Some(m) => m,
            None => {
                if let Some(n) = f.parameter_names.iter().find(|n| {
                    matches!(
                        n.parse::<ModelParameter>(),
                        Ok(p) if !matches!(p, ModelParameter::Modal(_))
                    )
                }) {
                    return Err(invalid(
                        path,
                        format!(
                            "`{n}` is an absolute value: give `mean` (it defaults to zero only for theta parameters)"
                        ),
                    ));
                }
                vec![0.0; f.parameter_names.len()]
            }
        };
        Self::new(&f.parameter_names, mean, f.covariance, None, path)
    }

    /// Read a posterior folder: `summary.json` and, when present, `posterior.csv`.
    pub fn from_posterior_dir(dir: &Path) -> Result<Self> {
        let summary_path = dir.join("summary.json");
        let text = read(&summary_path)?;
        let s: PosteriorSummary =
            serde_json::from_str(&text).map_err(|e| invalid(&summary_path, e.to_string()))?;
        let csv_path = dir.join("posterior.csv");
        let samples = if csv_path.exists() {
            Some(read_samples(&csv_path, &s.parameter_names)?)
        } else {
            None
        };
        Self::new(
            &s.parameter_names,
            s.posterior_mean,
            s.posterior_covariance,
            samples,
            &summary_path,
        )
    }

    /// The map from parameter values to models around `nominal`.
    pub fn parameterization(&self, nominal: &ModalModel) -> Result<Parameterization> {
        Parameterization::new(nominal.clone(), self.parameters.clone()).map_err(|e| {
            UncertaintyError::InvalidInput {
                field: "parameters",
                message: e.to_string(),
            }
        })
    }

    /// The model at the mean parameters.
    pub fn mean_model(&self, nominal: &ModalModel) -> Result<ModalModel> {
        self.parameterization(nominal)?
            .model(&self.mean)
            .map_err(|e| UncertaintyError::InvalidInput {
                field: "mean",
                message: e.to_string(),
            })
    }

    /// The modal parameters, for the methods that propagate only those (the second-order
    /// perturbation of 000 Eq. 14-18): an error naming the first process parameter otherwise,
    /// so that its variance is never dropped.
    pub fn modal_parameters(&self) -> Result<Vec<Parameter>> {
        self.parameters
            .iter()
            .map(|p| match p {
                ModelParameter::Modal(m) => Ok(*m),
                other => Err(UncertaintyError::InvalidInput {
                    field: "parameters",
                    message: format!(
                        "`{other}` cannot be propagated by the perturbation bounds (modal \
                         parameters only); use the Monte Carlo map, which samples it"
                    ),
                }),
            })
            .collect()
    }

    /// The covariance of theta' measured from the mean model instead of the nominal one. A modal
    /// parameter scales a nominal value by (1 + theta), so x_0 (1 + theta) = x_0 (1 + mean)
    /// (1 + theta') gives theta' = (theta - mean) / (1 + mean); an absolute parameter is only
    /// shifted (theta' = theta - mean). Sigma' = D Sigma D with D = diag(1 / (1 + mean_i)) for
    /// the modal and 1 for the absolute parameters.
    pub fn covariance_about_mean(&self) -> DMatrix<f64> {
        let d = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
            self.mean.len(),
            self.parameters
                .iter()
                .zip(&self.mean)
                .map(|(p, m)| match p {
                    ModelParameter::Modal(_) => 1.0 / (1.0 + m),
                    _ => 1.0,
                }),
        ));
        &d * &self.covariance * &d
    }

    /// `n` parameter draws: the posterior samples when present (cycled in order if `n` exceeds
    /// them, every k-th when fewer are asked), else Gaussian draws of N(mean, covariance).
    pub fn draws(&self, n: usize, seed: u64) -> Result<Vec<Vec<f64>>> {
        match &self.samples {
            Some(s) if !s.is_empty() => {
                let stride = (s.len() / n.max(1)).max(1);
                Ok((0..n).map(|i| s[(i * stride) % s.len()].clone()).collect())
            }
            _ => gaussian_draws(&self.mean, &self.covariance, n, seed),
        }
    }
}

fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| invalid(path, format!("cannot read: {e}")))
}

/// Samples from a CSV whose header holds (at least) `names`, in that order of columns.
fn read_samples(path: &Path, names: &[String]) -> Result<Vec<Vec<f64>>> {
    let mut reader = csv::Reader::from_path(path).map_err(|e| invalid(path, e.to_string()))?;
    let header = reader
        .headers()
        .map_err(|e| invalid(path, e.to_string()))?
        .clone();
    let columns: Vec<usize> = names
        .iter()
        .map(|n| {
            header
                .iter()
                .position(|h| h == n)
                .ok_or_else(|| invalid(path, format!("no column `{n}` in the header")))
        })
        .collect::<Result<_>>()?;
    reader
        .records()
        .enumerate()
        .map(|(row, rec)| {
            let rec = rec.map_err(|e| invalid(path, e.to_string()))?;
            columns
                .iter()
                .map(|&c| {
                    rec.get(c)
                        .and_then(|v| v.trim().parse::<f64>().ok())
                        .ok_or_else(|| {
                            invalid(
                                path,
                                format!("row {}: `{}` is not a number", row + 2, &header[c]),
                            )
                        })
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_names_are_errors_and_cutting_coefficients_are_kept() {
        let names = vec!["kt_n_per_mm2".to_string(), "theta_omega_1".into()];
        let d = ParameterDistribution::new(
            &names,
            vec![700.0, 0.0],
            vec![vec![4900.0, 0.0], vec![0.0, 1e-6]],
            None,
            Path::new("x.json"),
        )
        .unwrap();
        assert_eq!(d.parameters[0], ModelParameter::KtNPerMm2);
        assert!(
            d.modal_parameters()
                .unwrap_err()
                .to_string()
                .contains("kt_n_per_mm2")
        );
        // absolute parameters are shifted, not scaled
        assert_eq!(d.covariance_about_mean()[(0, 0)], 4900.0);
        let e = ParameterDistribution::new(
            &["kt".to_string()],
            vec![700.0],
            vec![vec![4900.0]],
            None,
            Path::new("x.json"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("`kt`") && e.contains("kt_n_per_mm2"), "{e}");
        let dir = std::env::temp_dir().join(format!("chatter-unc-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("kt.json");
        std::fs::write(
            &file,
            r#"{"parameter_names": ["kt_n_per_mm2"], "covariance": [[4900]]}"#,
        )
        .unwrap();
        let e = ParameterDistribution::from_covariance_file(&file)
            .unwrap_err()
            .to_string();
        assert!(e.contains("give `mean`"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn drops_non_model_parameters_and_checks_shapes() {
        let names = vec!["theta_omega_2".to_string(), "sigma_r2".into()];
        let d = ParameterDistribution::new(
            &names,
            vec![0.01, 0.5],
            vec![vec![1e-6, 0.0], vec![0.0, 1.0]],
            Some(vec![vec![0.02, 0.3]]),
            Path::new("x.json"),
        )
        .unwrap();
        assert_eq!(d.parameters.len(), 1);
        assert_eq!(d.mean, vec![0.01]);
        assert_eq!(d.samples.as_ref().unwrap()[0], vec![0.02]);
        // theta' = (theta - mean) / (1 + mean)
        assert!((d.covariance_about_mean()[(0, 0)] - 1e-6 / 1.01f64.powi(2)).abs() < 1e-18);
        let bad = ParameterDistribution::new(
            &names,
            vec![0.0],
            vec![vec![1.0, 0.0], vec![0.0, 1.0]],
            None,
            Path::new("x.json"),
        );
        assert!(bad.unwrap_err().to_string().contains("x.json"));
    }
}
