//! Correlated priors: a multivariate normal block over some of the sampled parameters times the
//! independent marginals of the others, as seed 004 builds it (Schmitz et al. 2022, Sec. 2:
//! P_prior(u) = N_d(mu, Sigma) over u = [K_s, beta, f_n1, k_1, zeta_1, f_n2, k_2, zeta_2], the
//! modal block estimated from an RCSA FRF ensemble, `chatter_rcsa::prior`).
//!
//! The block comes from a prior file `{"parameter_names": [...], "mean": [...],
//! "covariance": [[...]]}` (what `chatter_rcsa::prior::ModalPrior::to_json` writes); its names
//! are sampled parameter names ([`crate::parameters`]). A normal has unbounded support while the
//! model does not (a stiffness or a damping ratio must be positive, K_t > 0): the prior is
//! truncated to the draws whose model can be built. ln p is then the normal's ln density up to
//! the truncation's constant, which cancels in the samplers' ratios (and shifts a log-evidence
//! by ln of the kept mass, negligible where the truncation removes little; the plan reports no
//! evidence); a draw repeats until the model is valid (at most [`MAX_REDRAWS`] times).
//!
//! An ensemble prior is nearly singular (004's six modal parameters all follow the two joint
//! parameters k and c: correlations of 0.998 and more), and a random-walk sampler that proposes
//! in u almost never lands on its ridge. The samplers therefore run in whitened coordinates
//! ([`WhitenedPrior`], [`WhitenedLikelihood`]): z = L^-1 (u - mu) on the block with
//! Sigma = L L^T, the other parameters unchanged, so the block's prior is N(0, I); the samples
//! are mapped back by u = mu + L z (the Jacobian |det L| is a constant).

use crate::classes::{
    ClassSelection, Posterior, SamplerOptions, sample_posterior, select_model_class,
};
use crate::error::{Result, UpdatingError};
use crate::parameters::{ModelParameter, Parameterization};
use crate::update::PriorOverrides;
use chatter_bayes::Prior;
use chatter_bayes::prior::{Marginal, MultivariateNormalPrior};
use chatter_bayes::samples::SampleSet;
use chatter_bayes::tmcmc::{LikelihoodFailure, LogLikelihood};
use chatter_progress::Observer;

/// Draws of a truncated prior tried before giving up (the last one is then returned, and the
/// model built from it fails with its own error message).
pub const MAX_REDRAWS: usize = 10_000;

/// A multivariate normal prior over named parameters, as read from a prior file.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointNormal {
    /// Sampled parameter names, in the order of `mean` and `covariance`.
    pub parameter_names: Vec<String>,
    /// Mean, in the parameters' units.
    pub mean: Vec<f64>,
    /// Covariance (rows), in the parameters' units squared.
    pub covariance: Vec<Vec<f64>>,
}

/// A priors file: marginals by name, or one correlated normal (a file with `parameter_names`).
#[derive(Debug, Clone, PartialEq)]
pub enum PriorFile {
    /// `{"NAME": {"kind": ...}, ...}`.
    Marginals(PriorOverrides),
    /// `{"parameter_names": [...], "mean": [...], "covariance": [[...]]}`.
    Joint(JointNormal),
}

impl PriorFile {
    /// Parse a priors file; the error names the form that was expected.
    pub fn from_json_str(text: &str) -> std::result::Result<Self, serde_json::Error> {
        let value: serde_json::Value = serde_json::from_str(text)?;
        if value.get("parameter_names").is_some() {
            serde_json::from_value(value).map(PriorFile::Joint)
        } else {
            serde_json::from_value(value).map(PriorFile::Marginals)
        }
    }
}

