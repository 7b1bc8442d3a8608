//! Chatter likelihoods for Bayesian model updating: they connect the machining model
//! (`chatter-dynamics`, `chatter-stability`) with the generic samplers of `chatter-bayes`.
//!
//! - [`turning`]: characteristic-equation residuals of identified poles (Ahmadi 2022, seed 000,
//!   Eq. 28-31).

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod error;
pub mod turning;

pub use error::{Result, UpdatingError};
