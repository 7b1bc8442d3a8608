//! Default spindle-speed and depth grids: the one home of the defaults every front end uses.
//!
//! Speeds: [`lobe_speeds_rpm`] resolves every lobe; [`default_speeds_rpm`] and
//! [`even_lobe_speeds_rpm`] are 200 evenly spaced speeds over the same range
//! ([`lobe_range_rpm`]). Depths: [`depth_grid`] up to 1.5 times the deepest limit
//! ([`deepest_limit_m`]), [`depth_grid_to`] to any top, [`covering_depths_mm`] around every lobe.
//!
//! The lobes of a mode f (Hz) at z delays per revolution lie at lobe numbers
//! N = 60 f / (z n) (n in rpm), one lobe per unit of N, so in speed they crowd together as
//! n^2 z / (60 f) at low speed. An evenly spaced speed grid that resolves the top lobe aliases
//! the low ones (seed 000's turning tool: 200 speeds over 6000-60 000 rpm are 270 rpm apart
//! against lobes ~330 rpm apart at 7000 rpm). This grid is evenly spaced in N instead, so every
//! lobe gets the same number of points.

use crate::boundary::{LobePoint, dominant_mode_frequency_hz};
use chatter_dynamics::ModalModel;
use chatter_dynamics::grid::evenly_spaced;

/// Speeds per unit lobe number of [`lobe_speeds_rpm`].
pub const POINTS_PER_LOBE: f64 = 20.0;
/// Fewest and most speeds of [`lobe_speeds_rpm`].
pub const SPEED_COUNT_RANGE: (usize, usize) = (200, 2000);

/// Number of speeds of [`default_speeds_rpm`] and [`even_lobe_speeds_rpm`].
pub const DEFAULT_SPEED_COUNT: usize = 200;
/// The deepest depth of [`depth_grid`] as a multiple of the deepest limit.
pub const DEPTH_GRID_TOP: f64 = 1.5;

/// The speed range (min, max) in rpm of the lobes of a mode at `frequency_hz` with
/// `delays_per_revolution` delays per revolution (z): from a tenth of the top to
/// 1.2 f x 60 / z rpm (lobe numbers ~1 to 10), the top capped at 60 000 rpm.
pub fn lobe_range_rpm(frequency_hz: f64, delays_per_revolution: f64) -> (f64, f64) {
    let max = (60.0 * frequency_hz / delays_per_revolution * 1.2).min(60_000.0);
    (max / 10.0, max)
}

/// [`DEFAULT_SPEED_COUNT`] speeds evenly spaced over [`lobe_range_rpm`] (a measured model's
/// default, with its receptance peak for the mode).
pub fn even_lobe_speeds_rpm(frequency_hz: f64, delays_per_revolution: f64) -> Vec<f64> {
    let (min, max) = lobe_range_rpm(frequency_hz, delays_per_revolution);
    evenly_spaced(min, max, DEFAULT_SPEED_COUNT)
}

/// [`even_lobe_speeds_rpm`] of the model's dominant mode ([`dominant_mode_frequency_hz`]).
pub fn default_speeds_rpm(model: &ModalModel) -> Vec<f64> {
    even_lobe_speeds_rpm(
        dominant_mode_frequency_hz(model),
        model.operation().delays_per_revolution() as f64,
    )
}

/// `count` depths from 1 / `count` to [`DEPTH_GRID_TOP`] times `deepest` (in the unit of
/// `deepest`): the default depth grid of maps and bands over lobes whose deepest finite limit
/// is `deepest` ([`deepest_limit_m`]).
pub fn depth_grid(deepest: f64, count: usize) -> Vec<f64> {
    depth_grid_to(DEPTH_GRID_TOP * deepest, count)
}

/// `count` depths `top` j / `count`, j = 1..=`count` (in the unit of `top`): zero left out, the
/// top included. The one depth-grid rule of the workspace; [`depth_grid`] is its default top.
pub fn depth_grid_to(top: f64, count: usize) -> Vec<f64> {
    (1..=count).map(|j| top * j as f64 / count as f64).collect()
}

/// The deepest finite limiting depth (m) of `lobes`; `None` when no speed has a limit below
/// the depth ceiling.
pub fn deepest_limit_m(lobes: &[LobePoint]) -> Option<f64> {
    let deepest = lobes
        .iter()
        .map(|p| p.depth_m)
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max);
    (deepest > 0.0).then_some(deepest)
}

/// Depths (mm) from half the lowest to 1.4 times the highest finite limit of `lobes`,
/// `step_mm` apart: the contours around every lobe, its top included, lie on the grid (the
/// credibility bounds of `chatter demo`). `None` when no speed has a finite limit.
pub fn covering_depths_mm(lobes: &[LobePoint], step_mm: f64) -> Option<Vec<f64>> {
    let finite = lobes.iter().map(|p| p.depth_mm()).filter(|d| d.is_finite());
    let (lo, hi) = finite.fold((f64::INFINITY, 0.0f64), |(a, b), d| (a.min(d), b.max(d)));
    if !(lo.is_finite() && hi > 0.0) {
        return None;
    }
    let (from, to) = (0.5 * lo, 1.4 * hi);
    let n = ((to - from) / step_mm).ceil() as usize;
    Some((0..=n).map(|j| from + step_mm * j as f64).collect())
}

/// Speeds over [`lobe_range_rpm`] of the dominant mode f_d ([`dominant_mode_frequency_hz`]),
/// evenly spaced in the lobe number N = 60 f_d / (z n): [`POINTS_PER_LOBE`] per lobe, within
/// [`SPEED_COUNT_RANGE`]; ascending.
pub fn lobe_speeds_rpm(model: &ModalModel) -> Vec<f64> {
    let f = dominant_mode_frequency_hz(model);
    let z = model.operation().delays_per_revolution() as f64;
    let (min, max) = lobe_range_rpm(f, z);
    let lobe = |n: f64| 60.0 * f / (z * n);
    let (lo, hi) = (lobe(max), lobe(min));
    let count = ((POINTS_PER_LOBE * (hi - lo)).ceil() as usize)
        .clamp(SPEED_COUNT_RANGE.0, SPEED_COUNT_RANGE.1);
    (0..count)
        .map(|i| {
            let n_lobe = hi - (hi - lo) * i as f64 / (count - 1) as f64;
            60.0 * f / (z * n_lobe)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    /// Seed 000's turning tool: ascending from 6000 to 60 000 rpm, and at 7000 rpm the speeds
    /// are at most a twentieth of the lobe spacing apart.
    #[test]
    fn turning_lobes_are_resolved() {
        let model = examples::ahmadi_2022_turning();
        let s = lobe_speeds_rpm(&model);
        assert!(s.windows(2).all(|w| w[1] > w[0]));
        assert!((s[s.len() - 1] - 60_000.0).abs() < 1e-6 && (s[0] - 6000.0).abs() < 1e-6);
        let f = dominant_mode_frequency_hz(&model);
        let i = s.iter().position(|&n| n > 7000.0).unwrap();
        let lobe_spacing = 7000.0_f64.powi(2) / (60.0 * f);
        assert!(
            s[i] - s[i - 1] <= lobe_spacing / 19.0,
            "{} vs {lobe_spacing}",
            s[i] - s[i - 1]
        );
    }
}
