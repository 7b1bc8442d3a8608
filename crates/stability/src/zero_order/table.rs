//! Lobe crossings at any delay from the eigenvalue branches tabulated once per system.
//!
//! The branches Lambda_1,2(w) of an [`OrientedSystem`] are tabulated on a frequency grid
//! concentrated at the resonances (sinh-spaced points around each natural frequency plus a coarse
//! geometric grid over [f_min / 2, 2 f_max], the range of chatter frequencies considered) and
//! followed by continuity. Where a branch enters or leaves Re(Lambda) < 0 between two points, the
//! edge is located by bisection and a point just inside it is added, so no part of a lobe is
//! lost between grid points.
//!
//! At a delay tau, lobe k crosses where the phase residual psi(w) = w tau - eps(w) - 2 pi k
//! changes sign (module docs of [`crate::zero_order`]); on a grid segment these are the integers
//! between p = (w tau - eps) / 2 pi at its ends. Their depths are estimated by interpolating
//! 1 / b (smooth where b is not), and the crossings are refined in the order of the estimates by
//! the Illinois method on psi, until the estimates exceed the wanted lobes by a margin. The
//! branch points (eps, b) come from a [`BranchPoints`]: the eigenvalue itself, or with process
//! damping the fixed point of module `damped`, solved on the same grid at each speed.

use super::Lobe;
use super::system::{AddedDamping, EigenPair, LobePhase, OrientedSystem};
use crate::error::{Result, invalid};
use crate::root::{Bracket, illinois};
use num_complex::Complex64;
use std::f64::consts::PI;

/// Points of the sinh-spaced grid around each natural frequency.
const MODE_POINTS: usize = 40;
/// Points of the geometric grid over the whole range.
const GLOBAL_POINTS: usize = 32;
/// Range of the grid relative to the lowest and highest natural frequency.
const GRID_LOW: f64 = 0.5;
const GRID_HIGH: f64 = 2.0;
/// The sinh grid: f_n (1 + 2 zeta_n sinh(u)) for u in [SINH_FROM, SINH_TO] (about -6 to +16
/// half-power bandwidths).
const SINH_FROM: f64 = -2.5;
const SINH_TO: f64 = 3.5;
/// Damping ratio floor of the sinh grid's width.
const MIN_GRID_DAMPING: f64 = 1e-4;
/// Segments put in order at the front of a search at one speed; it rarely needs more.
pub(crate) const EARLY_SEGMENTS: usize = 32;
/// Bisection steps locating the edge of a lobe region between two grid points.
const EDGE_STEPS: usize = 16;
/// Crossings whose estimate exceeds the wanted depth by more than this fraction are not
/// refined (the estimates' interpolation error stays well inside it; see the tests).
pub(crate) const MARGIN: f64 = 0.3;
/// Crossings of one lobe index closer than this (relative) are one.
pub(crate) const SAME_CROSSING: f64 = 1e-9;
/// Most segments a crossing is followed from where its estimate put it.
const MAX_WALK: usize = 16;
/// Relative tolerance and most steps of a crossing's chatter frequency.
pub(crate) const FREQUENCY_TOLERANCE: f64 = 1e-11;
const FREQUENCY_STEPS: usize = 60;

/// A grid segment on which a branch is a lobe at both ends, with the lower of their depths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Segment {
    lower_depth_m: f64,
    start: usize,
    branch: usize,
}

/// Segments, the first `sorted` of them the lowest and in order.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Segments {
    list: Vec<Segment>,
    sorted: usize,
}

/// The segments on which a branch is a lobe at both ends, from the depths (m) per branch and
/// grid point (None where no lobe): the `sorted` lowest first and in order, then the rest in any
/// order.
pub(crate) fn segments(depths: &[Vec<Option<f64>>; 2], sorted: usize) -> Segments {
    let mut out: Vec<Segment> = (0..2)
        .flat_map(|branch| {
            let d = &depths[branch];
            (0..d.len().saturating_sub(1)).filter_map(move |start| match (d[start], d[start + 1]) {
                (Some(a), Some(b)) => Some(Segment {
                    lower_depth_m: a.min(b),
                    start,
                    branch,
                }),
                _ => None,
            })
        })
        .collect();
    let by_depth = |a: &Segment, b: &Segment| a.lower_depth_m.total_cmp(&b.lower_depth_m);
    if out.len() > sorted {
        out.select_nth_unstable_by(sorted, by_depth);
    }
    let sorted = out.len().min(sorted);
    out[..sorted].sort_by(by_depth);
    Segments { list: out, sorted }
}

