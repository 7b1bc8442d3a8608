//! Credibility-bounded limiting depths of the seed-000 turning case (Ahmadi 2022, Section 6.4):
//! the posterior covariance of Eq. 34 propagated by the second-order perturbation of Eq. 14-18,
//! for the nominal model and the model at the posterior mean.
//!
//! Run with `cargo run --release -p chatter-uncertainty --example eq34_bounds`.

use chatter_dynamics::{Parameter, examples};
use chatter_stability::monodromy::Discretization;
use chatter_uncertainty::perturbation::model_moment_grid;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = examples::ahmadi_2022_turning();
    let params = ["theta_omega_2", "theta_zeta_2", "theta_phi_2"]
        .iter()
        .map(|s| s.parse())
        .collect::<Result<Vec<Parameter>, _>>()?;
    let posterior = examples::ahmadi_2022_posterior();
    let sigma = posterior.covariance_matrix();
    let updated = model.perturbed(&params, &posterior.mean)?;
    let depths_mm: Vec<f64> = (0..=60).map(|j| 1.0 + 0.05 * f64::from(j)).collect();
    let speeds_rpm = [6950.0, 7150.0, 7300.0, 7500.0];
    let show = |x: Option<f64>| x.map_or_else(|| "> 4".to_string(), |v| format!("{v:.3}"));
    println!("model,speed_rpm,lower_mm,depth_mm,upper_mm");
    for (name, m) in [("nominal", &model), ("updated", &updated)] {
        let grid = model_moment_grid(
            Discretization::full(),
            m,
            &params,
            &sigma,
            &speeds_rpm,
            &depths_mm,
            &chatter_progress::Silent,
        )?;
        for b in grid.bounds(chatter_uncertainty::perturbation::BoundRule::ComplexSd) {
            println!(
                "{name},{},{},{},{}",
                b.speed_rpm,
                show(b.lower_mm),
                show(b.depth_mm),
                show(b.upper_mm)
            );
        }
    }
    Ok(())
}
