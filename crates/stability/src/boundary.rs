//! Stability boundaries: the limiting depth per spindle speed by root finding on |mu| = 1, lobe
//! diagrams over speed ranges (parallel, thread-count independent), and |mu| grids for contours.
//!
//! At each speed the depth is raised geometrically from a small value until |mu| >= 1 (the first
//! crossing, so the lowest lobe is found even where higher lobes overlap), then the bracket is
//! refined by the Illinois variant of regula falsi on |mu| - 1 to a relative depth tolerance. The
//! chatter frequency on the boundary is the member of the multiplier's frequency family
//! f_mu + k / tau closest to the mode that dominates the cut.

use crate::StabilitySolver;
use crate::error::{Result, StabilityError, invalid};
use crate::root::{Bracket, illinois};
use chatter_dynamics::ModalModel;
use rayon::prelude::*;

/// Most Illinois steps refining a bracketed limiting depth.
const MAX_REFINEMENT_STEPS: usize = 200;

/// Options of the boundary search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryOptions {
    /// First depth tried (m).
    pub start_depth_m: f64,
    /// Largest depth searched (m); beyond it the cut counts as unconditionally stable.
    pub max_depth_m: f64,
    /// Geometric growth factor of the bracketing scan.
    pub growth: f64,
    /// Relative tolerance on the limiting depth.
    pub relative_tolerance: f64,
}

impl Default for BoundaryOptions {
    /// 0.01 mm start, 100 mm ceiling, growth 1.25, tolerance 1e-4.
    fn default() -> Self {
        Self {
            start_depth_m: 1e-5,
            max_depth_m: 0.1,
            growth: 1.25,
            relative_tolerance: 1e-4,
        }
    }
}

impl BoundaryOptions {
    /// Check the options: 0 < start < max depth, growth > 1, tolerance in (0, 0.1).
    pub fn validate(&self) -> Result<()> {
        if !(self.start_depth_m > 0.0 && self.start_depth_m < self.max_depth_m) {
            return invalid("start_depth_m", self.start_depth_m, "0 < start < max depth");
        }
        if !(self.growth > 1.0 && self.growth.is_finite()) {
            return invalid("growth", self.growth, "a factor > 1");
        }
        if !(self.relative_tolerance > 0.0 && self.relative_tolerance < 0.1) {
            return invalid("relative_tolerance", self.relative_tolerance, "in (0, 0.1)");
        }
        Ok(())
    }
}

/// One point of a stability boundary.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LobePoint {
    /// Spindle speed.
    pub speed_rpm: f64,
    /// Limiting depth (m); `f64::INFINITY` when no instability up to the search ceiling.
    pub depth_m: f64,
    /// Chatter frequency at the boundary (Hz); NaN when unbounded.
    pub chatter_hz: f64,
}

impl LobePoint {
    /// Limiting depth in mm.
    pub fn depth_mm(&self) -> f64 {
        self.depth_m * 1e3
    }
}

/// Progress of long boundary computations; no-op by default.
pub trait BoundaryObserver: Sync {
    /// Called after each speed is done with the number done and the total.
    fn speed_done(&self, _done: usize, _total: usize) {}
}

/// The observer that does nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;
impl BoundaryObserver for Silent {}

/// The natural frequency (Hz) of the mode that dominates regenerative chatter: the largest
/// negative real part of the oriented FRF over the modes' resonances.
pub fn dominant_mode_frequency_hz(model: &ModalModel) -> f64 {
    let h = model.average_directional_matrix();
    model
        .modes()
        .iter()
        .map(|m| {
            let phi = m.mass_normalized_shape();
            // oriented modal weight phi^T H phi
            let w = phi[0] * (h[(0, 0)] * phi[0] + h[(0, 1)] * phi[1])
                + phi[1] * (h[(1, 0)] * phi[0] + h[(1, 1)] * phi[1]);
            (
                m.frequency_hz(),
                w / (m.damping_ratio().max(1e-6) * m.omega_rad_s().powi(2)),
            )
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|x| x.0)
        .unwrap_or(0.0)
}

/// The limiting depth at one speed.
pub fn limiting_depth<S: StabilitySolver + ?Sized>(
    solver: &S,
    model: &ModalModel,
    speed_rpm: f64,
    options: &BoundaryOptions,
) -> Result<LobePoint> {
    options.validate()?;
    let f = |b: f64| -> Result<f64> {
        Ok(solver.dominant_multiplier(model, speed_rpm, b)?.modulus() - 1.0)
    };
    let mut lo = 0.0;
    let mut g_lo = f(0.0)?;
    if g_lo >= 0.0 {
        return Err(StabilityError::Unsupported {
            method: solver.name(),
            reason: format!(
                "|mu| >= 1 at zero depth at {speed_rpm} rpm: the structure is unstable"
            ),
        });
    }
    let mut hi = options.start_depth_m;
    let mut g_hi = f(hi)?;
    while g_hi < 0.0 {
        lo = hi;
        g_lo = g_hi;
        hi *= options.growth;
        if hi > options.max_depth_m {
            return Ok(LobePoint {
                speed_rpm,
                depth_m: f64::INFINITY,
                chatter_hz: f64::NAN,
            });
        }
        g_hi = f(hi)?;
    }
    let bracket = illinois(
        Bracket::new((lo, g_lo), (hi, g_hi)),
        options.relative_tolerance,
        MAX_REFINEMENT_STEPS,
        f,
    )?;
    let depth_m = bracket.root();
    let (_, chatter_hz) = solver.chatter_frequency_hz(model, speed_rpm, depth_m)?;
    Ok(LobePoint {
        speed_rpm,
        depth_m,
        chatter_hz,
    })
}

/// Limiting depths at many speeds, in parallel; the result does not depend on the thread count.
pub fn lobe_diagram<S: StabilitySolver + ?Sized>(
    solver: &S,
    model: &ModalModel,
    speeds_rpm: &[f64],
    options: &BoundaryOptions,
    observer: &dyn BoundaryObserver,
) -> Result<Vec<LobePoint>> {
    let done = std::sync::atomic::AtomicUsize::new(0);
    speeds_rpm
        .par_iter()
        .map(|&s| {
            let p = limiting_depth(solver, model, s, options);
            let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            observer.speed_done(k, speeds_rpm.len());
            p
        })
        .collect()
}

/// |mu| on a speed x depth grid (rows per speed), for contour plots.
pub fn multiplier_grid<S: StabilitySolver + ?Sized>(
    solver: &S,
    model: &ModalModel,
    speeds_rpm: &[f64],
    depths_m: &[f64],
) -> Result<Vec<Vec<f64>>> {
    speeds_rpm
        .par_iter()
        .map(|&s| {
            depths_m
                .iter()
                .map(|&b| Ok(solver.dominant_multiplier(model, s, b)?.modulus()))
                .collect()
        })
        .collect()
}

/// `n` evenly spaced speeds from `min_rpm` to `max_rpm` inclusive.
pub fn speed_range(min_rpm: f64, max_rpm: f64, n: usize) -> Result<Vec<f64>> {
    if !(min_rpm > 0.0 && max_rpm > min_rpm && n >= 2) {
        return Err(StabilityError::InvalidInput {
            field: "speeds",
            value: min_rpm,
            expected: "0 < min < max and at least 2 speeds",
        });
    }
    Ok((0..n)
        .map(|i| min_rpm + (max_rpm - min_rpm) * i as f64 / (n - 1) as f64)
        .collect())
}