/// A lobe crossing located on a segment, with its interpolated depth.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Candidate {
    estimate_m: f64,
    segment: Segment,
    index: usize,
}

/// The branch points (eps, b) the lobes are crossings of.
pub(crate) trait BranchPoints {
    /// The point of `branch` at grid point `j`, possibly estimated (for the crossing search).
    fn at_grid(&self, j: usize, branch: usize) -> Option<LobePhase>;
    /// The point of `branch` at grid point `j` solved exactly (for refining crossings).
    fn exact_at_grid(&self, j: usize, branch: usize) -> Option<LobePhase> {
        self.at_grid(j, branch)
    }
    /// The point of `branch` at `w` (rad/s) inside the segment from grid point `j`.
    fn between(&self, j: usize, branch: usize, w: f64) -> Option<LobePhase>;
    /// The segments.
    fn segments(&self) -> &Segments;
    /// Relative tolerance of a crossing's chatter frequency.
    fn frequency_tolerance(&self) -> f64;
}

/// The eigenvalues themselves (structural damping only).
struct Structural<'a>(&'a LobeTable);

impl BranchPoints for Structural<'_> {
    fn at_grid(&self, j: usize, branch: usize) -> Option<LobePhase> {
        self.0.lobes[branch][j]
    }

    fn between(&self, j: usize, branch: usize, w: f64) -> Option<LobePhase> {
        let t = self.0;
        let reference = t.interpolated(j, branch, w);
        let pair = t.system.eigenvalues(w, AddedDamping::NONE)?;
        pair.lobe(pair.closest(reference))
    }

    fn segments(&self) -> &Segments {
        &self.0.segments
    }

    fn frequency_tolerance(&self) -> f64 {
        FREQUENCY_TOLERANCE
    }
}

/// The eigenvalue branches of one system on a frequency grid, ready for lobe crossings at any
/// delay (spindle speed).
#[derive(Debug, Clone, PartialEq)]
pub struct LobeTable {
    system: OrientedSystem,
    omega_rad_s: Vec<f64>,
    pairs: Vec<EigenPair>,
    /// Lobe point of each branch at each grid point.
    lobes: [Vec<Option<LobePhase>>; 2],
    /// All in order of the lower depth.
    segments: Segments,
}

/// `n` points from `from` to `to` in geometric progression.
fn geometric(from: f64, to: f64, n: usize) -> impl Iterator<Item = f64> {
    let ratio = (to / from).powf(1.0 / (n - 1) as f64);
    std::iter::successors(Some(from), move |x| Some(x * ratio)).take(n)
}

/// The grid (rad/s): geometric over the range plus sinh-spaced around every mode, sorted.
fn frequency_grid(system: &OrientedSystem) -> Vec<f64> {
    let (f_min, f_max) = system.frequency_span_hz();
    let (lo, hi) = (2.0 * PI * GRID_LOW * f_min, 2.0 * PI * GRID_HIGH * f_max);
    let mut w: Vec<f64> = geometric(lo, hi, GLOBAL_POINTS).collect();
    // sinh(u) = (e^u - e^-u) / 2 on the evenly spaced u
    let sinh: Vec<f64> = geometric(SINH_FROM.exp(), SINH_TO.exp(), MODE_POINTS)
        .map(|e| 0.5 * (e - 1.0 / e))
        .collect();
    for m in system.modes() {
        let zeta = m.damping_ratio.max(MIN_GRID_DAMPING);
        w.extend(
            sinh.iter()
                .map(|s| m.omega_rad_s * (1.0 + 2.0 * zeta * s))
                .filter(|v| *v > lo && *v < hi),
        );
    }
    w.sort_by(f64::total_cmp);
    w.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * *b);
    w
}

