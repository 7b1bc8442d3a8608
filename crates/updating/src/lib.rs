//! Chatter likelihoods and test planning for Bayesian model updating: they connect the machining
//! model (`chatter-dynamics`, `chatter-stability`) with the generic samplers of `chatter-bayes`.
//!
//! | module | holds | source |
//! |---|---|---|
//! | [`parameters`] | named parameters (`theta_omega_N`, ..., `kt_n_per_mm2`, `kn_n_per_mm2`, `c_n_per_m`; 004's `ks_n_per_mm2`, `beta_deg`, `fnN_hz`, `kN_n_per_m`, `zetaN`) and theta -> model | 000 Eq. 2, 002 Eq. 16, 003 Eq. 1, 004 Sec. 2 |
//! | [`joint_prior`] | correlated (multivariate normal) prior block from a prior file, times marginals | 004 Sec. 2 |
//! | [`turning`] | identified turning poles against the characteristic equation, sigma_I^2 = alpha sigma_R^2 | 000 Eq. 28-31 |
//! | [`milling`] | identified Floquet multipliers (frequency, damping) against the exact discretized monodromy operator, sigma_zeta = alpha sigma_w | 002 Eq. 13-15 |
//! | [`cuts`] | stable / chatter results with chatter frequency; the one-sided kernel | 004 Eq. 5, 003 Eq. 3-4 |
//! | [`classes`] | iTMCMC / TMCMC / rejection + adaptive MCMC, evidence-based class selection | 000 Eq. 32-33 |
//! | [`sampled`] | sampled stability boundaries (limits and chatter frequencies per sample and speed, probabilities, failures), P_s maps and quantile bands | 003 Eq. 7, 004 Eq. 8, Fig. 2 |
//! | [`ensemble`] | random-walk paths: updating, posterior moments, value of information; risk-based test at maximum MRR | 003 Eq. 2-6, 004 Section 3 |
//! | [`ebrahimi2025`] | 002's simulated system and Table 1's poles beside the exact monodromy poles (at the stated 194 Hz and at 195.3 Hz) | 002 Sec. 3.1 |
//! | [`schmitz2022`] | 004's example with its correlated RCSA prior: the paper's numbers beside ours | 004 Sec. 2, 3, 6 |
//! | [`karandikar`] | 003's prior, Table 2's candidate tests with the paper's numbers, RSS identification of C | 003 |
//! | [`surrogate`] | Matérn GP surrogate of the dominant milling multiplier, with its error against the exact one | 002 Section 2.2 |
//! | [`prior_bounds`] | posteriors that pile against a prior bound | 000 Section 6.3 |
//! | [`defaults`] | the papers' priors, model classes and parameter choice | 000 Section 6, 002 Section 3.2, 003 |
//! | [`update`], [`plan`] | the jobs behind `chatter update` and `chatter plan` | |
//!
//! Updating seed 000's mode 2 from its Table 2 poles (one model class, few samples):
//!
//! ```
//! use chatter_dynamics::examples;
//! use chatter_updating::classes::{Sampler, SamplerOptions};
//! use chatter_progress::Silent;
//! use chatter_updating::update::{UpdateJob, UpdateSettings};
//! let settings = UpdateSettings { classes: Some(vec![1.0]), ..Default::default() };
//! let job = UpdateJob::new(
//!     &examples::ahmadi_2022_turning(),
//!     &examples::ahmadi_2022_turning_observations(),
//!     &settings,
//! )?;
//! let options = SamplerOptions { sampler: Sampler::Itmcmc, samples: 200, seed: 1 };
//! let result = job.run(&options, &Silent)?;
//! assert_eq!(result.parameter_names[0], "theta_omega_2");
//! // the modal frequency rises by about half a percent (the paper: 0.67 %)
//! assert!(result.posterior_mean[0] > 0.003 && result.posterior_mean[0] < 0.009);
//! # Ok::<(), chatter_updating::UpdatingError>(())
//! ```

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod classes;
pub mod cuts;
pub mod defaults;
pub mod ebrahimi2025;
pub mod ensemble;
pub mod error;
pub mod joint_prior;
pub mod karandikar;
pub mod milling;
pub mod parameters;
pub mod plan;
pub mod prior_bounds;
pub mod sampled;
pub mod schmitz2022;
pub mod surrogate;
pub mod turning;
pub mod update;

pub use error::{Result, UpdatingError};
