//! The Monte Carlo map on the prepared solvers, against the direct search it replaced and an
//! independent converged reference (issue 14).
//!
//! 1. The single-DOF benchmark (Insperger and Stepan 2004, full immersion) with 1 % / 10 % / 5 %
//!    standard deviations on the modal frequency, damping and stiffness: every sample's limiting
//!    depth by
//!    - the search the map used before (`boundary::limiting_depth` with FDM at the automatic
//!      resolution of the sample's own model),
//!    - prepared FDM on the nominal model's grid, searched from the zero-order limit (what the
//!      random-walk paths of `chatter plan` use; the first version of the map on the prepared
//!      solvers),
//!    - the map now (`sample_boundaries`: prepared FDM on the sample's own grid,
//!      Richardson-extrapolated from m and 2m steps),
//!
//!    each against a reference computed here: semi-discretization (another scheme) at 100 and
//!    200 steps per period, Richardson-extrapolated (its error falls as 1/m^2), searched to a
//!    relative tolerance of 1e-7.
//!
//! (Issue 14's 4000-sample map of the 2-DOF mill where lobes used to abort is the ignored test
//! `tests/issue_14_map.rs`.)
//!
//! Run with `cargo run --profile test -p chatter-uncertainty --example montecarlo_prepared`
//! (`-- SAMPLES` for part 1, default 60).

use chatter_dynamics::{ModalModel, examples};
use chatter_progress::Silent;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::monodromy::{Discretization, steps};
use chatter_stability::prepared::{Method, SolverOptions};
use chatter_uncertainty::montecarlo::{gaussian_draws, quantile, sample_boundaries};
use chatter_updating::parameters::{ModelParameter, Parameterization};
use chatter_updating::sampled::boundary_of;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::num::NonZeroUsize;
use std::time::Instant;

type Error = Box<dyn std::error::Error + Send + Sync>;

fn parameterization(model: &ModalModel, names: &[&str]) -> Result<Parameterization, Error> {
    let params = names
        .iter()
        .map(|s| s.parse().map(ModelParameter::Modal))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Parameterization::new(model.clone(), params)?)
}

/// SDM at 100 and 200 steps, Richardson-extrapolated (mm).
fn reference_mm(model: &ModalModel, speed_rpm: f64) -> Result<f64, Error> {
    let tight = BoundaryOptions {
        relative_tolerance: 1e-7,
        ..BoundaryOptions::default()
    };
    let at = |m: NonZeroUsize| -> Result<f64, Error> {
        let d = Discretization::semi().with_steps(m);
        Ok(limiting_depth(&d, model, speed_rpm, &tight)?.depth_mm())
    };
    let (coarse, fine) = (at(steps::<100>())?, at(steps::<200>())?);
    Ok((4.0 * fine - coarse) / 3.0)
}

fn part_1(samples: usize) -> Result<(), Error> {
    let model = examples::insperger_benchmark(1.0);
    let p = parameterization(&model, &["theta_omega_1", "theta_zeta_1", "theta_k_1"])?;
    let sigma = DMatrix::from_diagonal(&DVector::from_vec(vec![1e-4, 1e-2, 2.5e-3]));
    let thetas = gaussian_draws(&[0.0; 3], &sigma, samples, 1)?;
    let speeds = [
        6000.0, 8500.0, 10_000.0, 12_500.0, 15_000.0, 18_000.0, 21_000.0,
    ];
    let options = BoundaryOptions::default();
    let models = thetas
        .iter()
        .map(|t| p.model(t))
        .collect::<Result<Vec<_>, _>>()?;
    let clock = Instant::now();
    let before: Vec<Vec<f64>> = models
        .par_iter()
        .map(|m| {
            speeds
                .iter()
                .map(|&s| {
                    limiting_depth(&Discretization::full(), m, s, &options)
                        .map_or(f64::NAN, |p| p.depth_mm())
                })
                .collect()
        })
        .collect();
    let t_before = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    let fdm = SolverOptions {
        method: Method::Fdm,
        boundary: options,
    };
    let after = sample_boundaries(&p, &thetas, &speeds, &fdm, &Silent)?;
    let t_after = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    let nominal_grid: Vec<Vec<f64>> = models
        .par_iter()
        .map(|m| match boundary_of(&fdm, m, Some(p.nominal()), &speeds) {
            Ok(points) => points
                .iter()
                .map(|q| q.as_ref().map_or(f64::NAN, |q| q.depth_mm()))
                .collect(),
            Err(_) => vec![f64::NAN; speeds.len()],
        })
        .collect();
    let t_nominal = clock.elapsed().as_secs_f64();
    let reference: Vec<Vec<f64>> = models
        .par_iter()
        .map(|m| {
            speeds
                .iter()
                .map(|&s| reference_mm(m, s).unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    println!(
        "single-DOF benchmark, full immersion, {samples} samples; time: before {t_before:.2} s, \
         nominal grid {t_nominal:.2} s, after (own grid + Richardson) {t_after:.2} s"
    );
    println!(
        "speed_rpm,ref_q05,ref_q50,ref_q95,before_q50_err_pct,nominal_grid_q50_err_pct,\
         after_q50_err_pct,before_max_err_pct,nominal_grid_max_err_pct,after_max_err_pct"
    );
    let column = |rows: &[Vec<f64>], i: usize| -> Vec<f64> { rows.iter().map(|r| r[i]).collect() };
    let mut worst = [0.0f64; 3];
    for (i, &s) in speeds.iter().enumerate() {
        let r = column(&reference, i);
        let methods = [
            column(&before, i),
            column(&nominal_grid, i),
            column(&after.limits_mm, i),
        ];
        let q50 = quantile(r.clone(), 0.5);
        let mut line = format!(
            "{s},{:.4},{q50:.4},{:.4}",
            quantile(r.clone(), 0.05),
            quantile(r.clone(), 0.95)
        );
        for m in &methods {
            line += &format!(",{:+.3}", 100.0 * (quantile(m.clone(), 0.5) / q50 - 1.0));
        }
        for (k, m) in methods.iter().enumerate() {
            let max = m
                .iter()
                .zip(&r)
                .map(|(a, b)| (a / b - 1.0).abs())
                .fold(0.0, f64::max);
            worst[k] = worst[k].max(max);
            line += &format!(",{:.3}", 100.0 * max);
        }
        println!("{line}");
    }
    println!(
        "worst |error| over samples and speeds: before {:.3} %, nominal grid {:.3} %, after \
         (own grid + Richardson) {:.3} %",
        100.0 * worst[0],
        100.0 * worst[1],
        100.0 * worst[2]
    );
    Ok(())
}

fn main() -> Result<(), Error> {
    let samples = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(60);
    part_1(samples)
}
