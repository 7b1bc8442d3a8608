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
use chatter_progress::Observer;
use rayon::prelude::*;

/// Most Illinois steps refining a bracketed limiting depth.
const MAX_REFINEMENT_STEPS: usize = 200;

/// |mu| - 1 at zero depth up to which the structure counts as marginally stable rather than
/// unstable: an undamped mode has |mu| = 1 exactly at b = 0, which the discretizations compute to
/// round-off. Measured: 2e-12 at 40 steps (the product of m step matrices and the eigenvalue
/// condition of an undamped pair, ~w_n, in (x, v) coordinates); 1e-8 leaves a factor 100 over the
/// Krylov–Schur residual tolerance (1e-10) and still tells apart any damping ratio above ~1e-9
/// (1 - |mu| = 1 - e^{-2 pi zeta f_n tau} with f_n tau >= 1 on the lobes).
pub const MARGINAL_TOLERANCE: f64 = 1e-8;

/// Factor of the downward scan below the start depth that decides, for a marginally stable
/// structure unstable at the start depth, whether the limit is zero or a small positive depth.
const MARGINAL_SCAN_FACTOR: f64 = 10.0;
/// Depth (fraction of the start depth) below which that scan stops: the structure is unstable
/// at any depth it can resolve, and the limiting depth is zero.
const MARGINAL_SCAN_FLOOR: f64 = 1e-6;

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
    /// The point of a cut stable up to the depth ceiling: infinite depth, no chatter frequency.
    pub fn unbounded(speed_rpm: f64) -> Self {
        Self {
            speed_rpm,
            depth_m: f64::INFINITY,
            chatter_hz: f64::NAN,
        }
    }

    /// The point of the shallowest lobe crossing at `speed_rpm`, `crossing` = (depth m, chatter
    /// Hz): [`Self::unbounded`] where no lobe crosses or the crossing lies above `max_depth_m`.
    pub fn below_ceiling(speed_rpm: f64, crossing: Option<(f64, f64)>, max_depth_m: f64) -> Self {
        match crossing {
            Some((depth_m, chatter_hz)) if depth_m <= max_depth_m => Self {
                speed_rpm,
                depth_m,
                chatter_hz,
            },
            _ => Self::unbounded(speed_rpm),
        }
    }

    /// Limiting depth in mm.
    pub fn depth_mm(&self) -> f64 {
        self.depth_m * 1e3
    }
}

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

/// The limiting depth at one speed: the first crossing of |mu| = 1 on a geometric scan from
/// `options.start_depth_m`, refined by Illinois steps.
pub fn limiting_depth<S: StabilitySolver + ?Sized>(
    solver: &S,
    model: &ModalModel,
    speed_rpm: f64,
    options: &BoundaryOptions,
) -> Result<LobePoint> {
    limiting_depth_near(solver, model, speed_rpm, None, options)
}

/// The limiting depth at one speed, searched from a first guess `guess_m` (e.g. the zero-order
/// limit, microseconds per speed): the bracket [b_g / g^k, b_g g^k] (g = `options.growth`) is
/// widened from the guess until |mu| - 1 changes sign, then refined as in [`limiting_depth`].
/// Near a good guess this takes a few evaluations instead of the ~30 of the scan from
/// `options.start_depth_m`. Where the widening falls below the start depth, or without a (finite,
/// positive) guess, it is the scan of [`limiting_depth`], which also checks that the structure is
/// stable at zero depth. Like the scan, it assumes the cut is stable below the crossing it finds
/// (no unstable island between the scan's points).
pub fn limiting_depth_near<S: StabilitySolver + ?Sized>(
    solver: &S,
    model: &ModalModel,
    speed_rpm: f64,
    guess_m: Option<f64>,
    options: &BoundaryOptions,
) -> Result<LobePoint> {
    match boundary_bracket_near(solver, model, speed_rpm, guess_m, options)? {
        Search::Unbounded => Ok(LobePoint::unbounded(speed_rpm)),
        Search::Zero { probe_m } => zero_limit(solver, model, speed_rpm, probe_m),
        Search::Bracket(bracket) => {
            let depth_m = bracket.root();
            let (_, chatter_hz) = solver.chatter_frequency_hz(model, speed_rpm, depth_m)?;
            Ok(LobePoint {
                speed_rpm,
                depth_m,
                chatter_hz,
            })
        }
    }
}

