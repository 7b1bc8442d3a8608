//! Seed 001 numerical example with offsets 100 rpm and 0.2 mm (Section 4, Figs. 7-10).
#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples;
use chatter_stability::zero_order::zoa_lobes;
use chatter_uncertainty::geometric::{TypeBOffsets, type_b_offsets};

/// Near the lobe maxima (about 5660 and 11298 rpm) theta approaches 90 deg and d the speed offset
/// (100 rpm); at the minimum near 6960 rpm theta approaches 0 and d the depth offset (200 um).
/// Tolerances: theta > 80 deg and d within 10 % of 100 at the point of steepest rise next to each
/// peak; theta < 5 deg and d within 2 % of 200 at the pocket.
#[test]
fn theta_and_distance_at_peaks_and_pocket() {
    let model = examples::schmitz_2023_milling();
    let speeds: Vec<f64> = (0..=2000).map(|i| 4500.0 + 4.0 * i as f64).collect();
    let lobes = zoa_lobes(&model, &speeds).unwrap();
    let curve: Vec<(f64, f64)> = lobes.iter().map(|p| (p.speed_rpm, p.depth_mm())).collect();
    let b = type_b_offsets(&curve, TypeBOffsets::new(100.0, 0.2).unwrap()).unwrap();
    for peak in [5660.0, 11298.0] {
        // the largest theta within 1.5 % of the peak speed
        let p = b
            .points
            .iter()
            .filter(|p| (p.speed_rpm - peak).abs() < 0.015 * peak)
            .max_by(|a, c| a.theta_deg.total_cmp(&c.theta_deg))
            .unwrap();
        assert!(p.theta_deg > 80.0, "{peak}: theta {}", p.theta_deg);
        assert!(
            (p.distance - 100.0).abs() < 10.0,
            "{peak}: d {}",
            p.distance
        );
    }
    let pocket = b
        .points
        .iter()
        .filter(|p| (p.speed_rpm - 6960.0).abs() < 0.015 * 6960.0)
        .min_by(|a, c| a.depth_mm.total_cmp(&c.depth_mm))
        .unwrap();
    assert!(pocket.theta_deg < 5.0, "pocket theta {}", pocket.theta_deg);
    assert!(
        (pocket.distance - 200.0).abs() < 4.0,
        "pocket d {}",
        pocket.distance
    );
    // and the offset boundaries bracket the mean boundary there
    assert!(pocket.lower.1 < pocket.depth_mm && pocket.upper.1 > pocket.depth_mm);
}
