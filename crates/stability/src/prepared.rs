//! Prepared solvers: each method is prepared once per model and then queried at any cutting
//! condition (the planner of RustFFT, the problem/solver split of argmin).
//!
//! | method | prepared once | per query |
//! |---|---|---|
//! | [`Method::Zoa`] ([`PreparedZeroOrder`]) | the eigenvalue branches of A_0 G(i w) on a frequency grid, with process damping (001, 003) | the lowest lobe crossing at the speed's delay |
//! | [`Method::Fdm`], [`Method::Sdm`] ([`PreparedDiscretization`]) | the step resolution policy (own model or a reference grid) and the zero-order table that guides the boundary search | the step program and its dominant multiplier (000 Eq. 9-11, 002 Eq. 3-5) |
//! | [`PreparedFrequencyDomain`] (turning) | the zero-order guide | the closed-loop poles of the characteristic equation (000 Eq. 28) |
//!
//! Every prepared solver answers the same four queries ([`PreparedSolver`]): the dominant
//! multiplier, the chatter frequency, the limiting depth and the lobes over speeds. The
//! zero-order method gives limiting depths only; its multiplier queries are a typed
//! [`StabilityError::Unsupported`], never a made-up value.
//!
//! The discretizations search the boundary from the zero-order limit
//! ([`crate::boundary::limiting_depth_near`]): a handful of multiplier evaluations per speed
//! instead of the ~30 of a scan from zero depth.
//!
//! ```
//! use chatter_dynamics::examples;
//! use chatter_stability::boundary::BoundaryOptions;
//! use chatter_stability::prepared::Method;
//! let model = examples::schmitz_2023_milling();
//! let options = BoundaryOptions::default();
//! let zoa = Method::Zoa.prepare(&model, &options)?;
//! let fdm = Method::Fdm.prepare(&model, &options)?;
//! let (a, b) = (zoa.limiting_depth(6960.0)?, fdm.limiting_depth(6960.0)?);
//! // the two methods agree on this two-mode mill within a few percent
//! assert!((a.depth_m - b.depth_m).abs() < 0.1 * b.depth_m, "{a:?} {b:?}");
//! assert!(zoa.dominant_multiplier(6960.0, 1e-3).is_err());
//! assert!(fdm.dominant_multiplier(6960.0, 0.5 * b.depth_m)?.modulus() < 1.0);
//! # Ok::<(), chatter_stability::StabilityError>(())
//! ```

use crate::StabilitySolver;
use crate::boundary::{
    BoundaryOptions, LobePoint, Search, boundary_bracket_near, in_parallel, limiting_depth_near,
    zero_limit,
};
use crate::error::{Result, StabilityError};
use crate::frequency_domain::FrequencyDomain;
use crate::monodromy::{Discretization, Monodromy, Scheme, StepPlan, StepsPerDelay, steps};
use crate::multiplier::DominantMultiplier;
use crate::zero_order::{PreparedZeroOrder, ZeroOrderOptions};
use chatter_dynamics::{ModalModel, Operation};
use chatter_progress::Observer;
use std::num::NonZeroUsize;
use std::sync::Mutex;

/// A stability method by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Zero-order approximation (Altintas-Budak; exact for turning).
    Zoa,
    /// First-order full discretization.
    Fdm,
    /// First-order semi-discretization.
    Sdm,
}

impl Method {
    /// Short name (`"zoa"`, `"fdm"`, `"sdm"`).
    pub fn name(self) -> &'static str {
        match self {
            Method::Zoa => "zoa",
            Method::Fdm => "fdm",
            Method::Sdm => "sdm",
        }
    }

    /// The discretization of FDM and SDM at the automatic resolution; `None` for zero-order.
    pub fn discretization(self) -> Option<Discretization> {
        match self {
            Method::Zoa => None,
            Method::Fdm => Some(Discretization::full()),
            Method::Sdm => Some(Discretization::semi()),
        }
    }

    /// The method prepared for `model` with the boundary `options` (depth ceiling, tolerance).
    pub fn prepare(
        self,
        model: &ModalModel,
        options: &BoundaryOptions,
    ) -> Result<Box<dyn PreparedSolver>> {
        Ok(match self.discretization() {
            None => Box::new(PreparedZeroOrder::new(model, &zero_order_options(options))?),
            Some(d) => Box::new(PreparedDiscretization::new(d, model, options)?),
        })
    }
}

