//! Uncertainty speed: the second-order perturbation moments (000 Eq. 15-18) on a 200 x 100
//! speed x depth grid of the single-DOF benchmark (FDM, m = 40), and a 1000-sample Monte Carlo
//! probability-of-stability map (004 Fig. 2) of the same benchmark over 50 speeds (the prepared
//! FDM at each sample's automatic resolution, extrapolated, as `chatter bands --kind
//! montecarlo`).
use chatter_dynamics::{Parameter, examples};
use chatter_progress::Silent;
use chatter_stability::boundary::{BoundaryOptions, speed_range};
use chatter_stability::monodromy::{Discretization, steps};
use chatter_stability::prepared::{Method, SolverOptions};
use chatter_uncertainty::montecarlo::{gaussian_draws, sample_boundaries};
use chatter_uncertainty::perturbation::model_moment_grid;
use chatter_updating::parameters::{ModelParameter, Parameterization};
use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::DMatrix;

fn bench(c: &mut Criterion) {
    let model = examples::insperger_benchmark(0.05);
    let fdm40 = Discretization::full().with_steps(steps::<40>());
    let params: Vec<Parameter> = ["theta_omega_1", "theta_zeta_1", "theta_k_1"]
        .iter()
        .filter_map(|s| s.parse().ok())
        .collect();
    // 1 % in frequency, 10 % in damping, 5 % in stiffness
    let sigma = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1e-4, 1e-2, 2.5e-3]));
    let speeds = speed_range(5000.0, 25_000.0, 200).unwrap_or_default();
    let depths: Vec<f64> = (1..=100).map(|j| 0.05 * f64::from(j)).collect();
    let mut group = c.benchmark_group("uncertainty");
    group.sample_size(10);
    group.bench_function("perturbation_grid_200x100_sdof_fdm_m40", |b| {
        b.iter(|| model_moment_grid(fdm40, &model, &params, &sigma, &speeds, &depths, &Silent))
    });
    let thetas = gaussian_draws(&[0.0; 3], &sigma, 1000, 1).unwrap_or_default();
    let mc_speeds = speed_range(5000.0, 25_000.0, 50).unwrap_or_default();
    let Ok(parameterization) = Parameterization::new(
        model.clone(),
        params.iter().map(|&p| ModelParameter::Modal(p)).collect(),
    ) else {
        return;
    };
    let fdm = SolverOptions {
        method: Method::Fdm,
        boundary: BoundaryOptions::default(),
    };
    group.bench_function(
        "montecarlo_map_1000_samples_50_speeds_sdof_fdm_prepared",
        |b| {
            b.iter(|| {
                sample_boundaries(
                    &parameterization,
                    &thetas,
                    &mc_speeds,
                    &fdm,
                    &chatter_progress::Silent,
                )
                .map(|s| s.stability_map(&depths))
            })
        },
    );
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
