//! Priors: uniform, normal, truncated normal, lognormal, independent joints of them, and the
//! correlated multivariate normal (given by its mean and covariance, or estimated from samples).

use crate::error::{BayesError, Result};
use crate::special::normal_cdf;
use rand_distr::{Distribution, StandardNormal};
use std::f64::consts::PI;

/// A prior over parameter vectors.
pub trait Prior: Sync {
    /// Dimension.
    fn dimension(&self) -> usize;
    /// ln p(theta); -inf outside the support.
    fn ln_pdf(&self, theta: &[f64]) -> f64;
    /// One draw.
    fn sample(&self, rng: &mut dyn rand::RngCore) -> Vec<f64>;
}

/// A one-dimensional prior. Its serde form is tagged by `kind`, e.g.
/// `{"kind": "truncated_normal", "mean": 0, "sd": 0.03, "low": -0.03, "high": 0.03}`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Marginal {
    /// Uniform on [low, high].
    Uniform {
        /// Lower bound.
        low: f64,
        /// Upper bound.
        high: f64,
    },
    /// Normal N(mean, sd^2).
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        sd: f64,
    },
    /// Normal N(mean, sd^2) truncated to [low, high].
    TruncatedNormal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        sd: f64,
        /// Lower bound.
        low: f64,
        /// Upper bound.
        high: f64,
    },
    /// ln(x) ~ N(mu, sigma^2).
    LogNormal {
        /// Mean of ln x.
        mu: f64,
        /// Standard deviation of ln x.
        sigma: f64,
    },
}

impl Marginal {
    /// Validate the parameters.
    pub fn validated(self) -> Result<Self> {
        let bad = |m: &str| {
            Err(BayesError::InvalidInput {
                field: "prior",
                message: format!("{self:?}: {m}"),
            })
        };
        match self {
            Marginal::Uniform { low, high }
                if !(low.is_finite() && high.is_finite() && low < high) =>
            {
                bad("expected finite low < high")
            }
            Marginal::Normal { mean, sd } if !(mean.is_finite() && sd.is_finite() && sd > 0.0) => {
                bad("expected a finite mean and sd > 0")
            }
            Marginal::TruncatedNormal {
                mean,
                sd,
                low,
                high,
            } if !(mean.is_finite() && sd > 0.0 && sd.is_finite() && low < high) => {
                bad("expected sd > 0 and low < high")
            }
            Marginal::LogNormal { mu, sigma }
                if !(mu.is_finite() && sigma.is_finite() && sigma > 0.0) =>
            {
                bad("expected sigma > 0")
            }
            ok => Ok(ok),
        }
    }

    /// ln pdf.
    pub fn ln_pdf(&self, x: f64) -> f64 {
        match *self {
            Marginal::Uniform { low, high } => {
                if (low..=high).contains(&x) {
                    -(high - low).ln()
                } else {
                    f64::NEG_INFINITY
                }
            }
            Marginal::Normal { mean, sd } => {
                let z = (x - mean) / sd;
                -0.5 * z * z - sd.ln() - 0.5 * (2.0 * PI).ln()
            }
            Marginal::TruncatedNormal {
                mean,
                sd,
                low,
                high,
            } => {
                if !(low..=high).contains(&x) {
                    return f64::NEG_INFINITY;
                }
                let mass = normal_cdf((high - mean) / sd) - normal_cdf((low - mean) / sd);
                let z = (x - mean) / sd;
                -0.5 * z * z - sd.ln() - 0.5 * (2.0 * PI).ln() - mass.ln()
            }
            Marginal::LogNormal { mu, sigma } => {
                if x <= 0.0 {
                    return f64::NEG_INFINITY;
                }
                let z = (x.ln() - mu) / sigma;
                -0.5 * z * z - (x * sigma).ln() - 0.5 * (2.0 * PI).ln()
            }
        }
    }

    /// One draw (truncated normal by rejection, fine for the moderate truncations used here).
    pub fn sample(&self, rng: &mut dyn rand::RngCore) -> f64 {
        let mut normal = || -> f64 { StandardNormal.sample(rng) };
        match *self {
            Marginal::Uniform { low, high } => {
                let u: f64 = rand::RngCore::next_u64(&mut *rng) as f64 / u64::MAX as f64;
                low + (high - low) * u
            }
            Marginal::Normal { mean, sd } => mean + sd * normal(),
            Marginal::TruncatedNormal {
                mean,
                sd,
                low,
                high,
            } => {
                for _ in 0..100_000 {
                    let x = mean + sd * normal();
                    if (low..=high).contains(&x) {
                        return x;
                    }
                }
                mean.clamp(low, high)
            }
            Marginal::LogNormal { mu, sigma } => (mu + sigma * normal()).exp(),
        }
    }
}

