//! Process damping (Karandikar, Tyler and Schmitz, seed 003, Section 2) as a branch of the
//! zero-order lobes.
//!
//! F_d = -C b ydot / V raises the damping ratios to zeta_n + b s_n, s_n = c sigma_n with c = C / V
//! (or any speed-dependent scale) and sigma_n fixed. 003 iterates b_{j+1} = M(b_j) from the
//! boundary without process damping, M(b) the lowest lobe of the modes damped at width b; its
//! limit is a fixed point b = M(b). A fixed point is a lobe crossing, w tau = eps + 2 pi k, of the
//! eigenvalue Lambda(w; b) of the system damped at the crossing's own depth,
//! b = -1 / (2 Re Lambda(w; b)). So with process damping the lobes are those of the branch whose
//! depth at each frequency is the smallest fixed point
//!
//! b(w) = -1 / (2 Re Lambda(w; b(w))),
//!
//! with eps(w) the phase of Lambda(w; b(w)), and the lowest crossing of that branch is the
//! limiting depth, with no iteration over lobes or depths.
//!
//! With u = c b the damping ratios are zeta_n + u sigma_n, and b(w) = u / c for the smallest u with
//! K(u) = u (-2 Re Lambda(w; u)) = c. [`ProcessDampedTable`] tabulates K at every frequency of the
//! [`LobeTable`] on a geometric grid of u up to the value at which a damping ratio reaches 1
//! (the eigenvalues followed from zero damping by continuity, so the branches are not mixed), once
//! for all speeds. At a speed the first grid interval where K reaches c brackets b(w): its lower
//! end orders the crossing search (a lower bound, so no lower lobe is passed over), the eigenvalue
//! interpolated at the root of u g(u) = c with g = -2 Re Lambda linear over the interval gives the
//! phase, and b(w) is solved exactly by the Illinois method on h(b) = b + 1 / (2 Re Lambda(w; b))
//! only at the crossings refined. Between grid points it is solved from the interpolated
//! neighbours by the steps b - h(b) of 003's iteration, accelerated by secant steps, until
//! bracketed.
//!
//! With several modes the added damping can make lobes where the eigenvalues without it are none,
//! and lower b(w) below the depth without it; the table covers both. Where the two roots of h meet
//! (a fold) the branch ends between grid points at a finite depth, so the fold is located by
//! bisection in w and the lobes between it and the last grid point are solved too. Where no fixed
//! point lies below a damping ratio of 1 the cut is stable at every depth, as in
//! [`crate::process_damping::process_damping_limiting_depth`].

use super::system::{AddedDamping, LobePhase};
use super::table::{
    BranchPoints, EARLY_SEGMENTS, FREQUENCY_TOLERANCE, LobeTable, SAME_CROSSING, Segments,
    crossing, insert, segments,
};
use super::{Lobe, ZeroOrderOptions};
use crate::error::{Result, invalid};
use crate::root::{Bracket, illinois};
use num_complex::Complex64;
use std::borrow::Cow;
use std::cell::{Cell, OnceCell};
use std::convert::Infallible;
use std::f64::consts::PI;

/// Points of the geometric grid of u, each DAMPING_RATIO times the one before, the last where a
/// damping ratio reaches 1 (the first about 3e-5 of that).
const DAMPING_POINTS: usize = 16;
const DAMPING_RATIO: f64 = 2.0;
/// Relative distance below the value at which a damping ratio reaches 1 tabulated up to.
const SATURATION_MARGIN: f64 = 1e-9;
/// Most Illinois steps on a fixed point.
const FIXED_POINT_STEPS: usize = 100;
/// Most steps bracketing a fixed point between grid points.
const BRACKET_STEPS: usize = 64;
/// A secant step is taken up to this multiple of 003's step.
const MAX_ACCELERATION: f64 = 4.0;
/// Bisection steps locating the fold where the branch ends between two grid points.
const FOLD_STEPS: usize = 12;
/// The chatter frequency is solved to this fraction of the depth tolerance.
const FREQUENCY_FRACTION: f64 = 1e-2;

