//! The multivariate normal prior: its density against the closed-form bivariate normal, its
//! draws' moments within Monte Carlo error, its estimate from samples, and the samplers with it
//! on a conjugate problem with an exact posterior and evidence.
#![allow(clippy::unwrap_used)]

use chatter_bayes::prior::{MultivariateNormalPrior, Prior};
use chatter_bayes::rejection::{LikelihoodBound, rejection_sample};
use chatter_bayes::tmcmc::{TmcmcOptions, tmcmc};
use chatter_progress::Silent;
use nalgebra::{DMatrix, DVector, Matrix2, Vector2};
use rand::SeedableRng;
use std::f64::consts::PI;

/// sd 2 and 0.5, correlation -0.8.
const SD: [f64; 2] = [2.0, 0.5];
const RHO: f64 = -0.8;
const MEAN: [f64; 2] = [1.0, -3.0];

fn prior() -> MultivariateNormalPrior {
    let c = RHO * SD[0] * SD[1];
    MultivariateNormalPrior::new(
        MEAN.to_vec(),
        &[vec![SD[0] * SD[0], c], vec![c, SD[1] * SD[1]]],
    )
    .unwrap()
}

#[test]
fn density_is_the_bivariate_normal() {
    let p = prior();
    for x in [[1.0, -3.0], [0.0, 0.0], [3.5, -3.7], [-2.0, -2.0]] {
        let (z1, z2) = ((x[0] - MEAN[0]) / SD[0], (x[1] - MEAN[1]) / SD[1]);
        let q = (z1 * z1 - 2.0 * RHO * z1 * z2 + z2 * z2) / (1.0 - RHO * RHO);
        let exact = -(2.0 * PI * SD[0] * SD[1] * (1.0 - RHO * RHO).sqrt()).ln() - 0.5 * q;
        assert!((p.ln_pdf(&x) - exact).abs() < 1e-12, "{x:?}");
    }
    assert_eq!(p.ln_pdf(&[1.0]), f64::NEG_INFINITY);
    assert_eq!(p.ln_pdf(&[f64::NAN, 1.0]), f64::NEG_INFINITY);
}

#[test]
fn draws_have_the_moments_and_from_samples_recovers_them() {
    let p = prior();
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let n = 20_000;
    let draws: Vec<Vec<f64>> = (0..n).map(|_| p.sample(&mut rng)).collect();
    let est = MultivariateNormalPrior::from_samples(&draws).unwrap();
    let c = est.covariance();
    let corr = c[(0, 1)] / (c[(0, 0)] * c[(1, 1)]).sqrt();
    eprintln!(
        "from {n} draws: mean {:?}, sd {:.4} {:.4}, correlation {corr:.4}",
        est.mean(),
        c[(0, 0)].sqrt(),
        c[(1, 1)].sqrt()
    );
    // standard errors: sd / sqrt(n) for the means, var sqrt(2 / n) for the variances,
    // (1 - rho^2) / sqrt(n) for the correlation; 4 of them
    let nf = n as f64;
    for i in 0..2 {
        assert!((est.mean()[i] - MEAN[i]).abs() < 4.0 * SD[i] / nf.sqrt());
        let var = SD[i] * SD[i];
        assert!((c[(i, i)] - var).abs() < 4.0 * var * (2.0 / nf).sqrt());
    }
    assert!((corr - RHO).abs() < 4.0 * (1.0 - RHO * RHO) / nf.sqrt());
}

