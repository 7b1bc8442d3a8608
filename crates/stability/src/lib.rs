//! Chatter stability of turning and milling (seeds 000, 001, 002, 003).
//!
//! Every method maps a cutting condition (spindle speed, depth) to the dominant multiplier of the
//! regenerative delay equation M x'' + C x' + K x = -b H(t) (x(t) - x(t - tau)) (000 Eq. 4,
//! 002 Eq. 1); the cut is stable when |mu| < 1. Solvers implement [`StabilitySolver`], so lobe
//! diagrams, uncertainty bands and likelihoods work with any of them.

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod boundary;
pub mod characteristic;
mod eigen;
pub mod error;
pub mod frequency_domain;
mod grid;
mod hessenberg;
mod krylov;
pub mod monodromy;
pub mod multiplier;
pub mod prepared;
pub mod process_damping;
pub mod recommend;
pub mod resonance;
mod root;
pub mod sensitivity;
pub mod speed_grid;
pub mod ssv;
mod step;
pub mod zero_order;

pub use error::{Result, StabilityError};
pub use multiplier::{DominantMultiplier, MultiplierKind};
pub use prepared::{Method, PreparedSolver};

use chatter_dynamics::ModalModel;

/// A stability method: the dominant multiplier at one cutting condition.
///
/// Implementations must be thread-safe and deterministic, because lobe diagrams evaluate them in
/// parallel over speeds and samplers call them thousands of times.
pub trait StabilitySolver: Sync {
    /// Short name (`"zoa"`, `"fdm"`, `"sdm"`, `"frequency-domain"`).
    fn name(&self) -> &'static str;

    /// Dominant multiplier over one delay at `speed_rpm` and depth (width) `depth_m`.
    fn dominant_multiplier(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<DominantMultiplier>;

    /// The dominant multiplier with the chatter frequency (Hz) it implies. The default picks the
    /// member of the family f_mu + k / tau closest to the mode that dominates the cut; solvers
    /// that know the eigenvector resolve the family exactly.
    fn chatter_frequency_hz(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)> {
        let mu = self.dominant_multiplier(model, speed_rpm, depth_m)?;
        let f = mu.chatter_frequency_near_hz(boundary::dominant_mode_frequency_hz(model));
        Ok((mu, f))
    }
}
