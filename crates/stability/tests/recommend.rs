//! The speed recommendation (`chatter_stability::recommend`) on seed 001's mill (4 teeth, 20 %
//! down milling, 750 Hz): the highest-MRR stable cut lies in the pocket where the tooth-passing
//! frequency meets the mode, 750 x 60 / 4 = 11 250 rpm (001's lobe top near 11 300 rpm); an SLE
//! tolerance lowers the depth there to keep the wall within it.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples;
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::prepared::Method;
use chatter_stability::recommend::{RecommendOptions, highest_mrr_cut};
use chatter_stability::speed_grid::default_speeds_rpm;

#[test]
fn proposes_the_11300_rpm_pocket() {
    let model = examples::schmitz_2023_milling();
    let solver = Method::Fdm
        .prepare(&model, &BoundaryOptions::default())
        .unwrap();
    let speeds = default_speeds_rpm(&model);
    let options = RecommendOptions::new(20e-3);
    let r = highest_mrr_cut(&model, solver.as_ref(), &speeds, &options).unwrap();
    eprintln!("{r:#?}");
    assert!((r.speed_rpm / 11_300.0 - 1.0).abs() < 0.03, "{r:?}");
    assert!(r.depth_mm < r.limiting_depth_mm);
    assert_eq!(r.limited_by, "stability");
    // the default derating: 1 - z(0.95) x 10 %
    assert!((r.derated_depth_mm / r.limiting_depth_mm - (1.0 - 0.164_485_362_7)).abs() < 1e-9);
    // with a wall tolerance of a tenth of the unconstrained cut's SLE the depth is lowered
    let free = highest_mrr_cut(
        &model,
        solver.as_ref(),
        &[r.speed_rpm],
        &RecommendOptions {
            sle_tolerance_m: Some(1.0),
            ..options
        },
    )
    .unwrap();
    let sle = free.sle_um.unwrap().abs();
    let tight = highest_mrr_cut(
        &model,
        solver.as_ref(),
        &[r.speed_rpm],
        &RecommendOptions {
            sle_tolerance_m: Some(0.1 * sle * 1e-6),
            ..options
        },
    )
    .unwrap();
    assert_eq!(tight.limited_by, "sle");
    assert!((tight.sle_um.unwrap().abs() / (0.1 * sle) - 1.0).abs() < 1e-9);
    assert!((tight.depth_mm / (0.1 * free.depth_mm) - 1.0).abs() < 1e-9);
}
