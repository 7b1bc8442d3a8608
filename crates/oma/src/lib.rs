//! Operational modal analysis: from measured vibration signals to poles, for any linear (or
//! lifted periodic) system. Knows nothing of machining.
//!
//! # Model
//! Under broadband excitation the correlation functions of the outputs of a linear system are
//! sums of damped exponentials in the lag, r(i) = sum_j A_j mu_j^i, whose discrete poles
//! mu_j = e^{lambda_j T_s} are the roots of a characteristic polynomial that the correlations
//! satisfy (000 Eq. 19-21); spindle harmonics add undamped poles e^{+-i w_k T_s}, which the
//! modified LSCE imposes as known (Eq. 22-24). A time-periodic system (milling) sampled once per
//! period is time invariant: its lifted signals (002 Eq. 6-7) obey the same model with the
//! Floquet multipliers as poles, fitted by polyreference on correlation matrices (Eq. 8-9).
//! Each pole gives lambda = ln(mu) / T, frequency |lambda| / 2 pi and damping ratio
//! -Re(lambda) / |lambda| (000 Eq. 25); for lifted data the principal frequency
//! arg(mu) / (2 pi T) in [0, 1 / 2T] is the one the tables of 002 report.
//!
//! - [`signals`]: CSV and WAV records (formats spec, `signals`).
//! - [`correlation`]: unbiased correlation functions by FFT (000 Eq. 21, 002 Eq. 8).
//! - [`lsce`]: least-squares complex exponential and the modified LSCE that imposes known
//!   harmonics (000 Eq. 19-25).
//! - [`harmonics`]: which spindle harmonics the modified LSCE imposes; spectral lines.
//! - [`decimation`]: low-pass and decimation so that the pole is not crowded next to mu = 1.
//! - [`polyreference`]: time-domain polyreference on correlation matrices (002 Eq. 9).
//! - [`lifting`]: lifting of time-periodic signals at their period (002 Eq. 6-7).
//! - [`stabilization`]: stabilization diagrams over model orders.
//! - [`picking`]: automatic choice of the dominant structural pole.
//! - [`support`]: spectral support of a pole (its PSD peak against the highest resonance peak).
//! - [`spectrum`]: first singular value of the cross-PSD matrix; Welch densities.
//! - [`detection`]: chatter detection, self-excited lines against the harmonics of a
//!   fundamental.
//! - [`interference`]: combs of lines at the multiples of a non-spindle fundamental (mains).
//! - [`synthetic`]: seeded records with known poles (the reference problems of tests and
//!   benches).
//! - [`identify`](mod@identify): all of it in one call, with repeated identification on random
//!   segments (mean and standard deviation, as in 000 and 002 Table 2).
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
pub mod decimation;
pub mod detection;
pub mod error;
pub mod harmonics;
pub mod identify;
pub mod interference;
pub mod lifting;
pub mod lsce;
pub mod picking;
pub mod polyreference;
pub mod signals;
pub mod spectrum;
pub mod stabilization;
pub mod support;
pub mod synthetic;

pub use error::{OmaError, Result};
pub use harmonics::Harmonics;
pub use identify::{
    Decimation, Identification, IdentifyOptions, Lifting, identify, identify_with_observer,
};