/// A method with the options of its boundary search: what samplers prepare for every sampled
/// model (the random-walk paths of 003, the cut likelihoods of 004, `chatter plan`), thousands
/// of boundaries per run.
///
/// The default method is the first-order full discretization (Ding et al. 2010) with the model's
/// process damping as -b D(t) x' (003 Eq. 1), its boundary searched from the zero-order limit.
/// The zero-order method alone is not the default: on 003's single-tooth flexure it is 6-11 %
/// low without process damping and 42 % low at 300 rpm with it (C = 2.5e5 N/m), and paths built
/// on it then converge to C = 3.3e5 N/m when the cuts come from the exact machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// The stability method; default [`Method::Fdm`].
    pub method: Method,
    /// The boundary search: [`BoundaryOptions::default`] with a relative tolerance of 1e-3 (a
    /// micrometre per millimetre, far inside the cut kernels' widths of 0.125-0.5 mm).
    pub boundary: BoundaryOptions,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            method: Method::Fdm,
            boundary: BoundaryOptions {
                relative_tolerance: 1e-3,
                ..BoundaryOptions::default()
            },
        }
    }
}

impl SolverOptions {
    /// The default options with `method`.
    pub fn new(method: Method) -> Self {
        Self {
            method,
            ..Self::default()
        }
    }

    /// These options with the depth ceiling `max_depth_m` (depths above it count as stable).
    pub fn with_max_depth_m(self, max_depth_m: f64) -> Self {
        Self {
            boundary: BoundaryOptions {
                max_depth_m,
                ..self.boundary
            },
            ..self
        }
    }

    /// The method prepared for `model`, the discretizations on the grid of `grid` (the nominal
    /// model of a parameterization, [`PreparedDiscretization::on_grid_of`]): every sampled model
    /// then has the nominal's grid at each speed and its limiting depth is a smooth function of
    /// the parameters.
    pub fn prepare_on_grid_of(
        &self,
        model: &ModalModel,
        grid: &ModalModel,
    ) -> Result<Box<dyn PreparedSolver>> {
        Ok(match self.method.discretization() {
            None => self.method.prepare(model, &self.boundary)?,
            Some(d) => {
                Box::new(PreparedDiscretization::new(d, model, &self.boundary)?.on_grid_of(grid))
            }
        })
    }
}

/// A stability method prepared for one model.
///
/// Implementations are thread-safe and deterministic: [`Self::lobes`] runs speeds in parallel
/// and gives the same result on any number of threads.
pub trait PreparedSolver: Send + Sync {
    /// Short name (`"zoa"`, `"fdm"`, `"sdm"`, `"frequency-domain"`).
    fn name(&self) -> &'static str;

    /// Dominant multiplier over one delay at `speed_rpm` and depth `depth_m`.
    fn dominant_multiplier(&self, speed_rpm: f64, depth_m: f64) -> Result<DominantMultiplier>;

    /// The dominant multiplier with its chatter frequency (Hz).
    fn chatter_frequency_hz(
        &self,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)>;

    /// The limiting depth at `speed_rpm` (infinite when stable up to the depth ceiling).
    fn limiting_depth(&self, speed_rpm: f64) -> Result<LobePoint>;

    /// Limiting depths at `speeds_rpm`, in order on the calling thread (samplers, which run
    /// their models in parallel).
    fn limiting_depths(&self, speeds_rpm: &[f64]) -> Result<Vec<LobePoint>> {
        speeds_rpm.iter().map(|&s| self.limiting_depth(s)).collect()
    }

