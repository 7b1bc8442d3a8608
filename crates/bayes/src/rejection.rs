//! Rejection sampling (Schmitz et al. 2022, seed 004, Section 4-5).
//!
//! Samples u_i from a distribution q (the prior, or the posterior of earlier tests) are kept with
//! probability L(u_i) / L_max and discarded otherwise; the kept samples u* follow
//! q(u) L(u) / Z. In 004 the likelihood P(a | u) of Eq. 5 is a probability, so L_max = 1 and a
//! sample is discarded with probability 1 - P(a | u). Here everything is in log space:
//! u_i is kept when ln U_i < ln L(u_i) - ln L_max with U_i uniform on (0, 1).
//!
//! The bound is either known ([`LikelihoodBound::Known`], exact) or estimated as the largest
//! likelihood over the samples ([`LikelihoodBound::Estimated`], slightly biased towards the
//! likelihood's peak when the samples miss it).
//!
//! Each sample draws its uniform (and, in [`rejection_sample`], its prior draw) from its own random
//! stream seeded by (seed, index), and likelihoods are evaluated in parallel with rayon, so the
//! result does not depend on the number of threads. The observer is polled before every
//! likelihood evaluation; a cancelled run returns [`BayesError::Cancelled`].

use crate::error::{BayesError, Result};
use crate::prior::Prior;
use crate::special::log_mean_exp;
use crate::tmcmc::{LogLikelihood, stream};
use chatter_progress::Observer;
use rand::Rng;
use rayon::prelude::*;

/// The stream stage of the prior draws.
const PRIOR_STAGE: usize = 0;
/// The stream stage of the acceptance uniforms.
const UNIFORM_STAGE: usize = 1;

/// The bound ln L_max of the acceptance probability L / L_max.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LikelihoodBound {
    /// A known upper bound of ln L (0 for a likelihood that is a probability, as 004 Eq. 5).
    /// A sample above it is an error.
    Known(f64),
    /// The largest ln L over the samples.
    Estimated,
}

/// What rejection sampling kept.
#[derive(Debug, Clone, PartialEq)]
pub struct RejectionResult {
    /// The retained samples u*, in the order of the input.
    pub accepted: Vec<Vec<f64>>,
    /// ln L at each retained sample.
    pub ln_likelihoods: Vec<f64>,
    /// Index of each retained sample in the input.
    pub indices: Vec<usize>,
    /// The bound ln L_max used.
    pub ln_bound: f64,
    /// Fraction of the samples kept.
    pub acceptance_rate: f64,
    /// ln of the mean likelihood over all input samples: the Monte Carlo log-evidence
    /// ln p(D) = ln E_q(L) when the samples come from the prior q.
    pub log_mean_likelihood: f64,
}