/// Independent marginals.
#[derive(Debug, Clone, PartialEq)]
pub struct IndependentPrior {
    marginals: Vec<Marginal>,
}

impl IndependentPrior {
    /// Validated joint of independent marginals.
    pub fn new(marginals: Vec<Marginal>) -> Result<Self> {
        if marginals.is_empty() {
            return Err(BayesError::InvalidInput {
                field: "prior",
                message: "no parameters".into(),
            });
        }
        let marginals = marginals
            .into_iter()
            .map(Marginal::validated)
            .collect::<Result<_>>()?;
        Ok(Self { marginals })
    }
    /// The marginals.
    pub fn marginals(&self) -> &[Marginal] {
        &self.marginals
    }
}

impl Prior for IndependentPrior {
    fn dimension(&self) -> usize {
        self.marginals.len()
    }
    fn ln_pdf(&self, theta: &[f64]) -> f64 {
        if theta.len() != self.marginals.len() {
            return f64::NEG_INFINITY;
        }
        self.marginals
            .iter()
            .zip(theta)
            .map(|(m, &x)| m.ln_pdf(x))
            .sum()
    }
    fn sample(&self, rng: &mut dyn rand::RngCore) -> Vec<f64> {
        self.marginals.iter().map(|m| m.sample(rng)).collect()
    }
}

/// Multivariate normal N(mu, Sigma): a correlated prior, e.g. one estimated from an ensemble of
/// fitted parameter vectors. ln p(x) = -1/2 |L^-1 (x - mu)|^2 - d/2 ln(2 pi) - sum ln L_ii with
/// the Cholesky factor Sigma = L L^T; a draw is mu + L z, z ~ N(0, I).
#[derive(Debug, Clone, PartialEq)]
pub struct MultivariateNormalPrior {
    mean: Vec<f64>,
    covariance: nalgebra::DMatrix<f64>,
    cholesky: nalgebra::DMatrix<f64>,
    ln_normalization: f64,
}

/// Largest relative asymmetry |S_ij - S_ji| / sqrt(S_ii S_jj) of a covariance accepted as
/// rounding (a covariance written to a file with 15 digits and read back).
const SYMMETRY_TOLERANCE: f64 = 1e-9;

impl MultivariateNormalPrior {
    /// Validated: `mean` non-empty and finite, `covariance` d x d (rows), finite, symmetric to
    /// rounding and positive definite.
    pub fn new(mean: Vec<f64>, covariance: &[Vec<f64>]) -> Result<Self> {
        let d = mean.len();
        let invalid =
            |field: &'static str, message: String| BayesError::InvalidInput { field, message };
        if d == 0 {
            return Err(invalid("mean", "no parameters".into()));
        }
        if let Some((i, v)) = mean.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(invalid(
                "mean",
                format!("entry {i} is {v}; expected a finite mean"),
            ));
        }
        if covariance.len() != d || covariance.iter().any(|r| r.len() != d) {
            let rows: Vec<usize> = covariance.iter().map(Vec::len).collect();
            return Err(invalid(
                "covariance",
                format!("row lengths {rows:?}; expected {d} rows of {d} (the mean's dimension)"),
            ));
        }
        let c = nalgebra::DMatrix::from_fn(d, d, |i, j| covariance[i][j]);
        for i in 0..d {
            for j in 0..d {
                let v = c[(i, j)];
                let scale = (c[(i, i)] * c[(j, j)]).abs().sqrt();
                if !v.is_finite() || (v - c[(j, i)]).abs() > SYMMETRY_TOLERANCE * scale {
                    return Err(invalid(
                        "covariance",
                        format!(
                            "entry ({i}, {j}) is {v}, entry ({j}, {i}) {}; expected a finite symmetric matrix",
                            c[(j, i)]
                        ),
                    ));
                }
            }
        }
        let symmetric = (&c + c.transpose()) * 0.5;
        let Some(chol) = symmetric.clone().cholesky() else {
            return Err(invalid(
                "covariance",
                "not positive definite; expected a covariance with positive variances and correlations inside (-1, 1)".into(),
            ));
        };
        let l = chol.l();
        let ln_det_half: f64 = (0..d).map(|i| l[(i, i)].ln()).sum();
        Ok(Self {
            mean,
            covariance: symmetric,
            cholesky: l,
            ln_normalization: -0.5 * d as f64 * (2.0 * PI).ln() - ln_det_half,
        })
    }

    /// The sample mean and covariance (divisor n - 1) of `samples`: at least d + 1 vectors of
    /// one dimension d, spanning all d directions.
    pub fn from_samples(samples: &[Vec<f64>]) -> Result<Self> {
        let d = samples.first().map_or(0, Vec::len);
        if d == 0 || samples.len() < d + 1 {
            return Err(BayesError::InvalidInput {
                field: "samples",
                message: format!(
                    "{} samples of dimension {d}; expected at least dimension + 1 samples of a dimension >= 1",
                    samples.len()
                ),
            });
        }
        if let Some(i) = samples.iter().position(|s| s.len() != d) {
            return Err(BayesError::InvalidInput {
                field: "samples",
                message: format!("sample {i} has {} entries, sample 0 {d}", samples[i].len()),
            });
        }
        let n = samples.len() as f64;
        let mean: Vec<f64> = (0..d)
            .map(|j| samples.iter().map(|s| s[j]).sum::<f64>() / n)
            .collect();
        let covariance: Vec<Vec<f64>> = (0..d)
            .map(|i| {
                (0..d)
                    .map(|j| {
                        samples
                            .iter()
                            .map(|s| (s[i] - mean[i]) * (s[j] - mean[j]))
                            .sum::<f64>()
                            / (n - 1.0)
                    })
                    .collect()
            })
            .collect();
        Self::new(mean, &covariance)
    }

    /// The mean mu.
    pub fn mean(&self) -> &[f64] {
        &self.mean
    }

    /// The covariance Sigma.
    pub fn covariance(&self) -> &nalgebra::DMatrix<f64> {
        &self.covariance
    }
}

