//! Second-order perturbation moments of the seed-000 turning model against brute-force Monte
//! Carlo of the perturbed eigenvalue.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::{Parameter, examples};
use chatter_progress::Silent;
use chatter_stability::monodromy::{Discretization, steps};
use chatter_stability::sensitivity::eigenvalue_sensitivity;
use chatter_uncertainty::perturbation::{EigenSensitivity, model_moment_grid, moments};
use nalgebra::DMatrix;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// The mode-2 parameters of seed 000 Section 6.2.
fn mode2_parameters() -> Vec<Parameter> {
    ["theta_omega_2", "theta_zeta_2", "theta_phi_2"]
        .iter()
        .map(|s| s.parse().unwrap())
        .collect()
}

/// The posterior covariance of seed 000, Eq. 34.
fn eq34() -> DMatrix<f64> {
    examples::ahmadi_2022_posterior().covariance_matrix()
}

/// With a small covariance (a tenth of the seed-000 posterior, Eq. 34) the Eq. 17-18 mean and
/// standard deviation of mu match 2000 Monte Carlo samples: mean within 1e-3 absolute, standard
/// deviation within 15 % (Monte Carlo error of an sd with 2000 samples is ~1.6 %; the rest is the
/// second-order truncation). A larger covariance widens the bounds.
#[test]
fn moments_match_monte_carlo_and_widen() {
    let model = examples::ahmadi_2022_turning();
    let (params, eq34) = (mode2_parameters(), eq34());
    let sigma = &eq34 * 0.1;
    let method = Discretization::full().with_steps(steps::<60>());
    let (rpm, mm) = (7150.0, 2.0);
    let grid =
        model_moment_grid(method, &model, &params, &sigma, &[rpm], &[mm, 2.2], &Silent).unwrap();
    let m = grid.moments[0][0];
    let chol = sigma.clone().cholesky().unwrap().l();
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let samples: Vec<num_complex::Complex64> = (0..2000)
        .map(|_| {
            let z = nalgebra::DVector::from_fn(3, |_, _| StandardNormal.sample(&mut rng));
            let t = &chol * z;
            let perturbed = model.perturbed(&params, t.as_slice()).unwrap();
            let mu = method
                .monodromy(&perturbed, rpm, mm * 1e-3)
                .unwrap()
                .dominant_eigenvalue()
                .unwrap();
            if mu.im < 0.0 { mu.conj() } else { mu }
        })
        .collect();
    let mean: num_complex::Complex64 = samples.iter().sum::<num_complex::Complex64>() / 2000.0;
    let sd = (samples.iter().map(|z| (z - mean).norm_sqr()).sum::<f64>() / 1999.0).sqrt();
    assert!((mean - m.mean).norm() < 1e-3, "mean {mean} vs {}", m.mean);
    assert!((sd - m.std()).abs() < 0.15 * sd, "sd {sd} vs {}", m.std());
    let wide =
        model_moment_grid(method, &model, &params, &eq34, &[rpm], &[mm, 2.2], &Silent).unwrap();
    assert!(wide.moments[0][0].std() > m.std());
}

/// Seed 000, Section 6.4: with the posterior covariance of Eq. 34 every stable cut of Table 2
/// lies below the lower credibility bound, i.e. |E mu| + sd(mu) < 1 there, for the nominal model
/// and for the model at the posterior mean. The default (automatic) step count is used, so this
/// also guards the sensitivity against a step count that changes with theta_omega of the
/// highest mode.
#[test]
fn eq34_stable_cuts_lie_below_the_lower_bound() {
    let model = examples::ahmadi_2022_turning();
    let (params, eq34) = (mode2_parameters(), eq34());
    let updated = model
        .perturbed(&params, &examples::ahmadi_2022_posterior().mean)
        .unwrap();
    // Table 2 stable cuts (rpm, mm).
    let stable = [
        (7150.0, 2.286),
        (7150.0, 2.54),
        (6950.0, 2.54),
        (7500.0, 2.032),
        (7500.0, 2.54),
    ];
    for m in [&model, &updated] {
        for &(rpm, mm) in &stable {
            let s =
                eigenvalue_sensitivity(Discretization::full(), m, &params, rpm, mm * 1e-3).unwrap();
            let sens = EigenSensitivity {
                mu: s.mu,
                gradient: s.gradient,
                hessian: s.hessian,
            };
            let moments = moments(&sens, &eq34).unwrap();
            let upper = moments.mean_modulus() + moments.std();
            assert!(upper < 1.0, "{rpm} rpm {mm} mm: |E mu| + sd = {upper}");
        }
    }
}

/// Seed 000 Section 6.4 / Fig. 8: at the posterior mean of Eq. 34 (the updated model) with the
/// Eq. 34 covariance, the credibility bounds exist at every speed of the tested range (a depth
/// grid that covers the lobe tops), lower <= mean <= upper, and at 7300 rpm they bracket the
/// observed limit: the stable cut at 3.048 mm lies below the lower bound and the chatter cut at
/// 3.81 mm above the upper one (000 Section 6: the updated SLD predicts every tested speed).
/// Also with 95 % coverage of |mu|.
#[test]
fn updated_bounds_cover_the_range_and_bracket_the_7300_rpm_cuts() {
    use chatter_uncertainty::perturbation::BoundRule;
    let model = examples::ahmadi_2022_turning();
    let (params, eq34) = (mode2_parameters(), eq34());
    let updated = model
        .perturbed(&params, &examples::ahmadi_2022_posterior().mean)
        .unwrap();
    let speeds: Vec<f64> = (0..10).map(|i| 6800.0 + 100.0 * f64::from(i)).collect();
    let depths: Vec<f64> = (0..=80).map(|j| 1.5 + 0.05 * f64::from(j)).collect();
    let grid = model_moment_grid(
        Discretization::full(),
        &updated,
        &params,
        &eq34,
        &speeds,
        &depths,
        &Silent,
    )
    .unwrap();
    for rule in [BoundRule::ComplexSd, BoundRule::coverage(0.95).unwrap()] {
        for b in grid.bounds(rule) {
            let (lo, mid, up) = (
                b.lower_mm.unwrap(),
                b.depth_mm.unwrap(),
                b.upper_mm.unwrap(),
            );
            assert!(lo <= mid && mid <= up, "{rule:?} {b:?}");
            if b.speed_rpm == 7300.0 {
                assert!(lo > 3.048 && up < 3.81, "{rule:?} {b:?}");
            }
        }
    }
}
