//! The jobs of the `chatter` program as library functions: each takes a model, observations and
//! a request in the units users write, checks the request, runs the science crates and returns
//! a result struct. The command-line program and the Python package both call these, so the
//! same request gives the same numbers bit for bit; they differ only in how they parse and
//! write.
//!
//! Each job has a request struct with the options in user units and their defaults (one home
//! for the defaults), checked once into the job (linfa's checked parameters, `ParamGuard`):
//! [`lobes::Lobes::new`], [`bands::Bands::new`], [`multiplier::Multiplier::new`],
//! [`fit_frf::FitFrfRequest::check`], [`simulate::SimulateRequest::check`],
//! [`update::PreparedUpdate::new`], [`sle::Sle::new`], [`recommend::Recommend::new`]. The checks are those of [`checks`]: ranges, the cost guard
//! [`checks::MAX_STEPS_PER_DELAY`] and the combinations a job refuses. Outcomes are typed
//! (`LobesOutcome`, `BandsOutcome` with its `curves()`, `MultiplierOutcome`, ...), so summaries
//! are computed from numbers, never from the text a front end wrote.
//!
//! - [`lobes`]: limiting depths per speed (modes or measured FRFs) and the |mu| map.
//! - [`multiplier`]: the dominant multiplier of one cut and the stability rule |mu| < 1.
//! - [`fit_frf`]: modes fitted to a measured FRF, merged into a model file.
//! - [`frf`]: the receptance of a modal model on a frequency grid.
//! - [`checks`]: the checks every request runs once (ranges, the cost guard, ignored options).
//! - [`update`]: Bayesian updating (000, 002, 004) with prior draws.
//! - [`diagnose`]: sim-to-real gap diagnosis ([`chatter_gap`]), also from recordings.
//! - [`plan`]: the next test cut (003 value of information, 004 risk-based).
//! - [`rcsa`]: the tool-tip FRF of an assembly by receptance coupling (004).
//! - [`bands`]: lobes, Type B offsets (001), credibility bounds (000), Monte Carlo (004).
//! - [`oma`]: operational modal analysis of every signal record of an observations file.
//! - [`detect`]: chatter detection of a signal record, as a labelled cut with its evidence.
//! - [`recordings`]: a shop's recordings to labelled cuts and identified poles, one row per
//!   record.
//! - [`sensitivity`]: d mu / d theta of the dominant pole at one cut (000 Table 3).
//! - [`demo`]: the demo's stages on the embedded examples, its grids and seeds in one request.
//! - [`sle`]: the surface location error of stable milling cuts over speeds (Schmitz & Mann
//!   2006), with |mu| to mark the unstable ones.
//! - [`recommend`]: the highest-MRR cut stable with probability >= 1 - P (derated nominal
//!   lobes, posterior samples or bands) within an SLE tolerance, and the Harmonizer's speeds.
//! - [`simulate`]: a time-domain regenerative cut from checked options.
//! - [`synthetic`]: the synthetic shop-floor campaign of the proving ground (demo and Python).
//! - [`campaign`]: fleet manifests, one row per machine-tool campaign, batches in parallel.
//! - [`inference_data`]: posteriors as ArviZ `InferenceData` netCDF-4 files.

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod bands;
pub mod campaign;
pub mod checks;
pub mod demo;
pub mod detect;
pub mod diagnose;
pub mod error;
pub mod fit_frf;
pub mod frf;
pub mod inference_data;
pub mod lobes;
pub mod multiplier;
pub mod oma;
pub mod plan;
pub mod rcsa;
pub mod recommend;
pub mod recordings;
pub mod sensitivity;
pub mod simulate;
pub mod sle;
pub mod synthetic;
pub mod update;

pub use error::{JobError, Result};
