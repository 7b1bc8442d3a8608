//! The lobe job (`chatter lobes`, `chatter.lobes`): the limiting depth per spindle speed by the
//! chosen method, from a modal model or straight from measured FRFs (zero-order, Altintas-Budak
//! on the sampled receptance), and optionally the map of the dominant multiplier's modulus |mu|
//! over speed x depth, the quantity whose unit contour the lobes are.
//!
//! A [`LobesRequest`] holds the options in user units with their defaults; [`Lobes::new`]
//! checks them once against the dynamics (speed range, the cost guard
//! [`crate::checks::MAX_STEPS_PER_DELAY`], refused combinations) and resolves the default speeds
//! ([`default_speeds_rpm`]), so both front ends compute on the same grid.

use crate::checks;
use crate::error::{JobError, Result};
use chatter_dynamics::{ModalModel, ModelFile};
use chatter_frf::MeasuredModel;
use chatter_progress::Observer;
use chatter_stability::Method;
use chatter_stability::boundary::{BoundaryOptions, LobePoint};
use chatter_stability::prepared::{PreparedDiscretization, PreparedSolver};
use chatter_stability::speed_grid;
use chatter_stability::zero_order::{ZeroOrderOptions, measured_limiting_depths};
use rayon::prelude::*;
use std::num::NonZeroUsize;

/// Depths of the default |mu| map: from 1/80 to 1.5x the deepest finite limit, 80 rows.
pub const DEFAULT_MAP_DEPTHS: usize = 80;

/// A machine's dynamics as its model file gives them.
#[derive(Debug, Clone)]
pub enum Dynamics {
    /// Modal parameters.
    Modal(ModalModel),
    /// Measured FRFs (`measured_frf`), for the zero-order method.
    Measured(MeasuredModel),
}

/// Whether `method` runs on the measured FRFs of `file` rather than on its modes: zero-order on
/// a file with `measured_frf`. FDM and SDM need modes; on a file with FRFs only they are refused
/// (`source` names the file in the message).
pub fn uses_measured_frf(file: &ModelFile, method: Method, source: &str) -> Result<bool> {
    if file.measured_frf.is_none() {
        return Ok(false);
    }
    if method == Method::Zoa {
        return Ok(true);
    }
    if file.modes.is_empty() {
        return Err(JobError::Refused(format!(
            "{source}: `method` {} needs modal parameters, and this model gives its dynamics as \
             measured_frf only; use `method` zoa (zero-order lobes straight from the FRF), or \
             fit modes with `chatter fit-frf` and add them to the model file as its modes",
            method.name()
        )));
    }
    // a model with both: the modes serve the time-domain methods
    Ok(false)
}

/// The default speeds of a lobe diagram: for modes, evenly spaced in lobe number over the
/// dominant mode's lobes ([`speed_grid::lobe_speeds_rpm`], every lobe resolved); for measured
/// FRFs, evenly spaced around the receptance's peak ([`speed_grid::even_lobe_speeds_rpm`]).
pub fn default_speeds_rpm(dynamics: &Dynamics) -> Vec<f64> {
    match dynamics {
        Dynamics::Modal(m) => speed_grid::lobe_speeds_rpm(m),
        Dynamics::Measured(m) => speed_grid::even_lobe_speeds_rpm(
            m.receptance.peak_frequency_hz(),
            m.operation.delays_per_revolution() as f64,
        ),
    }
}

/// What the lobe job was asked, in user units; the defaults are those of `chatter lobes`.
#[derive(Debug, Clone, PartialEq)]
pub struct LobesRequest {
    /// Stability method (default FDM).
    pub method: Method,
    /// Spindle speeds (rpm); default [`default_speeds_rpm`].
    pub speeds_rpm: Option<Vec<f64>>,
    /// FDM/SDM steps over the cutting part of one delay instead of the automatic resolution.
    pub cutting_steps: Option<NonZeroUsize>,
    /// Compute the |mu| map too.
    pub map: bool,
    /// Depths of the map (mm); default [`DEFAULT_MAP_DEPTHS`] up to 1.5x the deepest limit.
    pub map_depths_mm: Option<Vec<f64>>,
}

