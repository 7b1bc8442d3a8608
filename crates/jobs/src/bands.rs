//! The band jobs (`chatter bands`, `chatter.bands_*`): lobes by the chosen method, Type B
//! offsets around them (001), second-order credibility bounds at the distribution's mean
//! (000 Eq. 14-18) and Monte Carlo boundaries with their quantiles and probability map (004).

use crate::checks;
use crate::error::{JobError, Result};
use crate::lobes::Dynamics;
use chatter_dynamics::ModalModel;
use chatter_dynamics::limits::{Plausible, closed, written};
use chatter_frf::MeasuredModel;
use chatter_progress::Observer;
use chatter_stability::Method;
use chatter_stability::boundary::{BoundaryOptions, LobePoint};
use chatter_stability::monodromy::Discretization;
use chatter_stability::prepared::SolverOptions;
use chatter_stability::zero_order::{ZeroOrderOptions, measured_limiting_depths};
use chatter_uncertainty::geometric::{OffsetBoundaries, TypeBOffsets, type_b_offsets};
use chatter_uncertainty::measured::{FrfUncertainty, frf_ensemble, measured_type_b_bands};
use chatter_uncertainty::montecarlo::{
    FailureKind, QuantileBand, SampledBoundaries, StabilityMap, sample_boundaries,
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
    let bands = offsets_around(&lobes, offsets)?;
    Ok(GeometricBands { lobes, bands })
}

/// Type B offsets around the finite points of `lobes`; an error that counts the speeds without
/// a limit when fewer than two have one.
fn offsets_around(lobes: &[LobePoint], offsets: TypeBOffsets) -> Result<OffsetBoundaries> {
    let curve = finite_curve(lobes);
    if curve.len() < 2 {
        return Err(JobError::Refused(format!(
            "{} of {} speeds have no stability limit below the depth ceiling of {} mm; they are \
             left out of the bands, and the offsets need at least 2 speeds with a limit",
            crate::lobes::unbounded_count(lobes),
            lobes.len(),
            BoundaryOptions::default().max_depth_m * 1e3
        )));
    }
    Ok(type_b_offsets(&curve, offsets)?)
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
    let Some(deepest_m) = chatter_stability::speed_grid::deepest_limit_m(reference) else {
        return Err(JobError::Invalid {
            field: "depths",
            value: "(default)".into(),
            expected: "a depth grid: no finite limiting depth over these speeds".into(),
        });
    };
    Ok(chatter_stability::speed_grid::depth_grid(
        deepest_m * 1e3,
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

/// Default Type B speed offset (seed 001 Sec. 4).
pub const OFFSET_RPM: f64 = 100.0;
/// Default Type B depth offset (seed 001 Sec. 4).
pub const OFFSET_MM: f64 = 0.2;
/// Default Monte Carlo draws.
pub const MONTECARLO_SAMPLES: usize = 500;
/// Default FRF draws of a measured-FRF ensemble.
pub const FRF_SAMPLES: usize = 40;
/// Most draws of either.
pub const MAX_SAMPLES: usize = 100_000;
/// Coverage factor k of the FRF-ensemble offsets (o = k sd; about 95 % of a normal spread).
pub const FRF_COVERAGE_FACTOR: f64 = 2.0;
/// Speed offset range of the Type B bands.
pub const OFFSET_RPM_RANGE: Plausible = closed(0.0, 1e5, "a speed offset", "rpm");
/// Depth offset range of the Type B bands.
pub const OFFSET_MM_RANGE: Plausible = closed(0.0, 100.0, "a depth offset", "mm");

/// Band kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BandKind {
    /// Type B offset boundaries from stated speed and depth offsets (001), or from an FRF
    /// uncertainty on measured FRFs.
    Geometric,
    /// Credibility bounds from a parameter covariance by second-order perturbation of the
    /// dominant multiplier (000 Eq. 14-18).
    Perturbation,
    /// Probability of stability from sampled parameters (004).
    MonteCarlo,
}

impl BandKind {
    /// The kind's name as users type it.
    pub fn name(self) -> &'static str {
        match self {
            BandKind::Geometric => "geometric",
            BandKind::Perturbation => "perturbation",
            BandKind::MonteCarlo => "montecarlo",
        }
    }
}

/// What the band job was asked, in user units; `None` fields take the documented defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct BandsRequest {
    /// The band kind.
    pub kind: BandKind,
    /// Stability method; default zero-order for geometric bands, FDM otherwise.
    pub method: Option<Method>,
    /// Spindle speeds (rpm); default [`crate::lobes::default_speeds_rpm`].
    pub speeds_rpm: Option<Vec<f64>>,
    /// Depths (mm) of the perturbation grid or of the Monte Carlo map; default
    /// [`default_depths_mm`].
    pub depths_mm: Option<Vec<f64>>,
    /// Type B speed offset (rpm); default [`OFFSET_RPM`].
    pub offset_rpm: Option<f64>,
    /// Type B depth offset (mm); default [`OFFSET_MM`].
    pub offset_mm: Option<f64>,
    /// Relative gain standard deviation of a measured FRF (geometric bands on measured FRFs:
    /// offsets from the FRF ensemble).
    pub gain_sd: Option<f64>,
    /// Relative frequency-axis standard deviation of a measured FRF.
    pub frequency_sd: Option<f64>,
    /// Draws: Monte Carlo ([`MONTECARLO_SAMPLES`]) or FRF ensemble ([`FRF_SAMPLES`]).
    pub samples: Option<usize>,
    /// Seed of the draws (default 0).
    pub seed: Option<u64>,
    /// Perturbation bounds of this central credibility of |mu| (None: the mean modulus +- one
    /// standard deviation of the complex multiplier).
    pub coverage: Option<f64>,
    /// The Monte Carlo probability-of-stability map too.
    pub map: bool,
}