/// A zero limiting depth (a marginally stable structure that any cut destabilizes) with the
/// chatter frequency of the dominant multiplier at `probe_m`, the smallest depth probed: at zero
/// depth several undamped modes have |mu| = 1 and the unstable one need not dominate.
pub(crate) fn zero_limit<S: StabilitySolver + ?Sized>(
    solver: &S,
    model: &ModalModel,
    speed_rpm: f64,
    probe_m: f64,
) -> Result<LobePoint> {
    let (_, chatter_hz) = solver.chatter_frequency_hz(model, speed_rpm, probe_m)?;
    Ok(LobePoint {
        speed_rpm,
        depth_m: 0.0,
        chatter_hz,
    })
}

/// What a boundary search found at one speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Search {
    /// Stable up to the depth ceiling.
    Unbounded,
    /// Marginally stable at zero depth (|mu| = 1 within [`MARGINAL_TOLERANCE`]: undamped modes)
    /// and unstable at every depth resolved, down to `probe_m`: the limiting depth is zero.
    Zero {
        /// The smallest depth probed (m), where |mu| >= 1.
        probe_m: f64,
    },
    /// The refined bracket of |mu| - 1.
    Bracket(Bracket),
}

/// The search of [`limiting_depth_near`] up to its refined bracket of |mu| - 1, without the
/// chatter frequency.
pub(crate) fn boundary_bracket_near<S: StabilitySolver + ?Sized>(
    solver: &S,
    model: &ModalModel,
    speed_rpm: f64,
    guess_m: Option<f64>,
    options: &BoundaryOptions,
) -> Result<Search> {
    options.validate()?;
    let f = |b: f64| -> Result<f64> {
        Ok(solver.dominant_multiplier(model, speed_rpm, b)?.modulus() - 1.0)
    };
    let guess = guess_m
        .filter(|b| b.is_finite() && *b >= options.start_depth_m)
        .map(|b| b.min(options.max_depth_m));
    let bracket = match guess {
        Some(b) => match widen_from_guess(&f, b, options)? {
            Widened::Bracket(bracket) => Some(bracket),
            Widened::Unbounded => return Ok(Search::Unbounded),
            Widened::BelowStart => None,
        },
        None => None,
    };
    let bracket = match bracket {
        Some(bracket) => bracket,
        None => match scan_from_start(solver, &f, speed_rpm, options)? {
            Search::Bracket(bracket) => bracket,
            other => return Ok(other),
        },
    };
    illinois(bracket, options.relative_tolerance, MAX_REFINEMENT_STEPS, f).map(Search::Bracket)
}

/// What widening a bracket from a guess found.
enum Widened {
    Bracket(Bracket),
    /// Stable up to the depth ceiling.
    Unbounded,
    /// Unstable down to the start depth: the scan from the start decides.
    BelowStart,
}

/// Widen geometrically from `guess` until |mu| - 1 changes sign.
fn widen_from_guess(
    f: &impl Fn(f64) -> Result<f64>,
    guess: f64,
    options: &BoundaryOptions,
) -> Result<Widened> {
    let g = f(guess)?;
    if g < 0.0 {
        let (mut lo, mut g_lo) = (guess, g);
        loop {
            if lo >= options.max_depth_m {
                return Ok(Widened::Unbounded);
            }
            let hi = (lo * options.growth).min(options.max_depth_m);
            let g_hi = f(hi)?;
            if g_hi >= 0.0 {
                return Ok(Widened::Bracket(Bracket::new((lo, g_lo), (hi, g_hi))));
            }
            (lo, g_lo) = (hi, g_hi);
        }
    }
    let (mut hi, mut g_hi) = (guess, g);
    loop {
        let lo = hi / options.growth;
        if lo < options.start_depth_m {
            return Ok(Widened::BelowStart);
        }
        let g_lo = f(lo)?;
        if g_lo < 0.0 {
            return Ok(Widened::Bracket(Bracket::new((lo, g_lo), (hi, g_hi))));
        }
        (hi, g_hi) = (lo, g_lo);
    }
}

