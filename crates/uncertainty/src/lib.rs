//! Uncertainty bands around stability lobe diagrams.
//!
//! - [`geometric`]: Type B offset boundaries from user-stated offsets in speed and depth
//!   (Schmitz 2023, seed 001, Eq. 1-11).
//! - [`measured`]: Type B offsets around lobes straight from a measured FRF, set by the spread of
//!   an FRF ensemble (a gain and frequency-axis uncertainty, repeated taps, an RCSA ensemble).
//! - [`perturbation`]: second-order perturbation mean and variance of the dominant eigenvalue and
//!   the credibility-bounded lobes (Ahmadi 2022, seed 000, Eq. 14-18).
//! - [`montecarlo`]: probability-of-stability maps from parameter samples (seed 004, Fig. 2).
//! - [`sensitivity`]: the dominant pole's sensitivity to the modal parameters on the one-step or
//!   the period map (seed 000, Section 6.2, Table 3).
//! - [`parameters`]: parameter distributions from covariance files and posterior folders.

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod error;
pub mod geometric;
pub mod measured;
pub mod montecarlo;
pub mod parameters;
pub mod perturbation;
pub mod sensitivity;

pub use error::{Result, UncertaintyError};
