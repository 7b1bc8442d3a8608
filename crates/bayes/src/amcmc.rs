//! Parallel adaptive MCMC started from rejection-sampling survivors (Schmitz et al. 2022, seed 004,
//! Section 5 and Eq. 8).
//!
//! 004 runs a random walk on the posterior p(u | a_1:n) ∝ p(u) prod_i P(a_i | u) (004 Eq. 7):
//!
//! 1. rejection sampling of prior samples gives u* (see [`crate::rejection`]); the chain starts at
//!    one of them, u_last;
//! 2. the proposal is adaptive (Haario, Saksman and Tamminen 2001, 004 ref. 14):
//!    P_prop = N(u_last, 5.76/d S), with d the dimension and S the sample covariance of u* together
//!    with every sample the chain has accepted so far (5.76 = 2.38^2), recomputed at every step;
//! 3. j candidates u_cand_1..j are drawn from P_prop and, with u_cand_0 = u_last, form a finite
//!    set whose stationary distribution is Eq. 8,
//!    I(u_cand_i) = p(u_cand_i | a_1:n) / sum_{l=0..j} p(u_cand_l | a_1:n);
//!    k indices are drawn independently from I and their candidates appended to the chain, the
//!    last one becoming u_last;
//! 4. steps 2-3 repeat until s unique samples have been accepted.
//!
//! Eq. 8 weights the candidates by the posterior alone. That is exact for the multiple-proposal
//! construction of Calderhead (2014, 004 ref. 15), which this module follows: an auxiliary point
//! z ~ N(u_last, Sigma) is drawn first and the j candidates are drawn from N(z, Sigma). The joint
//! density of the j + 1 points given that u_cand_i is the current one is
//! N(z; u_cand_i, Sigma) prod_{l != i} N(u_cand_l; z, Sigma) = prod_l N(u_cand_l; z, Sigma), the
//! same for every i because the Gaussian is symmetric; the proposal terms cancel from the
//! stationary distribution of the index, which is then exactly Eq. 8, and each of the k draws is
//! a Gibbs update that leaves the posterior invariant. (Drawing the candidates around u_last
//! directly, with the Eq. 8 weights, would not be.)
//!
//! Parallelism: the j + 1 posterior evaluations of a step run in parallel with rayon, and so do
//! independent chains ([`AmcmcOptions::chains`], each from its own survivor with its own share of
//! s). Every chain draws all its random numbers from one stream seeded by (seed, chain), in a
//! fixed order, so the result does not depend on the number of threads.

use crate::error::{BayesError, Result};
use crate::prior::Prior;
use crate::samples::SampleSet;
use crate::tmcmc::{LogLikelihood, stream};
use chatter_progress::Observer;
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

/// The stream stage of the chains (stream (seed, [`CHAIN_STAGE`], chain)).
const CHAIN_STAGE: usize = 2;
/// The adaptive-Metropolis scale 2.38^2 of 004 (P_prop covariance 5.76/d S).
pub const PROPOSAL_SCALE: f64 = 5.76;
/// Regularization of S relative to its mean diagonal (Haario et al.: S + epsilon I).
const RELATIVE_JITTER: f64 = 1e-10;

/// Options of [`adaptive_mcmc`]; defaults are the values of 004 (j = k = 60, s = 4000).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AmcmcOptions {
    /// j: candidates drawn from P_prop per step (default 60).
    pub candidates: usize,
    /// k: indices drawn from the Eq. 8 distribution per step (default 60).
    pub draws: usize,
    /// s: unique samples to collect over all chains (default 4000).
    pub unique_samples: usize,
    /// Independent chains run in parallel, each with about s / chains unique samples (default 1,
    /// as in 004, where the parallelism is the j candidates of a step).
    pub chains: usize,
    /// Steps per chain before giving up with [`BayesError::Degenerate`] (default 100 000).
    pub max_steps: usize,
    /// Seed (default 0).
    pub seed: u64,
}