/// The eigenvalue branches of a [`LobeTable`] under process damping of growing strength, for
/// the process-damped lobes at any speed.
#[derive(Debug, Clone, PartialEq)]
pub struct ProcessDampedTable<'a> {
    table: Cow<'a, LobeTable>,
    slopes_per_m: Vec<f64>,
    options: ZeroOrderOptions,
    /// The grid of u (m, at unit scale), ascending.
    u: Vec<f64>,
    /// Per grid point, branch and u: the eigenvalue (NaN where none) and K = u (-2 Re Lambda).
    lambda: Vec<Complex64>,
    k: Vec<f64>,
    /// Per grid point and branch: the largest K.
    k_max: Vec<f64>,
}

/// A solved point of the branch: its phase and depth, and the eigenvalue there.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Solved {
    phase: LobePhase,
    lambda: Complex64,
}

/// Where K first reaches the scale at one grid point and branch: the bracket of the grid of u
/// (as depths, with h there), a lower bound of the depth (the bracket's lower end, or below the
/// grid, where the added damping is negligible, the interpolated depth), the interpolated depth
/// and the interpolated eigenvalue.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Estimate {
    bound_m: f64,
    depth_m: f64,
    lambda: Complex64,
    lower: (f64, f64),
    upper: (f64, f64),
}

/// The process-damped branch at one scale.
struct AtScale<'t, 'a> {
    damped: &'t ProcessDampedTable<'a>,
    scale: f64,
    estimates: [Vec<Option<Estimate>>; 2],
    phases: [Vec<OnceCell<Option<LobePhase>>>; 2],
    solved: [Vec<OnceCell<Option<Solved>>>; 2],
    segments: Segments,
}

impl<'a> ProcessDampedTable<'a> {
    /// The table of `table` under the damping ratios zeta_n + b c s_n at scale c, with
    /// s_n = `slopes_per_m` (one per mode, >= 0, at least one > 0) the slopes at unit scale.
    pub fn new(
        table: &'a LobeTable,
        slopes_per_m: &[f64],
        options: &ZeroOrderOptions,
    ) -> Result<Self> {
        Self::build(Cow::Borrowed(table), slopes_per_m, options)
    }