    /// Limiting depths at `speeds_rpm`, in parallel; `observer` hears of each speed done.
    fn lobes(&self, speeds_rpm: &[f64], observer: &dyn Observer) -> Result<Vec<LobePoint>> {
        in_parallel(speeds_rpm, observer, |s| self.limiting_depth(s))
    }
}

/// The zero-order options of a boundary search: the same ceiling and tolerance.
fn zero_order_options(options: &BoundaryOptions) -> ZeroOrderOptions {
    ZeroOrderOptions {
        max_depth_m: options.max_depth_m,
        relative_tolerance: options.relative_tolerance,
    }
}

/// The zero-order guide of a multiplier-based search; `None` where the zero-order method does
/// not apply to the model (the search then scans from zero depth: slower, equally exact).
fn guide(model: &ModalModel, options: &BoundaryOptions) -> Option<PreparedZeroOrder> {
    PreparedZeroOrder::new(model, &zero_order_options(options)).ok()
}

/// The guess of a guided search at one speed: the zero-order limit where it is finite.
fn guess(guide: Option<&PreparedZeroOrder>, speed_rpm: f64) -> Option<f64> {
    guide
        .and_then(|g| g.limiting_depth(speed_rpm).ok())
        .map(|p| p.depth_m)
        .filter(|b| b.is_finite())
}

/// Full- or semi-discretization prepared for one model.
///
/// The step count at each speed follows the discretization's [`crate::monodromy::StepsPerDelay`]
/// on the model itself, or, after [`Self::on_grid_of`], on a reference model: samplers give every
/// sampled model the grid of the nominal one, so that their operators have the same dimension and
/// the limiting depth is a smooth function of the parameters.
#[derive(Debug, Clone)]
pub struct PreparedDiscretization {
    model: ModalModel,
    discretization: Discretization,
    grid: Option<ModalModel>,
    guide: Option<PreparedZeroOrder>,
    options: BoundaryOptions,
}

impl PreparedDiscretization {
    /// Prepare `discretization` for `model` with the boundary `options`.
    pub fn new(
        discretization: Discretization,
        model: &ModalModel,
        options: &BoundaryOptions,
    ) -> Result<Self> {
        options.validate()?;
        Ok(Self {
            model: model.clone(),
            discretization,
            grid: None,
            guide: guide(model, options),
            options: *options,
        })
    }

    /// Resolve the grid at every speed on `reference` instead of the model.
    pub fn on_grid_of(self, reference: &ModalModel) -> Self {
        Self {
            grid: Some(reference.clone()),
            ..self
        }
    }

    /// The discretization with the step count fixed for `speed_rpm`: the automatic resolution
    /// on the grid's model, times [`SEMI_PROCESS_DAMPING_REFINEMENT`] for SDM on a model with
    /// process damping.
    pub fn at_speed(&self, speed_rpm: f64) -> Discretization {
        let resolved = self
            .discretization
            .resolved(self.grid.as_ref().unwrap_or(&self.model), speed_rpm);
        let refined = self.discretization.steps == StepsPerDelay::Auto
            && self.discretization.scheme == Scheme::Semi
            && self
                .model
                .process_damping_n_per_m()
                .is_some_and(|c| c > 0.0);
        match resolved.steps {
            StepsPerDelay::Fixed(m) if refined => {
                resolved.with_steps(m.saturating_mul(SEMI_PROCESS_DAMPING_REFINEMENT))
            }
            _ => resolved,
        }
    }
}

impl PreparedDiscretization {
    /// The finer grid of the Richardson extrapolation at `speed_rpm` (twice the steps of
    /// `coarse`), or `None` where the solver does not extrapolate: a fixed step count (the
    /// caller chose the grid) or a reference grid (samplers: their cost budget was set on one
    /// grid per speed).
    fn finer(&self, coarse: &Discretization) -> Option<Discretization> {
        match (self.discretization.steps, coarse.steps, &self.grid) {
            (StepsPerDelay::Auto, StepsPerDelay::Fixed(m), None) => {
                Some(coarse.with_steps(m.saturating_mul(steps::<2>())))
            }
            _ => None,
        }
    }
}

