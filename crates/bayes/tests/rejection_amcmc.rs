//! Rejection sampling and the parallel adaptive MCMC of 004 Section 5 on targets with exact
//! posteriors; tolerances are multiples of the Monte Carlo standard error.
#![allow(clippy::unwrap_used)]

use chatter_bayes::amcmc::{AmcmcOptions, AmcmcResult, adaptive_mcmc};
use chatter_bayes::prior::{IndependentPrior, Marginal};
use chatter_bayes::rejection::{LikelihoodBound, rejection_sample};
use chatter_progress::Silent;
use std::f64::consts::PI;

/// Observation of the conjugate problem.
const Y: f64 = 1.2;
/// Likelihood standard deviation.
const S: f64 = 0.5;

/// Prior N(0, 1), one observation Y ~ N(theta, S^2): posterior N(Y / (1 + S^2), S^2 / (1 + S^2)),
/// evidence N(Y; 0, 1 + S^2).
fn conjugate() -> (IndependentPrior, impl Fn(&[f64]) -> f64 + Sync) {
    let prior = IndependentPrior::new(vec![Marginal::Normal { mean: 0.0, sd: 1.0 }]).unwrap();
    let like = |t: &[f64]| -0.5 * ((Y - t[0]) / S).powi(2) - (S * (2.0 * PI).sqrt()).ln();
    (prior, like)
}

const POSTERIOR_MEAN: f64 = Y / (1.0 + S * S);
const POSTERIOR_VARIANCE: f64 = S * S / (1.0 + S * S);

#[test]
fn rejection_sampling_conjugate_gaussian() {
    let (prior, like) = conjugate();
    // the likelihood is a normalized density in Y: its largest value is 1 / (S sqrt(2 pi))
    let bound = LikelihoodBound::Known(-(S * (2.0 * PI).sqrt()).ln());
    let r = rejection_sample(&prior, &like, 20_000, bound, 3, &Silent).unwrap();
    // acceptance Z / L_max = sqrt(S^2 / (1 + S^2)) exp(-Y^2 / (2 (1 + S^2))) = 0.251
    let expected_rate = (S * S / (1.0 + S * S)).sqrt() * (-Y * Y / (2.0 * (1.0 + S * S))).exp();
    let n = r.accepted.len() as f64;
    // binomial standard error of the rate: sqrt(p (1 - p) / 20000) = 0.0031
    assert!(
        (r.acceptance_rate - expected_rate).abs() < 4.0 * 0.0031,
        "rate {}",
        r.acceptance_rate
    );
    let mean = r.accepted.iter().map(|u| u[0]).sum::<f64>() / n;
    let var = r
        .accepted
        .iter()
        .map(|u| (u[0] - mean).powi(2))
        .sum::<f64>()
        / (n - 1.0);
    // independent draws: SE(mean) = sd / sqrt(n), SE(variance) = var sqrt(2 / (n - 1))
    let se_mean = (POSTERIOR_VARIANCE / n).sqrt();
    let se_var = POSTERIOR_VARIANCE * (2.0 / (n - 1.0)).sqrt();
    println!(
        "rejection: n {n}, mean {mean} (exact {POSTERIOR_MEAN}), variance {var} (exact {POSTERIOR_VARIANCE})"
    );
    assert!((mean - POSTERIOR_MEAN).abs() < 4.0 * se_mean, "mean {mean}");
    assert!(
        (var - POSTERIOR_VARIANCE).abs() < 4.0 * se_var,
        "variance {var}"
    );
    // log-evidence by prior Monte Carlo: relative SE of the mean likelihood
    // sqrt(E[L^2] / Z^2 - 1) / sqrt(N) = 0.011
    let exact = -0.5 * (2.0 * PI * (1.0 + S * S)).ln() - Y * Y / (2.0 * (1.0 + S * S));
    println!("rejection: ln Z {} (exact {exact})", r.log_mean_likelihood);
    assert!((r.log_mean_likelihood - exact).abs() < 4.0 * 0.011);
}

/// Effective sample size of the AMCMC output for the stated tolerances. With j = k = 60 the k
/// draws of a step come from one local cloud of candidates, so the integrated autocorrelation time
/// of the posterior mean, counted in unique samples, is about 7 on the 1-D target and 11.5 on the
/// 2-D one (measured from the spread of the mean over 100 seeds, whose average was within 2.2
/// standard errors of the exact mean); the tests take s / 15.
fn effective_size(run: &AmcmcResult) -> f64 {
    run.samples.samples().len() as f64 / 15.0
}