impl BandsRequest {
    /// A request of `kind` with every default.
    pub fn new(kind: BandKind) -> Self {
        Self {
            kind,
            method: None,
            speeds_rpm: None,
            depths_mm: None,
            offset_rpm: None,
            offset_mm: None,
            gain_sd: None,
            frequency_sd: None,
            samples: None,
            seed: None,
            coverage: None,
            map: false,
        }
    }

    /// Whether the offsets come from an FRF ensemble (`gain_sd` or `frequency_sd` given).
    pub fn frf_draws(&self) -> bool {
        self.gain_sd.is_some() || self.frequency_sd.is_some()
    }

    /// The method: the request's, else zero-order for geometric bands and FDM otherwise.
    pub fn method(&self) -> Method {
        self.method.unwrap_or(match self.kind {
            BandKind::Geometric => Method::Zoa,
            _ => Method::Fdm,
        })
    }

    /// The checks that need no data (linfa's `ParamGuard::check_ref`): the options the kind
    /// uses are in range and those it ignores are absent. [`Bands::new`] runs them too; a front
    /// end may run them first, before it reads the model and the distribution.
    pub fn check(&self) -> Result<()> {
        let context = format!("with `kind` {}", self.kind.name());
        let geometric = self.kind == BandKind::Geometric;
        let montecarlo = self.kind == BandKind::MonteCarlo;
        for (given, field) in [
            (self.offset_rpm.is_some(), "offset_rpm"),
            (self.offset_mm.is_some(), "offset_mm"),
            (self.gain_sd.is_some(), "gain_sd"),
            (self.frequency_sd.is_some(), "frequency_sd"),
        ] {
            checks::unused(given && !geometric, field, &context, "`kind` geometric")?;
        }
        if self.frf_draws() && (self.offset_rpm.is_some() || self.offset_mm.is_some()) {
            return Err(JobError::Refused(
                "`offset_rpm`/`offset_mm` and `gain_sd`/`frequency_sd` both given: the offsets \
                 are either stated or set by the FRF uncertainty; give one of the two"
                    .into(),
            ));
        }
        for (given, field) in [
            (self.samples.is_some(), "samples"),
            (self.seed.is_some(), "seed"),
        ] {
            checks::unused(
                given && !montecarlo && !self.frf_draws(),
                field,
                &context,
                "`kind` montecarlo and the FRF draws of `gain_sd`/`frequency_sd`",
            )?;
        }
        checks::unused(
            self.map && !montecarlo,
            "map_out",
            &context,
            "`kind` montecarlo",
        )?;
        checks::unused(
            self.depths_mm.is_some() && (geometric || (montecarlo && !self.map)),
            "depths",
            &if montecarlo {
                format!("{context} without `map_out`")
            } else {
                context.clone()
            },
            "the perturbation grid and the Monte Carlo map (`map_out`)",
        )?;
        if let Some(v) = self.offset_rpm {
            checks::in_range("offset_rpm", v, &OFFSET_RPM_RANGE)?;
        }
        if let Some(v) = self.offset_mm {
            checks::in_range("offset_mm", v, &OFFSET_MM_RANGE)?;
        }
        if let Some(n) = self.samples {
            crate::error::count("samples", n, 2, MAX_SAMPLES, "Monte Carlo samples")?;
        }
        if let Some(d) = &self.depths_mm {
            checks::all_in_range("depths", d, &checks::DEPTH_GRID_MM)?;
        }
        if let Some(s) = &self.speeds_rpm {
            checks::speeds("speeds", s)?;
        }
        Ok(())
    }

