//! Probability-of-stability maps of a real model: monotone, 1 far below and 0 far above, and
//! the 0.5 contour on the mean-parameter boundary for small symmetric uncertainty. The samples'
//! boundaries come from the prepared zero-order method (exact for turning), the mean boundary
//! from the frequency-domain solver (the closed-loop poles, an independent computation).
#![allow(clippy::unwrap_used)]

use chatter_dynamics::{Parameter, examples};
use chatter_stability::boundary::{BoundaryOptions, lobe_diagram};
use chatter_stability::frequency_domain::FrequencyDomain;
use chatter_stability::prepared::{Method, SolverOptions};
use chatter_uncertainty::montecarlo::{gaussian_draws, sample_boundaries};
use chatter_updating::parameters::{ModelParameter, Parameterization};
use nalgebra::DMatrix;

#[test]
fn map_of_the_turning_case_is_monotone_and_centred_on_the_mean_boundary() {
    let model = examples::ahmadi_2022_turning();
    let params: Vec<Parameter> = ["theta_omega_2", "theta_zeta_2"]
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
    // sd 0.2 % on the frequency and 5 % on the damping of mode 2, zero mean
    let sigma = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![4e-6, 2.5e-3]));
    let thetas = gaussian_draws(&[0.0, 0.0], &sigma, 200, 11).unwrap();
    let speeds: Vec<f64> = (0..4).map(|i| 6900.0 + 200.0 * i as f64).collect();
    let options = BoundaryOptions::default();
    let solver = FrequencyDomain;
    let parameterization = Parameterization::new(
        model.clone(),
        params.iter().map(|&p| ModelParameter::Modal(p)).collect(),
    )
    .unwrap();
    let sampled = sample_boundaries(
        &parameterization,
        &thetas,
        &speeds,
        &SolverOptions {
            method: Method::Zoa,
            boundary: options,
        },
        &chatter_progress::Silent,
    )
    .unwrap();
    let nominal = lobe_diagram(
        &solver,
        &model,
        &speeds,
        &options,
        &chatter_progress::Silent,
    )
    .unwrap();
    let depths: Vec<f64> = (0..=80).map(|j| 0.1 * j as f64).collect();
    let map = sampled.stability_map(&depths);
    let median = sampled.probability_contour(0.5);
    for (i, row) in map.p_stable.iter().enumerate() {
        assert_eq!(row[0], 1.0, "P_s at zero depth");
        assert_eq!(*row.last().unwrap(), 0.0, "P_s at 8 mm");
        assert!(row.windows(2).all(|w| w[1] <= w[0]), "monotone in depth");
        // The boundary is monotone in each theta near the mean, so its median is the boundary of
        // the median parameters up to curvature and sampling: 2 % (the sd of the limits is ~5 %,
        // the standard error of a median of 200 draws is ~0.4 %).
        let b0 = nominal[i].depth_mm();
        println!(
            "{} rpm: median {:.5} mm, nominal {b0:.5} mm, q05 {:.5}, q95 {:.5}",
            speeds[i],
            median[i].1,
            sampled.depth_bands()[i].q05,
            sampled.depth_bands()[i].q95
        );
        assert!(
            (median[i].1 - b0).abs() < 0.02 * b0,
            "{} rpm: median {} vs nominal {b0}",
            speeds[i],
            median[i].1
        );
    }
    // Same seed, same draws.
    assert_eq!(
        thetas,
        gaussian_draws(&[0.0, 0.0], &sigma, 200, 11).unwrap()
    );
}
