//! The CSV tables and plot series the commands write from the jobs' typed outcomes: one writer
//! per table, shared by the command that computes it and by `chatter demo`. A leaf module (it
//! imports no command), so no two commands import each other.

use crate::plot::{Markers, Series};
use chatter_dynamics::Observations;
use chatter_jobs::bands::MonteCarloBands;
use chatter_jobs::frf::FrfOutcome;
use chatter_jobs::lobes::LobeMap;
use chatter_stability::boundary::{BoundaryOptions, LobePoint};
use chatter_uncertainty::geometric::OffsetBoundaries;
use chatter_uncertainty::montecarlo::StabilityMap;
use chatter_uncertainty::perturbation::{BoundRule, CredibilityPoint};
use plotters::style::{BLUE, GREEN, RGBColor};
use std::fmt::Write as _;

/// An optional cell: empty when absent.
fn cell(v: Option<f64>) -> String {
    v.map(|x| x.to_string()).unwrap_or_default()
}

/// The observed cuts as plot markers (o stable, x chatter).
pub fn markers(obs: Option<&Observations>) -> Option<Markers> {
    obs.map(|o| Markers {
        stable: o
            .cuts
            .iter()
            .filter(|c| c.stable)
            .map(|c| (c.speed_rpm, c.depth_mm))
            .collect(),
        unstable: o
            .cuts
            .iter()
            .filter(|c| !c.stable)
            .map(|c| (c.speed_rpm, c.depth_mm))
            .collect(),
    })
}

/// The lobes as CSV; a speed without a limit below the depth ceiling has empty depth and
/// chatter cells (see [`warn_unbounded`]).
pub fn lobes_csv(lobes: &[LobePoint]) -> String {
    let mut csv = String::from("speed_rpm,depth_mm,chatter_hz\n");
    for p in lobes {
        if p.depth_m.is_finite() {
            let _ = writeln!(csv, "{},{},{}", p.speed_rpm, p.depth_mm(), p.chatter_hz);
        } else {
            let _ = writeln!(csv, "{},,", p.speed_rpm);
        }
    }
    csv
}

/// A warning on stderr with the number of speeds that have no limit, and what became of them
/// (`fate`, e.g. "their depth_mm and chatter_hz cells are empty").
pub fn warn_unbounded(lobes: &[LobePoint], fate: &str) {
    let unbounded = chatter_jobs::lobes::unbounded_count(lobes);
    if unbounded > 0 {
        eprintln!(
            "warning: {unbounded} of {} speeds have no stability limit below the depth ceiling \
             of {} mm; {fate}",
            lobes.len(),
            BoundaryOptions::default().max_depth_m * 1e3
        );
    }
}

/// CSV `speed_rpm,depth_mm,modulus` of a |mu| map, one row per grid point.
pub fn map_csv(map: &LobeMap) -> String {
    let mut out = String::from("speed_rpm,depth_mm,modulus\n");
    for (s, row) in map.speeds_rpm.iter().zip(&map.grid) {
        for (b, m) in map.depths_m.iter().zip(row) {
            let _ = writeln!(out, "{s},{},{m}", b * 1e3);
        }
    }
    out
}

/// CSV of Type B offsets (001): per mean-boundary point the lower and upper boundaries at its
/// speed (`lower_mm`, `upper_mm`, from the gap-filled, loop-free polylines), Eq. 2's angle
/// `theta_deg` and Eq. 1's distance `distance` (rpm / um units), and the raw roots of Eq. 10-11
/// (`upper_speed_rpm`, `upper_depth_mm`, `lower_speed_rpm`, `lower_depth_mm`), unmodified.
pub fn geometric_csv(bands: &OffsetBoundaries) -> String {
    let mut csv = String::from(
        "speed_rpm,depth_mm,lower_mm,upper_mm,theta_deg,distance,upper_speed_rpm,\
         upper_depth_mm,lower_speed_rpm,lower_depth_mm\n",
    );
    for p in &bands.points {
        let lo = OffsetBoundaries::depth_at(&bands.lower, p.speed_rpm);
        let up = OffsetBoundaries::depth_at(&bands.upper, p.speed_rpm);
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{}",
            p.speed_rpm,
            p.depth_mm,
            cell(lo),
            cell(up),
            p.theta_deg,
            p.distance,
            p.upper.0,
            p.upper.1,
            p.lower.0,
            p.lower.1
        );
    }
    csv
}