    /// The bound rule of perturbation bands.
    fn rule(&self) -> Result<BoundRule> {
        match self.coverage {
            Some(c) => BoundRule::coverage(c).map_err(|e| JobError::Invalid {
                field: "coverage",
                value: written(c),
                expected: e.to_string(),
            }),
            None => Ok(BoundRule::ComplexSd),
        }
    }
}

/// The FRF uncertainty behind ensemble offsets (001 offsets from measured-FRF draws).
#[derive(Debug, Clone, PartialEq)]
pub struct FrfOffsets {
    /// Relative gain standard deviation.
    pub gain_sd: f64,
    /// Relative frequency-axis standard deviation.
    pub frequency_sd: f64,
    /// FRF draws.
    pub draws: usize,
    /// Coverage factor k.
    pub coverage_factor: f64,
    /// The offsets k sd of the pocket's speed and depth.
    pub offsets: TypeBOffsets,
    /// The nominal pocket (rpm, mm).
    pub pocket: (f64, f64),
}

/// What the band job computed.
#[derive(Debug, Clone)]
pub enum BandsOutcome {
    /// Type B offsets around the lobes.
    Geometric {
        /// The lobes (every speed).
        lobes: Vec<LobePoint>,
        /// The offset boundaries around their finite points.
        bands: OffsetBoundaries,
        /// The FRF uncertainty that set the offsets, when it did.
        frf: Option<FrfOffsets>,
    },
    /// Credibility bounds.
    Perturbation {
        /// The bound rule.
        rule: BoundRule,
        /// The bounds.
        bands: PerturbationBands,
    },
    /// Monte Carlo boundaries.
    MonteCarlo {
        /// The boundaries and their quantiles.
        bands: MonteCarloBands,
        /// The probability-of-stability map, when asked.
        map: Option<StabilityMap>,
    },
}

/// A checked band job.
pub struct Bands<'a> {
    dynamics: &'a Dynamics,
    distribution: Option<&'a ParameterDistribution>,
    request: BandsRequest,
    speeds_rpm: Vec<f64>,
}

impl<'a> Bands<'a> {
    /// Check `request` against the dynamics and the parameter distribution (perturbation and
    /// Monte Carlo bands need one and a discretization; FRF draws need measured FRFs; the speed
    /// offset at most the speed range; at most [`checks::MAX_STEPS_PER_DELAY`] steps per delay).
    pub fn new(
        dynamics: &'a Dynamics,
        distribution: Option<&'a ParameterDistribution>,
        request: BandsRequest,
    ) -> Result<Self> {
        request.check()?;
        let geometric = request.kind == BandKind::Geometric;
        if !geometric {
            request.rule()?;
            if distribution.is_none() {
                return Err(JobError::Missing {
                    what: "a parameter distribution",
                    needed_by: format!("`kind` {}", request.kind.name()),
                });
            }
            if request.method().discretization().is_none() {
                return Err(JobError::Refused(format!(
                    "`kind` {} needs `method` fdm or sdm",
                    request.kind.name()
                )));
            }
        }
        let model = match dynamics {
            Dynamics::Modal(m) => Some(m),
            Dynamics::Measured(_) if geometric && request.method() == Method::Zoa => None,
            Dynamics::Measured(_) => {
                return Err(JobError::Refused(
                    "measured FRFs give zero-order geometric bands only; fit modes for the \
                     other kinds and methods"
                        .into(),
                ));
            }
        };
        if model.is_some() && request.frf_draws() {
            return Err(JobError::Refused(
                "`gain_sd`/`frequency_sd`: the model has no measured_frf; the FRF uncertainty \
                 applies to zero-order geometric bands of a model with measured_frf"
                    .into(),
            ));
        }
        let speeds_rpm = request
            .speeds_rpm
            .clone()
            .unwrap_or_else(|| crate::lobes::default_speeds_rpm(dynamics));
        if let Some(offset) = request.offset_rpm
            && model.is_some()
        {
            let span = speeds_rpm.last().unwrap_or(&0.0) - speeds_rpm.first().unwrap_or(&0.0);
            if offset > span {
                return Err(JobError::Invalid {
                    field: "offset_rpm",
                    value: written(offset),
                    expected: format!(
                        "an offset within the speeds of the lobes: larger than the speed range \
                         ({} rpm)",
                        written(span)
                    ),
                });
            }
        }
        if let (Some(d), Some(model)) = (request.method().discretization(), model)
            && (!geometric || request.method.is_some())
        {
            checks::work_size(model, d, &speeds_rpm, "speeds")?;
        }
        Ok(Self {
            dynamics,
            distribution,
            request,
            speeds_rpm,
        })
    }

