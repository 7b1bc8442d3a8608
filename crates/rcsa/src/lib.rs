//! Receptance coupling substructure analysis (RCSA) for tool-tip FRFs, after Schmitz, Cornelius,
//! Karandikar, Tyler and Smith (2022), "Receptance coupling substructure analysis and chatter
//! frequency-informed machine learning for milling stability" (seed 004, Eq. 1-4).
//!
//! - [`beam`]: free-free Timoshenko beams of cylindrical segments (solid or hollow, with a loss
//!   factor) and their end receptances [[h, l], [n, p]] by chained field matrices (exact, no mode
//!   truncation);
//! - [`coupling`]: the holder-tool connection K(k, c, omega) (Eq. 4), coupling (Eq. 3) and
//!   decoupling of a spindle from an artifact tap test (Eq. 1);
//! - [`assembly`]: the assembly file and the tool-tip FRF;
//! - [`prior`]: 004's prior: FRF ensemble over the connection, two-mode fits, multivariate
//!   normal prior, probability-of-stability map.
//!
//! ```
//! use chatter_rcsa::{Assembly, Connection, Segment, Spindle};
//! // a 10 mm steel rod, 150 mm out of a rigid spindle: first bending mode at
//! // 1.8751^2 / (2 pi L^2) sqrt(E I / (rho A)) = 315 Hz
//! let rod = Assembly {
//!     tool: vec![Segment::steel(150.0, 10.0, 0.0)],
//!     holder: vec![],
//!     connection: Connection::Rigid,
//!     spindle: Spindle::Rigid,
//!     frequencies_hz: (1..=600).map(|f| f as f64).collect(),
//! };
//! let tip = rod.tool_tip_frf()?;
//! let (peak, _) = tip.frequencies_hz().iter().zip(tip.receptance_m_per_n())
//!     .max_by(|a, b| a.1.norm().total_cmp(&b.1.norm())).unwrap();
//! assert!((peak - 315.0).abs() < 2.0);
//! # Ok::<(), chatter_rcsa::RcsaError>(())
//! ```

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod assembly;
pub mod beam;
pub mod coupling;
pub mod error;
pub mod prior;

pub use assembly::{Assembly, AssemblyFile, SampledReceptance, Spindle, frequency_band};
pub use beam::{EndReceptances, Receptance, Segment, free_free_receptances};
pub use coupling::{Connection, FlexibleConnection, couple, decouple};
pub use error::{RcsaError, Result};
