//! A lobe diagram or a multiplier grid handed an observer cancelled from the start computes
//! nothing and returns `StabilityError::Cancelled`.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples::schmitz_2023_milling;
use chatter_progress::AlreadyCancelled;
use chatter_stability::StabilityError;
use chatter_stability::boundary::{BoundaryOptions, lobe_diagram, multiplier_grid, speed_range};
use chatter_stability::monodromy::Discretization;

#[test]
fn lobes_and_grids_stop_when_cancelled() {
    let model = schmitz_2023_milling();
    // 20 000 speeds by FDM would take minutes
    let speeds = speed_range(5000.0, 20_000.0, 20_000).unwrap();
    let fdm = Discretization::full();
    let lobes = lobe_diagram(
        &fdm,
        &model,
        &speeds,
        &BoundaryOptions::default(),
        &AlreadyCancelled,
    );
    assert!(
        matches!(lobes, Err(StabilityError::Cancelled(_))),
        "{lobes:?}"
    );
    let depths: Vec<f64> = (1..=100).map(|i| f64::from(i) * 1e-5).collect();
    let grid = multiplier_grid(&fdm, &model, &speeds, &depths, &AlreadyCancelled);
    assert!(
        matches!(grid, Err(StabilityError::Cancelled(_))),
        "{grid:?}"
    );
}