    /// The speeds (rpm) the job runs at.
    pub fn speeds_rpm(&self) -> &[f64] {
        &self.speeds_rpm
    }

    /// The draws of a Monte Carlo job.
    pub fn samples(&self) -> usize {
        self.request.samples.unwrap_or(MONTECARLO_SAMPLES)
    }

    /// The checked request.
    pub fn request(&self) -> &BandsRequest {
        &self.request
    }

    /// Run: `observer` hears of the speeds (geometric, perturbation) or the draws (Monte Carlo).
    pub fn run(&self, observer: &dyn Observer) -> Result<BandsOutcome> {
        let r = &self.request;
        let speeds = &self.speeds_rpm[..];
        let seed = r.seed.unwrap_or(0);
        let method = r.method();
        match (r.kind, self.dynamics, self.distribution) {
            (BandKind::Geometric, Dynamics::Measured(m), _) => measured_geometric(m, r, speeds),
            (BandKind::Geometric, Dynamics::Modal(model), _) => {
                let offsets = TypeBOffsets::new(
                    r.offset_rpm.unwrap_or(OFFSET_RPM),
                    r.offset_mm.unwrap_or(OFFSET_MM),
                )?;
                let g = geometric(model, method, speeds, offsets, observer)?;
                Ok(BandsOutcome::Geometric {
                    lobes: g.lobes,
                    bands: g.bands,
                    frf: None,
                })
            }
            (BandKind::Perturbation, Dynamics::Modal(model), Some(dist)) => {
                let rule = r.rule()?;
                let bands = perturbation(
                    model,
                    dist,
                    method,
                    rule,
                    speeds,
                    r.depths_mm.clone(),
                    observer,
                )?;
                Ok(BandsOutcome::Perturbation { rule, bands })
            }
            (BandKind::MonteCarlo, Dynamics::Modal(model), Some(dist)) => {
                let bands =
                    montecarlo(model, dist, method, self.samples(), seed, speeds, observer)?;
                let map = if r.map {
                    Some(bands.map(r.depths_mm.clone())?)
                } else {
                    None
                };
                Ok(BandsOutcome::MonteCarlo { bands, map })
            }
            (kind, _, _) => Err(JobError::Refused(format!(
                "`kind` {} needs a modal model and a parameter distribution",
                kind.name()
            ))),
        }
    }
}

/// Geometric bands straight from measured FRFs: stated offsets around the zero-order lobes, or
/// offsets k sd of the pocket over an ensemble of perturbed FRFs
/// ([`chatter_uncertainty::measured`]).
fn measured_geometric(
    model: &MeasuredModel,
    r: &BandsRequest,
    speeds_rpm: &[f64],
) -> Result<BandsOutcome> {
    if !r.frf_draws() {
        let lobes = measured_limiting_depths(
            &model.operation,
            model.cutting,
            &model.receptance,
            speeds_rpm,
            &ZeroOrderOptions::default(),
        )?;
        let offsets = TypeBOffsets::new(
            r.offset_rpm.unwrap_or(OFFSET_RPM),
            r.offset_mm.unwrap_or(OFFSET_MM),
        )?;
        let bands = offsets_around(&lobes, offsets)?;
        return Ok(BandsOutcome::Geometric {
            lobes,
            bands,
            frf: None,
        });
    }
    let (gain_sd, frequency_sd) = (r.gain_sd.unwrap_or(0.0), r.frequency_sd.unwrap_or(0.0));
    let uncertainty = FrfUncertainty::new(gain_sd, frequency_sd)?;
    let draws = r.samples.unwrap_or(FRF_SAMPLES);
    let members = frf_ensemble(&model.receptance, uncertainty, draws, r.seed.unwrap_or(0))?;
    let b = measured_type_b_bands(
        &model.operation,
        model.cutting,
        &model.receptance,
        &members,
        speeds_rpm,
        FRF_COVERAGE_FACTOR,
    )?;
    Ok(BandsOutcome::Geometric {
        lobes: b.lobes,
        bands: b.bands,
        frf: Some(FrfOffsets {
            gain_sd,
            frequency_sd,
            draws,
            coverage_factor: FRF_COVERAGE_FACTOR,
            offsets: b.offsets,
            pocket: b.pocket,
        }),
    })
}

