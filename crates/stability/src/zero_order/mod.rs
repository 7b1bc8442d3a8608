//! Zero-order approximation (Altintas and Budak 1995) for multi-mode milling and, with the
//! constant K_c, the classic oriented-FRF solution for turning, with process damping (003).
//!
//! Averaging H(t) over a delay gives A_0 ([`ModalModel::average_directional_matrix`]) and the
//! characteristic equation det(I + b (1 - e^{-i w tau}) A_0 G(i w)) = 0 at the chatter frequency
//! w. With Lambda an eigenvalue of A_0 G(i w) it reads 1 + b (1 - e^{-i eps}) Lambda = 0,
//! eps = w tau. Writing 1 - e^{-i eps} = 2 sin(eps/2) e^{i (pi - eps)/2} for eps in (0, 2 pi):
//! eps = (2 arg(Lambda) - pi) mod 4 pi must fall in (0, 2 pi) (this is Re(Lambda) < 0), and then
//! b = 1 / (2 sin(eps/2) |Lambda|) = -1 / (2 Re(Lambda)) (1 + kappa^2) with kappa = Im/Re,
//! the familiar form; tau = (eps + 2 pi k) / w for lobe k = 0, 1, 2, ...
//!
//! At one speed, lobe k crosses where psi(w) = w tau - eps(w) - 2 pi k = 0, and the limiting
//! depth is the lowest crossing. [`LobeTable`] tabulates the eigenvalue branches of an
//! [`OrientedSystem`] once, finds the crossings at any delay on the table and solves the lowest
//! ones exactly (module `table`), in microseconds per speed. Process damping (003) raises the
//! damping ratios to zeta_n + b s_n with b the depth itself; [`ProcessDampedTable`] tabulates how
//! the branches change with the damping once, and at each speed solves the lobes of the branch
//! whose depth is the fixed point b = -1 / (2 Re Lambda(w; b)) at each frequency: the limit of the
//! iteration of [`crate::process_damping::process_damping_limiting_depth`] without iterating
//! (module `damped`).
//!
//! A variable-pitch cutter (Altintas, Engin & Budak 1999) replaces N (1 - e^{-i w tau}) by the
//! pitch-averaged regeneration sum_j (1 - e^{-i w tau_j}) and is searched in frequency at each
//! speed ([`variable_pitch_lobe`]).
//!
//! [`limiting_depths`] and [`zoa_lobes`] are the model-level entries; the tables serve callers
//! that hold the modes and the directional matrix themselves (the samplers of `chatter-gap`).
//!
//! ```
//! use chatter_dynamics::examples;
//! use chatter_stability::zero_order::zoa_lobes;
//! // seed 001: lobe maxima near 5660 and 11298 rpm, a minimum near 6960 rpm between them
//! let lobes = zoa_lobes(&examples::schmitz_2023_milling(), &[5660.0, 6960.0, 11298.0])?;
//! let [high, low, higher] = [0, 1, 2].map(|i| lobes[i].depth_mm());
//! assert!(low < 0.5 * high && high < higher, "{high} {low} {higher}");
//! # Ok::<(), chatter_stability::StabilityError>(())
//! ```

mod damped;
mod measured;
mod system;
mod table;
mod variable_pitch;

pub use damped::ProcessDampedTable;
pub use measured::{MeasuredLobeTable, PreparedMeasured, measured_limiting_depths};
pub use system::{ModalTerm, OrientedSystem};
pub use table::LobeTable;
pub use variable_pitch::variable_pitch_lobe;

use crate::boundary::LobePoint;
use crate::error::{Result, StabilityError, check_condition, invalid};
use crate::multiplier::DominantMultiplier;
use crate::prepared::PreparedSolver;
use crate::process_damping::damping_ratio_slopes_per_cv;
use chatter_dynamics::ModalModel;

/// One lobe at a spindle speed: where lobe k crosses it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Lobe {
    /// Its limiting depth (m).
    pub depth_m: f64,
    /// Its chatter frequency (Hz).
    pub chatter_hz: f64,
    /// k in w tau = eps + 2 pi k: the chatter frequency lies in [k / tau, (k + 1) / tau].
    pub index: usize,
}

/// Options of the zero-order limiting depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZeroOrderOptions {
    /// Depths above this count as unconditionally stable (m); default 0.1 m.
    pub max_depth_m: f64,
    /// Relative tolerance of the process-damping fixed point; default 1e-4.
    pub relative_tolerance: f64,
}

impl Default for ZeroOrderOptions {
    fn default() -> Self {
        Self {
            max_depth_m: 0.1,
            relative_tolerance: 1e-4,
        }
    }
}

impl ZeroOrderOptions {
    /// No depth ceiling, the default tolerance.
    pub fn unbounded() -> Self {
        Self {
            max_depth_m: f64::INFINITY,
            ..Self::default()
        }
    }

    pub(crate) fn validate(&self) -> Result<()> {
        if self.max_depth_m.is_nan() || self.max_depth_m <= 0.0 {
            return invalid("max_depth_m", self.max_depth_m, "a depth ceiling > 0");
        }
        if !(self.relative_tolerance > 0.0 && self.relative_tolerance < 0.1) {
            return invalid("relative_tolerance", self.relative_tolerance, "in (0, 0.1)");
        }
        Ok(())
    }
}

