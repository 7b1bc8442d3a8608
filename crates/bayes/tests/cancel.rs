//! A call handed an observer that is cancelled from the start returns `BayesError::Cancelled`
//! after at most one step of each chain: every sampler polls the observer.
#![allow(clippy::unwrap_used)]

use chatter_bayes::BayesError;
use chatter_bayes::amcmc::{AmcmcOptions, adaptive_mcmc};
use chatter_bayes::prior::{IndependentPrior, Marginal};
use chatter_bayes::rejection::{LikelihoodBound, rejection_sample};
use chatter_bayes::tmcmc::{TmcmcOptions, rejuvenate, tmcmc};
use chatter_progress::{AlreadyCancelled, Silent};
use std::sync::atomic::{AtomicUsize, Ordering};

fn prior() -> IndependentPrior {
    IndependentPrior::new(vec![Marginal::Normal { mean: 0.0, sd: 1.0 }]).unwrap()
}

/// A Gaussian likelihood that counts its evaluations.
struct Counted(AtomicUsize);

impl Counted {
    fn new() -> Self {
        Self(AtomicUsize::new(0))
    }
    fn calls(&self) -> usize {
        self.0.load(Ordering::Relaxed)
    }
    fn ln(&self, t: &[f64]) -> f64 {
        self.0.fetch_add(1, Ordering::Relaxed);
        -0.5 * (t[0] - 1.0).powi(2)
    }
}

fn is_cancelled<T: std::fmt::Debug>(r: &Result<T, BayesError>) -> bool {
    matches!(r, Err(BayesError::Cancelled(_)))
}

#[test]
fn every_sampler_stops_when_cancelled() {
    let p = prior();
    let counted = Counted::new();
    let like = |t: &[f64]| counted.ln(t);
    let kept = rejection_sample(
        &p,
        &like,
        100_000,
        LikelihoodBound::Estimated,
        1,
        &AlreadyCancelled,
    );
    assert!(is_cancelled(&kept), "{kept:?}");
    assert_eq!(counted.calls(), 0);

    let options = TmcmcOptions {
        samples: 100_000,
        ..Default::default()
    };
    let run = tmcmc(&p, &like, &options, &AlreadyCancelled);
    assert!(is_cancelled(&run), "{run:?}");
    assert_eq!(counted.calls(), 0);

    let start: Vec<Vec<f64>> = (0..10).map(|i| vec![f64::from(i) / 10.0]).collect();
    let chain = adaptive_mcmc(
        &p,
        &like,
        &start,
        &AmcmcOptions {
            unique_samples: 100_000,
            ..Default::default()
        },
        &AlreadyCancelled,
    );
    assert!(is_cancelled(&chain), "{chain:?}");
    assert_eq!(counted.calls(), 0);

    // a short run to rejuvenate, then a long rejuvenation cancelled before its first move
    let small = TmcmcOptions {
        samples: 50,
        ..Default::default()
    };
    let run = tmcmc(&p, &like, &small, &Silent).unwrap();
    let before = counted.calls();
    let polished = rejuvenate(&p, &like, &run, 1000, 1000, 1, &AlreadyCancelled);
    assert!(is_cancelled(&polished), "{polished:?}");
    assert_eq!(counted.calls(), before);
}
