//! Surface location error against the simulator at ten speeds, up and down milling (seed 001's
//! mill at 0.4 mm, feed 0.1 mm/tooth): `cargo run --release -p chatter-integration --example
//! sle_sim`. The `sle` test runs three of them.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::MillingDirection;

#[path = "../sle_common.rs"]
mod sle_common;
use sle_common::{mill, sle_pair};

fn main() {
    println!("direction,speed_rpm,fourier_sle_um,simulated_sle_um,difference_over_peak");
    for direction in [MillingDirection::Down, MillingDirection::Up] {
        let model = mill(direction);
        let speeds: Vec<f64> = (0..10).map(|i| 5000.0 + 1000.0 * i as f64).collect();
        let pairs: Vec<(f64, f64)> = speeds
            .iter()
            .map(|&rpm| sle_pair(&model, rpm, 0.4e-3))
            .collect();
        let peak = pairs.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
        for (rpm, (a, b)) in speeds.iter().zip(&pairs) {
            println!(
                "{direction:?},{rpm},{:.5},{:.5},{:+.4}",
                a * 1e6,
                b * 1e6,
                (a - b) / peak
            );
        }
    }
}
