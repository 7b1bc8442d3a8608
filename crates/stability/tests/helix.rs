//! Helical cutters (`operation.helix_deg`, `operation.axial_slices`): the cut spread along the
//! axis in slices, each slice's tooth angle lagging by z tan(beta) / R (a distributed delay on a
//! variable helix), in the full and semi-discretizations.
//!
//! Checks against computations the helical program does not share:
//! - helix 0 (with slices given) is the straight cutter to the bit;
//! - a helical cutter with a pitch 1e-4 deg from even goes through the several-delay program over
//!   the revolution and gives the even-pitch helical multiplier over one tooth period to the
//!   fourth power (within 3e-3, measured 1.4e-3: the slices' entries fall inside steps, at other
//!   places on the revolution's grid than on the tooth period's, and the delayed points are
//!   interpolated where the slices' cuts overlap);
//! - the limiting depth converges in the number of axial slices (20 against 80 within 1 %,
//!   measured 0.7 %: the slices' midpoint rule is of second order, the rest is the step grid,
//!   whose steps the slices' entries and exits fall inside);
//! - FDM and SDM, two schemes, find the same stable island of low-immersion helical milling
//!   (Zatarain et al. 2006) where the straight cutter has none;
//! - a variable helix (delays along the axis) agrees between FDM and SDM within 1 %.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::{ModalModel, examples};
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::monodromy::{Discretization, steps};
use chatter_stability::prepared::Method;

#[path = "common/cutters.rs"]
mod cutters;
use cutters::{cutter, first_crossing_m};

#[test]
fn helix_zero_is_the_straight_cutter_to_the_bit() {
    let base = examples::schmitz_2023_milling();
    let diameter_mm = base
        .operation()
        .cutting_diameter_m()
        .map_or(12.7, |d| d * 1e3);
    let zero = cutter(&base, diameter_mm, &[0.0], 20, None);
    let straight = cutter(&base, diameter_mm, &[0.0], 1, None);
    assert!(!zero.operation().is_helical());
    for d in [Discretization::full(), Discretization::semi()] {
        for rpm in [6000.0, 11_300.0] {
            let a = d.dominant_multiplier(&base, rpm, 1.5e-3).unwrap();
            for other in [&zero, &straight] {
                let b = d.dominant_multiplier(other, rpm, 1.5e-3).unwrap();
                assert_eq!(a.value, b.value);
                assert_eq!(a.period_s, b.period_s);
            }
        }
    }
    let options = BoundaryOptions::default();
    for method in [Method::Zoa, Method::Fdm, Method::Sdm] {
        let a = method.prepare(&base, &options).unwrap();
        let b = method.prepare(&zero, &options).unwrap();
        let (pa, pb) = (
            a.limiting_depth(8000.0).unwrap(),
            b.limiting_depth(8000.0).unwrap(),
        );
        assert_eq!(pa.depth_m.to_bits(), pb.depth_m.to_bits(), "{method:?}");
    }
}

#[test]
fn near_even_pitch_helix_gives_the_fourth_power_of_the_tooth_multiplier() {
    let base = examples::schmitz_2023_milling();
    let even = cutter(&base, 12.0, &[30.0], 10, None);
    let near = cutter(
        &base,
        12.0,
        &[30.0],
        10,
        Some(&[90.0001, 89.9999, 90.0001, 89.9999]),
    );
    assert!(near.operation().is_variable_pitch() && near.operation().is_helical());
    for d in [
        Discretization::full().with_steps(steps::<60>()),
        Discretization::semi().with_steps(steps::<60>()),
    ] {
        for (rpm, depth) in [(6000.0, 1.5e-3), (11_300.0, 4e-3)] {
            let tooth = d.dominant_multiplier(&even, rpm, depth).unwrap();
            let revolution = d.dominant_multiplier(&near, rpm, depth).unwrap();
            let expected = tooth.modulus().powi(4);
            eprintln!(
                "{:?} {rpm} rpm: |mu_tooth|^4 {expected:.8}, |mu_rev| {:.8}",
                d.scheme,
                revolution.modulus()
            );
            assert!(
                (revolution.modulus() - expected).abs() < 3e-3 * expected.max(0.1),
                "{:?} {rpm}: {} vs {expected}",
                d.scheme,
                revolution.modulus()
            );
        }
    }
}

