//! Uncertainty bands around stability lobe diagrams.
//!
//! - [`geometric`]: Type B offset boundaries from user-stated offsets in speed and depth
//!   (Schmitz 2023, seed 001, Eq. 1-11).

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod error;
pub mod geometric;

pub use error::{Result, UncertaintyError};
