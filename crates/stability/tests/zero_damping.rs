//! Zero structural damping, a valid edge case (issue 19): at zero depth an undamped mode has
//! |mu| = 1 to round-off, and every solver must find the limiting depth, not call the structure
//! unstable.
//!
//! Reference (independent of the solvers): an undamped feed-direction mode in turning,
//! q'' + w_n^2 q = -b w (q - q(t - tau)) with w = w_n^2 k_fc / k. Roots cross the imaginary axis
//! only at i W with sin(W tau) = 0: W tau an odd multiple of pi gives
//! b = (W^2 - w_n^2) / (2 w) = k (r^2 - 1) / (2 k_fc), r = W / w_n > 1. The first-order shift
//! of the roots i w_n with depth has real part -b w sin(w_n tau) / (2 w_n): where
//! sin(w_n tau) < 0 any depth destabilizes the cut (limit 0, chatter at f_n); elsewhere the
//! limit is the crossing at the next odd multiple of pi / tau above w_n.

#![allow(clippy::unwrap_used)]

use chatter_dynamics::{
    CuttingCoefficients, Milling, MillingDirection, ModalModel, Mode, ModeShape, Operation, Turning,
};
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::prepared::Method;
use std::f64::consts::PI;

const FREQUENCY_HZ: f64 = 1000.0;
const STIFFNESS_N_PER_M: f64 = 2e7;
const KFC_N_PER_M2: f64 = 159e6;

/// One feed-direction mode of damping ratio `zeta` on a lathe (kt 635, kn 159 N/mm^2).
fn lathe(zeta: f64) -> ModalModel {
    let mode = Mode::new(
        FREQUENCY_HZ,
        zeta,
        ModeShape::Directional {
            coordinate: 0,
            stiffness_n_per_m: STIFFNESS_N_PER_M,
        },
    )
    .unwrap();
    ModalModel::new(
        None,
        Operation::Turning(Turning::new(None).unwrap()),
        CuttingCoefficients::new(635e6, KFC_N_PER_M2).unwrap(),
        vec![mode],
        None,
    )
    .unwrap()
}

/// The undamped lathe's limiting depth (m) and chatter frequency (Hz) at `speed_rpm`.
fn analytic(speed_rpm: f64) -> (f64, f64) {
    let tau = 60.0 / speed_rpm;
    let wn = 2.0 * PI * FREQUENCY_HZ;
    if (wn * tau).sin() < 0.0 {
        return (0.0, FREQUENCY_HZ);
    }
    let j = (wn * tau / PI).floor();
    let odd = if j % 2.0 == 0.0 { j + 1.0 } else { j + 2.0 };
    let w = odd * PI / tau;
    let r = w / wn;
    (
        STIFFNESS_N_PER_M * (r * r - 1.0) / (2.0 * KFC_N_PER_M2),
        w / (2.0 * PI),
    )
}

/// Speeds 5050-6050 rpm: five of the eleven have a zero limit. (Speeds where w_n tau is a
/// multiple of 2 pi, e.g. 5000 and 6000 rpm, are degenerate to first order and left out.)
fn speeds() -> Vec<f64> {
    (0..11).map(|i| 5050.0 + 100.0 * i as f64).collect()
}

/// Every method against the analytic lobes: zero limits exactly zero, the others within
/// 0.1 % (zoa is exact for turning up to its 1e-4 search tolerance; FDM and SDM after the
/// Richardson step are within 0.01 % on this mode) and the chatter frequency within 0.1 %.
#[test]
fn undamped_lathe_matches_the_analytic_lobes() {
    let model = lathe(0.0);
    let options = BoundaryOptions::default();
    let speeds = speeds();
    let zeros = speeds.iter().filter(|&&s| analytic(s).0 == 0.0).count();
    assert_eq!(zeros, 5);
    for method in [Method::Zoa, Method::Fdm, Method::Sdm] {
        let prepared = method.prepare(&model, &options).unwrap();
        for &speed in &speeds {
            let p = prepared.limiting_depth(speed).unwrap();
            let (depth, chatter) = analytic(speed);
            if depth == 0.0 {
                assert_eq!(p.depth_m, 0.0, "{method:?} {speed} rpm: {p:?}");
            } else {
                assert!(
                    (p.depth_m - depth).abs() < 1e-3 * depth,
                    "{method:?} {speed} rpm: {p:?}, analytic {depth}"
                );
            }
            assert!(
                (p.chatter_hz - chatter).abs() < 1e-3 * chatter,
                "{method:?} {speed} rpm: {p:?}, analytic {chatter} Hz"
            );
        }
    }
}

/// The zero-damping limits are the limit of small damping: FDM at zeta = 1e-3 and 1e-4 tends
/// to them. Where the limit is zero the depth is proportional to zeta (the lobe bottoms
/// b_min = 2 zeta (1 + zeta) k / K and the speeds around them scale with zeta): the ratio of
/// the depths at 1e-3 and 1e-4 is 10 within 20 %. Elsewhere the distance to the undamped
/// limit falls with zeta.
#[test]
fn small_damping_tends_to_the_undamped_limit() {
    let options = BoundaryOptions::default();
    let undamped = Method::Fdm.prepare(&lathe(0.0), &options).unwrap();
    let d3 = Method::Fdm.prepare(&lathe(1e-3), &options).unwrap();
    let d4 = Method::Fdm.prepare(&lathe(1e-4), &options).unwrap();
    for speed in [5150.0, 5350.0, 5550.0, 5750.0] {
        let b0 = undamped.limiting_depth(speed).unwrap().depth_m;
        let b3 = d3.limiting_depth(speed).unwrap().depth_m;
        let b4 = d4.limiting_depth(speed).unwrap().depth_m;
        if b0 == 0.0 {
            let ratio = b3 / b4;
            assert!((ratio - 10.0).abs() < 2.0, "{speed} rpm: {b3} / {b4}");
        } else {
            assert!(
                (b4 - b0).abs() < 0.5 * (b3 - b0).abs(),
                "{speed} rpm: {b0} {b3} {b4}"
            );
        }
    }
}

/// Two-mode milling (the 001 example with its x mode undamped): the zero-order method's
/// first-order criterion (module `zero_order::system`) and the multiplier search of FDM and
/// SDM (a downward scan of |mu| - 1) are independent and agree on where the limit is zero.
#[test]
fn undamped_mill_zero_limits_agree_between_methods() {
    let shape = |coordinate| ModeShape::Directional {
        coordinate,
        stiffness_n_per_m: 3e6,
    };
    let model = ModalModel::new(
        None,
        Operation::Milling(Milling::new(4, 0.2, MillingDirection::Down, None, None).unwrap()),
        CuttingCoefficients::from_ks_beta(750e6, 68f64.to_radians()).unwrap(),
        vec![
            Mode::new(750.0, 0.0, shape(0)).unwrap(),
            Mode::new(750.0, 0.03, shape(1)).unwrap(),
        ],
        None,
    )
    .unwrap();
    let options = BoundaryOptions::default();
    let speeds = [5000.0, 5300.0, 5600.0, 5800.0, 6000.0];
    let zero: Vec<Vec<bool>> = [Method::Zoa, Method::Fdm, Method::Sdm]
        .iter()
        .map(|m| {
            let prepared = m.prepare(&model, &options).unwrap();
            speeds
                .iter()
                .map(|&s| prepared.limiting_depth(s).unwrap().depth_m == 0.0)
                .collect()
        })
        .collect();
    assert_eq!(zero[0], [true, true, true, false, false]);
    assert_eq!(zero[1], zero[0]);
    assert_eq!(zero[2], zero[0]);
}
