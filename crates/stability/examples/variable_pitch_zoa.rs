//! The zero-order method for variable pitch (Altintas, Engin & Budak 1999) on seed 001's mill
//! (4 teeth, 750 Hz): an alternating pitch 90 -+ dP deg is designed for a chatter frequency f_c
//! at the speed where the two delays differ by half a chatter period, w_c (tau_2 - tau_1) = pi
//! with tau_2 - tau_1 = 2 dP / Omega, i.e. Omega = 2 dP w_c / pi (dP in rad): there the
//! regeneration of consecutive teeth cancels (for dP = 20 deg and f_c = 780 Hz, 10 400 rpm).
//! Prints the limiting depths of the even and the variable-pitch cutter (ZOA and SDM) over the
//! speeds and their ratio.
//! `cargo run --release -p chatter-stability --example variable_pitch_zoa [dP_deg]`.

use chatter_dynamics::{ModalModel, Operation, examples};
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::prepared::Method;

fn with_pitch(model: &ModalModel, pitch_deg: &[f64]) -> ModalModel {
    let Operation::Milling(m) = model.operation() else {
        unreachable!("001 is a milling model")
    };
    model
        .with_operation(Operation::Milling(
            m.clone()
                .with_pitch_deg(Some(pitch_deg))
                .expect("valid pitches"),
        ))
        .expect("valid model")
}

fn main() {
    let dp: f64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(20.0);
    let even = examples::schmitz_2023_milling();
    let variable = with_pitch(&even, &[90.0 - dp, 90.0 + dp, 90.0 - dp, 90.0 + dp]);
    let options = BoundaryOptions::default();
    let prepare = |m: &ModalModel, method: Method| method.prepare(m, &options).expect("prepared");
    let (zoa_even, zoa_var, sdm_even, sdm_var) = (
        prepare(&even, Method::Zoa),
        prepare(&variable, Method::Zoa),
        prepare(&even, Method::Sdm),
        prepare(&variable, Method::Sdm),
    );
    println!("dP = {dp} deg");
    println!(
        "rpm,zoa_even_mm,zoa_var_mm,zoa_gain,sdm_even_mm,sdm_var_mm,sdm_gain,zoa_var_chatter_hz"
    );
    let mut speeds: Vec<f64> = (0..=60).map(|i| 4000.0 + 200.0 * i as f64).collect();
    speeds.retain(|s| *s <= 16_000.0);
    for rpm in speeds {
        let ze = zoa_even.limiting_depth(rpm).expect("limit");
        let zv = zoa_var.limiting_depth(rpm).expect("limit");
        let se = sdm_even.limiting_depth(rpm).expect("limit");
        let sv = sdm_var.limiting_depth(rpm).expect("limit");
        println!(
            "{rpm:.0},{:.4},{:.4},{:.3},{:.4},{:.4},{:.3},{:.1}",
            ze.depth_mm(),
            zv.depth_mm(),
            zv.depth_m / ze.depth_m,
            se.depth_mm(),
            sv.depth_mm(),
            sv.depth_m / se.depth_m,
            zv.chatter_hz
        );
    }
}