/// A mean boundary with a lower and an upper curve, for plotting.
pub fn band_series(
    mean: Vec<(f64, f64)>,
    lower: Vec<(f64, f64)>,
    upper: Vec<(f64, f64)>,
    labels: [&str; 3],
) -> [Series; 3] {
    let line = |label: &str, points: Vec<(f64, f64)>, color: RGBColor| Series {
        label: label.into(),
        points,
        color,
        dashed: false,
    };
    [
        line(labels[0], mean, BLUE),
        line(labels[1], lower, RGBColor(200, 0, 0)),
        line(labels[2], upper, GREEN),
    ]
}

/// Credibility bounds (second-order perturbation of the dominant multiplier, Ahmadi 2022 Eq.
/// 14-18, `chatter_jobs::bands::perturbation`) under `rule` as CSV
/// `speed_rpm,depth_mm,lower_mm,upper_mm` (empty cells where a contour is not reached on the
/// grid) and the plot series, broken (NaN) at those speeds so no line is drawn across a gap.
pub fn credibility_bands(bounds: &[CredibilityPoint], rule: BoundRule) -> (String, [Series; 3]) {
    let mut csv = String::from("speed_rpm,depth_mm,lower_mm,upper_mm\n");
    for b in bounds {
        let _ = writeln!(
            csv,
            "{},{},{},{}",
            b.speed_rpm,
            cell(b.depth_mm),
            cell(b.lower_mm),
            cell(b.upper_mm)
        );
    }
    let pick = |f: fn(&CredibilityPoint) -> Option<f64>| {
        bounds
            .iter()
            .map(|b| (b.speed_rpm, f(b).unwrap_or(f64::NAN)))
            .collect::<Vec<_>>()
    };
    let (mean, lower, upper) = match rule {
        BoundRule::ComplexSd => (
            "limit of the mean multiplier".to_string(),
            "lower: mean + 1 sd reaches 1".to_string(),
            "upper: mean - 1 sd reaches 1".to_string(),
        ),
        BoundRule::Coverage(c) => {
            let p = 100.0 * c;
            (
                "limit of the mean modulus".to_string(),
                format!("lower ({p:.0} %)"),
                format!("upper ({p:.0} %)"),
            )
        }
    };
    let series = band_series(
        pick(|b| b.depth_mm),
        pick(|b| b.lower_mm),
        pick(|b| b.upper_mm),
        [&mean, &lower, &upper],
    );
    (csv, series)
}

/// Monte Carlo quantiles per speed: the median limit between the 5 % and 95 % quantiles and
/// the chatter-frequency quantiles.
pub fn montecarlo_csv(mc: &MonteCarloBands) -> String {
    let mut csv = String::from(
        "speed_rpm,depth_mm,lower_mm,upper_mm,chatter_hz_q05,chatter_hz_q50,chatter_hz_q95\n",
    );
    for (d, f) in mc.depth.iter().zip(&mc.chatter_hz) {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{}",
            d.speed_rpm, d.q50, d.q05, d.q95, f.q05, f.q50, f.q95
        );
    }
    csv
}

/// A probability-of-stability map as CSV `speed_rpm,depth_mm,p_stable`.
pub fn stability_map_csv(map: &StabilityMap) -> String {
    let mut text = String::from("speed_rpm,depth_mm,p_stable\n");
    for (s, row) in map.speeds_rpm.iter().zip(&map.p_stable) {
        for (b, p) in map.depths_mm.iter().zip(row) {
            let _ = writeln!(text, "{s},{b},{p}");
        }
    }
    text
}

/// A receptance as CSV `frequency_hz,real_m_per_n,imag_m_per_n,magnitude_m_per_n`.
pub fn frf_csv(g: &FrfOutcome) -> String {
    let mut csv = String::from("frequency_hz,real_m_per_n,imag_m_per_n,magnitude_m_per_n\n");
    for (f, r) in g.frequencies_hz.iter().zip(&g.receptance_m_per_n) {
        let _ = writeln!(csv, "{f},{:e},{:e},{:e}", r.re, r.im, r.norm());
    }
    csv
}