    /// [`Self::new`] owning its table (for a solver prepared once per model).
    pub fn owning(
        table: LobeTable,
        slopes_per_m: &[f64],
        options: &ZeroOrderOptions,
    ) -> Result<ProcessDampedTable<'static>> {
        ProcessDampedTable::build(Cow::Owned(table), slopes_per_m, options)
    }

    /// The underlying table without process damping.
    pub fn table(&self) -> &LobeTable {
        &self.table
    }

    fn build(
        table: Cow<'a, LobeTable>,
        slopes_per_m: &[f64],
        options: &ZeroOrderOptions,
    ) -> Result<Self> {
        options.validate()?;
        let modes = table.system().modes();
        if slopes_per_m.len() != modes.len() {
            return invalid(
                "slopes_per_m",
                slopes_per_m.len() as f64,
                "one process-damping slope per mode",
            );
        }
        if let Some(&s) = slopes_per_m.iter().find(|s| !(s.is_finite() && **s >= 0.0)) {
            return invalid("slopes_per_m", s, "process-damping slopes >= 0");
        }
        let saturation = modes
            .iter()
            .zip(slopes_per_m)
            .filter(|(_, s)| **s > 0.0)
            .map(|(m, s)| (1.0 - m.damping_ratio) / s * (1.0 - SATURATION_MARGIN))
            .fold(f64::INFINITY, f64::min);
        if !(saturation.is_finite() && saturation > 0.0) {
            return invalid(
                "slopes_per_m",
                saturation,
                "a positive slope of a mode with damping ratio < 1",
            );
        }
        let u: Vec<f64> = (0..DAMPING_POINTS)
            .map(|i| saturation * DAMPING_RATIO.powi(i as i32 + 1 - DAMPING_POINTS as i32))
            .collect();
        let mut out = Self {
            table,
            slopes_per_m: slopes_per_m.to_vec(),
            options: *options,
            u,
            lambda: Vec::new(),
            k: Vec::new(),
            k_max: Vec::new(),
        };
        out.tabulate();
        Ok(out)
    }

    /// The process damping of depth `depth_m` at unit scale.
    fn added(&self, depth_m: f64) -> AddedDamping<'_> {
        AddedDamping {
            slopes_per_m: &self.slopes_per_m,
            depth_m,
        }
    }

    /// Index of grid point `j`, branch `branch`, u index `i`.
    fn at(&self, j: usize, branch: usize, i: usize) -> usize {
        (j * 2 + branch) * self.u.len() + i
    }

    /// K and the eigenvalues over the grid of u at every grid point, followed from zero damping.
    fn tabulate(&mut self) {
        let n = self.u.len();
        let len = self.table.len() * 2 * n;
        let mut lambda = vec![Complex64::new(f64::NAN, f64::NAN); len];
        let mut k = vec![f64::NEG_INFINITY; len];
        for j in 0..self.table.len() {
            let (w, mut followed) = self.table.grid_point(j);
            for (i, &u) in self.u.iter().enumerate() {
                let Some(pair) = self.table.system().eigenvalues(w, self.added(u)) else {
                    break;
                };
                followed = pair.matched(&followed);
                for branch in 0..2 {
                    let at = self.at(j, branch, i);
                    lambda[at] = followed.0[branch];
                    if followed.is_lobe(branch) {
                        k[at] = -2.0 * u * followed.0[branch].re;
                    }
                }
            }
        }
        self.k_max = k
            .chunks(n)
            .map(|c| c.iter().copied().fold(f64::NEG_INFINITY, f64::max))
            .collect();
        self.lambda = lambda;
        self.k = k;
    }

    /// The `count` lowest process-damped lobes at delay `delay_s` (s) with the slopes multiplied
    /// by `scale` (e.g. C / V), lowest first. Points deeper than `max_depth_m` are no lobe.
    pub fn lobes(&self, delay_s: f64, scale: f64, count: usize) -> Result<Vec<Lobe>> {
        if !(scale.is_finite() && scale >= 0.0) {
            return invalid("scale", scale, "a process-damping scale >= 0");
        }
        if scale == 0.0 {
            return self.table.lobes(delay_s, count);
        }
        let points = AtScale::new(self, scale);
        let mut lobes = self.table.lowest_at(delay_s, count, &points)?;
        let below = match lobes.get(count.saturating_sub(1)) {
            Some(l) => l.depth_m,
            None => self.options.max_depth_m,
        };
        for lobe in points.fold_lobes(delay_s, below) {
            insert(&mut lobes, lobe, count, SAME_CROSSING);
        }
        let slopes: Vec<f64> = self.slopes_per_m.iter().map(|s| s * scale).collect();
        if let Some(zero) = self.table.system().zero_depth_lobe(delay_s, &slopes) {
            insert(&mut lobes, zero, count, SAME_CROSSING);
        }
        Ok(lobes)
    }

    /// Where K first reaches `scale` at grid point `j` on `branch`, up to the depth ceiling.
    fn estimate(&self, j: usize, branch: usize, scale: f64) -> Option<Estimate> {
        if self.k_max[j * 2 + branch] < scale {
            return None;
        }
        let from = self.at(j, branch, 0);
        let k = &self.k[from..from + self.u.len()];
        let i = k.iter().position(|k| *k >= scale)?;
        let depth = |i: usize| self.u[i] / scale;
        let h = |i: usize| match self.k[from + i] {
            k if k > f64::NEG_INFINITY => depth(i) + 0.5 / self.lambda[from + i].re,
            _ => f64::NEG_INFINITY,
        };
        // below the grid, u from 0 with b0 the depth without process damping
        let (lower, u_lower, g_lower, lambda_lower) = match i.checked_sub(1) {
            Some(l) => (
                (depth(l), h(l)),
                self.u[l],
                k[l] / self.u[l],
                self.lambda[from + l],
            ),
            None => {
                let bare = self.table.grid_point(j).1;
                let b0 = bare.lobe(branch).map_or(f64::INFINITY, |l| l.depth_m);
                ((0.0, -b0), 0.0, 1.0 / b0, bare.0[branch])
            }
        };
        // u g(u) = scale with g = K / u = -2 Re Lambda linear in u over the interval:
        // m u^2 + c u - scale = 0 (where the lower end is no lobe, g = 0 there)
        let g_lower = g_lower.max(0.0);
        let m = (k[i] / self.u[i] - g_lower) / (self.u[i] - u_lower);
        let c = g_lower - m * u_lower;
        let root = 2.0 * scale / (c + (c * c + 4.0 * m * scale).sqrt());
        let t = match (root - u_lower) / (self.u[i] - u_lower) {
            t if (0.0..=1.0).contains(&t) => t,
            _ => 1.0,
        };
        let estimate = lower.0 + t * (depth(i) - lower.0);
        (estimate <= self.options.max_depth_m).then_some(Estimate {
            // near a tangency of b and 003's map the interpolation is poor; the bracket is not
            bound_m: if i > 0 { lower.0 } else { estimate },
            depth_m: estimate,
            lambda: lambda_lower + (self.lambda[from + i] - lambda_lower) * t,
            lower,
            upper: (depth(i), h(i)),
        })
    }

    /// b(w) at `w` (rad/s) from `start` (m) following the eigenvalue closest to `reference`:
    /// the Illinois method on h in `bracket` when given, else steps from `start` until
    /// bracketed; None where none is found below the ceiling.
    fn fixed_point(
        &self,
        w: f64,
        scale: f64,
        start: f64,
        bracket: Option<Bracket>,
        reference: Complex64,
    ) -> Option<Solved> {
        let system = self.table.system();
        let tolerance = self.options.relative_tolerance;
        let max = self
            .options
            .max_depth_m
            .min(self.u[self.u.len() - 1] / scale);
        let followed = Cell::new(reference);
        // the last depth evaluated and its eigenvalues
        let last = Cell::new(None);
        // h(b) = b + 1 / (2 Re Lambda(w; b)): -inf where there is no lobe, 0 within the
        // tolerance
        let h = |b: f64| {
            let Some(pair) = system.eigenvalues(w, self.added(scale * b)) else {
                return f64::NEG_INFINITY;
            };
            let branch = pair.closest(followed.get());
            let lambda = pair.0[branch];
            followed.set(lambda);
            last.set(Some((b, pair, branch)));
            match b + 0.5 / lambda.re {
                _ if !pair.is_lobe(branch) => f64::NEG_INFINITY,
                v if v.abs() <= tolerance * b => 0.0,
                v => v,
            }
        };
        let b = match bracket.or_else(|| march(&h, start.min(max), max)) {
            Some(b) if b.f_positive == 0.0 => b.positive,
            Some(b) => {
                let Ok(root) = illinois(b, tolerance, FIXED_POINT_STEPS, |x| {
                    Ok::<_, Infallible>(h(x))
                });
                if root.f_positive <= -root.f_negative {
                    root.positive
                } else {
                    root.negative
                }
            }
            None => return None,
        };
        if last.get().is_none_or(|l| l.0 != b) {
            h(b);
        }
        let (_, pair, branch) = last.get()?;
        pair.lobe(branch)
            .filter(|p| p.depth_m <= self.options.max_depth_m)
            .map(|phase| Solved {
                phase,
                lambda: pair.0[branch],
            })
    }
}