impl JointNormal {
    /// The block's parameters, parsed and validated against `sampled` (every name sampled,
    /// none twice) with their positions in theta.
    fn positions(&self, sampled: &[ModelParameter]) -> Result<Vec<usize>> {
        let invalid = |message: String| UpdatingError::InvalidInput {
            field: "priors",
            message,
        };
        let mut positions = Vec::with_capacity(self.parameter_names.len());
        for name in &self.parameter_names {
            let q: ModelParameter = name.parse()?;
            let k = sampled.iter().position(|p| *p == q).ok_or_else(|| {
                invalid(format!(
                    "the prior file's `{name}` is not a sampled parameter ({})",
                    sampled
                        .iter()
                        .map(ToString::to_string)
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
            if positions.contains(&k) {
                return Err(invalid(format!("the prior file lists `{name}` twice")));
            }
            positions.push(k);
        }
        Ok(positions)
    }

    /// The parsed parameter names (the sampled parameters when none are given).
    pub fn parameters(&self) -> Result<Vec<ModelParameter>> {
        self.parameter_names.iter().map(|n| n.parse()).collect()
    }
}

/// The prior of a parameterization: an optional correlated normal block, independent marginals
/// for the rest, truncated to valid models (module docs). Nuisance parameters (the error
/// variance of pole data) may follow the model parameters in theta; they have marginals only.
#[derive(Debug, Clone)]
pub struct SampledPrior {
    parameterization: Parameterization,
    marginals: Vec<Option<Marginal>>,
    block: Option<(Vec<usize>, MultivariateNormalPrior)>,
    /// Cholesky factor L of the block's covariance and ln |det L|.
    whitening: Option<(nalgebra::DMatrix<f64>, f64)>,
}

impl SampledPrior {
    /// `marginals[k]` for every parameter outside the block (`None` inside it); `joint`
    /// validated (sampled names, positive definite covariance). A marginal override of a block
    /// parameter is an error: the block sets its prior.
    pub fn new(
        parameterization: Parameterization,
        marginals: Vec<Marginal>,
        overrides: &PriorOverrides,
        joint: Option<&JointNormal>,
    ) -> Result<Self> {
        Self::with_nuisance(parameterization, marginals, &[], overrides, joint)
    }

    /// As [`Self::new`], with nuisance parameters named `nuisance` after the model parameters:
    /// `marginals` covers the model parameters, then the nuisance ones.
    pub fn with_nuisance(
        parameterization: Parameterization,
        mut marginals: Vec<Marginal>,
        nuisance: &[String],
        overrides: &PriorOverrides,
        joint: Option<&JointNormal>,
    ) -> Result<Self> {
        let mut names = parameterization.names();
        names.extend(nuisance.iter().cloned());
        if marginals.len() != names.len() {
            return Err(UpdatingError::InvalidInput {
                field: "priors",
                message: format!(
                    "{} marginals for {} parameters ({})",
                    marginals.len(),
                    names.len(),
                    names.join(", ")
                ),
            });
        }
        for (name, spec) in overrides {
            let k = names.iter().position(|n| n == name).ok_or_else(|| {
                UpdatingError::InvalidInput {
                    field: "priors",
                    message: format!("`{name}` is not a sampled parameter ({})", names.join(", ")),
                }
            })?;
            marginals[k] = spec.validated()?;
        }
        let block = match joint {
            None => None,
            Some(j) => {
                let positions = j.positions(parameterization.parameters())?;
                if let Some(name) = overrides.keys().find(|n| j.parameter_names.contains(n)) {
                    return Err(UpdatingError::InvalidInput {
                        field: "priors",
                        message: format!(
                            "`{name}` has a marginal prior and is in the correlated prior file"
                        ),
                    });
                }
                Some((
                    positions,
                    MultivariateNormalPrior::new(j.mean.clone(), &j.covariance)?,
                ))
            }
        };
        let whitening = match &block {
            None => None,
            Some((_, normal)) => {
                let chol = normal.covariance().clone().cholesky().ok_or_else(|| {
                    UpdatingError::InvalidInput {
                        field: "priors",
                        message: "the covariance is not positive definite".into(),
                    }
                })?;
                let l = chol.l();
                let ln_det = (0..l.nrows()).map(|i| l[(i, i)].ln()).sum();
                Some((l, ln_det))
            }
        };
        let marginals = marginals
            .into_iter()
            .enumerate()
            .map(|(k, m)| {
                let inside = block.as_ref().is_some_and(|(pos, _)| pos.contains(&k));
                (!inside).then_some(m)
            })
            .collect();
        Ok(Self {
            parameterization,
            marginals,
            block,
            whitening,
        })
    }

    /// theta -> z: z = L^-1 (u - mu) on the block, the rest unchanged (module docs).
    pub fn to_whitened(&self, theta: &[f64]) -> Vec<f64> {
        let mut z = theta.to_vec();
        if let (Some((positions, normal)), Some((l, _))) = (&self.block, &self.whitening) {
            let r = nalgebra::DVector::from_iterator(
                positions.len(),
                positions
                    .iter()
                    .zip(normal.mean())
                    .map(|(&k, m)| theta[k] - m),
            );
            if let Some(w) = l.solve_lower_triangular(&r) {
                for (&k, v) in positions.iter().zip(w.iter()) {
                    z[k] = *v;
                }
            }
        }
        z
    }

    /// z -> theta: u = mu + L z on the block, the rest unchanged.
    pub fn from_whitened(&self, z: &[f64]) -> Vec<f64> {
        let mut theta = z.to_vec();
        if let (Some((positions, normal)), Some((l, _))) = (&self.block, &self.whitening) {
            let w =
                nalgebra::DVector::from_iterator(positions.len(), positions.iter().map(|&k| z[k]));
            let u = l * w;
            for ((&k, v), m) in positions.iter().zip(u.iter()).zip(normal.mean()) {
                theta[k] = m + v;
            }
        }
        theta
    }

    /// Whether the model parameters of `theta` give a model (the truncation).
    fn valid(&self, theta: &[f64]) -> bool {
        let d = self.parameterization.dimension();
        theta.len() >= d && self.parameterization.model(&theta[..d]).is_ok()
    }

    /// The marginal prior of every sampled parameter: its own, or for a block parameter the
    /// normal N(mu_k, Sigma_kk) (before truncation), e.g. for prior boxes and bound checks.
    pub fn marginals(&self) -> Vec<Marginal> {
        let mut all = self.marginals.clone();
        if let Some((positions, normal)) = &self.block {
            for (i, &k) in positions.iter().enumerate() {
                all[k] = Some(Marginal::Normal {
                    mean: normal.mean()[i],
                    sd: normal.covariance()[(i, i)].sqrt(),
                });
            }
        }
        // every parameter is either outside the block (its marginal) or inside it
        all.into_iter().flatten().collect()
    }

    /// ln p(theta) before truncation.
    fn untruncated_ln_pdf(&self, theta: &[f64]) -> f64 {
        let mut ln_p: f64 = self
            .marginals
            .iter()
            .zip(theta)
            .filter_map(|(m, &x)| m.map(|m| m.ln_pdf(x)))
            .sum();
        if let Some((positions, normal)) = &self.block {
            let u: Vec<f64> = positions.iter().map(|&k| theta[k]).collect();
            ln_p += normal.ln_pdf(&u);
        }
        ln_p
    }
}

impl Prior for SampledPrior {
    fn dimension(&self) -> usize {
        self.marginals.len()
    }

    fn ln_pdf(&self, theta: &[f64]) -> f64 {
        if theta.len() != self.marginals.len() {
            return f64::NEG_INFINITY;
        }
        let ln_p = self.untruncated_ln_pdf(theta);
        if ln_p.is_finite() && !self.valid(theta) {
            return f64::NEG_INFINITY;
        }
        ln_p
    }

    fn sample(&self, rng: &mut dyn rand::RngCore) -> Vec<f64> {
        let mut theta = vec![0.0; self.marginals.len()];
        for _ in 0..MAX_REDRAWS {
            for (t, m) in theta.iter_mut().zip(&self.marginals) {
                if let Some(m) = m {
                    *t = m.sample(rng);
                }
            }
            if let Some((positions, normal)) = &self.block {
                for (&k, v) in positions.iter().zip(normal.sample(rng)) {
                    theta[k] = v;
                }
            }
            if self.valid(&theta) {
                break;
            }
        }
        theta
    }
}

/// The prior in the samplers' whitened coordinates z (module docs): p_z(z) = p(theta(z)) |det L|.
#[derive(Debug, Clone, Copy)]
pub struct WhitenedPrior<'a>(pub &'a SampledPrior);

impl Prior for WhitenedPrior<'_> {
    fn dimension(&self) -> usize {
        self.0.dimension()
    }
    fn ln_pdf(&self, z: &[f64]) -> f64 {
        let ln_det = self.0.whitening.as_ref().map_or(0.0, |w| w.1);
        self.0.ln_pdf(&self.0.from_whitened(z)) + ln_det
    }
    fn sample(&self, rng: &mut dyn rand::RngCore) -> Vec<f64> {
        self.0.to_whitened(&self.0.sample(rng))
    }
}

/// A likelihood evaluated at theta(z), for samplers that run in whitened coordinates.
#[derive(Debug, Clone)]
pub struct WhitenedLikelihood<'a, L> {
    /// The prior that defines the coordinates.
    pub prior: &'a SampledPrior,
    /// The likelihood in theta.
    pub likelihood: L,
}

impl<L: LogLikelihood> LogLikelihood for WhitenedLikelihood<'_, L> {
    fn ln_likelihood(&self, z: &[f64]) -> f64 {
        self.likelihood.ln_likelihood(&self.prior.from_whitened(z))
    }
    fn try_ln_likelihood(&self, z: &[f64]) -> std::result::Result<f64, LikelihoodFailure> {
        self.likelihood
            .try_ln_likelihood(&self.prior.from_whitened(z))
    }
}

