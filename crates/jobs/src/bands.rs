//! The band jobs (`chatter bands`, `chatter.bands_*`): lobes by the chosen method, Type B
//! offsets around them (001), second-order credibility bounds at the distribution's mean
//! (000 Eq. 14-18) and Monte Carlo boundaries with their quantiles and probability map (004).

use crate::error::{JobError, Result};
use chatter_dynamics::ModalModel;
use chatter_progress::Observer;
use chatter_stability::Method;
use chatter_stability::boundary::{BoundaryOptions, LobePoint};
use chatter_stability::monodromy::Discretization;
use chatter_stability::prepared::SolverOptions;
use chatter_uncertainty::geometric::{OffsetBoundaries, TypeBOffsets, type_b_offsets};
use chatter_uncertainty::montecarlo::{
    QuantileBand, SampledBoundaries, StabilityMap, sample_boundaries,
};
use chatter_uncertainty::parameters::ParameterDistribution;
use chatter_uncertainty::perturbation::{BoundRule, CredibilityPoint, model_moment_grid};

/// Depths of a default grid.
pub const DEFAULT_DEPTHS: usize = 100;

/// Limiting depth per speed by the prepared `method` (in parallel), with the model's process
/// damping (003) and the default depth ceiling, 100 mm (a "limit" of 200 m on a very stiff mode
/// is none): the zero-order lobes or the discretization's root of |mu| = 1.
pub fn lobes(
    model: &ModalModel,
    method: Method,
    speeds_rpm: &[f64],
    observer: &dyn Observer,
) -> Result<Vec<LobePoint>> {
    Ok(method
        .prepare(model, &BoundaryOptions::default())?
        .lobes(speeds_rpm, observer)?)
}

/// Type B offsets around a lobe diagram.
#[derive(Debug, Clone)]
pub struct GeometricBands {
    /// The mean boundary.
    pub lobes: Vec<LobePoint>,
    /// Offset boundaries and per-point angle and distance (001 Eq. 1-2, 10-11).
    pub bands: OffsetBoundaries,
}

/// The finite points of a lobe diagram as (rpm, mm).
pub fn finite_curve(lobes: &[LobePoint]) -> Vec<(f64, f64)> {
    lobes
        .iter()
        .filter(|p| p.depth_m.is_finite())
        .map(|p| (p.speed_rpm, p.depth_mm()))
        .collect()
}

/// Lobes by `method` and their Type B offset boundaries (001).
pub fn geometric(
    model: &ModalModel,
    method: Method,
    speeds_rpm: &[f64],
    offsets: TypeBOffsets,
    observer: &dyn Observer,
) -> Result<GeometricBands> {
    let lobes = lobes(model, method, speeds_rpm, observer)?;
    let bands = type_b_offsets(&finite_curve(&lobes), offsets)?;
    Ok(GeometricBands { lobes, bands })
}

/// The discretization of a band kind that needs one.
pub fn discretization(method: Method) -> Result<Discretization> {
    method.discretization().ok_or(JobError::Invalid {
        field: "method",
        value: "zoa".into(),
        expected: "fdm or sdm: perturbation and Monte Carlo bands need a discretization".into(),
    })
}

/// 0 to 1.5 times the deepest finite limit of `reference`, [`DEFAULT_DEPTHS`] depths (mm).
pub fn default_depths_mm(reference: &[LobePoint]) -> Result<Vec<f64>> {
    let top = reference
        .iter()
        .map(|p| p.depth_mm())
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max);
    if top <= 0.0 {
        return Err(JobError::Invalid {
            field: "depths",
            value: "(default)".into(),
            expected: "a depth grid: no finite limiting depth over these speeds".into(),
        });
    }
    Ok(chatter_stability::speed_grid::depth_grid(
        top,
        DEFAULT_DEPTHS,
    ))
}