/// The ordered grid points just inside the lobe regions that begin or end between `from` and
/// `to` (on either branch).
fn region_edges(
    system: &OrientedSystem,
    from: (f64, EigenPair),
    to: (f64, EigenPair),
) -> Vec<(f64, EigenPair)> {
    let mut edges = Vec::new();
    for branch in 0..2 {
        let inside_from = from.1.is_lobe(branch);
        if inside_from == to.1.is_lobe(branch) {
            continue;
        }
        let (mut a, mut c) = (from, to);
        for _ in 0..EDGE_STEPS {
            let mid = 0.5 * (a.0 + c.0);
            let Some(pair) = system.eigenvalues(mid, AddedDamping::NONE) else {
                break;
            };
            let pair = pair.matched(&a.1);
            if pair.is_lobe(branch) == inside_from {
                a = (mid, pair);
            } else {
                c = (mid, pair);
            }
        }
        edges.push(if inside_from { a } else { c });
    }
    edges.sort_by(|x, y| x.0.total_cmp(&y.0));
    edges
}

/// Check a delay (s).
fn check_delay(delay_s: f64) -> Result<f64> {
    if delay_s.is_finite() && delay_s > 0.0 {
        Ok(delay_s)
    } else {
        invalid("delay_s", delay_s, "a delay > 0")
    }
}

/// Insert `lobe` into the ascending `best`, keeping at most `count` and no repeated crossing
/// (the same lobe index at a chatter frequency within `tolerance`, relative).
pub(crate) fn insert(best: &mut Vec<Lobe>, lobe: Lobe, count: usize, tolerance: f64) {
    let repeated = best.iter().any(|l| {
        l.index == lobe.index
            && (l.chatter_hz - lobe.chatter_hz).abs() <= tolerance * lobe.chatter_hz
    });
    if !repeated {
        let at = best.partition_point(|l| l.depth_m <= lobe.depth_m);
        best.insert(at, lobe);
        best.truncate(count);
    }
}

impl LobeTable {
    /// Tabulate the branches of `system`.
    pub fn new(system: OrientedSystem) -> Self {
        let mut omega_rad_s = Vec::new();
        let mut pairs: Vec<EigenPair> = Vec::new();
        for w in frequency_grid(&system) {
            let Some(pair) = system.eigenvalues(w, AddedDamping::NONE) else {
                continue;
            };
            if let (Some(&w0), Some(&p0)) = (omega_rad_s.last(), pairs.last()) {
                let pair = pair.matched(&p0);
                for (we, pe) in region_edges(&system, (w0, p0), (w, pair)) {
                    omega_rad_s.push(we);
                    pairs.push(pe);
                }
                omega_rad_s.push(w);
                pairs.push(pair);
            } else {
                omega_rad_s.push(w);
                pairs.push(pair);
            }
        }
        let lobes = [0, 1].map(|b| pairs.iter().map(|p| p.lobe(b)).collect::<Vec<_>>());
        let depths = [0, 1].map(|b| lobes[b].iter().map(|p| p.map(|p| p.depth_m)).collect());
        let segments = segments(&depths, usize::MAX);
        Self {
            system,
            omega_rad_s,
            pairs,
            lobes,
            segments,
        }
    }

    /// The tabulated system.
    pub fn system(&self) -> &OrientedSystem {
        &self.system
    }

    /// Grid points.
    pub(crate) fn len(&self) -> usize {
        self.omega_rad_s.len()
    }

    /// Grid point `j`: its frequency (rad/s) and eigenvalue pair.
    pub(crate) fn grid_point(&self, j: usize) -> (f64, EigenPair) {
        (self.omega_rad_s[j], self.pairs[j])
    }

    /// The position of `w` (rad/s) in the segment from grid point `j`, 0 to 1.
    pub(crate) fn fraction(&self, j: usize, w: f64) -> f64 {
        (w - self.omega_rad_s[j]) / (self.omega_rad_s[j + 1] - self.omega_rad_s[j])
    }

    /// The eigenvalue of `branch` interpolated at `w` in the segment from grid point `j`.
    pub(crate) fn interpolated(&self, j: usize, branch: usize, w: f64) -> Complex64 {
        let (a, b) = (self.pairs[j].0[branch], self.pairs[j + 1].0[branch]);
        a + (b - a) * self.fraction(j, w)
    }

    /// The `count` lowest lobes at delay `delay_s` (s) with the structural damping, lowest
    /// first (fewer where fewer lobes cross).
    pub fn lobes(&self, delay_s: f64, count: usize) -> Result<Vec<Lobe>> {
        let mut lobes = self.lowest_at(delay_s, count, &Structural(self))?;
        if let Some(zero) = self.system.zero_depth_lobe(delay_s, &[]) {
            insert(&mut lobes, zero, count, SAME_CROSSING);
        }
        Ok(lobes)
    }

