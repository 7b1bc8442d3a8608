//! Stratified TMCMC: the prior split into strata of known prior mass, one TMCMC run per stratum,
//! the runs pooled by the law of total probability.
//!
//! With strata S_k of prior mass P_k (sum 1) and p_k(theta) = p(theta | S_k),
//!
//! p(D) = sum_k P_k Z_k,   Z_k = integral of p(D | theta) p_k(theta),
//!
//! p(theta | D) = sum_k (P_k Z_k / p(D)) p(theta | D, S_k).
//!
//! A posterior with well separated modes along one coordinate (the frequency of an unmodelled
//! structural mode, say) defeats a single tempered population: its resampling concentrates on
//! whichever mode the early stages favour, and the population-wide proposal covariance spans
//! the gap between modes so that no chain moves within one. Splitting that coordinate's range
//! leaves each run one or few modes; a stratum without support only costs its evaluations.
//! The pooled evidence is unbiased whenever each stratum's is; its Monte Carlo error is that of
//! the dominant strata.

use crate::error::{BayesError, Result};
use crate::prior::{IndependentPrior, Marginal, Prior};
use crate::samples::SampleSet;
use crate::special::log_sum_exp;
use crate::tmcmc::{LogLikelihood, TmcmcOptions, TmcmcResult, stream, systematic_resample, tmcmc};
use chatter_progress::Observer;

/// One stratum: the prior restricted to it (normalized) and the stratum's prior mass.
#[derive(Debug, Clone, PartialEq)]
pub struct Stratum<P> {
    /// p(theta | S_k).
    pub prior: P,
    /// ln P_k.
    pub log_mass: f64,
}

/// `prior` with its uniform marginal `coordinate` cut into `count` equal slices: strata of
/// equal prior mass 1 / count.
///
/// ```
/// use chatter_bayes::prior::{IndependentPrior, Marginal};
/// use chatter_bayes::strata::uniform_strata;
/// let prior = IndependentPrior::new(vec![Marginal::Uniform { low: 0.0, high: 3.0 }])?;
/// let strata = uniform_strata(&prior, 0, 3)?;
/// assert_eq!(strata[1].prior.marginals()[0], Marginal::Uniform { low: 1.0, high: 2.0 });
/// assert!((strata[2].log_mass - (1.0f64 / 3.0).ln()).abs() < 1e-15);
/// # Ok::<(), chatter_bayes::BayesError>(())
/// ```
pub fn uniform_strata(
    prior: &IndependentPrior,
    coordinate: usize,
    count: usize,
) -> Result<Vec<Stratum<IndependentPrior>>> {
    let invalid = |message: String| BayesError::InvalidInput {
        field: "strata",
        message,
    };
    if count == 0 {
        return Err(invalid("need >= 1 stratum".into()));
    }
    let Some(&Marginal::Uniform { low, high }) = prior.marginals().get(coordinate) else {
        return Err(invalid(format!(
            "coordinate {coordinate} is not a uniform marginal of the prior"
        )));
    };
    let width = (high - low) / count as f64;
    (0..count)
        .map(|k| {
            let mut marginals = prior.marginals().to_vec();
            marginals[coordinate] = Marginal::Uniform {
                low: low + width * k as f64,
                high: if k + 1 == count {
                    high
                } else {
                    low + width * (k + 1) as f64
                },
            };
            Ok(Stratum {
                prior: IndependentPrior::new(marginals)?,
                log_mass: -(count as f64).ln(),
            })
        })
        .collect()
}

/// TMCMC in every stratum (`options.samples` samples each, the k-th run seeded by `options.seed`
/// and k), pooled: ln p(D) = ln sum_k P_k Z_k, and `options.samples` equally weighted posterior
/// samples drawn by systematic resampling of the union, a sample of stratum k weighing
/// P_k Z_k / (p(D) n_k). `betas` and `acceptance` are those of the stratum of largest posterior
/// mass; evaluations and numerical failures are summed over the strata.
///
/// ```
/// use chatter_bayes::prior::{IndependentPrior, Marginal};
/// use chatter_bayes::strata::{stratified_tmcmc, uniform_strata};
/// use chatter_bayes::tmcmc::TmcmcOptions;
/// use chatter_progress::Silent;
/// // two narrow modes at -2 and 2 on a U(-4, 4) prior: Z = 2 x N-mass / 8
/// let sd: f64 = 0.1;
/// let like = |t: &[f64]| {
///     let g = |m: f64| (-0.5 * ((t[0] - m) / sd).powi(2)).exp() / (sd * (2.0 * std::f64::consts::PI).sqrt());
///     (g(-2.0) + g(2.0)).ln()
/// };
/// let prior = IndependentPrior::new(vec![Marginal::Uniform { low: -4.0, high: 4.0 }])?;
/// let options = TmcmcOptions { samples: 400, ..Default::default() };
/// let run = stratified_tmcmc(&uniform_strata(&prior, 0, 2)?, &like, &options, &Silent)?;
/// assert!((run.log_evidence - (2.0f64 / 8.0).ln()).abs() < 0.15);
/// let right = run.samples.samples().iter().filter(|t| t[0] > 0.0).count();
/// assert!((right as f64 / 400.0 - 0.5).abs() < 0.1);
/// # Ok::<(), chatter_bayes::BayesError>(())
/// ```
pub fn stratified_tmcmc<P: Prior, L: LogLikelihood>(
    strata: &[Stratum<P>],
    likelihood: &L,
    options: &TmcmcOptions,
    observer: &dyn Observer,
) -> Result<TmcmcResult> {
    if strata.is_empty() {
        return Err(BayesError::InvalidInput {
            field: "strata",
            message: "need >= 1 stratum".into(),
        });
    }
    let mut runs = Vec::with_capacity(strata.len());
    for (k, stratum) in strata.iter().enumerate() {
        let seed = stream_seed(options.seed, k);
        let run = match tmcmc(
            &stratum.prior,
            likelihood,
            &TmcmcOptions { seed, ..*options },
            observer,
        ) {
            // a stratum where the likelihood vanishes at every prior draw holds no posterior
            // mass at this population: its evidence is taken as zero
            Err(BayesError::ZeroLikelihood) if strata.len() > 1 => None,
            other => Some(other?),
        };
        runs.push(run);
    }
    pool(strata, &runs, options.samples, options.seed)
}

