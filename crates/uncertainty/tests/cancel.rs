//! A perturbation moment grid handed an observer cancelled from the start computes no cell and
//! returns `UncertaintyError::Cancelled`.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::{Parameter, examples};
use chatter_progress::AlreadyCancelled;
use chatter_stability::boundary::speed_range;
use chatter_stability::monodromy::Discretization;
use chatter_uncertainty::UncertaintyError;
use chatter_uncertainty::perturbation::model_moment_grid;

#[test]
fn the_moment_grid_stops_when_cancelled() {
    let model = examples::ahmadi_2022_turning();
    let params: Vec<Parameter> = ["theta_omega_2", "theta_zeta_2", "theta_phi_2"]
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
    let sigma = examples::ahmadi_2022_posterior().covariance_matrix();
    // 2000 speeds x 100 depths of eigenvalue Hessians by FDM would take many minutes
    let speeds = speed_range(6000.0, 8000.0, 2000).unwrap();
    let depths: Vec<f64> = (1..=100).map(|j| 0.05 * f64::from(j)).collect();
    let grid = model_moment_grid(
        Discretization::full(),
        &model,
        &params,
        &sigma,
        &speeds,
        &depths,
        &AlreadyCancelled,
    );
    assert!(
        matches!(grid, Err(UncertaintyError::Cancelled(_))),
        "{grid:?}"
    );
}