impl Prior for MultivariateNormalPrior {
    fn dimension(&self) -> usize {
        self.mean.len()
    }
    fn ln_pdf(&self, theta: &[f64]) -> f64 {
        if theta.len() != self.mean.len() || theta.iter().any(|v| !v.is_finite()) {
            return f64::NEG_INFINITY;
        }
        let r = nalgebra::DVector::from_iterator(
            theta.len(),
            theta.iter().zip(&self.mean).map(|(x, m)| x - m),
        );
        // L y = r by forward substitution
        match self.cholesky.solve_lower_triangular(&r) {
            Some(y) => self.ln_normalization - 0.5 * y.norm_squared(),
            None => f64::NEG_INFINITY,
        }
    }
    fn sample(&self, rng: &mut dyn rand::RngCore) -> Vec<f64> {
        let d = self.mean.len();
        let z = nalgebra::DVector::from_iterator(
            d,
            (0..d).map(|_| {
                let v: f64 = StandardNormal.sample(&mut *rng);
                v
            }),
        );
        let x = &self.cholesky * z;
        self.mean.iter().zip(x.iter()).map(|(m, v)| m + v).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn densities_integrate_to_one() {
        for m in [
            Marginal::Uniform {
                low: -1.0,
                high: 3.0,
            },
            Marginal::Normal { mean: 0.5, sd: 0.3 },
            Marginal::TruncatedNormal {
                mean: 0.0,
                sd: 0.0316,
                low: -0.03,
                high: 0.03,
            },
            Marginal::LogNormal {
                mu: 0.0,
                sigma: 0.5,
            },
        ] {
            let (a, b) = (-5.0, 10.0);
            let n = 400_000;
            let h = (b - a) / n as f64;
            let integral: f64 = (0..n)
                .map(|i| m.ln_pdf(a + (i as f64 + 0.5) * h).exp() * h)
                .sum();
            assert!((integral - 1.0).abs() < 1e-4, "{m:?}: {integral}");
        }
    }

    #[test]
    fn samples_lie_in_support_and_invalid_priors_fail() {
        let m = Marginal::TruncatedNormal {
            mean: 0.0,
            sd: 0.2236,
            low: -0.8,
            high: 0.8,
        };
        let mut rng = rand::rngs::StdRng::seed_from_u64(1);
        assert!((0..1000).all(|_| m.sample(&mut rng).abs() <= 0.8));
        assert!(
            Marginal::Uniform {
                low: 1.0,
                high: 0.0
            }
            .validated()
            .is_err()
        );
        assert!(
            Marginal::Normal {
                mean: 0.0,
                sd: -1.0
            }
            .validated()
            .is_err()
        );
        assert!(IndependentPrior::new(vec![]).is_err());
    }
}