/// Richardson extrapolation of the modulus of the dominant multiplier from the grids of m and
/// 2m steps: |mu| = (4 |mu_2m| - |mu_m|) / 3 (the first-order schemes' error falls as 1/m^2), with
/// the argument of the finer grid's multiplier.
fn extrapolated(coarse: &DominantMultiplier, fine: &DominantMultiplier) -> DominantMultiplier {
    let modulus = ((4.0 * fine.modulus() - coarse.modulus()) / 3.0).max(0.0);
    let value = if fine.modulus() > 0.0 {
        fine.value * (modulus / fine.modulus())
    } else {
        fine.value
    };
    DominantMultiplier::new(value, fine.period_s)
}

/// Factor on the automatic step count of SDM for a model with process damping. SDM's error there
/// is second order in the step, like FDM's, but far from the asymptotic regime at the automatic
/// resolution: on the 003-type flexure (C = 2.5e5 N/m, 300 rpm) SDM is 12 / 5.3 / 1.5 / 0.36 %
/// above the converged limit at 200 / 400 / 800 / 1600 steps (error ratios 2.3, 3.5, 4.2), FDM
/// 3.7 / 0.9 / 0.2 / 0.05 %, so the extrapolation from m and 2m left SDM 2.9 % high there. With
/// twice the steps it is within 0.1 % of the converged limit (`tests/conformance.rs`, against a
/// reference itself 0.29 % high at 300 rpm: -0.37 %). The velocity term itself is integrated
/// exactly over each step (A_0 + A(t) frozen at its step mean); the slow part is the delayed
/// term at the ~45 vibration cycles per delay of such low speeds.
pub const SEMI_PROCESS_DAMPING_REFINEMENT: NonZeroUsize = steps::<2>();

/// Largest relative shift of the limiting depth from the coarse to the fine grid that one secant
/// step (with the coarse grid's slope) resolves; beyond it (e.g. another lobe takes over on the
/// finer grid) the fine grid gets a search of its own.
const MAX_SECANT_SHIFT: f64 = 0.1;
/// Relative shift beyond which a second secant step on the finer grid (one more evaluation)
/// corrects the first one's slope error (at 8500 rpm on the single-DOF benchmark the shift is
/// 4.4 % and one step leaves b_2m 0.4 % off).
const SECOND_SECANT_SHIFT: f64 = 0.01;