#[test]
fn sdm_converges_in_the_axial_slices() {
    let base = examples::insperger_benchmark(0.05);
    let sdm = Discretization::semi();
    for rpm in [9000.0, 12_000.0, 17_600.0, 22_000.0] {
        let limits: Vec<f64> = [5, 20, 80]
            .iter()
            .map(|&s| first_crossing_m(&sdm, &cutter(&base, 6.0, &[30.0], s, None), rpm, 5e-5))
            .collect();
        eprintln!("{rpm} rpm: limits (mm) at 5, 20, 80 slices {limits:?}");
        let converged = limits[2];
        assert!(
            (limits[1] - converged).abs() < 0.01 * converged,
            "{rpm}: {limits:?}"
        );
    }
}

#[test]
fn low_immersion_helix_has_an_isolated_stable_island() {
    // 5 % down milling, 2 teeth, a 6 mm tool: at 17 600 rpm the straight cutter is unstable from
    // about 2 mm up; with a 30 deg helix the cut is stable to about 2.3 mm, unstable to about
    // 4.2 mm, stable again (the island) to about 5.5 mm and unstable above
    let base = examples::insperger_benchmark(0.05);
    let helical = cutter(&base, 6.0, &[30.0], 20, None);
    let straight = cutter(&base, 6.0, &[0.0], 20, None);
    let rpm = 17_600.0;
    for solver in [Discretization::semi(), Discretization::full()] {
        let mu = |model: &ModalModel, depth_mm: f64| {
            solver
                .dominant_multiplier(model, rpm, depth_mm * 1e-3)
                .unwrap()
                .modulus()
        };
        let scan: Vec<(f64, bool)> = (1..=48)
            .map(|k| {
                let b = 0.125 * k as f64;
                (b, mu(&helical, b) < 1.0)
            })
            .collect();
        // stable, then unstable, then stable (the island), then unstable
        let changes: Vec<f64> = scan
            .windows(2)
            .filter(|w| w[0].1 != w[1].1)
            .map(|w| w[1].0)
            .collect();
        eprintln!("{:?}: stability changes at {changes:?} mm", solver.scheme);
        assert_eq!(changes.len(), 3, "{:?}: {changes:?}", solver.scheme);
        assert!(scan[0].1, "stable at the smallest depth");
        let island = 0.5 * (changes[1] + changes[2]);
        assert!(mu(&helical, island) < 1.0);
        assert!(mu(&straight, island) > 1.0, "no island without the helix");
        assert!(
            (2.0..2.6).contains(&changes[0])
                && (3.8..4.6).contains(&changes[1])
                && (5.0..6.0).contains(&changes[2]),
            "{changes:?}"
        );
    }
}

#[test]
fn variable_helix_fdm_and_sdm_agree() {
    let base = examples::schmitz_2023_milling();
    let model = cutter(&base, 12.0, &[30.0, 35.0, 30.0, 35.0], 20, None);
    assert!(model.operation().has_uneven_teeth());
    let straight = examples::schmitz_2023_milling();
    let options = BoundaryOptions::default();
    let fdm = Method::Fdm.prepare(&model, &options).unwrap();
    let sdm = Method::Sdm.prepare(&model, &options).unwrap();
    let even = Method::Sdm.prepare(&straight, &options).unwrap();
    let mut differs = false;
    for rpm in [6000.0, 8000.0, 11_300.0] {
        let (f, s) = (
            fdm.limiting_depth(rpm).unwrap().depth_m,
            sdm.limiting_depth(rpm).unwrap().depth_m,
        );
        let e = even.limiting_depth(rpm).unwrap().depth_m;
        eprintln!("{rpm} rpm: FDM {f:.6e} SDM {s:.6e} straight {e:.6e}");
        assert!((f - s).abs() < 0.01 * s, "{rpm}: FDM {f} SDM {s}");
        differs |= (s - e).abs() > 0.01 * e;
    }
    assert!(differs, "the variable helix changes the limit somewhere");
}
