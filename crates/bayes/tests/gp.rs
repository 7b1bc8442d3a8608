//! Gaussian-process surrogate: interpolation of smooth functions, predictive variance, and a
//! posterior computed through the surrogate against the exact one (as 002 uses the GPR).
#![allow(clippy::unwrap_used)]

use chatter_bayes::gp::{GaussianProcess, GpOptions, Kernel, MeanFunction};
use chatter_bayes::prior::{IndependentPrior, Marginal};
use chatter_bayes::tmcmc::{TmcmcOptions, tmcmc};
use chatter_progress::Silent;
use std::f64::consts::PI;

fn grid_1d(n: usize, low: f64, high: f64) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| vec![low + (high - low) * i as f64 / (n - 1) as f64])
        .collect()
}

fn grid_2d(n: usize, low: f64, high: f64) -> Vec<Vec<f64>> {
    let g = grid_1d(n, low, high);
    g.iter()
        .flat_map(|a| g.iter().map(move |b| vec![a[0], b[0]]))
        .collect()
}

#[test]
fn interpolates_sine_1d_with_variance_vanishing_at_data() {
    for (kernel, tolerance) in [(Kernel::Matern52, 3e-3), (Kernel::Matern32, 3e-2)] {
        let x = grid_1d(12, 0.0, 2.0 * PI);
        let y: Vec<f64> = x.iter().map(|v| v[0].sin()).collect();
        let opts = GpOptions {
            kernel,
            ..Default::default()
        };
        let gp = GaussianProcess::fit(&x, &y, &opts).unwrap();
        let h = gp.hyperparameters();
        // held-out points halfway between the training points
        let mut worst = 0.0f64;
        for i in 0..11 {
            let t = (i as f64 + 0.5) * 2.0 * PI / 11.0;
            worst = worst.max((gp.predict_mean(&[t]).unwrap() - t.sin()).abs());
        }
        let at_data = x
            .iter()
            .map(|v| gp.predict(v).unwrap().variance)
            .fold(0.0, f64::max);
        let between = gp.predict(&[PI / 11.0]).unwrap().variance;
        let far = gp.predict(&[4.0 * PI]).unwrap().variance;
        println!(
            "{kernel:?}: {h:?}, max held-out error {worst:.2e}, variance at data {at_data:.1e}, \
             between {between:.1e}, far {far:.2}"
        );
        assert!(worst < tolerance, "{kernel:?}: held-out error {worst}");
        assert!(
            at_data < 1e-6 * h.signal_variance,
            "variance at data {at_data}"
        );
        assert!(between > 10.0 * at_data && far > 100.0 * between);
        assert!(far > 0.5 * h.signal_variance);
    }
}

#[test]
fn interpolates_smooth_2d_function() {
    let f = |v: &[f64]| v[0].sin() * (2.0 * v[1]).cos() + 0.3 * v[0];
    let x = grid_2d(7, 0.0, PI);
    let y: Vec<f64> = x.iter().map(|v| f(v)).collect();
    let gp = GaussianProcess::fit(&x, &y, &GpOptions::default()).unwrap();
    let held_out = grid_2d(6, 0.5 * PI / 6.0, PI - 0.5 * PI / 6.0);
    let worst = held_out
        .iter()
        .map(|v| (gp.predict_mean(v).unwrap() - f(v)).abs())
        .fold(0.0, f64::max);
    println!(
        "2-D: {:?}, max held-out error {worst:.2e}",
        gp.hyperparameters()
    );
    // the function varies by about 2 over the square
    assert!(worst < 0.02, "held-out error {worst}");
    let zero_mean = GaussianProcess::fit(
        &x,
        &y,
        &GpOptions {
            mean: MeanFunction::Zero,
            ..Default::default()
        },
    )
    .unwrap();
    assert!((zero_mean.predict_mean(&[1.0, 1.0]).unwrap() - f(&[1.0, 1.0])).abs() < 0.02);
}