    /// The `count` lowest lobes of the branch `points` at delay `delay_s` (s).
    pub(crate) fn lowest_at(
        &self,
        delay_s: f64,
        count: usize,
        points: &impl BranchPoints,
    ) -> Result<Vec<Lobe>> {
        Ok(self.lowest(check_delay(delay_s)?, count, points))
    }

    /// The `count` lowest lobes of the branch `points` at `tau`, lowest first.
    fn lowest(&self, tau: f64, count: usize, points: &impl BranchPoints) -> Vec<Lobe> {
        let mut best: Vec<Lobe> = Vec::with_capacity(count + 1);
        if count == 0 {
            return best;
        }
        // `best` never holds more than `count`
        let threshold = |best: &Vec<Lobe>| best.get(count - 1).map_or(f64::INFINITY, |l| l.depth_m);
        let (mut candidates, mut limit) = self.candidates(tau, count, f64::INFINITY, points);
        let mut done = f64::NEG_INFINITY;
        loop {
            for c in candidates.iter().filter(|c| c.estimate_m > done) {
                if c.estimate_m > threshold(&best) * (1.0 + MARGIN) {
                    return best;
                }
                if let Some(lobe) = self.refine(tau, c, points) {
                    insert(&mut best, lobe, count, SAME_CROSSING);
                }
            }
            // the lobes came out higher than estimated: look further
            let needed = threshold(&best) * (1.0 + MARGIN);
            if needed <= limit || limit == f64::INFINITY {
                return best;
            }
            done = limit;
            (candidates, limit) = self.candidates(tau, 0, needed, points);
        }
    }

    /// The crossings at `tau` with estimates at most `bound` and, for `count` > 0, at most the
    /// margin above the count-th lowest estimate, ascending, with the limit that applied.
    fn candidates(
        &self,
        tau: f64,
        count: usize,
        bound: f64,
        points: &impl BranchPoints,
    ) -> (Vec<Candidate>, f64) {
        let mut out = Vec::new();
        let mut lowest: Vec<f64> = Vec::with_capacity(count + 1);
        let mut limit = bound;
        let segments = points.segments();
        for (i, &segment) in segments.list.iter().enumerate() {
            if segment.lower_depth_m > limit {
                if i < segments.sorted {
                    break;
                }
                continue;
            }
            let (j, branch) = (segment.start, segment.branch);
            let (Some(a), Some(b)) = (points.at_grid(j, branch), points.at_grid(j + 1, branch))
            else {
                continue;
            };
            // a jump of eps by more than pi is a switch of branches, not a lobe
            if (a.eps - b.eps).abs() > PI {
                continue;
            }
            let p0 = (self.omega_rad_s[j] * tau - a.eps) / (2.0 * PI);
            let p1 = (self.omega_rad_s[j + 1] * tau - b.eps) / (2.0 * PI);
            let (lo, hi) = (p0.min(p1), p0.max(p1));
            if p0 == p1 || hi < 0.0 {
                continue;
            }
            // (truncation is the floor of the non-negative, cheaper than floor and ceil here)
            let last = hi as usize;
            let first = match lo.max(0.0) {
                l if (l as usize) as f64 == l => l as usize,
                l => l as usize + 1,
            };
            for index in first..=last {
                let t = (index as f64 - p0) / (p1 - p0);
                // a crossing at the segment's end belongs to the next segment
                if !(0.0..1.0).contains(&t) {
                    continue;
                }
                let estimate_m = 1.0 / ((1.0 - t) / a.depth_m + t / b.depth_m);
                if estimate_m > limit {
                    continue;
                }
                out.push(Candidate {
                    estimate_m,
                    segment,
                    index,
                });
                if count > 0 {
                    let at = lowest.partition_point(|x| *x <= estimate_m);
                    lowest.insert(at, estimate_m);
                    lowest.truncate(count);
                    if lowest.len() == count {
                        limit = limit.min(lowest[count - 1] * (1.0 + MARGIN));
                    }
                }
            }
        }
        out.retain(|c| c.estimate_m <= limit);
        out.sort_by(|x, y| x.estimate_m.total_cmp(&y.estimate_m));
        (out, limit)
    }