impl SampledPrior {
    /// A posterior sampled in whitened coordinates with its samples mapped back to theta (the
    /// weights, evidence and data fit do not change: the map is affine).
    fn unwhitened(&self, posterior: Posterior) -> Result<Posterior> {
        let set = &posterior.samples;
        let samples = set
            .samples()
            .iter()
            .map(|z| self.from_whitened(z))
            .collect();
        Ok(Posterior {
            samples: SampleSet::new(samples, set.weights().to_vec())?,
            ..posterior
        })
    }
}

/// [`sample_posterior`] run in the whitened coordinates of `prior` (module docs), the samples
/// returned in theta.
pub fn sample_posterior_whitened<L: LogLikelihood>(
    prior: &SampledPrior,
    likelihood: L,
    options: &SamplerOptions,
    observer: &dyn Observer,
) -> Result<Posterior> {
    let whitened = WhitenedLikelihood { prior, likelihood };
    prior.unwhitened(sample_posterior(
        &WhitenedPrior(prior),
        &whitened,
        options,
        observer,
    )?)
}

/// [`select_model_class`] run in the whitened coordinates of `prior`, every class's samples
/// returned in theta.
pub fn select_model_class_whitened<L, F>(
    prior: &SampledPrior,
    alphas: &[f64],
    likelihood: F,
    options: &SamplerOptions,
    observer: &dyn Observer,
) -> Result<ClassSelection>
where
    L: LogLikelihood,
    F: Fn(f64) -> Result<L>,
{
    let whitened =
        |alpha| likelihood(alpha).map(|likelihood| WhitenedLikelihood { prior, likelihood });
    let mut selection =
        select_model_class(&WhitenedPrior(prior), alphas, whitened, options, observer)?;
    for class in &mut selection.classes {
        class.posterior = prior.unwhitened(class.posterior.clone())?;
    }
    Ok(selection)
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;
    use rand::SeedableRng;

    fn joint() -> JointNormal {
        JointNormal {
            parameter_names: vec!["ks_n_per_mm2".into(), "fn1_hz".into()],
            mean: vec![750.0, 750.0],
            covariance: vec![
                vec![75.0f64.powi(2), 0.5 * 75.0 * 15.0],
                vec![0.5 * 75.0 * 15.0, 225.0],
            ],
        }
    }

    #[test]
    fn the_block_is_the_normal_and_the_rest_their_marginals() {
        // 001's model: one mode in x and one in y; fn1_hz moves both
        let model = examples::schmitz_2023_milling();
        let params: Vec<ModelParameter> = ["ks_n_per_mm2", "beta_deg", "fn1_hz"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let p = Parameterization::new(model.clone(), params).unwrap();
        let beta = Marginal::Normal {
            mean: 68.0,
            sd: 5.0,
        };
        let j = joint();
        let prior =
            SampledPrior::new(p.clone(), vec![beta; 3], &PriorOverrides::new(), Some(&j)).unwrap();
        // ln p written out: the bivariate normal (correlation 0.5) plus the beta marginal
        let theta = [700.0, 70.0, 760.0];
        let (z1, z2, r) = ((700.0 - 750.0) / 75.0, (760.0 - 750.0) / 15.0, 0.5f64);
        let ln_bivariate = -(z1 * z1 - 2.0 * r * z1 * z2 + z2 * z2) / (2.0 * (1.0 - r * r))
            - (2.0 * std::f64::consts::PI * 75.0 * 15.0 * (1.0 - r * r).sqrt()).ln();
        let expected = ln_bivariate + beta.ln_pdf(70.0);
        assert!((prior.ln_pdf(&theta) - expected).abs() < 1e-12);
        // the model at theta: both directional modes at 760 Hz, kt = ks sin(beta)
        let m = p.model(&theta).unwrap();
        for mode in m.modes() {
            assert!((mode.frequency_hz() - 760.0).abs() < 1e-9);
        }
        let kt = 700e6 * 70f64.to_radians().sin();
        assert!((m.cutting().kt_n_per_m2() - kt).abs() < 1e-3);
        // draws: the block's sample correlation is 0.5 (4000 draws: sd of r about 0.012)
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let draws: Vec<Vec<f64>> = (0..4000).map(|_| prior.sample(&mut rng)).collect();
        let fitted = MultivariateNormalPrior::from_samples(
            &draws.iter().map(|d| vec![d[0], d[2]]).collect::<Vec<_>>(),
        )
        .unwrap();
        let c = fitted.covariance();
        let corr = c[(0, 1)] / (c[(0, 0)] * c[(1, 1)]).sqrt();
        assert!((corr - 0.5).abs() < 0.05, "{corr}");
        // a non-physical theta has no prior mass
        assert_eq!(prior.ln_pdf(&[700.0, 70.0, -5.0]), f64::NEG_INFINITY);
        // whitened coordinates: a round trip, and the block's prior is N(0, I) there
        let z = prior.to_whitened(&theta);
        let back = prior.from_whitened(&z);
        assert!(
            back.iter()
                .zip(theta)
                .all(|(a, b)| (a - b).abs() < 1e-9 * b.abs())
        );
        let whitened = WhitenedPrior(&prior);
        let standard = -(z[0] * z[0] + z[2] * z[2]) / 2.0 - (2.0 * std::f64::consts::PI).ln();
        assert!((whitened.ln_pdf(&z) - standard - beta.ln_pdf(70.0)).abs() < 1e-12);
    }

    #[test]
    fn files_and_misuse() {
        let text = serde_json::to_string(&joint()).unwrap();
        assert_eq!(
            PriorFile::from_json_str(&text).unwrap(),
            PriorFile::Joint(joint())
        );
        let marginal = r#"{"kt_n_per_mm2": {"kind": "normal", "mean": 700, "sd": 70}}"#;
        assert!(matches!(
            PriorFile::from_json_str(marginal).unwrap(),
            PriorFile::Marginals(_)
        ));
        assert!(PriorFile::from_json_str(r#"{"parameter_names": ["fn1_hz"]}"#).is_err());
        let model = examples::schmitz_2023_milling();
        let only_ks =
            Parameterization::new(model.clone(), vec![ModelParameter::KsNPerMm2]).unwrap();
        let m = vec![Marginal::Normal { mean: 1.0, sd: 1.0 }];
        let err = SampledPrior::new(only_ks, m, &PriorOverrides::new(), Some(&joint()))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("fn1_hz") && err.contains("not a sampled parameter"),
            "{err}"
        );
        // kt with ks, a mode number the model does not have
        let clash = "kt_n_per_mm2,ks_n_per_mm2"
            .split(',')
            .map(|s| s.parse().unwrap())
            .collect();
        assert!(Parameterization::new(model.clone(), clash).is_err());
        let second: Vec<ModelParameter> = vec!["fn2_hz".parse().unwrap()];
        let err = Parameterization::new(model.clone(), second)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("fn2_hz") && err.contains("x: 1, y: 1"),
            "{err}"
        );
        let both: Vec<ModelParameter> =
            vec!["fn1_hz".parse().unwrap(), "theta_omega_2".parse().unwrap()];
        assert!(Parameterization::new(model, both).is_err());
    }
}
