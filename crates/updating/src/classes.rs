//! Posterior sampling with a choice of sampler, and evidence-based model-class selection
//! (Ahmadi 2022, seed 000, Eq. 32-33; 002 Section 2.2).
//!
//! Each model class M_k fixes the weighting alpha_k of the likelihood's two error components
//! (000: sigma_I^2 = alpha sigma_R^2; 002: sigma_zeta = alpha sigma_w). Every class is sampled and
//! its log-evidence ln p(D | M_k) estimated; with equal prior class probabilities
//! p(M_k | D) = p(D | M_k) / sum_l p(D | M_l) (Eq. 32), and the class of largest evidence is
//! selected. ln p(D | M) = E[ln p(D | theta, M)] - E[ln p(theta | D, M) / p(theta | M)] splits it
//! into data fit and information gain (Eq. 33).

use crate::error::{Result, UpdatingError};
use chatter_bayes::amcmc::{AmcmcOptions, adaptive_mcmc};
use chatter_bayes::rejection::{LikelihoodBound, rejection_sample};
use chatter_bayes::samples::SampleSet;
use chatter_bayes::tmcmc::{TmcmcOptions, Variant, class_probabilities, tmcmc};
use chatter_bayes::{LogLikelihood, Prior};
use chatter_progress::Observer;

/// Which posterior sampler.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Sampler {
    /// Improved TMCMC (Betz et al. 2016), as 000 (default).
    #[default]
    Itmcmc,
    /// Classic TMCMC (Ching and Chen 2007), as 002.
    Tmcmc,
    /// Rejection sampling of prior draws, then parallel adaptive MCMC from the survivors (004
    /// Section 5); the log-evidence is the Monte Carlo mean of the likelihood over the prior draws.
    Amcmc,
}

/// Prior draws per requested sample for the rejection step of [`Sampler::Amcmc`].
pub const REJECTION_DRAWS_PER_SAMPLE: usize = 4;

/// Sampler settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SamplerOptions {
    /// Which sampler.
    pub sampler: Sampler,
    /// Samples per stage (TMCMC) or unique samples (adaptive MCMC).
    pub samples: usize,
    /// Seed.
    pub seed: u64,
}

/// Posterior samples with the model evidence.
#[derive(Debug, Clone, PartialEq)]
pub struct Posterior {
    /// Posterior samples (weighted for adaptive MCMC).
    pub samples: SampleSet,
    /// ln p(D | M).
    pub log_evidence: f64,
    /// E[ln p(D | theta, M)] over the posterior (TMCMC only): the data fit of Eq. 33.
    pub data_fit: Option<f64>,
    /// Likelihood evaluations that failed numerically (TMCMC only): rejected and counted,
    /// never read as a fit or as "stable".
    pub numerical_failures: Option<usize>,
}

/// Sample the posterior p(theta | D) ∝ p(D | theta) p(theta).
pub fn sample_posterior<P: Prior, L: LogLikelihood>(
    prior: &P,
    likelihood: &L,
    options: &SamplerOptions,
    observer: &dyn Observer,
) -> Result<Posterior> {
    match options.sampler {
        Sampler::Itmcmc | Sampler::Tmcmc => {
            let run = tmcmc(
                prior,
                likelihood,
                &TmcmcOptions {
                    samples: options.samples,
                    seed: options.seed,
                    variant: if options.sampler == Sampler::Itmcmc {
                        Variant::Improved
                    } else {
                        Variant::Classic
                    },
                    ..Default::default()
                },
                observer,
            )?;
            Ok(Posterior {
                data_fit: Some(run.data_fit()),
                log_evidence: run.log_evidence,
                samples: run.samples,
                numerical_failures: Some(run.numerical_failures),
            })
        }
        Sampler::Amcmc => {
            let draws = options.samples.saturating_mul(REJECTION_DRAWS_PER_SAMPLE);
            let kept = rejection_sample(
                prior,
                likelihood,
                draws,
                LikelihoodBound::Estimated,
                options.seed,
                observer,
            )?;
            if kept.accepted.len() < 2 {
                return Err(UpdatingError::InvalidInput {
                    field: "samples",
                    message: format!(
                        "rejection sampling kept {} of {draws} prior draws; at least 2 are \
                         needed to start adaptive MCMC (draw more samples, or use iTMCMC for \
                         a sharply peaked likelihood)",
                        kept.accepted.len()
                    ),
                });
            }
            let chain = adaptive_mcmc(
                prior,
                likelihood,
                &kept.accepted,
                &AmcmcOptions {
                    unique_samples: options.samples,
                    seed: options.seed,
                    ..Default::default()
                },
                observer,
            )?;
            Ok(Posterior {
                samples: chain.samples,
                log_evidence: kept.log_mean_likelihood,
                data_fit: None,
                numerical_failures: None,
            })
        }
    }
}