impl PreparedSolver for PreparedDiscretization {
    fn name(&self) -> &'static str {
        self.discretization.name()
    }

    /// At the automatic resolution (own grid), the Richardson extrapolation of the grids of m
    /// and 2m steps (see [`Self::limiting_depth`]).
    fn dominant_multiplier(&self, speed_rpm: f64, depth_m: f64) -> Result<DominantMultiplier> {
        let coarse = self.at_speed(speed_rpm);
        let mu = coarse.dominant_multiplier(&self.model, speed_rpm, depth_m)?;
        match self.finer(&coarse) {
            Some(fine) => Ok(extrapolated(
                &mu,
                &fine.dominant_multiplier(&self.model, speed_rpm, depth_m)?,
            )),
            None => Ok(mu),
        }
    }

    fn chatter_frequency_hz(
        &self,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)> {
        let coarse = self.at_speed(speed_rpm);
        let Some(fine) = self.finer(&coarse) else {
            return coarse.chatter_frequency_hz(&self.model, speed_rpm, depth_m);
        };
        let (mu, f) = fine.chatter_frequency_hz(&self.model, speed_rpm, depth_m)?;
        let coarse_mu = coarse.dominant_multiplier(&self.model, speed_rpm, depth_m)?;
        Ok((extrapolated(&coarse_mu, &mu), f))
    }

    /// The guided search on the grid of m steps. At the automatic resolution (own grid) the
    /// depth is then extrapolated (Richardson): one evaluation on the grid of 2m steps at the
    /// coarse limit b_m gives b_2m by a secant step with the slope of |mu| of the coarse search's
    /// last bracket (a second secant step through two fine-grid points when the shift exceeds
    /// 1 %), and b = (4 b_2m - b_m) / 3. The first-order schemes' limiting depth
    /// converges as 1/m^2 (`examples/resolution_accuracy.rs`: the error falls by 4.0-4.4 from m
    /// to 2m on the single-DOF benchmark), so the extrapolation removes the leading term: the
    /// worst error over the benchmark's full immersion at 5000-21 000 rpm goes from 6.1 % to
    /// 0.2 % (FDM; SDM 4.5 % to 0.09 %), at the cost of one or two evaluations on the finer grid
    /// per speed. Exception: at a crossing of two lobes (5500 rpm there: 1.1 %) the coarse grids
    /// may put the other lobe lowest, and the dominant lobe alone is extrapolated.
    fn limiting_depth(&self, speed_rpm: f64) -> Result<LobePoint> {
        let coarse = self.at_speed(speed_rpm);
        let solver = WarmStarted::new(&coarse, &self.model, speed_rpm, None)?;
        let guess_m = guess(self.guide.as_ref(), speed_rpm);
        let Some(fine) = self.finer(&coarse) else {
            return limiting_depth_near(&solver, &self.model, speed_rpm, guess_m, &self.options);
        };
        let bracket =
            match boundary_bracket_near(&solver, &self.model, speed_rpm, guess_m, &self.options)? {
                Search::Bracket(bracket) => bracket,
                Search::Unbounded => return Ok(LobePoint::unbounded(speed_rpm)),
                // zero on either grid: the sign of the first-order shift does not depend on m
                Search::Zero { probe_m } => {
                    return zero_limit(&solver, &self.model, speed_rpm, probe_m);
                }
            };
        let coarse_depth = bracket.root();
        let slope =
            (bracket.f_positive - bracket.f_negative) / (bracket.positive - bracket.negative);
        // the finer grid's Krylov runs start from the coarse eigenvector on the finer grid
        let start = solver
            .start
            .into_inner()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .map(|v| prolonged(&v, self.model.mode_count()));
        let fine = WarmStarted::new(&fine, &self.model, speed_rpm, start)?;
        let (mu, chatter_hz) = fine.chatter_frequency_hz(&self.model, speed_rpm, coarse_depth)?;
        let g = mu.modulus() - 1.0;
        let mut fine_depth = coarse_depth - g / slope;
        let secant_applies = slope.is_finite()
            && slope != 0.0
            && (fine_depth - coarse_depth).abs() <= MAX_SECANT_SHIFT * coarse_depth;
        if secant_applies && (fine_depth - coarse_depth).abs() > SECOND_SECANT_SHIFT * coarse_depth
        {
            // a second secant step through the two points on the finer grid
            let g2 = fine
                .dominant_multiplier(&self.model, speed_rpm, fine_depth)?
                .modulus()
                - 1.0;
            if g2 != g {
                fine_depth -= g2 * (fine_depth - coarse_depth) / (g2 - g);
            }
        }
        let fine_point = if secant_applies {
            LobePoint {
                speed_rpm,
                depth_m: fine_depth,
                chatter_hz,
            }
        } else {
            limiting_depth_near(
                &fine,
                &self.model,
                speed_rpm,
                Some(coarse_depth),
                &self.options,
            )?
        };
        if !fine_point.depth_m.is_finite() {
            return Ok(fine_point);
        }
        let depth_m = (4.0 * fine_point.depth_m - coarse_depth) / 3.0;
        Ok(LobePoint {
            depth_m: if depth_m > 0.0 {
                depth_m
            } else {
                fine_point.depth_m
            },
            ..fine_point
        })
    }
}

/// A start vector of the grid of 2m steps from the state `coarse` on the grid of m steps
/// (layout [y_0 (2N); delayed q at the M grid points, N each]): y_0 as it is and every delayed
/// value held over the two finer grid points that halve its step. Only a start of the Krylov
/// iteration (a close one saves restarts), so the hold needs no better accuracy; where the finer
/// grid has another dimension (free flight) the start is ignored.
fn prolonged(coarse: &[f64], modes: usize) -> Vec<f64> {
    let head = (2 * modes).min(coarse.len());
    let mut v = Vec::with_capacity(2 * coarse.len());
    v.extend_from_slice(&coarse[..head]);
    for q in coarse[head..].chunks(modes.max(1)) {
        v.extend_from_slice(q);
        v.extend_from_slice(q);
    }
    v
}

