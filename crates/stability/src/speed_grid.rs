//! Default spindle-speed grids that resolve every lobe.
//!
//! The lobes of a mode f (Hz) at z delays per revolution lie at lobe numbers
//! N = 60 f / (z n) (n in rpm), one lobe per unit of N, so in speed they crowd together as
//! n^2 z / (60 f) at low speed. An evenly spaced speed grid that resolves the top lobe aliases
//! the low ones (seed 000's turning tool: 200 speeds over 6000-60 000 rpm are 270 rpm apart
//! against lobes ~330 rpm apart at 7000 rpm). This grid is evenly spaced in N instead, so every
//! lobe gets the same number of points.

use crate::boundary::dominant_mode_frequency_hz;
use chatter_dynamics::ModalModel;

/// Speeds per unit lobe number of [`lobe_speeds_rpm`].
pub const POINTS_PER_LOBE: f64 = 20.0;
/// Fewest and most speeds of [`lobe_speeds_rpm`].
pub const SPEED_COUNT_RANGE: (usize, usize) = (200, 2000);

/// Speeds from a tenth of the top to 1.2 f_d x 60 / z rpm (f_d the dominant mode,
/// [`dominant_mode_frequency_hz`]; capped at 60 000 rpm), evenly spaced in the lobe number
/// N = 60 f_d / (z n): [`POINTS_PER_LOBE`] per lobe, within [`SPEED_COUNT_RANGE`]; ascending.
pub fn lobe_speeds_rpm(model: &ModalModel) -> Vec<f64> {
    let f = dominant_mode_frequency_hz(model);
    let z = model.operation().delays_per_revolution() as f64;
    let max = (60.0 * f / z * 1.2).min(60_000.0);
    let min = max / 10.0;
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