/// One sampled model class.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassResult {
    /// The class weight alpha.
    pub alpha: f64,
    /// Its posterior and evidence.
    pub posterior: Posterior,
}

/// All classes with their posterior probabilities (Eq. 32) and the selected one.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassSelection {
    /// The classes in the order given.
    pub classes: Vec<ClassResult>,
    /// p(M_k | D) with equal prior class probabilities.
    pub probabilities: Vec<f64>,
    /// Index of the class of largest evidence.
    pub selected: usize,
}

impl ClassSelection {
    /// The selected class.
    pub fn selected_class(&self) -> &ClassResult {
        &self.classes[self.selected]
    }
}

/// Sample every class alpha in `alphas` with the likelihood `likelihood(alpha)` and select by
/// evidence. Every class uses the same seed (common random numbers), so evidence differences are
/// not blurred by sampler noise.
pub fn select_model_class<P, L, F>(
    prior: &P,
    alphas: &[f64],
    likelihood: F,
    options: &SamplerOptions,
    observer: &dyn Observer,
) -> Result<ClassSelection>
where
    P: Prior,
    L: LogLikelihood,
    F: Fn(f64) -> Result<L>,
{
    if alphas.is_empty() {
        return Err(UpdatingError::InvalidInput {
            field: "classes",
            message: "no model classes".into(),
        });
    }
    let classes = alphas
        .iter()
        .enumerate()
        .map(|(k, &alpha)| {
            observer.class_started(k, alphas.len(), alpha);
            let like = likelihood(alpha)?;
            Ok(ClassResult {
                alpha,
                posterior: sample_posterior(prior, &like, options, observer)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let evidences: Vec<f64> = classes.iter().map(|c| c.posterior.log_evidence).collect();
    let probabilities = class_probabilities(&evidences);
    let selected = evidences
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i);
    Ok(ClassSelection {
        classes,
        probabilities,
        selected,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_bayes::prior::{IndependentPrior, Marginal};
    use chatter_progress::Silent;

    #[test]
    fn the_class_with_the_true_noise_ratio_wins() {
        // data x = 1 (noise sd 1) and y = 0 (noise sd 0.1): the class alpha = sd_y / sd_x = 0.1
        // must have the largest evidence among 0.01, 0.1, 1
        let prior = IndependentPrior::new(vec![Marginal::Normal { mean: 0.0, sd: 2.0 }]).unwrap();
        let make = |alpha: f64| -> Result<_> {
            Ok(move |t: &[f64]| {
                let (sx, sy) = (1.0, alpha);
                let r = [(1.0 - t[0]) / sx, (0.0 - 0.1 * t[0]) / sy, 0.3 / sy];
                -0.5 * r.iter().map(|v| v * v).sum::<f64>() - (sx * sy * sy).ln()
            })
        };
        for sampler in [Sampler::Itmcmc, Sampler::Tmcmc, Sampler::Amcmc] {
            let options = SamplerOptions {
                sampler,
                samples: 600,
                seed: 4,
            };
            let sel =
                select_model_class(&prior, &[0.01, 0.3, 3.0], make, &options, &Silent).unwrap();
            assert_eq!(sel.selected, 1, "{sampler:?}");
            assert!((sel.probabilities.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(select_model_class(&prior, &[], make, &options, &Silent).is_err());
        }
    }
}