#[test]
fn amcmc_conjugate_gaussian() {
    let (prior, like) = conjugate();
    let start =
        rejection_sample(&prior, &like, 200, LikelihoodBound::Estimated, 1, &Silent).unwrap();
    for seed in 0..3 {
        let opts = AmcmcOptions {
            unique_samples: 4000,
            seed,
            ..Default::default()
        };
        let run = adaptive_mcmc(&prior, &like, &start.accepted, &opts, &Silent).unwrap();
        assert_eq!(run.samples.samples().len(), 4000);
        let mean = run.samples.mean()[0];
        let var = run.samples.covariance()[(0, 0)];
        let ess = effective_size(&run);
        let se_mean = (POSTERIOR_VARIANCE / ess).sqrt();
        let se_var = POSTERIOR_VARIANCE * (2.0 / ess).sqrt();
        println!(
            "amcmc seed {seed}: mean {mean}, variance {var}, steps {:?}, moves {:.3}",
            run.steps, run.move_rate
        );
        assert!((mean - POSTERIOR_MEAN).abs() < 4.0 * se_mean, "mean {mean}");
        assert!(
            (var - POSTERIOR_VARIANCE).abs() < 4.0 * se_var,
            "variance {var}"
        );
    }
}

/// A 2-D Gaussian target with correlation 0.9 and unequal scales under a wide uniform prior
/// (truncation below 1e-100): the posterior is N(MU, SIGMA).
#[test]
fn amcmc_correlated_gaussian_2d() {
    const MU: [f64; 2] = [1.0, -2.0];
    const SD: [f64; 2] = [1.0, 0.2];
    const RHO: f64 = 0.9;
    let prior = IndependentPrior::new(vec![
        Marginal::Uniform {
            low: -10.0,
            high: 10.0
        };
        2
    ])
    .unwrap();
    let like = |t: &[f64]| {
        let a = (t[0] - MU[0]) / SD[0];
        let b = (t[1] - MU[1]) / SD[1];
        -0.5 * (a * a - 2.0 * RHO * a * b + b * b) / (1.0 - RHO * RHO)
    };
    let start = rejection_sample(
        &prior,
        &like,
        20_000,
        LikelihoodBound::Known(0.0),
        5,
        &Silent,
    )
    .unwrap();
    assert!(
        start.accepted.len() >= 10,
        "{} survivors",
        start.accepted.len()
    );
    let opts = AmcmcOptions {
        unique_samples: 4000,
        chains: 2,
        seed: 11,
        ..Default::default()
    };
    let run = adaptive_mcmc(&prior, &like, &start.accepted, &opts, &Silent).unwrap();
    let m = run.samples.mean();
    let c = run.samples.covariance();
    let ess = effective_size(&run);
    println!(
        "amcmc 2-D: mean {m:?}, cov {:?}, moves {:.3}",
        c.as_slice(),
        run.move_rate
    );
    for q in 0..2 {
        assert!(
            (m[q] - MU[q]).abs() < 4.0 * SD[q] / ess.sqrt(),
            "mean {q}: {}",
            m[q]
        );
        let var = SD[q] * SD[q];
        assert!(
            (c[(q, q)] - var).abs() < 4.0 * var * (2.0 / ess).sqrt(),
            "var {q}"
        );
    }
    // SE of a sample correlation: (1 - rho^2) / sqrt(n)
    let r = c[(0, 1)] / (c[(0, 0)] * c[(1, 1)]).sqrt();
    assert!(
        (r - RHO).abs() < 4.0 * (1.0 - RHO * RHO) / ess.sqrt(),
        "correlation {r}"
    );
}

#[test]
fn same_seed_same_result_for_any_thread_count() {
    let (prior, like) = conjugate();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let run = |seed| {
        let r = rejection_sample(
            &prior,
            &like,
            500,
            LikelihoodBound::Estimated,
            seed,
            &Silent,
        )
        .unwrap();
        let opts = AmcmcOptions {
            unique_samples: 300,
            chains: 3,
            candidates: 20,
            draws: 10,
            seed,
            ..Default::default()
        };
        let a = adaptive_mcmc(&prior, &like, &r.accepted, &opts, &Silent).unwrap();
        (r, a)
    };
    let a = one.install(|| run(7));
    let b = two.install(|| run(7));
    assert_eq!(a, b);
    assert_ne!(a.1.samples, two.install(|| run(8)).1.samples);
}
