//! The numerical example of Schmitz (2023, seed 001, Sec. 4) and what its text states about it,
//! beside ours: zero-order lobes of the 4-tooth, 20 % down-milling example
//! ([`chatter_dynamics::examples::schmitz_2023_milling`]) on a 10 rpm grid from 4000 to 14 000 rpm,
//! offset by o_Omega = 100 rpm and o_b = 0.2 mm (Eq. 1-11).
//!
//! The text gives no table; Figs. 6-10 are not in the extracted copy. What it states (Sec. 4):
//! local maxima of the boundary (the cusps where lobes meet) at 5660 and 11 298 rpm, where theta
//! approaches 90 deg (Figs. 7, 9) and d approaches o_Omega = 100 (Figs. 8, 10); a local minimum
//! at 6960 rpm, where theta approaches 0 and d approaches o_b = 200 um; the offset boundaries are
//! the two roots of Eq. 10-11, so at the minimum they lie o_b above and below the mean boundary,
//! and at a cusp about o_Omega to either side. [`checks`] compares each with a tolerance:
//! - speeds of the extremes: 1 % (the figures are read at about that precision);
//! - theta at a cusp: 5 deg from 90 (the steepest grid segment meeting the cusp; on a 10 rpm grid
//!   an independent zero-order solution reaches 88.1 deg at 5660 rpm and 88.3 deg at 11 290 rpm);
//!   theta at the minimum: 1 deg from 0;
//! - d and the roots' offsets: 5 % of o_Omega at a cusp (Eq. 1 gives d <= 105 for theta >= 79.4
//!   deg), 1 % of o_b at the minimum.
//!
//! Reproduced by `cargo run --release -p chatter-uncertainty --example schmitz2023` and in
//! `chatter demo` (`papers.csv`); held by `tests/schmitz2023.rs`.

use super::{OffsetBoundaries, PointOffset, TypeBOffsets, type_b_offsets};
use crate::error::Result;
use chatter_dynamics::examples;
use chatter_stability::zero_order::zoa_lobes;

/// The example's offsets (Sec. 4): speed (rpm) and depth (mm).
pub const OFFSETS: (f64, f64) = (100.0, 0.2);
/// The extremes the text names: (speed rpm, a local maximum).
pub const EXTREMES: [(f64, bool); 3] = [(5660.0, true), (11_298.0, true), (6960.0, false)];

/// The speed grid: 4000 to 14 000 rpm in 10 rpm steps.
pub fn speeds_rpm() -> Vec<f64> {
    (0..=1000).map(|i| 4000.0 + 10.0 * f64::from(i)).collect()
}

/// The example's zero-order mean boundary on [`speeds_rpm`] (finite limits only) and its Type B
/// offsets by [`OFFSETS`].
pub fn example_boundaries() -> Result<OffsetBoundaries> {
    let lobes = zoa_lobes(&examples::schmitz_2023_milling(), &speeds_rpm())?;
    let curve: Vec<(f64, f64)> = lobes
        .iter()
        .filter(|p| p.depth_m.is_finite())
        .map(|p| (p.speed_rpm, p.depth_mm()))
        .collect();
    type_b_offsets(&curve, TypeBOffsets::new(OFFSETS.0, OFFSETS.1)?)
}

/// One stated result of the paper beside ours.
#[derive(Debug, Clone, PartialEq)]
pub struct PaperCheck {
    /// What is compared, with its unit.
    pub quantity: String,
    /// The paper's value.
    pub paper: f64,
    /// Ours.
    pub ours: f64,
    /// Allowed |ours - paper| (in the quantity's unit).
    pub tolerance: f64,
}

impl PaperCheck {
    /// Within the tolerance.
    pub fn within(&self) -> bool {
        (self.ours - self.paper).abs() <= self.tolerance
    }
}

/// Index of the boundary's largest (`max`) or smallest depth within 5 % of `near` rpm.
fn extreme(points: &[PointOffset], near: f64, max: bool) -> Option<usize> {
    (0..points.len())
        .filter(|&i| (points[i].speed_rpm - near).abs() <= 0.05 * near)
        .max_by(|&a, &b| {
            let (x, y) = (points[a].depth_mm, points[b].depth_mm);
            if max {
                x.total_cmp(&y)
            } else {
                y.total_cmp(&x)
            }
        })
}

/// The paper's statements of Sec. 4 (see the [module documentation](self)) checked on `bands`,
/// the offsets of the example's mean boundary by [`OFFSETS`] ([`example_boundaries`]): per
/// extreme its speed, theta and d of the point whose segment (Eq. 2: the point and the next one)
/// is the steepest of the three nearest a cusp (the two meeting at the grid's maximum and the
/// next, as the cusp lies between grid points) or the flatter of the two meeting at the minimum,
/// and the offset
/// of the two Eq. 10-11 roots from that point, in speed at a cusp and in depth at the minimum.
pub fn checks(bands: &OffsetBoundaries) -> Vec<PaperCheck> {
    let p = &bands.points;
    let (o_rpm, o_mm) = OFFSETS;
    let mut out = Vec::new();
    for (near, max) in EXTREMES {
        let what = if max { "maximum (cusp)" } else { "minimum" };
        let row = |quantity: String, paper: f64, ours: f64, tolerance: f64| PaperCheck {
            quantity,
            paper,
            ours,
            tolerance,
        };
        let Some(i) = extreme(p, near, max) else {
            out.push(row(
                format!("speed of the lobe {what} near {near} rpm (rpm)"),
                near,
                f64::NAN,
                0.01 * near,
            ));
            continue;
        };
        out.push(row(
            format!("speed of the lobe {what} near {near} rpm (rpm)"),
            near,
            p[i].speed_rpm,
            0.01 * near,
        ));
        // the segments of points i - 1 and i meet at the extreme; a cusp falls between grid
        // points, so the segment of i may straddle it (mixing the two lobes) and the steep side
        // is that of i + 1
        let candidates = if max {
            vec![i.saturating_sub(1), i, (i + 1).min(p.len() - 1)]
        } else {
            vec![i.saturating_sub(1), i]
        };
        let j = candidates
            .into_iter()
            .max_by(|&a, &b| {
                let (x, y) = (p[a].theta_deg, p[b].theta_deg);
                if max {
                    x.total_cmp(&y)
                } else {
                    y.total_cmp(&x)
                }
            })
            .unwrap_or(i);
        let q = p[j];
        let at = format!("at the {what} near {near} rpm");
        if max {
            out.push(row(format!("theta {at} (deg)"), 90.0, q.theta_deg, 5.0));
            out.push(row(
                format!("d {at} (rpm)"),
                o_rpm,
                q.distance,
                0.05 * o_rpm,
            ));
            for (side, root) in [("upper", q.upper), ("lower", q.lower)] {
                out.push(row(
                    format!("speed shift of the {side} Eq. 10-11 root {at} (rpm)"),
                    o_rpm,
                    (root.0 - q.speed_rpm).abs(),
                    0.05 * o_rpm,
                ));
            }
        } else {
            out.push(row(format!("theta {at} (deg)"), 0.0, q.theta_deg, 1.0));
            out.push(row(
                format!("d {at} (um)"),
                1000.0 * o_mm,
                q.distance,
                10.0 * o_mm,
            ));
            for (side, root, sign) in [("upper", q.upper, 1.0), ("lower", q.lower, -1.0)] {
                out.push(row(
                    format!("depth shift of the {side} Eq. 10-11 root {at} (mm)"),
                    sign * o_mm,
                    root.1 - q.depth_mm,
                    0.01 * o_mm,
                ));
            }
        }
    }
    out
}