impl Default for LobesRequest {
    fn default() -> Self {
        Self {
            method: Method::Fdm,
            speeds_rpm: None,
            cutting_steps: None,
            map: false,
            map_depths_mm: None,
        }
    }
}

/// The |mu| map over speed x depth.
#[derive(Debug, Clone, PartialEq)]
pub struct LobeMap {
    /// Speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// Depths (m).
    pub depths_m: Vec<f64>,
    /// |mu| per speed (rows) and depth.
    pub grid: Vec<Vec<f64>>,
}

/// What the lobe job computed.
#[derive(Debug, Clone)]
pub struct LobesOutcome {
    /// Limiting depth and chatter frequency per speed (infinite depth: no limit below the
    /// ceiling).
    pub lobes: Vec<LobePoint>,
    /// The |mu| map, when asked.
    pub map: Option<LobeMap>,
}

/// A checked lobe job: the request passed its checks against the dynamics.
pub struct Lobes<'a> {
    dynamics: &'a Dynamics,
    request: LobesRequest,
    speeds_rpm: Vec<f64>,
}

impl<'a> Lobes<'a> {
    /// Check `request` against `dynamics`: the speeds plausible, `cutting_steps` only with FDM
    /// or SDM, the map and `cutting_steps` only with modes, map depths only with the map and
    /// plausible, and at most [`checks::MAX_STEPS_PER_DELAY`] steps per delay.
    pub fn new(dynamics: &'a Dynamics, request: LobesRequest) -> Result<Self> {
        if let Some(s) = &request.speeds_rpm {
            checks::speeds("speeds", s)?;
        }
        checks::unused(
            request.map_depths_mm.is_some() && !request.map,
            "map_depths_mm",
            "without the |mu| map",
            "the |mu| map",
        )?;
        if let Some(d) = &request.map_depths_mm {
            checks::all_in_range("depths", d, &checks::DEPTH_GRID_MM)?;
        }
        let discretization = request.method.discretization();
        checks::unused(
            request.cutting_steps.is_some() && discretization.is_none(),
            "cutting_steps",
            "with `method` zoa",
            "fdm and sdm",
        )?;
        let speeds_rpm = request
            .speeds_rpm
            .clone()
            .unwrap_or_else(|| default_speeds_rpm(dynamics));
        match dynamics {
            Dynamics::Measured(_) => {
                if request.cutting_steps.is_some() || request.map {
                    return Err(JobError::Refused(
                        "`cutting_steps` and the |mu| map need a modal model (run chatter \
                         fit-frf)"
                            .into(),
                    ));
                }
            }
            Dynamics::Modal(model) => {
                if let Some(d) = discretization {
                    let d = request.cutting_steps.map_or(d, |m| d.with_steps(m));
                    checks::work_size(model, d, &speeds_rpm, "speeds")?;
                }
            }
        }
        Ok(Self {
            dynamics,
            request,
            speeds_rpm,
        })
    }

    /// The speeds (rpm) the job runs at (the request's or the default).
    pub fn speeds_rpm(&self) -> &[f64] {
        &self.speeds_rpm
    }

    /// The method prepared for the modal model, with `cutting_steps` when given.
    fn solver(&self, model: &ModalModel) -> Result<Box<dyn PreparedSolver>> {
        let options = BoundaryOptions::default();
        Ok(
            match (
                self.request.method.discretization(),
                self.request.cutting_steps,
            ) {
                (Some(d), Some(m)) => Box::new(PreparedDiscretization::new(
                    d.with_steps(m),
                    model,
                    &options,
                )?),
                _ => self.request.method.prepare(model, &options)?,
            },
        )
    }

    /// The limiting depths at every speed (in parallel); `observer` hears of each speed.
    pub fn lobes(&self, observer: &dyn Observer) -> Result<Vec<LobePoint>> {
        match self.dynamics {
            Dynamics::Measured(m) => Ok(measured_limiting_depths(
                &m.operation,
                m.cutting,
                &m.receptance,
                &self.speeds_rpm,
                // the depth ceiling of every method
                &ZeroOrderOptions::default(),
            )?),
            Dynamics::Modal(model) => Ok(self.solver(model)?.lobes(&self.speeds_rpm, observer)?),
        }
    }

