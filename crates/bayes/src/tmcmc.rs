//! Transitional MCMC (Ching and Chen 2007) and its improved variant iTMCMC (Betz, Papaioannou
//! and Straub 2016), with the model evidence.
//!
//! Stage j samples p_j(theta) ~ p(theta) L(theta)^beta_j, beta from 0 to 1. The step
//! beta_{j+1} - beta_j is chosen so the coefficient of variation of the plausibility weights
//! w_i = L(theta_i)^(beta_{j+1} - beta_j) equals the target (1), by bisection on max-shifted log
//! weights. ln p(D) = sum_j ln mean(w) (evidence). Samples are resampled by weight and moved by
//! Metropolis-Hastings chains with Gaussian proposals of covariance c^2 Sigma_w (weighted sample
//! covariance). iTMCMC adapts c towards an acceptance rate of 0.21 and burns in the chains.
//!
//! Every chain draws from its own random stream seeded by (seed, stage, chain), and likelihoods are
//! evaluated in parallel with rayon, so results do not depend on the number of threads.

use crate::error::{BayesError, Result};
use crate::prior::Prior;
use crate::samples::SampleSet;
use crate::special::{log_mean_exp, normalized_weights};
use chatter_progress::Observer;
use nalgebra::{DMatrix, DVector};
use rand::SeedableRng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

/// Why a log-likelihood has no finite value at a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LikelihoodFailure {
    /// theta lies outside the model's support (no valid model): probability zero, as a prior
    /// bound would say.
    OutsideSupport,
    /// The model is valid but computing its prediction failed (a solver did not converge).
    /// Samplers reject the point like an impossible one but count it and report the count, so
    /// a numerical failure is never mistaken for a parameter the data rule out.
    Numerical,
}

/// A log-likelihood ln p(D | theta); -inf where theta is impossible.
pub trait LogLikelihood: Sync {
    /// ln p(D | theta).
    fn ln_likelihood(&self, theta: &[f64]) -> f64;

    /// ln p(D | theta) with the reason when there is none. The default reads -inf as outside
    /// the support and NaN as a numerical failure; likelihoods that call solvers override it.
    fn try_ln_likelihood(&self, theta: &[f64]) -> std::result::Result<f64, LikelihoodFailure> {
        let l = self.ln_likelihood(theta);
        if l.is_nan() {
            Err(LikelihoodFailure::Numerical)
        } else if l == f64::NEG_INFINITY {
            Err(LikelihoodFailure::OutsideSupport)
        } else {
            Ok(l)
        }
    }
}

/// Evaluate `likelihood` at `theta`: -inf for either failure, counting numerical ones.
pub(crate) fn counted_ln_likelihood<L: LogLikelihood + ?Sized>(
    likelihood: &L,
    theta: &[f64],
    failures: &std::sync::atomic::AtomicUsize,
) -> f64 {
    match likelihood.try_ln_likelihood(theta) {
        Ok(l) => l,
        Err(LikelihoodFailure::OutsideSupport) => f64::NEG_INFINITY,
        Err(LikelihoodFailure::Numerical) => {
            failures.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            f64::NEG_INFINITY
        }
    }
}

impl<F: Fn(&[f64]) -> f64 + Sync> LogLikelihood for F {
    fn ln_likelihood(&self, theta: &[f64]) -> f64 {
        self(theta)
    }
}

/// Which variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// Ching and Chen: fixed proposal scale 0.2, no burn-in, `steps` MH steps per chain; its
    /// log-evidence is biased low on peaked likelihoods (the bias iTMCMC corrects).
    Classic,
    /// Betz et al.: adaptive scale towards acceptance 0.21, burn-in.
    Improved,
}

/// Options of the sampler.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TmcmcOptions {
    /// Number of samples per stage.
    pub samples: usize,
    /// Target coefficient of variation of the weights (1).
    pub target_cov: f64,
    /// MH steps per chain and stage (after burn-in).
    pub steps: usize,
    /// Burn-in steps per chain (iTMCMC).
    pub burn_in: usize,
    /// Variant.
    pub variant: Variant,
    /// Seed.
    pub seed: u64,
}

impl Default for TmcmcOptions {
    /// 2000 samples, CoV 1, 6 steps, burn-in 4, iTMCMC, seed 0.
    fn default() -> Self {
        Self {
            samples: 2000,
            target_cov: 1.0,
            steps: 6,
            burn_in: 4,
            variant: Variant::Improved,
            seed: 0,
        }
    }
}

