//! Generic Bayesian inference, knowing nothing of machining: priors, the log-likelihood trait,
//! weighted sample sets and TMCMC / iTMCMC with model evidence and model-class probabilities
//! (Ching and Chen 2007; Betz, Papaioannou and Straub 2016; used by 000 and 002).
//!
//! ```
//! use chatter_bayes::prior::{IndependentPrior, Marginal};
//! use chatter_bayes::tmcmc::{tmcmc, Silent, TmcmcOptions};
//! let prior = IndependentPrior::new(vec![Marginal::Normal { mean: 0.0, sd: 1.0 }]).unwrap();
//! let like = |t: &[f64]| -0.5 * ((t[0] - 1.0) / 0.5).powi(2);
//! let run = tmcmc(&prior, &like, &TmcmcOptions { samples: 500, ..Default::default() }, &Silent).unwrap();
//! assert!((run.samples.mean()[0] - 0.8).abs() < 0.1);
//! ```

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod error;
pub mod prior;
pub mod samples;
pub mod tmcmc;

pub use error::{BayesError, Result};
pub use prior::Prior;
pub use tmcmc::LogLikelihood;