/// A bracket of a root of `h` from `x`: steps x - h(x) (003's iteration, monotone towards the
/// nearest root from either side where 1 / (2 |Re Lambda|) grows with the damping) or secant
/// steps through the last two points where those go further, up to `max`. None where a step
/// moves h away from zero (no root that way) or leaves `max`.
fn march(h: &impl Fn(f64) -> f64, mut x: f64, max: f64) -> Option<Bracket> {
    let mut hx = h(x);
    let mut previous: Option<(f64, f64)> = None;
    for _ in 0..BRACKET_STEPS {
        if hx == 0.0 {
            return Some(Bracket::new((x, f64::NEG_INFINITY), (x, 0.0)));
        }
        if !hx.is_finite() {
            return None;
        }
        let toward = x - hx;
        let mut next = toward;
        if let Some((xp, hp)) = previous {
            let (step, secant) = (toward - x, -hx * (x - xp) / (hx - hp));
            if secant * step > 0.0 && secant.abs() > step.abs() {
                let limit = MAX_ACCELERATION * step.abs();
                next = x + secant.clamp(-limit, limit);
            }
        }
        let mut hn = f64::NAN;
        for candidate in [next, toward] {
            next = candidate.min(max);
            if next == x {
                return None;
            }
            hn = h(next);
            let closer = if hx < 0.0 { hn > hx } else { hn < hx };
            if closer || (hn < 0.0) != (hx < 0.0) {
                break;
            }
            if candidate == toward {
                return None;
            }
        }
        if (hn < 0.0) != (hx < 0.0) {
            return Some(if hx < 0.0 {
                Bracket::new((x, hx), (next, hn))
            } else {
                Bracket::new((next, hn), (x, hx))
            });
        }
        previous = Some((x, hx));
        (x, hx) = (next, hn);
    }
    None
}

