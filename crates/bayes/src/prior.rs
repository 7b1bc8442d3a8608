//! Priors: uniform, normal, truncated normal, lognormal, and independent joints of them.

use crate::error::{BayesError, Result};
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

fn std_normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// Complementary error function (Numerical Recipes erfcc, relative error < 1.2e-7).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.265_512_23
            + t * (1.000_023_68
                + t * (0.374_091_96
                    + t * (0.096_784_18
                        + t * (-0.186_288_06
                            + t * (0.278_868_07
                                + t * (-1.135_203_98
                                    + t * (1.488_515_87
                                        + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
            .exp();
    if x >= 0.0 { r } else { 2.0 - r }
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
                let mass = std_normal_cdf((high - mean) / sd) - std_normal_cdf((low - mean) / sd);
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