/// A discretization at one speed whose Krylov runs start from the eigenvector of the previous
/// call: along one boundary search the operators differ only in depth and share their dimension,
/// so the previous eigenvector is a close start (the result is the same to the Krylov
/// tolerance). The depth-independent part of the step program is built once ([`StepPlan`]).
struct WarmStarted {
    plan: StepPlan,
    speed_rpm: f64,
    start: Mutex<Option<Vec<f64>>>,
}

impl WarmStarted {
    /// The plan of `discretization` for `model` at `speed_rpm`, started from `start`.
    fn new(
        discretization: &Discretization,
        model: &ModalModel,
        speed_rpm: f64,
        start: Option<Vec<f64>>,
    ) -> Result<Self> {
        Ok(Self {
            plan: discretization.plan(model, speed_rpm)?,
            speed_rpm,
            start: Mutex::new(start),
        })
    }

    /// The operator at `depth_m`; the plan's speed is the only one this solver answers for.
    fn monodromy(&self, speed_rpm: f64, depth_m: f64) -> Result<Monodromy> {
        debug_assert_eq!(speed_rpm, self.speed_rpm);
        self.plan.monodromy(depth_m)
    }
}

impl StabilitySolver for WarmStarted {
    fn name(&self) -> &'static str {
        self.plan.scheme().name()
    }

    fn dominant_multiplier(
        &self,
        _model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<DominantMultiplier> {
        let op = self.monodromy(speed_rpm, depth_m)?;
        let mut start = self
            .start
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let (mu, vector) = op.dominant_eigenpair_from(start.as_deref())?;
        *start = Some(vector.iter().map(|z| z.re + z.im).collect());
        Ok(DominantMultiplier::new(mu, op.period_s))
    }

    fn chatter_frequency_hz(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)> {
        let op = self.monodromy(speed_rpm, depth_m)?;
        let start = self
            .start
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        op.chatter_frequency_from(model, start.as_deref())
    }
}

/// The frequency-domain method (closed-loop poles of turning, 000 Eq. 28) prepared for one
/// turning model.
#[derive(Debug, Clone)]
pub struct PreparedFrequencyDomain {
    model: ModalModel,
    guide: Option<PreparedZeroOrder>,
    options: BoundaryOptions,
}

impl PreparedFrequencyDomain {
    /// Prepare for a turning `model`; milling models are [`StabilityError::Unsupported`].
    pub fn new(model: &ModalModel, options: &BoundaryOptions) -> Result<Self> {
        options.validate()?;
        if !matches!(model.operation(), Operation::Turning(_)) {
            return Err(StabilityError::Unsupported {
                method: "frequency-domain",
                reason: "the characteristic equation has constant coefficients only in turning"
                    .into(),
            });
        }
        Ok(Self {
            model: model.clone(),
            guide: guide(model, options),
            options: *options,
        })
    }
}

