//! Variable-pitch cutters against the time-domain simulator: at each speed the boundary of the
//! full discretization (`Method::Fdm`, the several-delay program over the revolution) against
//! the boundary the simulator's start-up transients give (dominant multiplier over one
//! revolution fitted at 0.9 and 1.1 times the FDM depth, ln|mu| interpolated linearly to 0).
//! Seed 001's mill (4 teeth, 20 % down milling) with pitches 70-110-70-110 and 80-95-85-100 at
//! 12 speeds; a feed of 0.2 mm per tooth keeps the tooth in contact (the lost-contact fraction is
//! printed). `cargo run --release -p chatter-integration --example variable_pitch_sim`.
#![allow(clippy::unwrap_used)]

#[path = "../variable_pitch_common.rs"]
mod variable_pitch_common;
use variable_pitch_common::{PITCHES, boundary_against_simulator};

fn main() {
    let speeds: Vec<f64> = (0..12).map(|i| 4000.0 + 1000.0 * i as f64).collect();
    println!(
        "pitch_deg,speed_rpm,fdm_depth_mm,sdm_depth_mm,simulated_depth_mm,sim_vs_fdm,sdm_vs_fdm,lost_contact"
    );
    let mut worst = (0.0f64, 0.0f64);
    for pitch in PITCHES {
        for &rpm in &speeds {
            let r = boundary_against_simulator(&pitch, rpm);
            let (sim, sdm) = (r.simulated_m / r.fdm_m - 1.0, r.sdm_m / r.fdm_m - 1.0);
            worst = (worst.0.max(sim.abs()), worst.1.max(sdm.abs()));
            println!(
                "{:?},{rpm},{:.5},{:.5},{:.5},{:+.4},{:+.5},{:.2e}",
                pitch,
                r.fdm_m * 1e3,
                r.sdm_m * 1e3,
                r.simulated_m * 1e3,
                sim,
                sdm,
                r.lost_contact
            );
        }
    }
    println!(
        "largest |simulated/fdm - 1| {:.4}, largest |sdm/fdm - 1| {:.5}",
        worst.0, worst.1
    );
}
