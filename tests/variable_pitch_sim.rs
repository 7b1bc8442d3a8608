//! Variable-pitch cutters against the time-domain simulator (see `variable_pitch_common.rs`):
//! the simulator's boundary from its start-up transients within 2 % of FDM's, and FDM and SDM
//! within 1 %, for 70-110-70-110 and 80-95-85-100 on seed 001's mill at three speeds (twelve in
//! `cargo run --release -p chatter-integration --example variable_pitch_sim`).
#![allow(clippy::unwrap_used)]

mod variable_pitch_common;
use variable_pitch_common::{PITCHES, boundary_against_simulator};

#[test]
fn simulated_boundary_agrees_with_fdm() {
    for pitch in PITCHES {
        for rpm in [6000.0, 9000.0, 12_000.0] {
            let r = boundary_against_simulator(&pitch, rpm);
            eprintln!(
                "{pitch:?} {rpm}: fdm {:.4} mm, sdm {:.4} mm, simulated {:.4} mm, lost contact {:.1e}",
                r.fdm_m * 1e3,
                r.sdm_m * 1e3,
                r.simulated_m * 1e3,
                r.lost_contact
            );
            assert!((r.sdm_m / r.fdm_m - 1.0).abs() < 0.01);
            assert!(
                (r.simulated_m / r.fdm_m - 1.0).abs() < 0.02,
                "{pitch:?} {rpm}: simulated {} vs fdm {}",
                r.simulated_m,
                r.fdm_m
            );
        }
    }
}
