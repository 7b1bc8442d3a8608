//! Measured frequency response functions for chatter: readers for the CSV that `chatter frf`
//! writes, the universal file format dataset 58 (ASCII and binary 58b) and the CutPro `.frf` /
//! tap-test text columns; a dataset 58 writer; models whose dynamics are measured FRFs
//! (`measured_frf` in a model file); the H1 estimate of a tap test; and modal fitting by the
//! least-squares complex frequency-domain method with a stabilization diagram and residual
//! terms.
//!
//! A measured receptance H(i w) (m/N) feeds the zero-order stability of
//! `chatter_stability::zero_order::measured_limiting_depths` directly (Altintas and Budak 1995:
//! the eigenvalues of A_0 G(i w) at the measured frequencies), or is fitted by modes
//! (module [`fit`]) for the time-domain methods.
//!
//! ```
//! use chatter_frf::{Frf, uff};
//! use chatter_dynamics::examples;
//! let model = examples::schmitz_2023_milling();
//! let f: Vec<f64> = (0..=2000).map(|k| k as f64).collect();
//! let frf = Frf::from_model(&model, 0, 0, f)?;
//! let text = uff::to_uff58_string(&[uff::Uff58Record::receptance(&frf, "tip", (1, 1), (1, 1))]);
//! let back = uff::parse_uff58(text.as_bytes(), std::path::Path::new("tip.uff"))?;
//! assert_eq!(back[0].to_frf(std::path::Path::new("tip.uff"))?.len(), 2001);
//! # Ok::<(), chatter_frf::FrfError>(())
//! ```

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod error;
pub mod fit;
mod frf;
pub mod h1;
pub mod measured;
pub mod text;
pub mod uff;

pub use error::{FrfError, Result};
pub use fit::{FitOptions, ModalFit, Residuals, fit_modes};
pub use frf::{Frf, Quantity};
pub use h1::{H1Estimate, H1Options, h1_estimate};
pub use measured::{MeasuredModel, read_frf, read_model_file};