/// Keep each of `samples` with probability L / L_max (004 Section 4: discard with probability
/// 1 - P(a | u)). `seed` fixes the uniforms; `observer` can cancel the evaluations.
pub fn rejection_filter<L: LogLikelihood>(
    samples: &[Vec<f64>],
    likelihood: &L,
    bound: LikelihoodBound,
    seed: u64,
    observer: &dyn Observer,
) -> Result<RejectionResult> {
    if samples.is_empty() {
        return Err(BayesError::InvalidInput {
            field: "samples",
            message: "no samples to filter".into(),
        });
    }
    let ln_l: Vec<f64> = samples
        .par_iter()
        .map(|u| {
            if observer.cancelled() {
                return f64::NEG_INFINITY;
            }
            likelihood.ln_likelihood(u)
        })
        .collect();
    chatter_progress::check(observer)?;
    if let Some(i) = ln_l.iter().position(|l| l.is_nan()) {
        return Err(BayesError::InvalidInput {
            field: "likelihood",
            message: format!("ln L is NaN at sample {i}: {:?}", samples[i]),
        });
    }
    let ln_bound = match bound {
        LikelihoodBound::Known(b) => {
            if b.is_nan() || b == f64::INFINITY {
                return Err(BayesError::InvalidInput {
                    field: "bound",
                    message: format!("ln L_max = {b}: expected a number below +inf"),
                });
            }
            // allow rounding in the caller's bound
            let tolerance = 1e-9 * b.abs().max(1.0);
            if let Some(i) = ln_l.iter().position(|&l| l > b + tolerance) {
                return Err(BayesError::InvalidInput {
                    field: "bound",
                    message: format!(
                        "ln L = {} at sample {i} exceeds the stated bound ln L_max = {b}",
                        ln_l[i]
                    ),
                });
            }
            b
        }
        LikelihoodBound::Estimated => ln_l.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    };
    if ln_bound == f64::NEG_INFINITY {
        return Err(BayesError::Degenerate(
            "the likelihood is zero at every sample".into(),
        ));
    }
    let keep: Vec<bool> = ln_l
        .par_iter()
        .enumerate()
        .map(|(i, &l)| {
            let u: f64 = stream(seed, UNIFORM_STAGE, i).random();
            u.ln() < l - ln_bound
        })
        .collect();
    let mut accepted = Vec::new();
    let mut ln_likelihoods = Vec::new();
    let mut indices = Vec::new();
    for (i, _) in keep.iter().enumerate().filter(|(_, k)| **k) {
        accepted.push(samples[i].clone());
        ln_likelihoods.push(ln_l[i]);
        indices.push(i);
    }
    Ok(RejectionResult {
        acceptance_rate: accepted.len() as f64 / samples.len() as f64,
        accepted,
        ln_likelihoods,
        indices,
        ln_bound,
        log_mean_likelihood: log_mean_exp(&ln_l),
    })
}

/// Draw `draws` samples from the prior (sample i from the stream (seed, i)) and filter them with
/// [`rejection_filter`]: the retained samples follow the posterior p(u) L(u) / Z.
pub fn rejection_sample<P: Prior, L: LogLikelihood>(
    prior: &P,
    likelihood: &L,
    draws: usize,
    bound: LikelihoodBound,
    seed: u64,
    observer: &dyn Observer,
) -> Result<RejectionResult> {
    if draws == 0 {
        return Err(BayesError::InvalidInput {
            field: "draws",
            message: "expected at least one prior draw".into(),
        });
    }
    let samples: Vec<Vec<f64>> = (0..draws)
        .into_par_iter()
        .map(|i| prior.sample(&mut stream(seed, PRIOR_STAGE, i)))
        .collect();
    rejection_filter(&samples, likelihood, bound, seed, observer)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prior::{IndependentPrior, Marginal};
    use chatter_progress::Silent;

    #[test]
    fn known_bound_is_checked_and_zero_likelihood_fails() {
        let samples = vec![vec![0.0], vec![1.0]];
        let like = |t: &[f64]| -t[0];
        assert!(
            rejection_filter(&samples, &like, LikelihoodBound::Known(-0.5), 1, &Silent).is_err()
        );
        let r = rejection_filter(&samples, &like, LikelihoodBound::Known(0.0), 1, &Silent).unwrap();
        assert!(r.accepted.iter().all(|u| u.len() == 1));
        let zero = |_: &[f64]| f64::NEG_INFINITY;
        assert!(rejection_filter(&samples, &zero, LikelihoodBound::Estimated, 1, &Silent).is_err());
        assert!(rejection_filter(&[], &like, LikelihoodBound::Estimated, 1, &Silent).is_err());
    }

    #[test]
    fn flat_likelihood_keeps_everything() {
        let prior = IndependentPrior::new(vec![Marginal::Normal { mean: 0.0, sd: 1.0 }]).unwrap();
        let flat = |_: &[f64]| -3.0;
        let r =
            rejection_sample(&prior, &flat, 100, LikelihoodBound::Estimated, 4, &Silent).unwrap();
        assert_eq!(r.accepted.len(), 100);
        assert!((r.log_mean_likelihood + 3.0).abs() < 1e-12);
    }
}