/// Credibility bounds at the distribution's mean.
#[derive(Debug, Clone)]
pub struct PerturbationBands {
    /// The model at the distribution's mean.
    pub mean_model: ModalModel,
    /// The depth grid (mm).
    pub depths_mm: Vec<f64>,
    /// Per speed the mean boundary and the bounds (mm; None where not reached on the grid).
    pub bounds: Vec<CredibilityPoint>,
}

/// Second-order credibility bounds (000 Eq. 14-18) of the model at the distribution's mean with
/// the covariance about it, on `speeds_rpm` x `depths_mm` (default [`default_depths_mm`] of the
/// mean model's lobes) under `rule`; `observer` hears of the speeds done (of those lobes first,
/// when the depth grid is the default, then of the moment grid) and can stop both between
/// speeds or grid cells.
pub fn perturbation(
    model: &ModalModel,
    distribution: &ParameterDistribution,
    method: Method,
    rule: BoundRule,
    speeds_rpm: &[f64],
    depths_mm: Option<Vec<f64>>,
    observer: &dyn Observer,
) -> Result<PerturbationBands> {
    let discretization = discretization(method)?;
    let mean_model = distribution.mean_model(model)?;
    let depths_mm = match depths_mm {
        Some(d) => d,
        None => default_depths_mm(&lobes(&mean_model, method, speeds_rpm, observer)?)?,
    };
    let grid = model_moment_grid(
        discretization,
        &mean_model,
        &distribution.modal_parameters()?,
        &distribution.covariance_about_mean(),
        speeds_rpm,
        &depths_mm,
        observer,
    )?;
    let bounds = grid.bounds(rule);
    Ok(PerturbationBands {
        mean_model,
        depths_mm,
        bounds,
    })
}

/// Monte Carlo boundaries.
#[derive(Debug, Clone)]
pub struct MonteCarloBands {
    /// Number of parameter draws.
    pub draws: usize,
    /// Per draw and speed the limiting depth and chatter frequency, and the failures.
    pub sampled: SampledBoundaries,
    /// 5 / 50 / 95 % limiting-depth quantiles per speed (mm).
    pub depth: Vec<QuantileBand>,
    /// Chatter-frequency quantiles per speed (Hz).
    pub chatter_hz: Vec<QuantileBand>,
}

impl MonteCarloBands {
    /// The probability-of-stability map on `depths_mm` (default 0 to 1.5 times the deepest
    /// 95 % quantile).
    pub fn map(&self, depths_mm: Option<Vec<f64>>) -> Result<StabilityMap> {
        let depths = match depths_mm {
            Some(d) => d,
            None => {
                let reference: Vec<LobePoint> = self
                    .depth
                    .iter()
                    .map(|d| LobePoint {
                        speed_rpm: d.speed_rpm,
                        depth_m: d.q95 * 1e-3,
                        chatter_hz: f64::NAN,
                    })
                    .collect();
                default_depths_mm(&reference)?
            }
        };
        Ok(self.sampled.stability_map(&depths))
    }
}

/// `samples` draws of the distribution (seeded), the boundary of each at every speed by the
/// prepared discretization of `method` at each draw's automatic resolution, Richardson-
/// extrapolated and searched from the zero-order limit (004;
/// `chatter_updating::sampled::sample_boundaries`); `observer` hears of each draw.
pub fn montecarlo(
    model: &ModalModel,
    distribution: &ParameterDistribution,
    method: Method,
    samples: usize,
    seed: u64,
    speeds_rpm: &[f64],
    observer: &dyn Observer,
) -> Result<MonteCarloBands> {
    // FDM or SDM, as the perturbation bands (zero-order is refused the same way)
    discretization(method)?;
    let thetas = distribution.draws(samples, seed)?;
    let options = SolverOptions {
        method,
        boundary: BoundaryOptions::default(),
    };
    let sampled = sample_boundaries(
        &distribution.parameterization(model)?,
        &thetas,
        speeds_rpm,
        &options,
        observer,
    )?;
    let depth = sampled.depth_bands();
    let chatter_hz = sampled.chatter_frequency_bands();
    Ok(MonteCarloBands {
        draws: thetas.len(),
        sampled,
        depth,
        chatter_hz,
    })
}
