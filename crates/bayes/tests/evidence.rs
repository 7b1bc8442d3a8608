//! Analytic evidence problems: log-evidence within 0.15 nats averaged over 3 seeds with
//! N = 2000, posterior moments within Monte Carlo error.
#![allow(clippy::unwrap_used)]

use chatter_bayes::prior::{IndependentPrior, Marginal};
use chatter_bayes::tmcmc::{Silent, TmcmcOptions, tmcmc};
use std::f64::consts::PI;

/// Mean over seeds 0..3 of (log-evidence - exact), with N = 2000, and the runs.
fn evidence_error<L: Fn(&[f64]) -> f64 + Sync>(
    prior: &IndependentPrior,
    like: &L,
    exact: f64,
) -> (f64, Vec<chatter_bayes::tmcmc::TmcmcResult>) {
    let runs: Vec<_> = (0..3)
        .map(|seed| {
            let opts = TmcmcOptions {
                samples: 2000,
                seed,
                ..Default::default()
            };
            tmcmc(prior, like, &opts, &Silent).unwrap()
        })
        .collect();
    let err = runs.iter().map(|r| r.log_evidence - exact).sum::<f64>() / 3.0;
    (err, runs)
}

/// Prior N(0, 1), likelihood N(5; theta, 0.2^2): evidence N(5; 0, 1.04), posterior
/// N(5/1.04, 0.04/1.04).
#[test]
fn normal_normal_evidence() {
    let prior = IndependentPrior::new(vec![Marginal::Normal { mean: 0.0, sd: 1.0 }]).unwrap();
    let like = |t: &[f64]| -0.5 * ((5.0 - t[0]) / 0.2).powi(2) - (0.2 * (2.0 * PI).sqrt()).ln();
    let exact = -0.5 * (2.0 * PI * 1.04).ln() - 25.0 / (2.0 * 1.04);
    let (err, runs) = evidence_error(&prior, &like, exact);
    for run in &runs {
        let m = run.samples.mean()[0];
        let v = run.samples.covariance()[(0, 0)];
        // MC error of the mean ~ sqrt(v / ESS); ESS of TMCMC ~ N/5 at worst
        assert!((m - 5.0 / 1.04).abs() < 0.03, "mean {m}");
        assert!((v - 0.04 / 1.04).abs() < 0.2 * 0.04 / 1.04, "variance {v}");
        assert!(run.information_gain() > 0.0);
    }
    assert!(err.abs() < 0.15, "mean log-evidence error {err}");
}

/// Conjugate Gaussian in 2 and 10 dimensions: prior N(0, I), likelihood N(y; theta, s^2 I).
#[test]
fn conjugate_gaussian_2_and_10_dimensions() {
    for d in [2usize, 10] {
        let prior =
            IndependentPrior::new(vec![Marginal::Normal { mean: 0.0, sd: 1.0 }; d]).unwrap();
        let s2: f64 = 0.25;
        let y: Vec<f64> = (0..d).map(|i| 0.5 + 0.1 * i as f64).collect();
        let yc = y.clone();
        let like = move |t: &[f64]| {
            t.iter()
                .zip(&yc)
                .map(|(a, b)| -0.5 * (a - b).powi(2) / s2 - 0.5 * (2.0 * PI * s2).ln())
                .sum::<f64>()
        };
        let exact: f64 = y
            .iter()
            .map(|b| -0.5 * (2.0 * PI * (1.0 + s2)).ln() - b * b / (2.0 * (1.0 + s2)))
            .sum();
        let (err, runs) = evidence_error(&prior, &like, exact);
        for run in &runs {
            let m = run.samples.mean();
            // posterior sd sqrt(s2 / (1 + s2)) = 0.447; with an effective sample size of N/5 the
            // Monte Carlo error of a mean is 0.022: allow 4.5 of those
            for (mi, yi) in m.iter().zip(&y) {
                assert!((mi - yi / (1.0 + s2)).abs() < 0.1, "d {d}: mean {mi}");
            }
        }
        assert!(err.abs() < 0.15, "d {d}: mean log-evidence error {err}");
    }
}

/// One-sided likelihood Phi((a - theta) / s) on a N(0, 1) prior: evidence Phi(a / sqrt(1 + s^2)).
#[test]
fn one_sided_likelihood_evidence() {
    let prior = IndependentPrior::new(vec![Marginal::Normal { mean: 0.0, sd: 1.0 }]).unwrap();
    let (a, s) = (-1.5, 0.3);
    let phi = |x: f64| 0.5 * chatter_bayes::prior::erfc(-x / std::f64::consts::SQRT_2);
    let like = move |t: &[f64]| phi((a - t[0]) / s).ln();
    let exact = phi(a / (1.0f64 + s * s).sqrt()).ln();
    let (err, _) = evidence_error(&prior, &like, exact);
    assert!(err.abs() < 0.15, "mean log-evidence error {err}");
}

/// Same seed, same result, whatever the number of threads.
#[test]
fn reproducible_across_thread_counts() {
    let prior = IndependentPrior::new(vec![
        Marginal::Uniform {
            low: -3.0,
            high: 3.0
        };
        2
    ])
    .unwrap();
    let like = |t: &[f64]| -0.5 * (t[0] * t[0] + (t[1] - 1.0).powi(2)) / 0.1;
    let opts = TmcmcOptions {
        samples: 300,
        seed: 9,
        ..Default::default()
    };
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let a = one.install(|| tmcmc(&prior, &like, &opts, &Silent).unwrap());
    let b = two.install(|| tmcmc(&prior, &like, &opts, &Silent).unwrap());
    assert_eq!(a, b);
}
