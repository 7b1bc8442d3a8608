//! Where a chattering cut's frequency lies (issue 15, proving ground part b): the proving
//! ground's lathe cut past its boundary, simulated in the time domain with loss of contact and
//! detected as a shop would (`tests/shop/chatter.rs`), beside the branches of
//! `chatter_stability::frequency_domain::chatter_branches` (each from its axis crossing to its
//! root at the cut's depth, dominant root first). `tests/chatter_frequency.rs` holds the result.
//!
//! `cargo run --release -p chatter-gap --example chatter_frequency [-- --ratios 1.5,2.5
//! --speeds 10 --pd 0]` (`--pd C`: process damping C in N/m).

#![allow(clippy::unwrap_used)]

#[allow(dead_code)]
#[path = "../tests/shop/mod.rs"]
mod shop;

#[path = "../tests/shop/chatter.rs"]
mod chatter;

mod common;

use chatter_gap::generator::proving_machines;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::frequency_domain::FrequencyDomain;
use common::{arg, list};

fn main() {
    let machine = proving_machines().unwrap().remove(3);
    let pd: f64 = arg("--pd").and_then(|s| s.parse().ok()).unwrap_or(0.0);
    let model = if pd > 0.0 {
        machine.model.with_process_damping(Some(pd)).unwrap()
    } else {
        machine.model.clone()
    };
    let (lo, hi) = machine.speed_range_rpm;
    let ratios: Vec<f64> = list("--ratios", vec![1.5, 2.5]);
    let n: usize = arg("--speeds").and_then(|s| s.parse().ok()).unwrap_or(10);
    println!(
        "speed rpm | limit mm | ratio | detected Hz | Hz from the nearest branch | branches: \
         weight, crossing Hz (depth mm) -> root at the cut's depth Hz"
    );
    for k in 0..n {
        // speeds off a regular grid, so that they fall on different lobe positions
        let speed = lo + (hi - lo) * (k as f64 + 0.37) / n as f64;
        let limit = limiting_depth(&FrequencyDomain, &model, speed, &BoundaryOptions::default())
            .unwrap()
            .depth_m;
        for (j, &ratio) in ratios.iter().enumerate() {
            let cut = chatter::simulated_chatter(
                &model,
                speed,
                ratio * limit,
                100 + 2 * k as u64 + j as u64,
            );
            let branches: Vec<String> = cut
                .branches
                .iter()
                .map(|b| {
                    format!(
                        "{:.2}, {:.1} ({}) -> {:.1}",
                        b.weight,
                        b.crossing_hz(),
                        b.crossing
                            .map_or("-".into(), |(w, _)| format!("{:.3}", w * 1e3)),
                        b.at_width_hz()
                    )
                })
                .collect();
            println!(
                "{speed:.0} | {:.3} | {ratio} | {} | {} | {}",
                limit * 1e3,
                cut.detected_hz
                    .map_or("stable".into(), |f| format!("{f:.1}")),
                cut.nearest_branch()
                    .map_or("-".into(), |(d, i)| format!("{d:.1} (branch {i})")),
                branches.join("; ")
            );
        }
    }
}