/// The zero-order method prepared for one model: its [`LobeTable`] and, when the model has
/// process damping, its [`ProcessDampedTable`], built once and queried at any speed.
#[derive(Debug, Clone)]
pub struct PreparedZeroOrder {
    model: ModalModel,
    tables: Tables,
    options: ZeroOrderOptions,
}

/// The tables of a prepared model.
#[derive(Debug, Clone)]
enum Tables {
    Bare(LobeTable),
    Damped(ProcessDampedTable<'static>),
    /// A variable-pitch cutter: the system and the pitches (rad), searched at each speed
    /// ([`variable_pitch_lobe`]).
    VariablePitch(OrientedSystem, Vec<f64>),
}

impl PreparedZeroOrder {
    /// Tabulate `model` (with its process damping, 003, when it has one).
    pub fn new(model: &ModalModel, options: &ZeroOrderOptions) -> Result<Self> {
        options.validate()?;
        if let Some(pitches_rad) = system::variable_pitch_of(model)? {
            return Ok(Self {
                model: model.clone(),
                tables: Tables::VariablePitch(OrientedSystem::averaged(model)?, pitches_rad),
                options: *options,
            });
        }
        let table = LobeTable::new(OrientedSystem::from_model(model)?);
        // the slopes at unit C / V, scaled by C / V at each speed
        let per_cv = damping_ratio_slopes_per_cv(model);
        let tables = if model.process_damping_n_per_m().is_some() && per_cv.iter().any(|s| *s > 0.0)
        {
            Tables::Damped(ProcessDampedTable::owning(table, &per_cv, options)?)
        } else {
            Tables::Bare(table)
        };
        Ok(Self {
            model: model.clone(),
            tables,
            options: *options,
        })
    }

    /// The model this solver was prepared for.
    pub fn model(&self) -> &ModalModel {
        &self.model
    }
}

/// The zero-order method's one query: the limiting depth; its multiplier queries are a typed
/// [`StabilityError::Unsupported`].
impl PreparedSolver for PreparedZeroOrder {
    fn name(&self) -> &'static str {
        "zoa"
    }

    fn dominant_multiplier(&self, _speed_rpm: f64, _depth_m: f64) -> Result<DominantMultiplier> {
        Err(multipliers_unsupported("zoa"))
    }

    fn chatter_frequency_hz(
        &self,
        _speed_rpm: f64,
        _depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)> {
        Err(multipliers_unsupported("zoa"))
    }

    /// The shallowest lobe at `speed_rpm`; infinite where the cut is stable up to the options'
    /// depth ceiling.
    fn limiting_depth(&self, speed_rpm: f64) -> Result<LobePoint> {
        check_condition(speed_rpm, 0.0)?;
        let tau = self.model.operation().delay_s(speed_rpm);
        let lobes = match &self.tables {
            Tables::Damped(d) => {
                d.lobes(tau, self.model.process_damping_per_width(speed_rpm), 1)?
            }
            Tables::Bare(t) => t.lobes(tau, 1)?,
            Tables::VariablePitch(system, pitches_rad) => {
                variable_pitch_lobe(system, pitches_rad, speed_rpm)
                    .into_iter()
                    .collect()
            }
        };
        Ok(LobePoint::below_ceiling(
            speed_rpm,
            lobes.first().map(|l| (l.depth_m, l.chatter_hz)),
            self.options.max_depth_m,
        ))
    }
}

/// The error of a multiplier query to a zero-order solver (`method`).
fn multipliers_unsupported(method: &'static str) -> StabilityError {
    StabilityError::Unsupported {
        method,
        reason: "the zero-order method gives limiting depths, not multipliers; use fdm or sdm"
            .into(),
    }
}

/// Zero-order limiting depths at `speeds_rpm`, with the model's process damping (003) when it
/// has one; `depth_m` is infinite where the cut is stable up to `options.max_depth_m`. One
/// [`PreparedZeroOrder`] serves every speed ([`PreparedSolver::limiting_depths`]).
pub fn limiting_depths(
    model: &ModalModel,
    speeds_rpm: &[f64],
    options: &ZeroOrderOptions,
) -> Result<Vec<LobePoint>> {
    options.validate()?;
    for &s in speeds_rpm {
        check_condition(s, 0.0)?;
    }
    PreparedZeroOrder::new(model, options)?.limiting_depths(speeds_rpm)
}

/// Zero-order limiting depths at the given speeds with the structural damping only (the
/// model's process damping is ignored; see [`limiting_depths`]), without a depth ceiling.
pub fn zoa_lobes(model: &ModalModel, speeds_rpm: &[f64]) -> Result<Vec<LobePoint>> {
    limiting_depths(
        &model.with_process_damping(None)?,
        speeds_rpm,
        &ZeroOrderOptions::unbounded(),
    )
}

/// Zero-order limiting depth at one speed, as [`zoa_lobes`].
pub fn zoa_limiting_depth(model: &ModalModel, speed_rpm: f64) -> Result<LobePoint> {
    PreparedZeroOrder::new(
        &model.with_process_damping(None)?,
        &ZeroOrderOptions::unbounded(),
    )?
    .limiting_depth(speed_rpm)
}

#[cfg(test)]
pub(crate) mod tests;
