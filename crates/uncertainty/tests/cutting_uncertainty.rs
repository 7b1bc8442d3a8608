//! Cutting-coefficient uncertainty enters the Monte Carlo map: a K_t standard deviation alone
//! widens the band, and with K_t and K_n scaled together the limiting depth is exactly
//! b_lim(s K_t, s K_n) = b_lim(K_t, K_n) / s (the cutting force is linear in b K_t at a fixed
//! ratio), so the depth quantiles follow from the K_t quantiles analytically. The samples'
//! boundaries come from the prepared zero-order method (exact for turning), the nominal one
//! from the frequency-domain solver (an independent computation).
#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::frequency_domain::FrequencyDomain;
use chatter_stability::prepared::{Method, SolverOptions};
use chatter_uncertainty::montecarlo::{quantile, sample_boundaries};
use chatter_uncertainty::parameters::ParameterDistribution;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::path::Path;

const SD_KT_N_PER_MM2: f64 = 70.0;

/// The prepared zero-order method with the default boundary search (relative tolerance 1e-4).
fn zoa() -> SolverOptions {
    SolverOptions {
        method: Method::Zoa,
        boundary: BoundaryOptions::default(),
    }
}

#[test]
fn a_kt_standard_deviation_alone_widens_the_band() {
    let model = examples::ahmadi_2022_turning();
    let kt = model.cutting().kt_n_per_m2() * 1e-6;
    let dist = ParameterDistribution::new(
        &["kt_n_per_mm2".to_string()],
        vec![kt],
        vec![vec![SD_KT_N_PER_MM2.powi(2)]],
        None,
        Path::new("kt.json"),
    )
    .unwrap();
    let speeds = [6900.0, 7300.0];
    let thetas = dist.draws(100, 3).unwrap();
    let sampled = sample_boundaries(
        &dist.parameterization(&model).unwrap(),
        &thetas,
        &speeds,
        &zoa(),
        &chatter_progress::Silent,
    )
    .unwrap();
    assert!(sampled.failures.is_empty());
    for b in sampled.depth_bands() {
        println!(
            "{} rpm: {:.4} / {:.4} / {:.4} mm (K_t sd {SD_KT_N_PER_MM2} of {kt} N/mm^2)",
            b.speed_rpm, b.q05, b.q50, b.q95
        );
        assert!(b.q95 - b.q05 > 0.05 * b.q50, "the band has width");
    }
}

#[test]
fn depth_quantiles_follow_the_kt_quantiles_at_a_fixed_ratio() {
    let model = examples::ahmadi_2022_turning();
    let (kt0, kn0) = (
        model.cutting().kt_n_per_m2() * 1e-6,
        model.cutting().kn_n_per_m2() * 1e-6,
    );
    // 201 samples of the common factor s = K_t / K_t0, sd 70 N/mm^2 in K_t
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let s: Vec<f64> = (0..201)
        .map(|_| {
            let z: f64 = StandardNormal.sample(&mut rng);
            1.0 + SD_KT_N_PER_MM2 / kt0 * z
        })
        .collect();
    let samples: Vec<Vec<f64>> = s.iter().map(|s| vec![kt0 * s, kn0 * s]).collect();
    let dist = ParameterDistribution::new(
        &["kt_n_per_mm2".to_string(), "kn_n_per_mm2".to_string()],
        vec![kt0, kn0],
        vec![vec![4900.0, 0.0], vec![0.0, 100.0]],
        Some(samples),
        Path::new("posterior.csv"),
    )
    .unwrap();
    let speeds = [6900.0, 7300.0];
    let options = BoundaryOptions::default();
    let sampled = sample_boundaries(
        &dist.parameterization(&model).unwrap(),
        &dist.draws(201, 0).unwrap(),
        &speeds,
        &zoa(),
        &chatter_progress::Silent,
    )
    .unwrap();
    for (i, band) in sampled.depth_bands().iter().enumerate() {
        let b0 = limiting_depth(&FrequencyDomain, &model, speeds[i], &options)
            .unwrap()
            .depth_mm();
        // the 5 % depth quantile is b0 over the 95 % K_t quantile (201 samples: both are
        // order statistics, no interpolation); the boundary searches' relative tolerances are
        // 1e-4, so 1e-3
        for (q, got) in [(0.05, band.q05), (0.5, band.q50), (0.95, band.q95)] {
            let expected = b0 / quantile(s.clone(), 1.0 - q);
            println!(
                "{} rpm q{q}: {got:.5} mm, analytic {expected:.5} mm",
                speeds[i]
            );
            assert!(
                (got - expected).abs() < 1e-3 * expected,
                "{got} vs {expected}"
            );
        }
    }
}
