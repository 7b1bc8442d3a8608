//! Limiting depths of sampled models, for the random-walk paths of 003, the cut likelihoods of
//! 004 and `chatter plan`: thousands of boundaries per run, each from a solver prepared once per
//! sampled model ([`chatter_stability::prepared`]).
//!
//! The default solver is the first-order full discretization (Ding et al. 2010) with the model's
//! process damping as -b D(t) x' (003 Eq. 1), its boundary searched from the zero-order limit.
//! The zero-order method alone is not used by default: on 003's single-tooth flexure it is 6-11 %
//! low without process damping and 42 % low at 300 rpm with it (C = 2.5e5 N/m), and paths built
//! on it then converge to C = 3.3e5 N/m when the cuts come from the exact machine.
//!
//! Every sampled model of one parameterization gets the discretization grid of the nominal model
//! at each speed ([`PreparedDiscretization::on_grid_of`]), so that the limiting depth is a smooth
//! function of the parameters.

use crate::error::Result;
use chatter_dynamics::ModalModel;
use chatter_stability::boundary::{self, LobePoint};
use chatter_stability::prepared::{Method, PreparedDiscretization, PreparedSolver};

/// Options of the sampled boundaries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryOptions {
    /// The stability method; default [`Method::Fdm`].
    pub method: Method,
    /// Depths above this count as unconditionally stable (m); default 0.1 m.
    pub max_depth_m: f64,
    /// Relative tolerance of the limiting depth; default 1e-3 (a micrometre per millimetre,
    /// far inside the cut kernels' widths of 0.125-0.5 mm).
    pub relative_tolerance: f64,
}

impl Default for BoundaryOptions {
    fn default() -> Self {
        Self {
            method: Method::Fdm,
            max_depth_m: 0.1,
            relative_tolerance: 1e-3,
        }
    }
}

impl BoundaryOptions {
    /// The search options of `chatter-stability` with this ceiling and tolerance.
    fn search(&self) -> boundary::BoundaryOptions {
        let default = boundary::BoundaryOptions::default();
        boundary::BoundaryOptions {
            start_depth_m: default.start_depth_m.min(0.01 * self.max_depth_m),
            max_depth_m: self.max_depth_m,
            relative_tolerance: self.relative_tolerance,
            ..default
        }
    }
}

/// The method of `options` prepared for `model`, with the discretization grid of `grid` (the
/// nominal model of a parameterization).
pub fn prepare(
    model: &ModalModel,
    grid: &ModalModel,
    options: &BoundaryOptions,
) -> Result<Box<dyn PreparedSolver>> {
    let search = options.search();
    Ok(match options.method.discretization() {
        None => options.method.prepare(model, &search)?,
        Some(d) => Box::new(PreparedDiscretization::new(d, model, &search)?.on_grid_of(grid)),
    })
}

/// Limiting depths of `model` at `speeds_rpm` (in order, on the calling thread) with the grid
/// of `grid`; `depth_m` is infinite where the cut is stable up to `options.max_depth_m`.
pub fn limiting_depths(
    model: &ModalModel,
    grid: &ModalModel,
    speeds_rpm: &[f64],
    options: &BoundaryOptions,
) -> Result<Vec<LobePoint>> {
    let solver = prepare(model, grid, options)?;
    speeds_rpm
        .iter()
        .map(|&s| Ok(solver.limiting_depth(s)?))
        .collect()
}

/// The limiting depth of `model` at one speed on its own grid.
pub fn limiting_depth(
    model: &ModalModel,
    speed_rpm: f64,
    options: &BoundaryOptions,
) -> Result<LobePoint> {
    Ok(prepare(model, model, options)?.limiting_depth(speed_rpm)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::UpdatingError;
    use chatter_dynamics::examples;
    use chatter_stability::monodromy::Discretization;

    /// The paths' boundary is FDM's (checked against the scan of `chatter-stability` at the
    /// search tolerance, 1e-3 relative, twice for the two searches); one speed and several agree;
    /// errors arrive as `UpdatingError::Stability`.
    #[test]
    fn paths_use_the_full_discretization() {
        let model = examples::process_damping_flexure(Some(2.5e5));
        let options = BoundaryOptions::default();
        let speeds = [300.0, 1100.0, 2900.0];
        let all = limiting_depths(&model, &model, &speeds, &options).unwrap();
        for (speed, together) in speeds.into_iter().zip(all) {
            let one = limiting_depth(&model, speed, &options).unwrap();
            assert_eq!(one, together);
            let scanned = boundary::limiting_depth(
                &Discretization::full(),
                &model,
                speed,
                &boundary::BoundaryOptions::default(),
            )
            .unwrap();
            assert!((one.depth_m - scanned.depth_m).abs() < 2e-3 * scanned.depth_m);
        }
        assert!(matches!(
            limiting_depth(&model, -1.0, &options),
            Err(UpdatingError::Stability(_))
        ));
    }
}