impl<'t, 'a> AtScale<'t, 'a> {
    fn new(damped: &'t ProcessDampedTable<'a>, scale: f64) -> Self {
        let n = damped.table.len();
        let estimates: [Vec<Option<Estimate>>; 2] =
            [0, 1].map(|b| (0..n).map(|j| damped.estimate(j, b, scale)).collect());
        let depths = [0, 1].map(|b| estimates[b].iter().map(|e| e.map(|e| e.bound_m)).collect());
        Self {
            damped,
            scale,
            estimates,
            phases: [0, 1].map(|_| (0..n).map(|_| OnceCell::new()).collect()),
            solved: [0, 1].map(|_| (0..n).map(|_| OnceCell::new()).collect()),
            segments: segments(&depths, EARLY_SEGMENTS),
        }
    }

    /// The lobes shallower than `below` (m) at delay `tau` that cross between a grid point and
    /// the fold where the branch ends before the next one: there the two roots of h meet and
    /// b(w) stays finite, so such a lobe can be low. The fold is found by bisection in w,
    /// following the branch from the grid point.
    fn fold_lobes(&self, tau: f64, below: f64) -> Vec<Lobe> {
        let table = &*self.damped.table;
        let mut out = Vec::new();
        for (branch, estimates) in self.estimates.iter().enumerate() {
            for j in 0..estimates.len().saturating_sub(1) {
                let (kept, gone) = match (estimates[j], estimates[j + 1]) {
                    (Some(e), None) if e.depth_m < below => (j, j + 1),
                    (None, Some(e)) if e.depth_m < below => (j + 1, j),
                    _ => continue,
                };
                let Some(first) = self.solved(kept, branch) else {
                    continue;
                };
                let w_first = table.grid_point(kept).0;
                let (mut w_last, mut last, mut w_gone) = (w_first, first, table.grid_point(gone).0);
                for _ in 0..FOLD_STEPS {
                    let w = 0.5 * (w_last + w_gone);
                    let found = self.damped.fixed_point(
                        w,
                        self.scale,
                        last.phase.depth_m,
                        None,
                        last.lambda,
                    );
                    match found {
                        Some(s) => (w_last, last) = (w, s),
                        None => w_gone = w,
                    }
                }
                let p = |w: f64, s: Solved| (w * tau - s.phase.eps) / (2.0 * PI);
                let (p_first, p_last) = (p(w_first, first), p(w_last, last));
                let (lo, hi) = (p_first.min(p_last).max(0.0), p_first.max(p_last));
                // the seeds between the grid point and the fold, interpolated
                let point = |w: f64| {
                    let t = (w - w_first) / (w_last - w_first);
                    let depth =
                        first.phase.depth_m + t * (last.phase.depth_m - first.phase.depth_m);
                    let lambda = first.lambda + (last.lambda - first.lambda) * t;
                    self.damped
                        .fixed_point(w, self.scale, depth, None, lambda)
                        .map(|s| s.phase)
                };
                for index in (lo.ceil() as usize)..=(hi.floor() as usize) {
                    let k = index as f64;
                    let ends = [
                        (w_first, 2.0 * PI * (p_first - k)),
                        (w_last, 2.0 * PI * (p_last - k)),
                    ];
                    out.extend(
                        crossing(tau, index, ends, point, self.frequency_tolerance())
                            .filter(|l| l.depth_m < below),
                    );
                }
            }
        }
        out
    }

