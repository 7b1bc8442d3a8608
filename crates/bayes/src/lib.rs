//! Generic Bayesian inference, knowing nothing of machining: priors p(theta), a log-likelihood
//! ln p(D | theta), and samplers of the posterior p(theta | D) = p(D | theta) p(theta) / p(D).
//!
//! | module | holds | source |
//! |---|---|---|
//! | [`prior`] | uniform, normal, truncated normal, lognormal marginals; independent joints; the correlated multivariate normal (from mean and covariance or from samples) | |
//! | [`samples`] | weighted sample sets: mean, covariance, quantiles, effective sample size | |
//! | [`tmcmc`] | TMCMC / iTMCMC with the log-evidence ln p(D), data fit and information gain, model-class probabilities | Ching and Chen 2007; Betz, Papaioannou and Straub 2016; 000 Eq. 32-33 |
//! | [`strata`] | stratified TMCMC: one run per slice of a uniform coordinate, pooled by total probability (for posteriors with separated modes along it) | |
//! | [`rejection`] | rejection sampling: keep theta with probability L / L_max | 004 Section 4-5 |
//! | [`amcmc`] | parallel adaptive MCMC with j candidates and k draws from the Eq. 8 stationary distribution, until s unique samples | 004 Section 5, Eq. 8 |
//! | [`special`] | log-sum-exp, log-mean-exp and normalized log weights; the standard normal distribution function and its inverse | Numerical Recipes erfcc; Acklam |
//! | [`gp`] | Gaussian-process regression with a Matérn 3/2 or 5/2 kernel, hyperparameters by maximum marginal likelihood: a surrogate of expensive model outputs | 002 Section 3.3 |
//!
//! Everything is in log space. Every stochastic routine takes a seed and draws from per-chain (or
//! per-sample) random streams seeded by (seed, index), and parallel work (rayon) is collected in a
//! fixed order, so results are the same for any number of threads.
//!
//! Rejection sampling, then adaptive MCMC from the survivors, then TMCMC for the evidence, on a
//! conjugate problem (prior N(0, 1), one observation 1 with noise sd 0.5: posterior mean 0.8,
//! evidence N(1; 0, 1.25)):
//!
//! ```
//! use chatter_bayes::amcmc::{adaptive_mcmc, AmcmcOptions};
//! use chatter_bayes::prior::{IndependentPrior, Marginal};
//! use chatter_bayes::rejection::{rejection_sample, LikelihoodBound};
//! use chatter_bayes::tmcmc::{tmcmc, TmcmcOptions};
//! use chatter_progress::Silent;
//! let prior = IndependentPrior::new(vec![Marginal::Normal { mean: 0.0, sd: 1.0 }])?;
//! let sd: f64 = 0.5;
//! let like = |t: &[f64]| -0.5 * ((t[0] - 1.0) / sd).powi(2) - (sd * (2.0 * std::f64::consts::PI).sqrt()).ln();
//! let kept = rejection_sample(&prior, &like, 2000, LikelihoodBound::Estimated, 1, &Silent)?;
//! let opts = AmcmcOptions { unique_samples: 2000, ..Default::default() };
//! let chain = adaptive_mcmc(&prior, &like, &kept.accepted, &opts, &Silent)?;
//! assert!((chain.samples.mean()[0] - 0.8).abs() < 0.1);
//! let run = tmcmc(&prior, &like, &TmcmcOptions { samples: 1000, ..Default::default() }, &Silent)?;
//! let exact = -0.5 * (2.0 * std::f64::consts::PI * 1.25).ln() - 1.0 / 2.5;
//! assert!((run.log_evidence - exact).abs() < 0.2);
//! # Ok::<(), chatter_bayes::BayesError>(())
//! ```
//!
//! A Matérn-5/2 surrogate of a smooth response:
//!
//! ```
//! use chatter_bayes::gp::{GaussianProcess, GpOptions};
//! let x: Vec<Vec<f64>> = (0..10).map(|i| vec![i as f64 / 3.0]).collect();
//! let y: Vec<f64> = x.iter().map(|v| v[0].sin()).collect();
//! let gp = GaussianProcess::fit(&x, &y, &GpOptions::default())?;
//! let p = gp.predict(&[1.5])?;
//! assert!((p.mean - 1.5f64.sin()).abs() < 1e-2 && p.variance < 1e-3);
//! # Ok::<(), chatter_bayes::BayesError>(())
//! ```

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod amcmc;
pub mod error;
pub mod gp;
pub mod prior;
pub mod rejection;
pub mod samples;
pub mod special;
pub mod strata;
pub mod tmcmc;

pub use error::{BayesError, Result};
pub use prior::Prior;
pub use tmcmc::{LikelihoodFailure, LogLikelihood};