    /// The |mu| map at the job's speeds and the request's depths (default from `lobes`), rows
    /// per speed computed in parallel; `observer` hears of each speed and may cancel. `None`
    /// when the request asks for no map.
    pub fn map(&self, lobes: &[LobePoint], observer: &dyn Observer) -> Result<Option<LobeMap>> {
        let (true, Dynamics::Modal(model)) = (self.request.map, self.dynamics) else {
            return Ok(None);
        };
        let depths_m = match &self.request.map_depths_mm {
            Some(d) => d.iter().map(|mm| mm * 1e-3).collect(),
            None => default_map_depths_m(lobes)?,
        };
        let solver = self.solver(model)?;
        let done = std::sync::atomic::AtomicUsize::new(0);
        let total = self.speeds_rpm.len();
        let grid = self
            .speeds_rpm
            .par_iter()
            .map(|&s| {
                chatter_progress::check(observer)?;
                let row = depths_m
                    .iter()
                    .map(|&b| Ok(solver.dominant_multiplier(s, b)?.modulus()))
                    .collect::<Result<Vec<f64>>>();
                observer.steps_done(
                    done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
                    total,
                );
                row
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Some(LobeMap {
            speeds_rpm: self.speeds_rpm.clone(),
            depths_m,
            grid,
        }))
    }

    /// The lobes, then the map when asked.
    pub fn run(&self, observer: &dyn Observer) -> Result<LobesOutcome> {
        let lobes = self.lobes(observer)?;
        let map = self.map(&lobes, observer)?;
        Ok(LobesOutcome { lobes, map })
    }
}

/// The default map depths (m): [`speed_grid::depth_grid`] of the deepest finite limit; an error
/// when no speed has one.
pub fn default_map_depths_m(lobes: &[LobePoint]) -> Result<Vec<f64>> {
    let deepest = speed_grid::deepest_limit_m(lobes).ok_or_else(|| {
        JobError::Refused(
            "no speed has a stability limit below the depth ceiling; give `depths` for the map"
                .into(),
        )
    })?;
    Ok(speed_grid::depth_grid(deepest, DEFAULT_MAP_DEPTHS))
}

/// The number of speeds without a limit below the depth ceiling (their depth is infinite).
pub fn unbounded_count(lobes: &[LobePoint]) -> usize {
    lobes.iter().filter(|p| !p.depth_m.is_finite()).count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    /// The request's defaults: the lobe-number speed grid (the same for every front end) and
    /// no map; the zero-order lobes over it have a finite, positive lowest limit.
    #[test]
    fn defaults_are_the_lobe_grid_without_a_map() {
        let model = examples::ahmadi_2022_turning();
        let dynamics = Dynamics::Modal(model.clone());
        let request = LobesRequest {
            method: Method::Zoa,
            ..LobesRequest::default()
        };
        let job = Lobes::new(&dynamics, request).unwrap();
        assert_eq!(job.speeds_rpm(), speed_grid::lobe_speeds_rpm(&model));
        let out = job.run(&chatter_progress::Silent).unwrap();
        assert!(out.map.is_none());
        let lowest = out
            .lobes
            .iter()
            .map(|p| p.depth_m)
            .fold(f64::INFINITY, f64::min);
        assert!(lowest.is_finite() && lowest > 0.0);
    }

    #[test]
    fn refused_combinations_name_the_fields() {
        let dynamics = Dynamics::Modal(examples::ahmadi_2022_turning());
        let e = Lobes::new(
            &dynamics,
            LobesRequest {
                method: Method::Zoa,
                cutting_steps: NonZeroUsize::new(50),
                ..LobesRequest::default()
            },
        )
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.starts_with("cutting_steps is not used with `method` zoa"),
            "{e}"
        );
        let e = Lobes::new(
            &dynamics,
            LobesRequest {
                speeds_rpm: Some(vec![100.0, 200.0]),
                ..LobesRequest::default()
            },
        )
        .err()
        .unwrap()
        .to_string();
        assert!(e.contains("at 100 rpm one delay needs"), "{e}");
    }
}
