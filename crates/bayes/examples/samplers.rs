//! The samplers of `chatter-bayes` on one small problem: two parameters observed through a smooth
//! nonlinear two-output model with noise sd 0.05 (as 002 observes a pole's frequency and damping).
//! Prints the posterior mean and standard deviations from iTMCMC with the exact model, iTMCMC
//! with a Matérn-5/2 GP surrogate of each output (002), and rejection sampling followed by the
//! parallel adaptive MCMC of 004.
//!
//! `cargo run --release -p chatter-bayes --example samplers`

use chatter_bayes::amcmc::{AmcmcOptions, adaptive_mcmc};
use chatter_bayes::gp::{GaussianProcess, GpOptions};
use chatter_bayes::prior::{IndependentPrior, Marginal};
use chatter_bayes::rejection::{LikelihoodBound, rejection_sample};
use chatter_bayes::samples::SampleSet;
use chatter_bayes::tmcmc::{TmcmcOptions, tmcmc};
use chatter_progress::Silent;

const NOISE_SD: f64 = 0.05;

fn model(t: &[f64]) -> [f64; 2] {
    [
        t[0] + 0.3 * t[1] * t[1],
        (1.5 * t[1]).sin() + 0.2 * t[0] * t[1],
    ]
}

fn report(name: &str, s: &SampleSet) {
    let (m, c) = (s.mean(), s.covariance());
    println!(
        "{name:<28} mean ({:+.4}, {:+.4})  sd ({:.4}, {:.4})",
        m[0],
        m[1],
        c[(0, 0)].sqrt(),
        c[(1, 1)].sqrt()
    );
}

fn main() -> Result<(), chatter_bayes::BayesError> {
    let prior = IndependentPrior::new(vec![
        Marginal::Uniform {
            low: -1.0,
            high: 1.0
        };
        2
    ])?;
    let observed = model(&[0.3, -0.4]);
    let ln_like = move |g: [f64; 2]| {
        -0.5 * g
            .iter()
            .zip(&observed)
            .map(|(a, b)| ((a - b) / NOISE_SD).powi(2))
            .sum::<f64>()
    };
    let exact = move |t: &[f64]| ln_like(model(t));
    let opts = TmcmcOptions {
        samples: 5000,
        seed: 1,
        ..Default::default()
    };
    let run = tmcmc(&prior, &exact, &opts, &Silent)?;
    report("iTMCMC, exact model", &run.samples);
    println!("{:<28} ln p(D) = {:.3}", "", run.log_evidence);

    let design: Vec<Vec<f64>> = (0..64)
        .map(|i| {
            vec![
                -1.0 + 2.0 * (i % 8) as f64 / 7.0,
                -1.0 + 2.0 * (i / 8) as f64 / 7.0,
            ]
        })
        .collect();
    let surrogates = (0..2)
        .map(|k| {
            let y: Vec<f64> = design.iter().map(|t| model(t)[k]).collect();
            GaussianProcess::fit(&design, &y, &GpOptions::default())
        })
        .collect::<Result<Vec<_>, _>>()?;
    let surrogate = |t: &[f64]| match (surrogates[0].predict_mean(t), surrogates[1].predict_mean(t))
    {
        (Ok(a), Ok(b)) => ln_like([a, b]),
        _ => f64::NEG_INFINITY,
    };
    let run = tmcmc(&prior, &surrogate, &opts, &Silent)?;
    report("iTMCMC, GP surrogate (64)", &run.samples);
    println!("{:<28} ln p(D) = {:.3}", "", run.log_evidence);

    let kept = rejection_sample(
        &prior,
        &exact,
        20_000,
        LikelihoodBound::Known(0.0),
        1,
        &Silent,
    )?;
    println!(
        "rejection: {} of 20000 prior samples kept, ln p(D) = {:.3} (prior Monte Carlo)",
        kept.accepted.len(),
        kept.log_mean_likelihood
    );
    let chain = adaptive_mcmc(
        &prior,
        &exact,
        &kept.accepted,
        &AmcmcOptions::default(),
        &Silent,
    )?;
    report("rejection + adaptive MCMC", &chain.samples);
    Ok(())
}
