//! Variable-pitch cutters (`operation.pitch_deg`): one regenerative delay per tooth, tau_j =
//! pitch_j / Omega, the monodromy over the spindle revolution (Altintas, Engin & Budak 1999;
//! Insperger & Stépán's semi-discretization with several delays).
//!
//! Checks against computations the variable-pitch program does not share:
//! - an explicit even pitch is the default cutter to the bit;
//! - a pitch 1e-4 degrees from even goes through the several-delay program and gives the
//!   even-pitch multiplier over one tooth period to the fourth power (the revolution is four tooth
//!   periods) within 1e-6 where the teeth's cuts do not overlap (delayed points on the grid) and
//!   within 1e-3 in slotting, where they overlap and the delayed points are interpolated;
//! - the reverse sweep is the adjoint of the forward one to round-off;
//! - FDM and SDM, two schemes, agree on the limiting depth within 1 % at 12 speeds for the
//!   70-110-70-110 cutter and a non-alternating one (80-95-85-100). The simulator's growth rate
//!   is compared in `tests/variable_pitch_sim.rs` of chatter-integration.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::{ModalModel, Operation, examples};
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::monodromy::{Discretization, steps};
use chatter_stability::prepared::Method;

fn with_pitch(model: &ModalModel, pitch_deg: Option<&[f64]>) -> ModalModel {
    let Operation::Milling(m) = model.operation() else {
        panic!("a milling model")
    };
    model
        .with_operation(Operation::Milling(
            m.clone().with_pitch_deg(pitch_deg).unwrap(),
        ))
        .unwrap()
}

fn with_immersion(model: &ModalModel, r: f64) -> ModalModel {
    let Operation::Milling(m) = model.operation() else {
        panic!("a milling model")
    };
    model
        .with_operation(Operation::Milling(m.with_radial_immersion(r).unwrap()))
        .unwrap()
}

const ALTERNATING: [f64; 4] = [70.0, 110.0, 70.0, 110.0];
const NON_ALTERNATING: [f64; 4] = [80.0, 95.0, 85.0, 100.0];

#[test]
fn explicit_even_pitch_is_the_default_to_the_bit() {
    let base = examples::schmitz_2023_milling();
    let even = with_pitch(&base, Some(&[90.0, 90.0, 90.0, 90.0]));
    assert!(!even.operation().is_variable_pitch());
    for d in [Discretization::full(), Discretization::semi()] {
        for rpm in [6000.0, 11_300.0] {
            let a = d.dominant_multiplier(&base, rpm, 1.5e-3).unwrap();
            let b = d.dominant_multiplier(&even, rpm, 1.5e-3).unwrap();
            assert_eq!(a.value, b.value);
            assert_eq!(a.period_s, b.period_s);
        }
    }
    let options = BoundaryOptions::default();
    for method in [Method::Zoa, Method::Fdm, Method::Sdm] {
        let a = method.prepare(&base, &options).unwrap();
        let b = method.prepare(&even, &options).unwrap();
        let (pa, pb) = (
            a.limiting_depth(8000.0).unwrap(),
            b.limiting_depth(8000.0).unwrap(),
        );
        assert_eq!(pa.depth_m.to_bits(), pb.depth_m.to_bits(), "{method:?}");
    }
}

#[test]
fn near_even_pitch_gives_the_fourth_power_of_the_tooth_multiplier() {
    let near = [90.0001, 89.9999, 90.0001, 89.9999];
    for (model, rpm, depth, tolerance) in [
        (examples::schmitz_2023_milling(), 6000.0, 1.5e-3, 1e-6),
        (examples::schmitz_2023_milling(), 11_300.0, 5e-3, 1e-6),
        // slotting: every tooth cuts half a turn, two at a time; the delayed points fall between
        // grid points (linear interpolation of the history)
        (
            with_immersion(&examples::schmitz_2023_milling(), 1.0),
            9000.0,
            0.3e-3,
            1e-3,
        ),
    ] {
        let variable = with_pitch(&model, Some(&near));
        assert!(variable.operation().is_variable_pitch());
        for d in [
            Discretization::full().with_steps(steps::<60>()),
            Discretization::semi().with_steps(steps::<60>()),
        ] {
            let tooth = d.dominant_multiplier(&model, rpm, depth).unwrap();
            let revolution = d.dominant_multiplier(&variable, rpm, depth).unwrap();
            assert!((revolution.period_s - 60.0 / rpm).abs() < 1e-15);
            let expected = tooth.modulus().powi(4);
            eprintln!(
                "{:?} {rpm} rpm: |mu_tooth|^4 {expected:.8}, |mu_rev| {:.8}",
                d.scheme,
                revolution.modulus()
            );
            assert!(
                (revolution.modulus() - expected).abs() < tolerance * expected.max(0.1),
                "{:?} {rpm}: {} vs {expected}",
                d.scheme,
                revolution.modulus()
            );
        }
    }
}

