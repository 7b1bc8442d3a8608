//! A mode's modal pole: its natural frequency and damping ratio, and the one conversion between
//! them and the pole lambda = -zeta w_n + i w_n sqrt(1 - zeta^2) ([`pole`]).
//!
//! Every type of the workspace that holds a mode holds a [`ModalPole`] for that pair and adds
//! what it carries besides: a machine model's mode its shape and residue phase
//! (`chatter_dynamics::Mode`), a fitted mode its residue, real-mode stiffness and stability share
//! (`chatter_frf::FittedMode`), a synthetic record's mode its participation per channel
//! (`chatter_oma::synthetic::SyntheticMode`).
//!
//! The type lives in a crate of its own because both roots of the crate graph need it:
//! `chatter-oma` (operational modal analysis, which knows nothing of machining) and
//! `chatter-dynamics` (machine models). The crate has no workspace dependencies.
//!
//! ```
//! use chatter_modal::ModalPole;
//! let mode = ModalPole::new(2473.0, 0.02);
//! let back = ModalPole::from_pole(mode.pole());
//! assert!((back.frequency_hz - 2473.0).abs() < 1e-9);
//! assert!((back.damping_ratio - 0.02).abs() < 1e-15);
//! ```

pub mod pole;

use num_complex::Complex64;
use std::f64::consts::PI;

/// A mode's natural frequency (Hz) and damping ratio: the modal part every mode type shares.
///
/// A plain value: the types that hold one validate it for their use (a machine model's
/// `chatter_dynamics::Mode::new` asks for f > 0 and 0 <= zeta < 1).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ModalPole {
    /// Natural frequency f_n = w_n / 2 pi (Hz).
    pub frequency_hz: f64,
    /// Damping ratio zeta (fraction of critical).
    pub damping_ratio: f64,
}

impl ModalPole {
    /// The pair (f_n in Hz, zeta).
    pub fn new(frequency_hz: f64, damping_ratio: f64) -> Self {
        Self {
            frequency_hz,
            damping_ratio,
        }
    }

    /// The pair of a pole lambda (rad/s) by [`pole::pole_frequency_damping`].
    pub fn from_pole(lambda: Complex64) -> Self {
        let (frequency_hz, damping_ratio) = pole::pole_frequency_damping(lambda);
        Self::new(frequency_hz, damping_ratio)
    }

    /// The upper-half-plane pole lambda (rad/s) by [`pole::pole_from_frequency_damping`].
    pub fn pole(&self) -> Complex64 {
        pole::pole_from_frequency_damping(self.frequency_hz, self.damping_ratio)
    }

    /// Natural frequency w_n = 2 pi f_n (rad/s).
    pub fn omega_rad_s(&self) -> f64 {
        2.0 * PI * self.frequency_hz
    }
}