    /// b(w) solved exactly at grid point `j` on `branch` (once).
    fn solved(&self, j: usize, branch: usize) -> Option<Solved> {
        *self.solved[branch][j].get_or_init(|| {
            let e = self.estimates[branch][j]?;
            let w = self.damped.table.grid_point(j).0;
            let bracket = Bracket::new(e.lower, e.upper);
            self.damped
                .fixed_point(w, self.scale, e.bound_m, Some(bracket), e.lambda)
        })
    }
}

impl BranchPoints for AtScale<'_, '_> {
    fn at_grid(&self, j: usize, branch: usize) -> Option<LobePhase> {
        // the lower bound, with the phase of the interpolated eigenvalue
        *self.phases[branch][j].get_or_init(|| {
            let e = self.estimates[branch][j]?;
            let eps = 2.0 * e.lambda.arg() - PI;
            Some(LobePhase {
                eps: if eps < 0.0 { eps + 4.0 * PI } else { eps },
                depth_m: e.bound_m,
            })
        })
    }

    fn exact_at_grid(&self, j: usize, branch: usize) -> Option<LobePhase> {
        self.solved(j, branch).map(|s| s.phase)
    }

    fn between(&self, j: usize, branch: usize, w: f64) -> Option<LobePhase> {
        let (a, b) = (self.solved(j, branch)?, self.solved(j + 1, branch)?);
        let t = self.damped.table.fraction(j, w);
        let guess = a.phase.depth_m + t * (b.phase.depth_m - a.phase.depth_m);
        let reference = a.lambda + (b.lambda - a.lambda) * t;
        self.damped
            .fixed_point(w, self.scale, guess, None, reference)
            .map(|s| s.phase)
    }

    fn segments(&self) -> &Segments {
        &self.segments
    }

    fn frequency_tolerance(&self) -> f64 {
        (FREQUENCY_FRACTION * self.damped.options.relative_tolerance).max(FREQUENCY_TOLERANCE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::process_damping::damping_ratio_slopes_per_cv;
    use crate::zero_order::table::MARGIN;
    use crate::zero_order::{OrientedSystem, tests::two_mode_milling};
    use chatter_dynamics::{Milling, MillingDirection, Operation, examples};

    /// The depths the crossing search orders by are lower bounds of the solved ones (within
    /// rounding) at every grid point up to twice the lowest, over speeds and process-damping
    /// strengths, so the search misses no lower lobe.
    #[test]
    fn estimates_are_lower_bounds() {
        let cutter = Milling::new(4, 0.2, MillingDirection::Down, Some(0.01905), None).unwrap();
        let schmitz = examples::schmitz_2023_milling()
            .with_operation(Operation::Milling(cutter))
            .unwrap();
        for (model, c) in [
            (schmitz.clone(), 3e4),
            (schmitz, 2e5),
            (two_mode_milling(Some(0.01905), None), 1e5),
        ] {
            let model = model.with_process_damping(Some(c)).unwrap();
            let table = LobeTable::new(OrientedSystem::from_model(&model).unwrap());
            let slopes = damping_ratio_slopes_per_cv(&model);
            let options = ZeroOrderOptions::unbounded();
            let damped = ProcessDampedTable::new(&table, &slopes, &options).unwrap();
            let mut worst: f64 = 0.0;
            for i in 0..40 {
                let speed = 600.0 * 1.08f64.powi(i);
                let at = AtScale::new(&damped, model.process_damping_per_width(speed));
                let pairs: Vec<(f64, f64)> = (0..table.len())
                    .flat_map(|j| [0, 1].map(|b| (j, b)))
                    .filter_map(|(j, b)| {
                        Some((at.estimates[b][j]?.bound_m, at.solved(j, b)?.phase.depth_m))
                    })
                    .collect();
                let lowest = pairs.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
                for (bound, exact) in pairs.into_iter().filter(|p| p.1 <= 2.0 * lowest) {
                    worst = worst.max(bound / exact - 1.0);
                }
            }
            assert!(worst < MARGIN / 30.0, "C {c}: {worst}");
        }
    }
}