impl Default for AmcmcOptions {
    fn default() -> Self {
        Self {
            candidates: 60,
            draws: 60,
            unique_samples: 4000,
            chains: 1,
            max_steps: 100_000,
            seed: 0,
        }
    }
}

impl AmcmcOptions {
    /// The options if every count is at least 1 and there are no more chains than unique samples.
    pub fn validated(self) -> Result<Self> {
        let bad = |m: &str| {
            Err(BayesError::InvalidInput {
                field: "options",
                message: format!("{self:?}: {m}"),
            })
        };
        if self.candidates == 0 || self.draws == 0 || self.max_steps == 0 {
            bad("candidates j, draws k and max_steps must be at least 1")
        } else if self.chains == 0 || self.chains > self.unique_samples {
            bad("need 1 <= chains <= unique_samples")
        } else {
            Ok(self)
        }
    }
}

/// Result of [`adaptive_mcmc`].
#[derive(Debug, Clone, PartialEq)]
pub struct AmcmcResult {
    /// The distinct accepted samples, each weighted by the number of times the chains drew it
    /// (the chains' empirical distribution).
    pub samples: SampleSet,
    /// Draws appended per chain (including repeats).
    pub chain_lengths: Vec<usize>,
    /// Steps (proposal rounds) per chain.
    pub steps: Vec<usize>,
    /// Posterior evaluations (prior density, and the likelihood where the prior is positive).
    pub evaluations: usize,
    /// Fraction of draws that moved away from the current point u_last.
    pub move_rate: f64,
}

/// The accepted part of one chain.
struct Chain {
    points: Vec<Vec<f64>>,
    counts: Vec<usize>,
    draws: usize,
    moves: usize,
    steps: usize,
    evaluations: usize,
}

/// Welford running mean and scatter of u* and the chain's draws: S = scatter / (n - 1).
#[derive(Clone)]
struct RunningCovariance {
    n: usize,
    mean: DVector<f64>,
    scatter: DMatrix<f64>,
}

impl RunningCovariance {
    fn new(d: usize) -> Self {
        Self {
            n: 0,
            mean: DVector::zeros(d),
            scatter: DMatrix::zeros(d, d),
        }
    }
    fn push(&mut self, x: &[f64]) {
        self.n += 1;
        let x = DVector::from_column_slice(x);
        let delta = &x - &self.mean;
        self.mean += &delta / self.n as f64;
        self.scatter += &delta * (x - &self.mean).transpose();
    }
    /// Lower Cholesky factor of 5.76/d (S + epsilon I).
    fn proposal_factor(&self) -> Option<DMatrix<f64>> {
        let d = self.mean.len();
        let s = &self.scatter / (self.n.max(2) - 1) as f64;
        let s = (&s + s.transpose()) * 0.5;
        let mean_diagonal = s.trace() / d as f64;
        if !(mean_diagonal > 0.0 && mean_diagonal.is_finite()) {
            return None;
        }
        let regularized = s + DMatrix::identity(d, d) * (RELATIVE_JITTER * mean_diagonal);
        (regularized * (PROPOSAL_SCALE / d as f64))
            .cholesky()
            .map(|c| c.l())
    }
}

fn gaussian_step(centre: &[f64], factor: &DMatrix<f64>, rng: &mut impl rand::RngCore) -> Vec<f64> {
    let z = DVector::from_fn(centre.len(), |_, _| StandardNormal.sample(rng));
    let step = factor * z;
    centre.iter().zip(step.iter()).map(|(a, b)| a + b).collect()
}

fn ln_posterior<P: Prior, L: LogLikelihood>(prior: &P, likelihood: &L, u: &[f64]) -> f64 {
    let p = prior.ln_pdf(u);
    if p == f64::NEG_INFINITY {
        p
    } else {
        p + likelihood.ln_likelihood(u)
    }
}