    /// The exact crossing of a candidate: the Illinois method on psi over its segment, or a
    /// nearby segment where the exact points move the crossing there. None where the branch
    /// leaves the lobe region.
    fn refine(&self, tau: f64, c: &Candidate, points: &impl BranchPoints) -> Option<Lobe> {
        let branch = c.segment.branch;
        let k = c.index as f64;
        let psi_at = |j: usize| {
            let p = points.exact_at_grid(j, branch)?;
            Some(self.omega_rad_s[j] * tau - p.eps - 2.0 * PI * k)
        };
        let mut j = c.segment.start;
        let (mut psi0, mut psi1) = (psi_at(j)?, psi_at(j + 1)?);
        // psi grows with w: walk towards its sign change where the estimate put it off
        for _ in 0..MAX_WALK {
            if psi0 > 0.0 && psi1 > 0.0 && psi0 < psi1 && j > 0 {
                j -= 1;
                (psi0, psi1) = (psi_at(j)?, psi0);
            } else if psi0 < 0.0 && psi1 < 0.0 && psi0 < psi1 && j + 2 < self.omega_rad_s.len() {
                j += 1;
                (psi0, psi1) = (psi1, psi_at(j + 1)?);
            } else {
                break;
            }
        }
        let ends = [(self.omega_rad_s[j], psi0), (self.omega_rad_s[j + 1], psi1)];
        crossing(
            tau,
            c.index,
            ends,
            |w| points.between(j, branch, w),
            points.frequency_tolerance(),
        )
    }
}

/// The crossing of lobe `index` at delay `tau` between `ends` (w rad/s, psi there), solved by the
/// Illinois method on psi(w) = w tau - eps(w) - 2 pi index with the branch `point` to the
/// relative frequency `tolerance`; None where psi does not change sign between the ends or the
/// branch ends inside.
pub(crate) fn crossing(
    tau: f64,
    index: usize,
    ends: [(f64, f64); 2],
    point: impl Fn(f64) -> Option<LobePhase>,
    tolerance: f64,
) -> Option<Lobe> {
    let k = index as f64;
    let psi = |w: f64| point(w).map(|p| w * tau - p.eps - 2.0 * PI * k);
    let [(w0, psi0), (w1, psi1)] = ends;
    let w = if psi0 == 0.0 {
        w0
    } else {
        let bracket = match (psi0 < 0.0, psi1 < 0.0) {
            (true, false) => Bracket::new((w0, psi0), (w1, psi1)),
            (false, true) => Bracket::new((w1, psi1), (w0, psi0)),
            _ => return None,
        };
        let root = illinois(bracket, tolerance, FREQUENCY_STEPS, |w| psi(w).ok_or(())).ok()?;
        if root.f_positive <= -root.f_negative {
            root.positive
        } else {
            root.negative
        }
    };
    point(w).map(|p| Lobe {
        depth_m: p.depth_m,
        chatter_hz: w / (2.0 * PI),
        index,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    /// The interpolated depths of the crossings up to twice the lowest are within a third of
    /// [`MARGIN`] of the solved ones at 300 speeds per model, so the margin never hides a lower
    /// lobe.
    #[test]
    fn estimates_stay_well_inside_the_margin() {
        for (model, from_rpm) in [
            (examples::schmitz_2023_milling(), 1000.0),
            (examples::ahmadi_2022_turning(), 500.0),
            (examples::insperger_benchmark(0.05), 2000.0),
            (examples::ebrahimi_2025_milling(), 1000.0),
        ] {
            let table = LobeTable::new(OrientedSystem::from_model(&model).unwrap());
            let mut worst: f64 = 0.0;
            for i in 0..300 {
                let speed = from_rpm * 1.01f64.powi(i);
                let tau = model.operation().delay_s(speed);
                let points = Structural(&table);
                let (candidates, _) = table.candidates(tau, 0, f64::INFINITY, &points);
                let solved: Vec<(f64, f64)> = candidates
                    .iter()
                    .map(|c| (c.estimate_m, table.refine(tau, c, &points).unwrap().depth_m))
                    .collect();
                let lowest = solved.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
                for (estimate, depth) in solved.into_iter().filter(|s| s.1 <= 2.0 * lowest) {
                    worst = worst.max((estimate / depth - 1.0).abs());
                }
            }
            assert!(worst < MARGIN / 3.0, "{worst}");
        }
    }
}
