//! Variable-pitch cutters against the time-domain simulator: at each speed the dominant
//! multiplier over one revolution of the full discretization (`Method::Fdm`, the several-delay
//! program) at 0.85 and 0.95 times its limiting depth against the one fitted to the simulator's
//! transient there, and the boundary those two simulated moduli give (ln|mu| extrapolated
//! linearly to 0).
//! Seed 001's mill (4 teeth, 20 % down milling) with its x mode alone (see `mill`) and
//! pitches 70-110-70-110 and 80-95-85-100 at 12 speeds; a feed of 0.2 mm per tooth; the
//! lost-contact fraction is printed. `cargo run --release -p chatter-integration --example variable_pitch_sim`.
#![allow(clippy::unwrap_used)]

#[path = "../variable_pitch_common.rs"]
mod variable_pitch_common;
use variable_pitch_common::{PITCHES, boundary_against_simulator};

fn main() {
    let speeds: Vec<f64> = (0..12).map(|i| 4000.0 + 1000.0 * i as f64).collect();
    println!(
        "pitch_deg,speed_rpm,fdm_depth_mm,sdm_vs_fdm,fdm_mu_085,sim_mu_085,fdm_mu_095,sim_mu_095,\
         simulated_depth_mm,sim_vs_fdm,lost_contact"
    );
    let (mut worst_mu, mut worst_depth, mut worst_sdm) = (0.0f64, 0.0f64, 0.0f64);
    for pitch in PITCHES {
        for &rpm in &speeds {
            let r = boundary_against_simulator(&pitch, rpm);
            let sdm = r.sdm_m / r.fdm_m - 1.0;
            let depth = r.simulated_m / r.fdm_m - 1.0;
            for i in 0..2 {
                worst_mu = worst_mu.max((r.simulated_modulus[i] / r.fdm_modulus[i] - 1.0).abs());
            }
            worst_depth = worst_depth.max(depth.abs());
            worst_sdm = worst_sdm.max(sdm.abs());
            println!(
                "\"{pitch:?}\",{rpm},{:.5},{sdm:+.5},{:.5},{:.5},{:.5},{:.5},{:.5},{depth:+.4},{:.2e}",
                r.fdm_m * 1e3,
                r.fdm_modulus[0],
                r.simulated_modulus[0],
                r.fdm_modulus[1],
                r.simulated_modulus[1],
                r.simulated_m * 1e3,
                r.lost_contact
            );
        }
    }
    println!(
        "largest |sim |mu| / fdm |mu| - 1| {worst_mu:.4}, largest |simulated boundary / fdm - 1| \
         {worst_depth:.4}, largest |sdm/fdm - 1| {worst_sdm:.5}"
    );
}
