//! Progress of long computations: one observer trait that every chatter crate reports to, and
//! one observer that does nothing ([`Silent`]). Libraries never print; a front end (the CLI's
//! progress bars, the Python bindings) implements [`Observer`] and hears what it cares about.
//!
//! The trait lives in a crate of its own because its reporters include both roots of the crate
//! graph: `chatter-bayes` (samplers, which know nothing of machining) and `chatter-dynamics`
//! (time-domain simulation); neither may depend on the other. Every method has a no-op default
//! (the observers of argmin), so an observer implements only the events it shows.
//!
//! The observer is also the way back: a front end that wants a long call stopped (the Python
//! bindings on Ctrl-C) answers [`Observer::cancelled`] with true, and the loops that report
//! progress poll it between their steps ([`check`]) and return their crate's `Cancelled` error,
//! made from [`Cancelled`].
//!
//! ```
//! use chatter_progress::{Observer, Silent};
//! use std::sync::atomic::{AtomicUsize, Ordering};
//! struct Count(AtomicUsize);
//! impl Observer for Count {
//!     fn steps_done(&self, done: usize, _total: usize) {
//!         self.0.store(done, Ordering::Relaxed);
//!     }
//! }
//! fn work(observer: &dyn Observer) {
//!     for k in 1..=3 {
//!         observer.steps_done(k, 3);
//!     }
//! }
//! let count = Count(AtomicUsize::new(0));
//! work(&count);
//! work(&Silent);
//! assert_eq!(count.0.load(Ordering::Relaxed), 3);
//! ```

/// Progress of a long computation; every event is a no-op by default. Implementations are
/// called from worker threads (lobe diagrams and ensembles run in parallel), hence `Sync`.
pub trait Observer: Sync {
    /// `done` of `total` steps are finished: the speeds of a lobe diagram, the paths of an
    /// ensemble of sampled boundaries, the folds of a validation.
    fn steps_done(&self, _done: usize, _total: usize) {}

    /// The fraction in [0, 1] of a computation without countable steps (a time-domain
    /// simulation's record).
    fn fraction_done(&self, _fraction: f64) {}

    /// A sampler finished stage `index` of its tempering: exponent `beta` in (0, 1] and the
    /// acceptance rate of the stage's chains (TMCMC).
    fn stage(&self, _index: usize, _beta: f64, _acceptance: f64) {}

    /// A chain sampler (adaptive MCMC) collected `done` of `total` unique samples in `chain`.
    fn chain_progress(&self, _chain: usize, _done: usize, _total: usize) {}

    /// Model class `index` of `total` starts; `parameter` is what defines the class (e.g. the
    /// error-variance ratio alpha), NaN where none does.
    fn class_started(&self, _index: usize, _total: usize, _parameter: f64) {}

    /// Model class `name` is fitted, with its log-evidence ln p(D | class).
    fn class_done(&self, _name: &str, _log_evidence: f64) {}

    /// Whether the caller asked the computation to stop. Long loops poll it between their steps
    /// (speeds, samples, sampler moves) and then return [`Cancelled`]; the work in flight
    /// finishes first, so a cancelled call returns within about one step. Default: never.
    fn cancelled(&self) -> bool {
        false
    }
}

/// A computation stopped because its observer asked ([`Observer::cancelled`]); every crate's
/// error type has a variant made from it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Cancelled;

impl std::fmt::Display for Cancelled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("cancelled by the caller")
    }
}

impl std::error::Error for Cancelled {}

/// `Err(Cancelled)` when `observer` asks to stop: the poll of a loop between its steps,
/// `check(observer)?`.
pub fn check(observer: &dyn Observer) -> Result<(), Cancelled> {
    if observer.cancelled() {
        Err(Cancelled)
    } else {
        Ok(())
    }
}

/// The observer that does nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Observer for Silent {}

/// The observer of a call cancelled before it started: [`Observer::cancelled`] is always true.
/// What the tests of the polls use: every long call handed it returns its crate's `Cancelled`
/// error after at most one step.
#[derive(Debug, Clone, Copy, Default)]
pub struct AlreadyCancelled;

impl Observer for AlreadyCancelled {
    fn cancelled(&self) -> bool {
        true
    }
}
