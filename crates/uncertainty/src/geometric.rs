//! Geometric Type B offset boundaries around a stability lobe diagram (Schmitz 2023, seed 001,
//! Eq. 1-11).
//!
//! The user states how far they believe the boundary may be off: `o_Omega` in spindle speed (rpm)
//! and `o_b` in depth (mm). Each point 1 of the mean boundary is moved perpendicular to the
//! boundary, towards point 1a, by the Euclidean distance (Eq. 1-2)
//!
//! d = sqrt((o_b cos theta)^2 + (o_Omega sin theta)^2),  theta = atan(|b_2 - b_1| / (Omega_2 - Omega_1)),
//!
//! with 2 the next point of the boundary. Eq. 3-11 solve A . B = 0 and |B| = d for point 1a; the
//! two roots are the upper and lower offsets, P_1 +- d n with n the unit normal of segment 1-2
//! (this closed form is what Eq. 10-11 compute). As in the paper, depth is measured in micrometres
//! so that rpm and um have comparable scales; d is reported in those mixed units.
//!
//! # Cusps
//! Lobe diagrams have cusps where adjacent lobes meet (the local maxima of the boundary, where
//! theta approaches 90 deg). Offsetting point by point there leaves a gap on one side of the cusp
//! and a swallowtail loop on the other. The boundary polylines returned here close gaps with a
//! fan of points around the cusp (the normal rotated in steps, d re-evaluated from Eq. 1 at each
//! angle) and cut loops at their self-intersection, so the offset boundaries never cross
//! themselves. The per-point values (`theta`, `d`, the two roots) are the paper's, unmodified.

use crate::error::{Result, UncertaintyError};

pub mod schmitz2023;

/// Depth scale that makes rpm and depth comparable, as in 001: micrometres per millimetre.
pub const DEPTH_SCALE_UM_PER_MM: f64 = 1000.0;

/// User-selected Type B offsets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TypeBOffsets {
    offset_rpm: f64,
    offset_mm: f64,
}

impl TypeBOffsets {
    /// Offsets in speed (rpm) and depth (mm); both finite and >= 0, not both zero.
    pub fn new(offset_rpm: f64, offset_mm: f64) -> Result<Self> {
        for (field, v) in [("offset_rpm", offset_rpm), ("offset_mm", offset_mm)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(UncertaintyError::InvalidInput {
                    field: if field == "offset_rpm" {
                        "offset_rpm"
                    } else {
                        "offset_mm"
                    },
                    message: format!("{v}; expected a finite offset >= 0"),
                });
            }
        }
        if offset_rpm == 0.0 && offset_mm == 0.0 {
            return Err(UncertaintyError::InvalidInput {
                field: "offset_rpm",
                message: "both offsets are zero; give at least one positive offset".into(),
            });
        }
        Ok(Self {
            offset_rpm,
            offset_mm,
        })
    }

    /// The speed offset o_Omega (rpm).
    pub fn offset_rpm(&self) -> f64 {
        self.offset_rpm
    }

    /// The depth offset o_b (mm).
    pub fn offset_mm(&self) -> f64 {
        self.offset_mm
    }

    /// Eq. 1: the offset distance (rpm / um units) for a boundary angle `theta_rad`.
    pub fn distance(&self, theta_rad: f64) -> f64 {
        let ob = self.offset_mm * DEPTH_SCALE_UM_PER_MM;
        ((ob * theta_rad.cos()).powi(2) + (self.offset_rpm * theta_rad.sin()).powi(2)).sqrt()
    }
}

/// The paper's per-point result for one point of the mean boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointOffset {
    /// Mean-boundary speed (rpm).
    pub speed_rpm: f64,
    /// Mean-boundary depth (mm).
    pub depth_mm: f64,
    /// Eq. 2 angle in degrees, in [0, 90].
    pub theta_deg: f64,
    /// Eq. 1 distance in rpm / um units.
    pub distance: f64,
    /// Upper root of Eq. 10-11: (speed rpm, depth mm).
    pub upper: (f64, f64),
    /// Lower root of Eq. 10-11: (speed rpm, depth mm).
    pub lower: (f64, f64),
}

/// Offset boundaries around a mean boundary.
#[derive(Debug, Clone, PartialEq)]
pub struct OffsetBoundaries {
    /// Per-point values of Eq. 1-11 (one per input point).
    pub points: Vec<PointOffset>,
    /// Upper boundary polyline (speed rpm, depth mm), cusp gaps filled and loops removed.
    pub upper: Vec<(f64, f64)>,
    /// Lower boundary polyline (speed rpm, depth mm), cusp gaps filled and loops removed.
    pub lower: Vec<(f64, f64)>,
}