/// Sample the posterior p(u) L(u) / Z with the parallel adaptive MCMC of 004 Section 5 (Eq. 8),
/// starting from `retained`, the survivors u* of rejection sampling (at least 2, spread out so
/// that their covariance is positive).
///
/// Chain c starts at `retained[c * retained.len() / chains]`.
pub fn adaptive_mcmc<P: Prior, L: LogLikelihood>(
    prior: &P,
    likelihood: &L,
    retained: &[Vec<f64>],
    options: &AmcmcOptions,
    observer: &dyn Observer,
) -> Result<AmcmcResult> {
    let options = options.validated()?;
    chatter_progress::check(observer)?;
    let d = prior.dimension();
    if retained.len() < 2 {
        return Err(BayesError::InvalidInput {
            field: "retained",
            message: format!(
                "{} retained samples: at least 2 are needed for the covariance S",
                retained.len()
            ),
        });
    }
    if let Some(i) = retained.iter().position(|u| u.len() != d) {
        return Err(BayesError::InvalidInput {
            field: "retained",
            message: format!(
                "retained sample {i} has {} coordinates, the prior {d}",
                retained[i].len()
            ),
        });
    }
    let mut base = RunningCovariance::new(d);
    for u in retained {
        base.push(u);
    }
    if base.proposal_factor().is_none() {
        return Err(BayesError::Degenerate(
            "the retained samples have no spread: S is zero or not finite".into(),
        ));
    }
    let sampler = Sampler {
        prior,
        likelihood,
        options: &options,
        observer,
    };
    let chains: Vec<Chain> = (0..options.chains)
        .into_par_iter()
        .map(|c| {
            let quota = options.unique_samples / options.chains
                + usize::from(c < options.unique_samples % options.chains);
            let start = c * retained.len() / options.chains;
            sampler.run_chain(&retained[start], base.clone(), quota, c)
        })
        .collect::<Result<_>>()?;
    let draws: usize = chains.iter().map(|c| c.draws).sum();
    let moves: usize = chains.iter().map(|c| c.moves).sum();
    let evaluations = chains.iter().map(|c| c.evaluations).sum();
    let chain_lengths = chains.iter().map(|c| c.draws).collect();
    let steps = chains.iter().map(|c| c.steps).collect();
    let mut points = Vec::new();
    let mut counts = Vec::new();
    for chain in chains {
        points.extend(chain.points);
        counts.extend(chain.counts.into_iter().map(|n| n as f64));
    }
    Ok(AmcmcResult {
        samples: SampleSet::new(points, counts)?,
        chain_lengths,
        steps,
        evaluations,
        move_rate: moves as f64 / draws.max(1) as f64,
    })
}

/// What every chain shares.
struct Sampler<'a, P, L> {
    prior: &'a P,
    likelihood: &'a L,
    options: &'a AmcmcOptions,
    observer: &'a dyn Observer,
}