/// Prior N(mu_0, Sigma_0), one observation y ~ N(theta, s^2 I): posterior covariance
/// (Sigma_0^-1 + I / s^2)^-1, mean Sigma_p (Sigma_0^-1 mu_0 + y / s^2), evidence N(y; mu_0,
/// Sigma_0 + s^2 I).
#[test]
fn samplers_take_the_correlated_prior() {
    let p = prior();
    let s: f64 = 0.7;
    let y = Vector2::new(2.0, -3.5);
    let like = move |t: &[f64]| {
        -0.5 * ((t[0] - y[0]).powi(2) + (t[1] - y[1]).powi(2)) / (s * s) - (2.0 * PI * s * s).ln()
    };
    let s0 = Matrix2::new(
        SD[0] * SD[0],
        RHO * SD[0] * SD[1],
        RHO * SD[0] * SD[1],
        SD[1] * SD[1],
    );
    let mu0 = Vector2::new(MEAN[0], MEAN[1]);
    let s0_inv = s0.try_inverse().unwrap();
    let post_cov = (s0_inv + Matrix2::identity() / (s * s))
        .try_inverse()
        .unwrap();
    let post_mean = post_cov * (s0_inv * mu0 + y / (s * s));
    let total = s0 + Matrix2::identity() * (s * s);
    let r = y - mu0;
    let evidence = -(2.0 * PI).ln()
        - 0.5 * total.determinant().ln()
        - 0.5 * (r.transpose() * total.try_inverse().unwrap() * r)[(0, 0)];
    // rejection sampling: independent posterior draws
    let bound = LikelihoodBound::Known(-(2.0 * PI * s * s).ln());
    let kept = rejection_sample(&p, &like, 40_000, bound, 11, &Silent).unwrap();
    let n = kept.accepted.len() as f64;
    let mean: Vec<f64> = (0..2)
        .map(|j| kept.accepted.iter().map(|u| u[j]).sum::<f64>() / n)
        .collect();
    eprintln!(
        "rejection: {n} kept, mean {mean:?}, exact {:?}",
        post_mean.as_slice()
    );
    for j in 0..2 {
        assert!((mean[j] - post_mean[j]).abs() < 4.0 * (post_cov[(j, j)] / n).sqrt());
    }
    // TMCMC: the evidence
    let run = tmcmc(
        &p,
        &like,
        &TmcmcOptions {
            samples: 2000,
            ..Default::default()
        },
        &Silent,
    )
    .unwrap();
    let m = run.samples.mean();
    eprintln!(
        "tmcmc: log evidence {:.4}, exact {evidence:.4}; mean {m:?}",
        run.log_evidence
    );
    assert!((run.log_evidence - evidence).abs() < 0.2);
    let c: DMatrix<f64> = run.samples.covariance();
    let d = DVector::from_vec(m) - DVector::from_column_slice(post_mean.as_slice());
    // TMCMC samples are correlated: a loose 0.15 posterior sd
    for j in 0..2 {
        assert!(
            d[j].abs() < 0.15 * post_cov[(j, j)].sqrt() * 4.0,
            "{j}: {}",
            d[j]
        );
        assert!((c[(j, j)] / post_cov[(j, j)] - 1.0).abs() < 0.25);
    }
}

#[test]
fn bad_covariances_are_refused() {
    let e = |mean: Vec<f64>, cov: &[Vec<f64>]| {
        MultivariateNormalPrior::new(mean, cov)
            .unwrap_err()
            .to_string()
    };
    assert!(e(vec![], &[]).contains("no parameters"));
    assert!(e(vec![0.0, 0.0], &[vec![1.0]]).contains("expected 2 rows of 2"));
    assert!(e(vec![0.0, 0.0], &[vec![1.0, 0.5], vec![0.4, 1.0]]).contains("symmetric"));
    assert!(e(vec![0.0, 0.0], &[vec![1.0, 2.0], vec![2.0, 1.0]]).contains("not positive definite"));
    assert!(e(vec![f64::NAN, 0.0], &[vec![1.0, 0.0], vec![0.0, 1.0]]).contains("finite mean"));
    let few = MultivariateNormalPrior::from_samples(&[vec![1.0, 2.0], vec![2.0, 3.0]]).unwrap_err();
    assert!(few.to_string().contains("at least dimension + 1"), "{few}");
}
