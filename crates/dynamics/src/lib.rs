//! Machining dynamics for chatter: multi-mode modal models, receptance FRFs, cutting-force
//! models, named parameter perturbations, the interchange file formats and a time-domain
//! simulator of regenerative chatter.
//!
//! # Model
//! In modal coordinates the structure obeys (Ahmadi 2022, seed 000, Eq. 1)
//! q'' + 2 Omega Z q' + Omega^2 q = Phi^T f, with Phi the mass-normalized shapes over the
//! operation's two coordinates (milling `x`, `y`; turning `feed`, `cutting`). The regenerative
//! cutting force is f(t) = -b H(t) (x(t) - x(t - tau)) with H the directional matrix
//! ([`ModalModel::directional_matrix`]): constant K_c in turning (000 Eq. 3), tooth-periodic in
//! milling (002 Eq. 1-2). Process damping adds F_d = -C b ydot / V (Karandikar et al., seed 003,
//! Eq. 1).
//!
//! # Units
//! SI inside (m, N/m, N/m^2, rad/s); file and CLI boundaries carry units in their names
//! (`depth_mm`, `kt_n_per_mm2`, `frequency_hz`).
//!
//! ```
//! use chatter_dynamics::{examples, Parameter};
//! let model = examples::ahmadi_2022_turning();
//! assert_eq!(model.mode_count(), 2);
//! let p: Parameter = "theta_omega_2".parse().unwrap();
//! let updated = model.perturbed(&[p], &[0.0067]).unwrap();
//! assert!((updated.modes()[1].frequency_hz() - 2445.0 * 1.0067).abs() < 1e-9);
//! ```

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod cutting;
pub mod error;
pub mod examples;
mod frf;
pub mod grid;
pub mod limits;
pub mod model;
pub mod model_file;
pub mod observations;
pub mod operation;
pub mod perturbation;
mod resample;
pub mod sampled;
pub mod simulate;
pub mod sle;

pub use chatter_modal::{ModalPole, pole};
pub use error::{DynamicsError, Result};
pub use model::{CuttingCoefficients, ModalModel, Mode, ModeShape, ResidualTerms};
pub use model_file::{HelixDeg, MeasuredFrfFile, ModelFile};
pub use observations::{Cut, CutEvidence, Observations, PoleObservation, SignalRecord};
pub use operation::{
    Coordinate, CuttingEdge, DEFAULT_AXIAL_SLICES, Milling, MillingDirection, Operation, Turning,
};
pub use perturbation::{Parameter, ParameterKind, parse_parameters};
pub use sampled::{ReceptanceMatrix, SampledReceptance};