/// Result of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct TmcmcResult {
    /// Equally weighted posterior samples.
    pub samples: SampleSet,
    /// ln of the log-likelihood at each final sample.
    pub ln_likelihoods: Vec<f64>,
    /// ln p(D | M).
    pub log_evidence: f64,
    /// Tempering schedule beta_0 = 0, ..., 1.
    pub betas: Vec<f64>,
    /// Mean acceptance per stage.
    pub acceptance: Vec<f64>,
    /// Likelihood evaluations.
    pub evaluations: usize,
    /// Of those, numerical failures ([`LikelihoodFailure::Numerical`]), rejected and counted.
    pub numerical_failures: usize,
}

impl TmcmcResult {
    /// Posterior mean of the log-likelihood: the data-fit term of 000 Eq. 33.
    pub fn data_fit(&self) -> f64 {
        self.ln_likelihoods.iter().sum::<f64>() / self.ln_likelihoods.len() as f64
    }
    /// Information gain E[ln posterior / prior] = data fit - log evidence (000 Eq. 33).
    pub fn information_gain(&self) -> f64 {
        self.data_fit() - self.log_evidence
    }
}

/// The random stream of one chain: a SplitMix64 mix of (seed, stage, chain) seeds a `StdRng`, so
/// every chain draws the same numbers whichever thread runs it.
pub(crate) fn stream(seed: u64, stage: usize, chain: usize) -> StdRng {
    // SplitMix64-style mixing of the three indices
    let mut z = seed
        ^ (stage as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (chain as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    StdRng::seed_from_u64(z ^ (z >> 31))
}

fn cov_of_weights(ln_l: &[f64], dbeta: f64) -> f64 {
    let m = ln_l.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = ln_l.iter().map(|l| (dbeta * (l - m)).exp()).collect();
    let mean = w.iter().sum::<f64>() / w.len() as f64;
    let var = w.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / w.len() as f64;
    var.sqrt() / mean
}

/// Run TMCMC / iTMCMC.
pub fn tmcmc<P: Prior, L: LogLikelihood>(
    prior: &P,
    likelihood: &L,
    options: &TmcmcOptions,
    observer: &dyn Observer,
) -> Result<TmcmcResult> {
    let n = options.samples;
    let d = prior.dimension();
    if n < 10 || options.target_cov <= 0.0 || options.steps == 0 {
        return Err(BayesError::InvalidInput {
            field: "options",
            message: format!("{options:?}: need >= 10 samples, target CoV > 0, >= 1 step"),
        });
    }
    let mut theta: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|i| prior.sample(&mut stream(options.seed, 0, i)))
        .collect();
    let failures = std::sync::atomic::AtomicUsize::new(0);
    let evaluations = std::sync::atomic::AtomicUsize::new(n);
    let mut ln_l: Vec<f64> = theta
        .par_iter()
        .map(|t| {
            if observer.cancelled() {
                return f64::NEG_INFINITY;
            }
            counted_ln_likelihood(likelihood, t, &failures)
        })
        .collect();
    chatter_progress::check(observer)?;
    if ln_l.iter().all(|l| !l.is_finite()) {
        return Err(BayesError::ZeroLikelihood);
    }
    let mut beta = 0.0;
    let mut betas = vec![0.0];
    let mut acceptance = Vec::new();
    let mut log_evidence = 0.0;
    let mut scale = 2.38 / (d as f64).sqrt();
    let mut stage = 0;
    while beta < 1.0 {
        stage += 1;
        // tempering step by bisection on the weights' coefficient of variation
        let remaining = 1.0 - beta;
        let dbeta = if cov_of_weights(&ln_l, remaining) <= options.target_cov {
            remaining
        } else {
            let (mut lo, mut hi) = (0.0, remaining);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if cov_of_weights(&ln_l, mid) > options.target_cov {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            lo.max(1e-12)
        };
        beta = (beta + dbeta).min(1.0);
        let ln_w: Vec<f64> = ln_l.iter().map(|l| dbeta * l).collect();
        log_evidence += log_mean_exp(&ln_w);
        let weights = normalized_weights(&ln_w);
        let chol = proposal_factor(&theta, &weights)?;
        let idx = systematic_resample(&weights, n, &mut stream(options.seed, stage, usize::MAX));
        let burn = if options.variant == Variant::Improved {
            options.burn_in
        } else {
            0
        };
        let steps = options.steps + burn;
        let c_scale = if options.variant == Variant::Improved {
            scale
        } else {
            0.2
        };
        let chains = Chains {
            prior,
            likelihood,
            factor: &chol,
            scale: c_scale,
            beta,
            steps,
            seed: options.seed,
            stage,
            evaluations: &evaluations,
            failures: &failures,
            observer,
        };
        let moved: Vec<(Vec<f64>, f64, usize)> = idx
            .par_iter()
            .enumerate()
            .map(|(chain, &start)| chains.run(chain, theta[start].clone(), ln_l[start]))
            .collect();
        chatter_progress::check(observer)?;
        let acc = moved.iter().map(|m| m.2).sum::<usize>() as f64 / (n * steps) as f64;
        theta = moved.iter().map(|m| m.0.clone()).collect();
        ln_l = moved.iter().map(|m| m.1).collect();
        acceptance.push(acc);
        if options.variant == Variant::Improved {
            // Betz et al.: move the scale towards acceptance 0.21
            scale *= ((acc - 0.21) * 2.0).exp();
        }
        betas.push(beta);
        observer.stage(stage, beta, acc);
        if stage > 1000 {
            return Err(BayesError::Degenerate(
                "more than 1000 tempering stages".into(),
            ));
        }
    }
    Ok(TmcmcResult {
        samples: SampleSet::equally_weighted(theta)?,
        ln_likelihoods: ln_l,
        log_evidence,
        betas,
        acceptance,
        evaluations: evaluations.into_inner(),
        numerical_failures: failures.into_inner(),
    })
}

/// Systematic resampling: `n` indices into `weights` (normalized), index k drawn about
/// n w_k times, deterministic given the weights and one uniform from `rng`.
pub(crate) fn systematic_resample(weights: &[f64], n: usize, rng: &mut StdRng) -> Vec<usize> {
    let u0: f64 = rand::Rng::random::<f64>(rng) / n as f64;
    let mut idx = Vec::with_capacity(n);
    let (mut c, mut k) = (weights[0], 0);
    for i in 0..n {
        let u = u0 + i as f64 / n as f64;
        while u > c && k + 1 < weights.len() {
            k += 1;
            c += weights[k];
        }
        idx.push(k);
    }
    idx
}

/// Cholesky factor of the weighted covariance of `theta` (with a relative jitter of 1e-12): the
/// shape of the Metropolis-Hastings proposals.
fn proposal_factor(theta: &[Vec<f64>], weights: &[f64]) -> Result<DMatrix<f64>> {
    let d = theta.first().map_or(0, Vec::len);
    let mut mean = DVector::zeros(d);
    for (t, wi) in theta.iter().zip(weights) {
        mean += DVector::from_column_slice(t) * *wi;
    }
    let mut cov = DMatrix::zeros(d, d);
    for (t, wi) in theta.iter().zip(weights) {
        let dv = DVector::from_column_slice(t) - &mean;
        cov += &dv * dv.transpose() * *wi;
    }
    let jitter = 1e-12 * (cov.trace() / d as f64).max(1e-300);
    Ok((cov + DMatrix::identity(d, d) * jitter)
        .cholesky()
        .ok_or_else(|| BayesError::Degenerate("sample covariance is not positive definite".into()))?
        .l())
}

/// Metropolis-Hastings chains on p(theta) L(theta)^beta with Gaussian proposals
/// scale x factor x N(0, I), each chain on its own (seed, stage, chain) stream.
struct Chains<'a, P, L> {
    prior: &'a P,
    likelihood: &'a L,
    factor: &'a DMatrix<f64>,
    scale: f64,
    beta: f64,
    steps: usize,
    seed: u64,
    stage: usize,
    evaluations: &'a std::sync::atomic::AtomicUsize,
    failures: &'a std::sync::atomic::AtomicUsize,
    /// Polled before every move: a cancelled stage stops its chains where they are.
    observer: &'a dyn Observer,
}

impl<P: Prior, L: LogLikelihood> Chains<'_, P, L> {
    /// `steps` moves of chain `chain` from `x` (log-likelihood `lx`): the end point, its
    /// log-likelihood and the number of accepted moves; fewer moves when the observer asks to
    /// stop (the caller then discards the stage).
    fn run(&self, chain: usize, mut x: Vec<f64>, mut lx: f64) -> (Vec<f64>, f64, usize) {
        let d = x.len();
        let mut rng = stream(self.seed, self.stage, chain);
        let mut px = self.prior.ln_pdf(&x);
        let mut accepted = 0;
        // buffers reused by every move, and the evaluations counted here and added once: the
        // shared counter's cache line is not passed between the threads at every move
        let (mut z, mut step, mut y) = (DVector::zeros(d), DVector::zeros(d), vec![0.0; d]);
        let mut evaluations = 0;
        for _ in 0..self.steps {
            if self.observer.cancelled() {
                break;
            }
            z.iter_mut()
                .for_each(|zi| *zi = StandardNormal.sample(&mut rng));
            self.factor.mul_to(&z, &mut step);
            for ((yi, xi), si) in y.iter_mut().zip(&x).zip(step.iter()) {
                *yi = xi + si * self.scale;
            }
            let py = self.prior.ln_pdf(&y);
            if !py.is_finite() {
                continue;
            }
            evaluations += 1;
            let ly = counted_ln_likelihood(self.likelihood, &y, self.failures);
            let log_ratio = py + self.beta * ly - px - self.beta * lx;
            let u: f64 = rand::Rng::random::<f64>(&mut rng);
            if log_ratio >= 0.0 || u.ln() < log_ratio {
                std::mem::swap(&mut x, &mut y);
                lx = ly;
                px = py;
                accepted += 1;
            }
        }
        self.evaluations
            .fetch_add(evaluations, std::sync::atomic::Ordering::Relaxed);
        (x, lx, accepted)
    }
}

