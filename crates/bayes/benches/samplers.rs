//! Sampler throughput on a cheap correlated 3-D Gaussian likelihood under a uniform prior:
//! iTMCMC with 5000 samples, rejection sampling + parallel adaptive MCMC (004 defaults
//! j = k = 60, s = 4000), and a Matérn-5/2 GP fit and prediction on 125 points.
use chatter_bayes::amcmc::{AmcmcOptions, adaptive_mcmc};
use chatter_bayes::gp::{GaussianProcess, GpOptions};
use chatter_bayes::prior::{IndependentPrior, Marginal};
use chatter_bayes::rejection::{LikelihoodBound, rejection_sample};
use chatter_bayes::tmcmc::{TmcmcOptions, tmcmc};
use chatter_progress::Silent;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

/// ln N(theta; (0.5, -0.5, 1), Sigma) up to a constant, sd (0.3, 0.2, 0.5), correlations 0.5.
fn like(t: &[f64]) -> f64 {
    let z = [(t[0] - 0.5) / 0.3, (t[1] + 0.5) / 0.2, (t[2] - 1.0) / 0.5];
    // inverse of the equicorrelation matrix with rho = 0.5: (I - rho/(1 + 2 rho) J) / (1 - rho)
    let s: f64 = z.iter().sum();
    let q: f64 = z.iter().map(|v| v * v).sum();
    -0.5 * (q - 0.25 * s * s) / 0.5
}

fn bench(c: &mut Criterion) {
    let prior = IndependentPrior::new(vec![
        Marginal::Uniform {
            low: -3.0,
            high: 3.0
        };
        3
    ])
    .expect("valid prior");
    let mut group = c.benchmark_group("samplers_3d_gaussian");
    group.sample_size(10);
    group.bench_function("itmcmc_5000", |b| {
        let opts = TmcmcOptions {
            samples: 5000,
            ..Default::default()
        };
        b.iter(|| tmcmc(&prior, &like, black_box(&opts), &Silent).expect("runs"))
    });
    group.bench_function("rejection_20000_then_amcmc_4000", |b| {
        b.iter(|| {
            let start = rejection_sample(
                &prior,
                &like,
                20_000,
                LikelihoodBound::Known(0.0),
                1,
                &Silent,
            )
            .expect("survivors");
            adaptive_mcmc(
                &prior,
                &like,
                &start.accepted,
                black_box(&AmcmcOptions::default()),
                &Silent,
            )
            .expect("runs")
        })
    });
    let design: Vec<Vec<f64>> = (0..125)
        .map(|i| {
            vec![
                (i % 5) as f64 / 4.0,
                ((i / 5) % 5) as f64 / 4.0,
                (i / 25) as f64 / 4.0,
            ]
        })
        .collect();
    let y: Vec<f64> = design.iter().map(|x| like(x)).collect();
    group.bench_function("gp_fit_125_points_3d", |b| {
        b.iter(|| {
            GaussianProcess::fit(&design, black_box(&y), &GpOptions::default()).expect("fits")
        })
    });
    let gp = GaussianProcess::fit(&design, &y, &GpOptions::default()).expect("fits");
    group.bench_function("gp_predict_mean_and_variance", |b| {
        b.iter(|| gp.predict(black_box(&[0.3, 0.6, 0.2])).expect("predicts"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