impl<P: Prior, L: LogLikelihood> Sampler<'_, P, L> {
    /// Run chain `index` from `start` until it holds `quota` unique samples.
    fn run_chain(
        &self,
        start: &[f64],
        mut covariance: RunningCovariance,
        quota: usize,
        index: usize,
    ) -> Result<Chain> {
        let (prior, likelihood, options) = (self.prior, self.likelihood, self.options);
        let mut rng = stream(options.seed, CHAIN_STAGE, index);
        let mut current = start.to_vec();
        let mut ln_current = ln_posterior(prior, likelihood, &current);
        if !ln_current.is_finite() {
            return Err(BayesError::Degenerate(format!(
                "chain {index} starts at {current:?}, where the posterior density is {}",
                ln_current.exp()
            )));
        }
        let mut chain = Chain {
            points: Vec::new(),
            counts: Vec::new(),
            draws: 0,
            moves: 0,
            steps: 0,
            evaluations: 1,
        };
        // index in chain.points of u_last, once it has been drawn
        let mut current_point: Option<usize> = None;
        while chain.points.len() < quota {
            chatter_progress::check(self.observer)?;
            if chain.steps == options.max_steps {
                return Err(BayesError::Degenerate(format!(
                    "chain {index}: {} of {quota} unique samples after {} steps",
                    chain.points.len(),
                    options.max_steps
                )));
            }
            chain.steps += 1;
            let factor = covariance.proposal_factor().ok_or_else(|| {
                BayesError::Degenerate(format!(
                    "chain {index}: the sample covariance S is not positive definite"
                ))
            })?;
            // Calderhead's construction: auxiliary centre z, then j candidates around it
            let z = gaussian_step(&current, &factor, &mut rng);
            let mut candidates = Vec::with_capacity(options.candidates + 1);
            candidates.push(current.clone());
            for _ in 0..options.candidates {
                candidates.push(gaussian_step(&z, &factor, &mut rng));
            }
            let mut ln_post = vec![ln_current];
            ln_post.par_extend(
                candidates[1..]
                    .par_iter()
                    .map(|u| ln_posterior(prior, likelihood, u)),
            );
            chain.evaluations += options.candidates;
            if let Some(i) = ln_post.iter().position(|l| l.is_nan()) {
                return Err(BayesError::InvalidInput {
                    field: "likelihood",
                    message: format!("ln posterior is NaN at {:?}", candidates[i]),
                });
            }
            // Eq. 8 with max-shifted logs; ln_post[0] is finite, so the total is positive
            let top = ln_post.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let mut cumulative: Vec<f64> = ln_post.iter().map(|l| (l - top).exp()).collect();
            for i in 1..cumulative.len() {
                cumulative[i] += cumulative[i - 1];
            }
            let total = cumulative[options.candidates];
            let mut point_of = vec![None; options.candidates + 1];
            point_of[0] = current_point;
            let mut last = 0;
            for _ in 0..options.draws {
                let target = rng.random::<f64>() * total;
                let i = cumulative
                    .partition_point(|&c| c <= target)
                    .min(options.candidates);
                match point_of[i] {
                    Some(p) => chain.counts[p] += 1,
                    None => {
                        chain.points.push(candidates[i].clone());
                        chain.counts.push(1);
                        point_of[i] = Some(chain.points.len() - 1);
                    }
                }
                if i != 0 {
                    chain.moves += 1;
                }
                chain.draws += 1;
                covariance.push(&candidates[i]);
                last = i;
                if chain.points.len() == quota {
                    break;
                }
            }
            current_point = point_of[last];
            current = candidates[last].clone();
            ln_current = ln_post[last];
            self.observer
                .chain_progress(index, chain.points.len(), quota);
        }
        Ok(chain)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prior::{IndependentPrior, Marginal};
    use chatter_progress::Silent;

    #[test]
    fn options_are_validated() {
        assert!(AmcmcOptions::default().validated().is_ok());
        for bad in [
            AmcmcOptions {
                candidates: 0,
                ..Default::default()
            },
            AmcmcOptions {
                draws: 0,
                ..Default::default()
            },
            AmcmcOptions {
                chains: 5,
                unique_samples: 4,
                ..Default::default()
            },
        ] {
            assert!(bad.validated().is_err());
        }
    }

    #[test]
    fn bad_starts_are_errors() {
        let prior = IndependentPrior::new(vec![Marginal::Uniform {
            low: 0.0,
            high: 1.0,
        }])
        .unwrap();
        let like = |t: &[f64]| -t[0];
        let opts = AmcmcOptions {
            unique_samples: 10,
            ..Default::default()
        };
        let run = |r: &[Vec<f64>]| adaptive_mcmc(&prior, &like, r, &opts, &Silent);
        assert!(run(&[vec![0.5]]).is_err());
        assert!(run(&[vec![0.5], vec![0.5]]).is_err());
        assert!(run(&[vec![0.5], vec![0.2, 0.1]]).is_err());
        assert!(run(&[vec![2.0], vec![3.0]]).is_err());
        let ok = run(&[vec![0.5], vec![0.2]]).unwrap();
        assert_eq!(ok.samples.samples().len(), 10);
        assert!(
            ok.samples
                .samples()
                .iter()
                .all(|u| (0.0..=1.0).contains(&u[0]))
        );
    }
}