/// The geometric scan from zero depth and `options.start_depth_m` to the first sign change.
/// Errors when the structure is unstable at zero depth (|mu| > 1 + [`MARGINAL_TOLERANCE`]).
/// A marginally stable structure (undamped modes) that is unstable at the start depth is
/// scanned downwards by [`MARGINAL_SCAN_FACTOR`]: a depth where it is stable brackets a small
/// limit; where |mu| - 1 stays positive down to the noise level or [`MARGINAL_SCAN_FLOOR`], any
/// cut destabilizes it (the first-order shift of an undamped pair's root with depth has the
/// sign of the regenerative term, -b Re[(1 - e^{-i w_n tau}) mu_n / (2 i w_n)]) and the limit is
/// zero.
fn scan_from_start<S: StabilitySolver + ?Sized>(
    solver: &S,
    f: &impl Fn(f64) -> Result<f64>,
    speed_rpm: f64,
    options: &BoundaryOptions,
) -> Result<Search> {
    let mut lo = 0.0;
    let mut g_lo = f(0.0)?;
    if g_lo > MARGINAL_TOLERANCE {
        return Err(StabilityError::Unsupported {
            method: solver.name(),
            reason: format!(
                "|mu| = 1 + {g_lo:.3e} at zero depth at {speed_rpm} rpm: the structure itself is \
                 unstable (a negative damping ratio?)"
            ),
        });
    }
    let marginal = g_lo >= -MARGINAL_TOLERANCE;
    let mut hi = options.start_depth_m;
    let mut g_hi = f(hi)?;
    if marginal && g_hi >= 0.0 {
        return scan_below_start(f, hi, g_hi, options);
    }
    while g_hi < 0.0 {
        lo = hi;
        g_lo = g_hi;
        hi *= options.growth;
        if hi > options.max_depth_m {
            return Ok(Search::Unbounded);
        }
        g_hi = f(hi)?;
    }
    // a marginal structure: g_lo at zero depth is noise, the start depth is the lower end
    Ok(Search::Bracket(Bracket::new((lo, g_lo), (hi, g_hi))))
}

/// The downward scan of [`scan_from_start`] from the start depth `hi` where |mu| - 1 = `g_hi`
/// >= 0.
fn scan_below_start(
    f: &impl Fn(f64) -> Result<f64>,
    mut hi: f64,
    mut g_hi: f64,
    options: &BoundaryOptions,
) -> Result<Search> {
    let floor = MARGINAL_SCAN_FLOOR * options.start_depth_m;
    loop {
        let lo = hi / MARGINAL_SCAN_FACTOR;
        if lo < floor {
            return Ok(Search::Zero { probe_m: hi });
        }
        let g_lo = f(lo)?;
        if g_lo < 0.0 {
            return Ok(Search::Bracket(Bracket::new((lo, g_lo), (hi, g_hi))));
        }
        if g_lo <= MARGINAL_TOLERANCE {
            // unstable down to the round-off level of |mu| at zero depth
            return Ok(Search::Zero { probe_m: lo });
        }
        (hi, g_hi) = (lo, g_lo);
    }
}

/// Limiting depths at many speeds, in parallel; the result does not depend on the thread count.
pub fn lobe_diagram<S: StabilitySolver + ?Sized>(
    solver: &S,
    model: &ModalModel,
    speeds_rpm: &[f64],
    options: &BoundaryOptions,
    observer: &dyn Observer,
) -> Result<Vec<LobePoint>> {
    in_parallel(speeds_rpm, observer, |s| {
        limiting_depth(solver, model, s, options)
    })
}

/// `point` at every speed of `speeds_rpm`, in parallel and in order; `observer` hears of each
/// speed done, and a speed not yet started when it asks to stop is not computed
/// ([`StabilityError::Cancelled`](crate::StabilityError::Cancelled)).
pub(crate) fn in_parallel(
    speeds_rpm: &[f64],
    observer: &dyn Observer,
    point: impl Fn(f64) -> Result<LobePoint> + Sync,
) -> Result<Vec<LobePoint>> {
    let done = std::sync::atomic::AtomicUsize::new(0);
    speeds_rpm
        .par_iter()
        .map(|&s| {
            chatter_progress::check(observer)?;
            let p = point(s);
            let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            observer.steps_done(k, speeds_rpm.len());
            p
        })
        .collect()
}

/// |mu| on a speed x depth grid (rows per speed), for contour plots; `observer` hears of each
/// speed done and is polled before every cell
/// ([`StabilityError::Cancelled`]).
pub fn multiplier_grid<S: StabilitySolver + ?Sized>(
    solver: &S,
    model: &ModalModel,
    speeds_rpm: &[f64],
    depths_m: &[f64],
    observer: &dyn Observer,
) -> Result<Vec<Vec<f64>>> {
    let done = std::sync::atomic::AtomicUsize::new(0);
    speeds_rpm
        .par_iter()
        .map(|&s| {
            let row = depths_m
                .iter()
                .map(|&b| {
                    chatter_progress::check(observer)?;
                    Ok(solver.dominant_multiplier(model, s, b)?.modulus())
                })
                .collect();
            let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            observer.steps_done(k, speeds_rpm.len());
            row
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
    Ok(chatter_dynamics::grid::evenly_spaced(min_rpm, max_rpm, n))
}