/// A per-stratum seed from the run's seed.
fn stream_seed(seed: u64, k: usize) -> u64 {
    rand::Rng::random::<u64>(&mut stream(seed, usize::MAX - 1, k))
}

/// The strata's runs pooled into `n` equally weighted samples (None: a stratum without
/// posterior mass).
fn pool<P>(
    strata: &[Stratum<P>],
    runs: &[Option<TmcmcResult>],
    n: usize,
    seed: u64,
) -> Result<TmcmcResult> {
    let log_terms: Vec<f64> = strata
        .iter()
        .zip(runs)
        .map(|(s, r)| {
            r.as_ref()
                .map_or(f64::NEG_INFINITY, |r| s.log_mass + r.log_evidence)
        })
        .collect();
    let log_evidence = log_sum_exp(&log_terms);
    if !log_evidence.is_finite() {
        return Err(BayesError::ZeroLikelihood);
    }
    // the union of the strata's samples with their pooled weights
    let mut union = Vec::new();
    for (run, &t) in runs.iter().zip(&log_terms) {
        if let Some(r) = run {
            let m = r.ln_likelihoods.len() as f64;
            let w = (t - log_evidence).exp() / m;
            union.extend(
                r.samples
                    .samples()
                    .iter()
                    .zip(&r.ln_likelihoods)
                    .map(|(x, &l)| (x, l, w)),
            );
        }
    }
    let weights: Vec<f64> = union.iter().map(|u| u.2).collect();
    let idx = systematic_resample(&weights, n, &mut stream(seed, usize::MAX - 2, 0));
    let samples: Vec<Vec<f64>> = idx.iter().map(|&k| union[k].0.clone()).collect();
    let ln_likelihoods: Vec<f64> = idx.iter().map(|&k| union[k].1).collect();
    let dominant = (0..runs.len())
        .max_by(|&a, &b| log_terms[a].total_cmp(&log_terms[b]))
        .and_then(|k| runs[k].as_ref())
        .ok_or_else(|| BayesError::Degenerate("no stratum holds posterior mass".into()))?;
    let flat = runs.iter().flatten();
    Ok(TmcmcResult {
        samples: SampleSet::equally_weighted(samples)?,
        ln_likelihoods,
        log_evidence,
        betas: dominant.betas.clone(),
        acceptance: dominant.acceptance.clone(),
        evaluations: flat.clone().map(|r| r.evaluations).sum(),
        numerical_failures: flat.map(|r| r.numerical_failures).sum(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_progress::Silent;

    /// Two well separated modes of unequal mass on U(-4, 4): a 1-D mixture
    /// 0.8 N(-2, 0.05^2) + 0.2 N(2.5, 0.05^2) as the likelihood, so Z = 1/8 and the posterior
    /// mass right of 0 is 0.2 exactly (the prior is flat over both modes).
    fn bimodal(t: &[f64]) -> f64 {
        let sd: f64 = 0.05;
        let g = |m: f64| {
            (-0.5 * ((t[0] - m) / sd).powi(2)).exp() / (sd * (2.0 * std::f64::consts::PI).sqrt())
        };
        (0.8 * g(-2.0) + 0.2 * g(2.5)).ln()
    }

    #[test]
    fn pooled_evidence_and_mode_masses_match_the_exact_values() {
        let prior = IndependentPrior::new(vec![Marginal::Uniform {
            low: -4.0,
            high: 4.0,
        }])
        .unwrap();
        let options = TmcmcOptions {
            samples: 500,
            seed: 3,
            ..Default::default()
        };
        let run = stratified_tmcmc(
            &uniform_strata(&prior, 0, 4).unwrap(),
            &bimodal,
            &options,
            &Silent,
        )
        .unwrap();
        // TMCMC's evidence error at 500 samples: a few hundredths of a nat; 0.1 allowed
        assert!((run.log_evidence - (1.0f64 / 8.0).ln()).abs() < 0.1);
        let right = run.samples.samples().iter().filter(|t| t[0] > 0.0).count() as f64;
        // binomial sd of the share at n = 500: 0.018; 3 sd allowed
        assert!((right / 500.0 - 0.2).abs() < 0.055, "{right}");
        assert_eq!(run.samples.samples().len(), 500);
        // same seed, same result
        let again = stratified_tmcmc(
            &uniform_strata(&prior, 0, 4).unwrap(),
            &bimodal,
            &options,
            &Silent,
        )
        .unwrap();
        assert_eq!(run, again);
    }

    #[test]
    fn strata_need_a_uniform_coordinate() {
        let prior = IndependentPrior::new(vec![Marginal::Normal { mean: 0.0, sd: 1.0 }]).unwrap();
        assert!(uniform_strata(&prior, 0, 2).is_err());
        assert!(uniform_strata(&prior, 1, 2).is_err());
        let flat = IndependentPrior::new(vec![Marginal::Uniform {
            low: 0.0,
            high: 1.0,
        }])
        .unwrap();
        assert!(uniform_strata(&flat, 0, 0).is_err());
    }
}
