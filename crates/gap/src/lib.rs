//! Sim-to-real gap diagnosis: where a chatter model and shop-floor data disagree, which
//! unmodelled effect causes it, and how far the gap shrinks once that effect is added.
//!
//! # What it answers
//! 1. **Where** ([`regions`]): per observation, the signed log-depth distance of a cut to the
//!    predicted boundary, the chatter-frequency residual folded over the tooth-passing
//!    harmonics, and pole frequency and damping residuals (per speed split into the zero-depth
//!    value and the slope with depth); then the regions where the misfit concentrates: speed
//!    bands (with the surface wavelength V / f_c), lobe pockets versus peaks, depth bands,
//!    observable type and run order (`sequence`).
//! 2. **Which effect** ([`diagnose()`]): Bayesian model-class selection between
//!    [`EffectClass`]es, each a parameterization of the nominal model with a prior
//!    ([`classes`]): `parameter_error` (recalibration, always a candidate), `process_damping`
//!    (C b ydot / V, seed 003), `speed_dependent_dynamics` (f_n(Omega) = f_n0 (1 - c Omega^2)),
//!    `extra_mode` and `drift` (cutting coefficients changing with `sequence`). The log-evidence
//!    ln p(D | M) of each comes from iTMCMC (`chatter-bayes`; for `extra_mode`, whose posterior
//!    has several modes in the extra mode's frequency, one run per slice of that frequency's
//!    prior, pooled by total probability: `chatter_bayes::strata`), the posterior class probabilities
//!    from equal prior odds (000 Eq. 32), and the verdict is the most probable class (an effect
//!    needs a Bayes factor of 10 over plain recalibration, which it contains) unless a
//!    posterior predictive check ([`PredictiveCheck`]) finds its residuals inconsistent with
//!    the noise: then it is `unexplained` rather than a confident wrong name.
//! 3. **How far it shrinks** ([`shrink`]): on held-out observations (k-fold, or leave one speed
//!    band out), the balanced misclassification rate of cuts, the log predictive density per
//!    observation and the RMS chatter-frequency and pole residuals, before (nominal model) and
//!    after (the winning class fitted to the other folds).
//!
//! # Verdicts
//! `consistent` when the nominal model itself passes the predictive check and either the classes'
//! mean evidence does not beat its likelihood (a class without parameters) by a Bayes factor of
//! 10, or the best class is practically equivalent to it ([`equivalence`]: no observation's
//! prediction moves by more than one noise standard deviation); otherwise the best class when it
//! passes the check; otherwise `unexplained`. The check includes a localized scan over bands of
//! speeds ([`local`]); when that part fails, the `unexplained` verdict names the band. A
//! rejection of the nominal model that one observation carries alone (without it the nominal
//! model would be `consistent`) gives `consistent` with a note naming that observation
//! (`influence`): one gross misidentification is not a model error. Besides the listed classes
//! the open alternative `speed_band` ([`unlisted`]: the cutting coefficients changed in one
//! band of speeds, or a trend toward one end of the range) is fitted; when its evidence beats
//! the nominal model's likelihood and every listed class's evidence by the Bayes factor an
//! effect needs, also without the observation it helps most, and moves some prediction by more
//! than the practical equivalence, the verdict is `unexplained` with the band named: a gap in a
//! shape none of the listed effects has.
//!
//! # Outside proving ground
//! Twenty campaigns of an outside generator (`../shared/data/gap_public`, its README; truth a
//! converged first-order full discretization, turning poles the rightmost characteristic root,
//! 1 % pole-frequency noise), diagnosed at the defaults, seed 1, validation off
//! (`cargo run --release -p chatter-gap --example confusion -- --public ../shared/data/gap_public`;
//! `tests/public_campaigns.rs` holds the turning campaigns and a control):
//!
//! | machine | control | 1x | 2x | outside the list |
//! |---|---|---|---|---|
//! | A: xy milling 30 % | 1/1 | 2/2 (parameter error, speed-dependent dynamics) | 1/1 (process damping) | 0/1 (cutting x3 in a band: `consistent`, nominal misses 4/40) |
//! | B: low immersion | 1/1 | 0/1 (drift taken for `extra_mode`) | 1/2 (parameter error right; extra mode `unexplained`) | 1/1 (damping band, seen in one pole: `consistent`, nominal misses 0/40) |
//! | C: turning | 1/1 | 2/2 (process damping, extra mode) | 1/1 (speed-dependent dynamics) | 1/1 (cutting rising at low speed: `unexplained`, the open alternative beating `process_damping` by 9.1 nats, 4.5 without its most helped observation) |
//! | D: two modes in x | 1/1 | 1/1 (parameter error) | 2/2 (drift, process damping) | 1/1 (`consistent`, nominal misses 1/40) |
//!
//! 17/20 right (10/20 before the pole-frequency noise scale was integrated out, [`likelihood`];
//! 15/20 before the gap resting on one observation became `consistent`, `influence`; 16/20
//! before the open alternative, [`unlisted`]); every control `consistent`; median held-out
//! closure 0.67 over the 13 campaigns with a gap (nominal misses >= 2 of 40). Still missed: the
//! cutting-coefficient band (its band holds one surprising label; the open alternative puts
//! its band at 11 128-12 327 rpm, inside the true 11 283-13 245, but its evidence, -65.6, stays
//! below the nominal model's likelihood, -57.3: the recalibration every class carries costs
//! more than one label gives), drift 1x on the low-immersion machine (taken for `extra_mode`)
//! and its extra mode 2x (the fitted extra mode leaves chatter frequencies failing the check,
//! p = 0.0004). The open alternative named no band on any control or listed effect: its
//! evidence stayed below the best explanation's plus the 2.3 nats it needs (at most 0.6 above
//! it, on `public_02`, a recalibration, where its band's factor is 1.01). Wall time per campaign on the free
//! two-core machine (before the open alternative, which adds 5-10 s): 17-27 s on the lathe,
//! 22-38 s on the low-immersion machine, 98 s for the two-mode machine's control (39 cuts, 8
//! poles); the 30 s target is not met (`extra_mode`'s four strata are most of it; the inference
//! tolerance of [`predict`] took 16 % of the CPU off that campaign).
//!
//! # Model: which approximation is used where
//! - **Inside the samplers and the checks** every prediction is one Floquet multiplier of the
//!   variant's own periodic delay equation at the observation's cutting condition
//!   ([`predict`]): for milling the first-order full discretization of `chatter-stability` at
//!   its automatic resolution, for turning (constant coefficients) the rightmost root of the
//!   characteristic equation. No limiting depth is searched and no averaged (zero-order) system
//!   is used. Against the proving ground's truth it errs by at most 0.6 % in limiting depth on
//!   the test machines (`tests/proving_ground.rs`), well inside the label width (8 % in depth).
//! - **The label model** interpolates ln|mu| linearly in depth between b = 0 and the cut to
//!   turn ln|mu| into a log-depth distance (exact at the boundary, approximate away from it,
//!   where it only shapes the probit's width).
//! - **The process-damping prior scale** uses the zero-order limiting depth (a scale only).
//! - **Solver failures** give a neutral term, are counted per class and flagged above 1 %.
//!
//! # Proving ground
//! [`generator`] makes shop-floor campaigns from a true machine with one hidden effect (every
//! class at magnitudes 0.5x, 1x, 2x, a control with the nominal model right, and effects
//! outside the list: runout, and cutting coefficients tripled in a speed band) on four machines
//! ([`generator::proving_machines`]: two-direction milling, low radial immersion, two modes in
//! one direction, turning). The truth is the semi-discretization at four times the resolution,
//! itself checked against an RK4 integration and the closed-form single-DOF turning boundary;
//! `examples/confusion.rs` prints the confusion matrix and the held-out closure. Measured
//! (seed 0, 70 campaigns of 24-40 cuts, all five classes; the milling columns with the sampler
//! of session 8, whose milling likelihood is unchanged since; the turning column with this
//! version's chatter-frequency branches and pole mixture):
//!
//! | magnitude | xy 30 % | low immersion 7 % | two modes in x | turning | all |
//! |---|---|---|---|---|---|
//! | 0.5x | 5/5 | 4/5 | 3/5 | 1/5 | 13/20 (65 %) |
//! | 1x | 5/5 | 5/5 | 5/5 | 4/5 | 19/20 (95 %) |
//! | 2x | 5/5 | 5/5 | 4/5 | 5/5 | 19/20 (95 %) |
//! | control (`consistent`) | 1/1 | 1/1 | 1/1 | 1/1 | 4/4 |
//! | outside the list (`unexplained`) | 2/2 | 2/2 | 1/1 | 0/1 | 5/6 |
//!
//! Median held-out closure 0.88 over the milling campaigns with a gap; 0.19 over the lathe's 29
//! (seeds 0 and 1), where a diagnosed extra mode at 2x misclassifies more held-out cuts than
//! the nominal model although its name is right. The misses: at 0.5x the effect often changes
//! no held-out label (closure undefined or 0: `consistent` or `parameter_error` is then as
//! good an answer as the data allow); the lathe's `speed_dependent_dynamics` 1x is taken for
//! `parameter_error`, and its band of tripled cutting coefficients for `drift` (the drift
//! class passes the in-sample check and generalizes worse than the nominal model); the
//! two-mode machine's `extra_mode` 2x ends `unexplained` (the best class fails the check).
//! Seed 1 on the lathe: 0.5x 0/5, 1x 4/5, 2x 5/5, control 1/1, outside 0/1 (`drift`).
//!
//! ```no_run
//! use chatter_gap::{DiagnoseOptions, HiddenEffect, Scenario, diagnose, nominal_milling, synthesize};
//! use chatter_progress::Silent;
//! let nominal = nominal_milling()?;
//! let data = synthesize(&nominal, &Scenario::new(HiddenEffect::ParameterError, 1))?;
//! let report = diagnose(&nominal, &data, &DiagnoseOptions::default(), &Silent)?;
//! assert_eq!(report.verdict.name(), "consistent");
//! # Ok::<(), chatter_gap::GapError>(())
//! ```

#![cfg_attr(test, allow(clippy::unwrap_used))]

mod check;
pub mod classes;
mod data;
pub mod diagnose;
pub mod equivalence;
pub mod error;
pub mod generator;
mod influence;
pub mod likelihood;
pub mod local;
pub mod predict;
pub mod regions;
pub mod shrink;
pub mod unlisted;
pub mod variant;

pub use check::PredictiveCheck;
pub use classes::EffectClass;
pub use diagnose::{DiagnoseOptions, Diagnosis, LobeComparison, Validation, Verdict, diagnose};
pub use error::{GapError, Result};
pub use generator::{HiddenEffect, Recalibration, RunOrder, Scenario, nominal_milling, synthesize};
pub use likelihood::NoiseModel;
pub use local::LocalCheck;
pub use variant::Variant;