/// The curves of a band (or lobe) result per speed, for summaries: the boundary, and the
/// conservative (lower) and upper curves where the kind has them; NaN where a curve has no
/// value at a speed.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BandCurves {
    /// Speeds (rpm).
    pub speed_rpm: Vec<f64>,
    /// The boundary (mm).
    pub depth_mm: Vec<f64>,
    /// The conservative curve (mm).
    pub lower_mm: Option<Vec<f64>>,
    /// The upper curve (mm).
    pub upper_mm: Option<Vec<f64>>,
}

impl BandCurves {
    /// The limiting depths of a lobe diagram (no lower or upper curve).
    pub fn of_lobes(lobes: &[LobePoint]) -> Self {
        Self {
            speed_rpm: lobes.iter().map(|p| p.speed_rpm).collect(),
            depth_mm: lobes
                .iter()
                .map(|p| {
                    let d = p.depth_mm();
                    if d.is_finite() { d } else { f64::NAN }
                })
                .collect(),
            lower_mm: None,
            upper_mm: None,
        }
    }

    /// Type B offsets: at each mean-boundary point the offset boundaries at its speed.
    pub fn of_offsets(bands: &OffsetBoundaries) -> Self {
        let at = |curve: &[(f64, f64)]| -> Vec<f64> {
            bands
                .points
                .iter()
                .map(|p| OffsetBoundaries::depth_at(curve, p.speed_rpm).unwrap_or(f64::NAN))
                .collect()
        };
        Self {
            speed_rpm: bands.points.iter().map(|p| p.speed_rpm).collect(),
            depth_mm: bands.points.iter().map(|p| p.depth_mm).collect(),
            lower_mm: Some(at(&bands.lower)),
            upper_mm: Some(at(&bands.upper)),
        }
    }

    /// Credibility bounds.
    pub fn of_credibility(bounds: &[CredibilityPoint]) -> Self {
        let pick = |f: fn(&CredibilityPoint) -> Option<f64>| -> Vec<f64> {
            bounds.iter().map(|b| f(b).unwrap_or(f64::NAN)).collect()
        };
        Self {
            speed_rpm: bounds.iter().map(|b| b.speed_rpm).collect(),
            depth_mm: pick(|b| b.depth_mm),
            lower_mm: Some(pick(|b| b.lower_mm)),
            upper_mm: Some(pick(|b| b.upper_mm)),
        }
    }

    /// Monte Carlo quantiles: the median boundary between the 5 % and 95 % quantiles.
    pub fn of_quantiles(depth: &[QuantileBand]) -> Self {
        Self {
            speed_rpm: depth.iter().map(|d| d.speed_rpm).collect(),
            depth_mm: depth.iter().map(|d| d.q50).collect(),
            lower_mm: Some(depth.iter().map(|d| d.q05).collect()),
            upper_mm: Some(depth.iter().map(|d| d.q95).collect()),
        }
    }
}

impl BandsOutcome {
    /// The outcome's curves per speed.
    pub fn curves(&self) -> BandCurves {
        match self {
            BandsOutcome::Geometric { bands, .. } => BandCurves::of_offsets(bands),
            BandsOutcome::Perturbation { bands, .. } => BandCurves::of_credibility(&bands.bounds),
            BandsOutcome::MonteCarlo { bands, .. } => BandCurves::of_quantiles(&bands.depth),
        }
    }
}

/// A warning on the Monte Carlo draws that failed (left out of the map and the quantiles,
/// never counted as stable), `None` when none did.
pub fn failure_warning(mc: &MonteCarloBands) -> Option<String> {
    let sampled = &mc.sampled;
    let first = sampled.failures.first()?;
    let invalid = sampled
        .failures
        .iter()
        .filter(|f| f.kind == FailureKind::InvalidSample)
        .count();
    let worst = sampled.failures_per_speed().into_iter().max().unwrap_or(0);
    Some(format!(
        "{} sample-speed failures ({} numerical, {invalid} invalid samples), at most {worst} of \
         {} samples at one speed, left out of the map; first: {}",
        sampled.failures.len(),
        sampled.failures.len() - invalid,
        mc.draws,
        first.message
    ))
}