/// More Metropolis-Hastings moves of a finished run's posterior samples (beta = 1), `rounds`
/// rounds of `steps` steps per sample, the proposal reshaped to the samples' covariance each
/// round and its scale moved towards acceptance 0.21 as iTMCMC does. With the small populations
/// that expensive likelihoods allow, the final resampling leaves many copies of few points;
/// these moves spread them over the posterior again (for a posterior predictive check, say).
/// The log-evidence is the run's; samples, their log-likelihoods, counts, and one beta = 1 and
/// acceptance entry per round are updated. Seeded by `seed` (stages numbered after the run's).
/// `observer` is polled before every move; a cancelled call returns [`BayesError::Cancelled`].
pub fn rejuvenate<P: Prior, L: LogLikelihood>(
    prior: &P,
    likelihood: &L,
    run: &TmcmcResult,
    rounds: usize,
    steps: usize,
    seed: u64,
    observer: &dyn Observer,
) -> Result<TmcmcResult> {
    let mut theta: Vec<Vec<f64>> = run.samples.samples().to_vec();
    let n = theta.len();
    let d = prior.dimension();
    let mut ln_l = run.ln_likelihoods.clone();
    let mut out = run.clone();
    let evaluations = std::sync::atomic::AtomicUsize::new(0);
    let failures = std::sync::atomic::AtomicUsize::new(0);
    let mut scale = 2.38 / (d as f64).sqrt();
    for round in 0..rounds {
        let weights = vec![1.0 / n as f64; n];
        let factor = proposal_factor(&theta, &weights)?;
        let chains = Chains {
            prior,
            likelihood,
            factor: &factor,
            scale,
            beta: 1.0,
            steps,
            seed,
            stage: run.betas.len() + round,
            evaluations: &evaluations,
            failures: &failures,
            observer,
        };
        let moved: Vec<(Vec<f64>, f64, usize)> = theta
            .par_iter()
            .zip(&ln_l)
            .enumerate()
            .map(|(chain, (x, &lx))| chains.run(chain, x.clone(), lx))
            .collect();
        chatter_progress::check(observer)?;
        let acc = moved.iter().map(|m| m.2).sum::<usize>() as f64 / (n * steps.max(1)) as f64;
        theta = moved.iter().map(|m| m.0.clone()).collect();
        ln_l = moved.iter().map(|m| m.1).collect();
        out.acceptance.push(acc);
        out.betas.push(1.0);
        scale *= ((acc - 0.21) * 2.0).exp();
    }
    out.samples = SampleSet::equally_weighted(theta)?;
    out.ln_likelihoods = ln_l;
    out.evaluations += evaluations.into_inner();
    out.numerical_failures += failures.into_inner();
    Ok(out)
}

/// Posterior probabilities of model classes from their log-evidences (equal prior
/// probabilities; 000 Eq. 32).
pub fn class_probabilities(log_evidences: &[f64]) -> Vec<f64> {
    crate::special::normalized_weights(log_evidences)
}
