//! Operational modal analysis: from measured vibration signals to poles, for any linear (or
//! lifted periodic) system. Knows nothing of machining.
//!
//! - [`signals`]: CSV and WAV records (formats spec, `signals`).
//! - [`correlation`]: unbiased correlation functions by FFT (000 Eq. 21).
//! - [`lsce`]: least-squares complex exponential and the modified LSCE that imposes known
//!   harmonics (000 Eq. 19-25).
//!
//! ```
//! use chatter_oma::lsce::lsce;
//! // r(i) = 0.98^i cos(0.3 i): one pole pair
//! let r: Vec<f64> = (0..200).map(|i| 0.98f64.powi(i) * (0.3 * i as f64).cos()).collect();
//! let poles = lsce(&[r], 1000.0, 2, &[]).unwrap();
//! assert!((poles[0].multiplier.norm() - 0.98).abs() < 1e-10);
//! ```

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod correlation;
pub mod error;
pub mod lsce;
pub mod signals;

pub use error::{OmaError, Result};