#[test]
fn reverse_sweep_is_the_adjoint() {
    for (model, rpm, depth) in [
        (examples::schmitz_2023_milling(), 7000.0, 1e-3),
        (
            with_immersion(&examples::schmitz_2023_milling(), 0.7),
            9000.0,
            0.5e-3,
        ),
    ] {
        let model = with_pitch(&model, Some(&NON_ALTERNATING));
        for d in [
            Discretization::full().with_steps(steps::<30>()),
            Discretization::semi().with_steps(steps::<30>()),
        ] {
            let op = d.monodromy(&model, rpm, depth).unwrap();
            let dim = op.dimension();
            let x: Vec<f64> = (0..dim).map(|i| (0.3 * i as f64).sin()).collect();
            let y: Vec<f64> = (0..dim).map(|i| (0.7 * i as f64 + 1.0).cos()).collect();
            let (mut ux, mut uty) = (vec![0.0; dim], vec![0.0; dim]);
            op.apply(&x, &mut ux);
            op.apply_transpose(&y, &mut uty);
            let lhs: f64 = ux.iter().zip(&y).map(|(a, b)| a * b).sum();
            let rhs: f64 = x.iter().zip(&uty).map(|(a, b)| a * b).sum();
            assert!(
                (lhs - rhs).abs() < 1e-11 * lhs.abs().max(1.0),
                "{lhs} vs {rhs}"
            );
        }
    }
}

/// 12 speeds over the first lobes of the 750 Hz mode of 001 (4 teeth): 4000-15 000 rpm.
fn speeds() -> Vec<f64> {
    (0..12).map(|i| 4000.0 + 1000.0 * i as f64).collect()
}

#[test]
fn fdm_and_sdm_agree_within_one_percent() {
    let options = BoundaryOptions::default();
    for pitch in [ALTERNATING, NON_ALTERNATING] {
        let model = with_pitch(&examples::schmitz_2023_milling(), Some(&pitch));
        let fdm = Method::Fdm.prepare(&model, &options).unwrap();
        let sdm = Method::Sdm.prepare(&model, &options).unwrap();
        let mut worst = 0.0f64;
        for rpm in speeds() {
            let a = fdm.limiting_depth(rpm).unwrap().depth_m;
            let b = sdm.limiting_depth(rpm).unwrap().depth_m;
            let rel = (a - b).abs() / b;
            worst = worst.max(rel);
            assert!(rel < 0.01, "{pitch:?} {rpm}: fdm {a} sdm {b}");
        }
        eprintln!("{pitch:?}: largest FDM-SDM difference {:.2e}", worst);
    }
}

#[test]
fn zero_order_refuses_a_variable_pitch_by_name() {
    let model = with_pitch(&examples::schmitz_2023_milling(), Some(&ALTERNATING));
    let options = BoundaryOptions::default();
    let err = Method::Zoa.prepare(&model, &options).err().unwrap();
    let text = err.to_string();
    assert!(text.contains("operation.pitch_deg"), "{text}");
    assert!(text.contains("70"), "{text}");
    // the discretizations still search the boundary (from zero depth, without the guide)
    assert!(
        Method::Fdm
            .prepare(&model, &options)
            .unwrap()
            .limiting_depth(9000.0)
            .unwrap()
            .depth_m
            > 0.0
    );
}