impl OffsetBoundaries {
    /// Depth (mm) of a boundary polyline at `speed_rpm` by linear interpolation; the smallest
    /// value if the polyline crosses that speed several times, `None` outside its range.
    pub fn depth_at(polyline: &[(f64, f64)], speed_rpm: f64) -> Option<f64> {
        polyline
            .windows(2)
            .filter_map(|w| {
                let ((x0, y0), (x1, y1)) = (w[0], w[1]);
                let (lo, hi) = if x0 <= x1 { (x0, x1) } else { (x1, x0) };
                if speed_rpm < lo || speed_rpm > hi {
                    return None;
                }
                if (x1 - x0).abs() < 1e-300 {
                    return Some(y0.min(y1));
                }
                Some(y0 + (y1 - y0) * (speed_rpm - x0) / (x1 - x0))
            })
            .min_by(f64::total_cmp)
    }
}

/// Offsets of a mean boundary given as (speed rpm, depth mm) points with strictly increasing
/// speed (Eq. 1-11 applied point by point; see the module docs for cusps).
///
/// ```
/// use chatter_uncertainty::geometric::{type_b_offsets, TypeBOffsets};
/// let line = [(1000.0, 1.0), (2000.0, 1.0), (3000.0, 1.0)];
/// let b = type_b_offsets(&line, TypeBOffsets::new(100.0, 0.2).unwrap()).unwrap();
/// // a flat boundary moves by o_b straight up and down
/// assert!((b.points[0].upper.1 - 1.2).abs() < 1e-12);
/// assert!((b.points[0].lower.1 - 0.8).abs() < 1e-12);
/// ```
pub fn type_b_offsets(curve: &[(f64, f64)], offsets: TypeBOffsets) -> Result<OffsetBoundaries> {
    if curve.len() < 2 {
        return Err(UncertaintyError::InvalidInput {
            field: "curve",
            message: format!("{} points; at least 2 expected", curve.len()),
        });
    }
    for (i, &(s, b)) in curve.iter().enumerate() {
        if !(s.is_finite() && b.is_finite()) {
            return Err(UncertaintyError::InvalidInput {
                field: "curve",
                message: format!("point {i} is not finite ({s}, {b})"),
            });
        }
        if i > 0 && s <= curve[i - 1].0 {
            return Err(UncertaintyError::InvalidInput {
                field: "curve",
                message: format!("speeds must increase strictly; point {i} has {s} rpm"),
            });
        }
    }
    let scaled: Vec<(f64, f64)> = curve
        .iter()
        .map(|&(s, b)| (s, b * DEPTH_SCALE_UM_PER_MM))
        .collect();
    // Segment angles (Eq. 2, signed slope kept for the normal) and unit normals.
    let segments: Vec<Segment> = scaled
        .windows(2)
        .map(|w| Segment::new(w[0], w[1]))
        .collect();
    let n = curve.len();
    let points: Vec<PointOffset> = (0..n)
        .map(|i| {
            let seg = segments[i.min(n - 2)];
            let d = offsets.distance(seg.theta);
            let p = scaled[i];
            let up = (p.0 + d * seg.normal.0, p.1 + d * seg.normal.1);
            let lo = (p.0 - d * seg.normal.0, p.1 - d * seg.normal.1);
            PointOffset {
                speed_rpm: curve[i].0,
                depth_mm: curve[i].1,
                theta_deg: seg.theta.to_degrees(),
                distance: d,
                upper: unscale(up),
                lower: unscale(lo),
            }
        })
        .collect();
    let upper = offset_polyline(&scaled, &segments, offsets, 1.0);
    let lower = offset_polyline(&scaled, &segments, offsets, -1.0);
    Ok(OffsetBoundaries {
        points,
        upper: upper.into_iter().map(unscale).collect(),
        lower: lower.into_iter().map(unscale).collect(),
    })
}

#[derive(Debug, Clone, Copy)]
struct Segment {
    /// Eq. 2 angle in [0, pi/2].
    theta: f64,
    /// Unit normal pointing to larger depth.
    normal: (f64, f64),
}

impl Segment {
    fn new(p1: (f64, f64), p2: (f64, f64)) -> Self {
        let (ax, ay) = (p2.0 - p1.0, p2.1 - p1.1);
        let len = ax.hypot(ay);
        Self {
            theta: (ay.abs() / ax).atan(),
            normal: (-ay / len, ax / len),
        }
    }
}

fn unscale(p: (f64, f64)) -> (f64, f64) {
    (p.0, p.1 / DEPTH_SCALE_UM_PER_MM)
}