#[test]
fn fit_is_independent_of_thread_count() {
    let x = grid_2d(5, -1.0, 1.0);
    let y: Vec<f64> = x.iter().map(|v| (v[0] + 2.0 * v[1]).exp()).collect();
    let fit = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| GaussianProcess::fit(&x, &y, &GpOptions::default()).unwrap())
    };
    let (a, b) = (fit(1), fit(2));
    assert_eq!(a.hyperparameters(), b.hyperparameters());
    assert_eq!(
        a.predict(&[0.1, 0.2]).unwrap(),
        b.predict(&[0.1, 0.2]).unwrap()
    );
}

/// The cheap "model" whose outputs are observed: two smooth responses of two parameters, as the
/// dominant pole's frequency and damping are of the modal parameters in 002.
fn model(t: &[f64]) -> [f64; 2] {
    [
        t[0] + 0.3 * t[1] * t[1],
        (1.5 * t[1]).sin() + 0.2 * t[0] * t[1],
    ]
}

/// TMCMC through a Matérn-5/2 surrogate of each model output, trained on an 8 x 8 grid over the
/// uniform prior (002 trains on a uniform grid), against TMCMC with the exact model. Same seed for
/// both runs; the posterior means must agree within 0.2 posterior standard deviations and the
/// standard deviations within 10 %.
#[test]
fn surrogate_posterior_matches_exact_posterior() {
    const NOISE_SD: f64 = 0.05;
    let prior = IndependentPrior::new(vec![
        Marginal::Uniform {
            low: -1.0,
            high: 1.0
        };
        2
    ])
    .unwrap();
    let observed = model(&[0.3, -0.4]);
    let ln_like = move |g: [f64; 2]| {
        -0.5 * g
            .iter()
            .zip(&observed)
            .map(|(a, b)| ((a - b) / NOISE_SD).powi(2))
            .sum::<f64>()
    };
    let exact = move |t: &[f64]| ln_like(model(t));
    let design = grid_2d(8, -1.0, 1.0);
    let surrogates: Vec<GaussianProcess> = (0..2)
        .map(|k| {
            let y: Vec<f64> = design.iter().map(|t| model(t)[k]).collect();
            GaussianProcess::fit(&design, &y, &GpOptions::default()).unwrap()
        })
        .collect();
    let surrogate = |t: &[f64]| {
        let g0 = surrogates[0].predict_mean(t);
        let g1 = surrogates[1].predict_mean(t);
        match (g0, g1) {
            (Ok(a), Ok(b)) => ln_like([a, b]),
            _ => f64::NEG_INFINITY,
        }
    };
    let opts = TmcmcOptions {
        samples: 2000,
        seed: 4,
        ..Default::default()
    };
    let a = tmcmc(&prior, &exact, &opts, &Silent).unwrap();
    let b = tmcmc(&prior, &surrogate, &opts, &Silent).unwrap();
    let (ma, mb) = (a.samples.mean(), b.samples.mean());
    let (ca, cb) = (a.samples.covariance(), b.samples.covariance());
    println!(
        "exact mean {ma:?} sd {:?}; surrogate mean {mb:?} sd {:?}; ln Z {} vs {}",
        [ca[(0, 0)].sqrt(), ca[(1, 1)].sqrt()],
        [cb[(0, 0)].sqrt(), cb[(1, 1)].sqrt()],
        a.log_evidence,
        b.log_evidence
    );
    for q in 0..2 {
        let (sa, sb) = (ca[(q, q)].sqrt(), cb[(q, q)].sqrt());
        assert!(
            (ma[q] - mb[q]).abs() < 0.2 * sa,
            "mean {q}: {} vs {}",
            ma[q],
            mb[q]
        );
        assert!((sb / sa - 1.0).abs() < 0.1, "sd {q}: {sa} vs {sb}");
    }
}