impl PreparedSolver for PreparedFrequencyDomain {
    fn name(&self) -> &'static str {
        FrequencyDomain.name()
    }

    fn dominant_multiplier(&self, speed_rpm: f64, depth_m: f64) -> Result<DominantMultiplier> {
        FrequencyDomain.dominant_multiplier(&self.model, speed_rpm, depth_m)
    }

    fn chatter_frequency_hz(
        &self,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)> {
        FrequencyDomain.chatter_frequency_hz(&self.model, speed_rpm, depth_m)
    }

    fn limiting_depth(&self, speed_rpm: f64) -> Result<LobePoint> {
        limiting_depth_near(
            &FrequencyDomain,
            &self.model,
            speed_rpm,
            guess(self.guide.as_ref(), speed_rpm),
            &self.options,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::limiting_depth;
    use chatter_dynamics::examples;

    /// At the automatic resolution the limiting depth is extrapolated from m and 2m: on the
    /// single-DOF benchmark at 12 500 rpm (full immersion, where m alone is 2.1 % high with FDM)
    /// it is within 0.1 % of SDM at 1600 steps (converged to 0.01 %: 800 and 1600 steps differ
    /// by 0.03 %), and |mu| is 1 there to 1e-3.
    #[test]
    fn extrapolated_depth_is_within_a_tenth_of_a_percent() {
        let model = examples::insperger_benchmark(1.0);
        let options = BoundaryOptions::default();
        let fine = BoundaryOptions {
            relative_tolerance: 1e-6,
            ..options
        };
        let reference = limiting_depth(
            &Discretization::semi().with_steps(steps::<1600>()),
            &model,
            12_500.0,
            &fine,
        )
        .unwrap()
        .depth_m;
        for method in [Method::Fdm, Method::Sdm] {
            let prepared = method.prepare(&model, &options).unwrap();
            let p = prepared.limiting_depth(12_500.0).unwrap();
            assert!(
                (p.depth_m - reference).abs() < 1e-3 * reference,
                "{method:?}: {} vs {reference}",
                p.depth_m
            );
            let mu = prepared.dominant_multiplier(12_500.0, p.depth_m).unwrap();
            assert!(
                (mu.modulus() - 1.0).abs() < 1e-3,
                "{method:?}: |mu| {}",
                mu.modulus()
            );
        }
    }

    /// The guided search finds the same boundary as the scan from zero depth (to the search
    /// tolerance, 1e-4 relative, twice for the two brackets), with process damping too, on one
    /// fixed grid (no extrapolation).
    #[test]
    fn guided_search_agrees_with_the_scan() {
        let options = BoundaryOptions::default();
        let flexure = examples::process_damping_flexure(Some(2.5e5));
        let mill = examples::schmitz_2023_milling();
        for (model, speed) in [(&flexure, 300.0), (&flexure, 2000.0), (&mill, 6960.0)] {
            let fixed = Discretization::full().resolved(model, speed);
            let prepared = PreparedDiscretization::new(fixed, model, &options).unwrap();
            let guided = PreparedSolver::limiting_depth(&prepared, speed).unwrap();
            let scanned = limiting_depth(&fixed, model, speed, &options).unwrap();
            assert!(
                (guided.depth_m - scanned.depth_m).abs() < 2e-4 * scanned.depth_m,
                "{guided:?} {scanned:?}"
            );
        }
    }

    #[test]
    fn frequency_domain_is_for_turning_and_zoa_has_no_multipliers() {
        let options = BoundaryOptions::default();
        let mill = examples::schmitz_2023_milling();
        assert!(PreparedFrequencyDomain::new(&mill, &options).is_err());
        let zoa = Method::Zoa.prepare(&mill, &options).unwrap();
        assert!(matches!(
            zoa.chatter_frequency_hz(6960.0, 1e-3),
            Err(StabilityError::Unsupported { .. })
        ));
    }

    /// A reference grid fixes the step count: a model 5 % stiffer gets the nominal's grid.
    #[test]
    fn reference_grid_is_the_nominal_one() {
        let nominal = examples::process_damping_flexure(None);
        let options = BoundaryOptions::default();
        let prepared =
            PreparedDiscretization::new(Discretization::full(), &nominal, &options).unwrap();
        let at = prepared.at_speed(300.0);
        let modes = nominal
            .modes()
            .iter()
            .map(|m| {
                chatter_dynamics::Mode::new(1.05 * m.frequency_hz(), m.damping_ratio(), m.shape())
                    .unwrap()
            })
            .collect();
        let stiffer = nominal.with_modes(modes).unwrap();
        let on_nominal = PreparedDiscretization::new(Discretization::full(), &stiffer, &options)
            .unwrap()
            .on_grid_of(&nominal);
        assert_eq!(on_nominal.at_speed(300.0), at);
    }
}