/// Angle step of the fan that fills a gap at a corner of the mean boundary.
const FAN_STEP_RAD: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// Offset polyline on one side (`sign` +1 upper, -1 lower): both segment normals at every
/// interior vertex, a fan between them, then loops cut at self-intersections.
fn offset_polyline(
    pts: &[(f64, f64)],
    segments: &[Segment],
    offsets: TypeBOffsets,
    sign: f64,
) -> Vec<(f64, f64)> {
    let at = |p: (f64, f64), normal: (f64, f64), theta: f64| {
        let d = sign * offsets.distance(theta);
        (p.0 + d * normal.0, p.1 + d * normal.1)
    };
    let mut out = Vec::with_capacity(pts.len() * 2);
    out.push(at(pts[0], segments[0].normal, segments[0].theta));
    for i in 1..pts.len() - 1 {
        let (a, b) = (segments[i - 1], segments[i]);
        let angle_a = a.normal.1.atan2(a.normal.0);
        let mut turn = b.normal.1.atan2(b.normal.0) - angle_a;
        if turn > std::f64::consts::PI {
            turn -= 2.0 * std::f64::consts::PI;
        } else if turn < -std::f64::consts::PI {
            turn += 2.0 * std::f64::consts::PI;
        }
        let steps = (turn.abs() / FAN_STEP_RAD).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let ang = angle_a + turn * k as f64 / steps as f64;
            let normal = (ang.cos(), ang.sin());
            // the boundary angle that has this normal: theta = atan(|n_x| / n_y)
            let theta = (normal.0.abs() / normal.1.abs().max(1e-300)).atan();
            out.push(at(pts[i], normal, theta));
        }
    }
    let last = segments[segments.len() - 1];
    out.push(at(pts[pts.len() - 1], last.normal, last.theta));
    remove_loops(out)
}

/// Cut every loop of a polyline at its self-intersection (the furthest later segment that crosses
/// the current one), so the result is a simple curve.
fn remove_loops(mut p: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    let mut i = 0;
    while i + 3 < p.len() {
        let hit = ((i + 2)..p.len() - 1)
            .rev()
            .find_map(|j| intersection(p[i], p[i + 1], p[j], p[j + 1]).map(|x| (j, x)));
        if let Some((j, x)) = hit {
            p.splice(i + 1..=j, [x]);
        }
        i += 1;
    }
    p
}

/// Proper intersection point of segments ab and cd.
fn intersection(a: (f64, f64), b: (f64, f64), c: (f64, f64), d: (f64, f64)) -> Option<(f64, f64)> {
    let r = (b.0 - a.0, b.1 - a.1);
    let s = (d.0 - c.0, d.1 - c.1);
    let den = r.0 * s.1 - r.1 * s.0;
    if den.abs() < 1e-300 {
        return None;
    }
    let qp = (c.0 - a.0, c.1 - a.1);
    let t = (qp.0 * s.1 - qp.1 * s.0) / den;
    let u = (qp.0 * r.1 - qp.1 * r.0) / den;
    let eps = 1e-12;
    if t > eps && t < 1.0 - eps && u > eps && u < 1.0 - eps {
        Some((a.0 + t * r.0, a.1 + t * r.1))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn simple(p: &[(f64, f64)]) -> bool {
        for i in 0..p.len() - 1 {
            for j in i + 2..p.len() - 1 {
                if intersection(p[i], p[i + 1], p[j], p[j + 1]).is_some() {
                    return false;
                }
            }
        }
        true
    }

    #[test]
    fn steep_segment_moves_by_speed_offset() {
        // theta -> 90 deg: d -> o_Omega (Eq. 1)
        let line = [(1000.0, 0.0), (1000.001, 5.0)];
        let b = type_b_offsets(&line, TypeBOffsets::new(100.0, 0.2).unwrap()).unwrap();
        assert!((b.points[0].theta_deg - 90.0).abs() < 1e-3);
        assert!((b.points[0].distance - 100.0).abs() < 1e-3);
    }

    #[test]
    fn cusp_offsets_do_not_self_cross() {
        // two lobes meeting at a sharp cusp at 2000 rpm
        let curve: Vec<(f64, f64)> = (0..=80)
            .map(|i| {
                let s = 1000.0 + 25.0 * i as f64;
                let lobe = |c: f64| 1.0 + ((s - c) / 400.0).powi(2);
                (s, lobe(1500.0).min(lobe(2600.0)))
            })
            .collect();
        let b = type_b_offsets(&curve, TypeBOffsets::new(100.0, 0.2).unwrap()).unwrap();
        assert!(simple(&b.upper), "upper offset crosses itself");
        assert!(simple(&b.lower), "lower offset crosses itself");
        // lower lies below and upper above the mean everywhere inside the range
        for &(s, depth) in &curve[2..curve.len() - 2] {
            let lo = OffsetBoundaries::depth_at(&b.lower, s).unwrap();
            assert!(lo < depth, "lower {lo} not below mean {depth} at {s}");
        }
    }

    #[test]
    fn rejects_bad_curves() {
        let o = TypeBOffsets::new(100.0, 0.2).unwrap();
        assert!(type_b_offsets(&[(1.0, 1.0)], o).is_err());
        assert!(type_b_offsets(&[(2.0, 1.0), (1.0, 1.0)], o).is_err());
        assert!(type_b_offsets(&[(1.0, f64::NAN), (2.0, 1.0)], o).is_err());
        assert!(TypeBOffsets::new(-1.0, 0.2).is_err());
        assert!(TypeBOffsets::new(0.0, 0.0).is_err());
    }
}
