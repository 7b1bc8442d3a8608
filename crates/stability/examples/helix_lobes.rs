//! Helical cutters (`operation.helix_deg`, `operation.axial_slices`) in the semi-discretization:
//! the convergence of the limiting depth in the number of axial slices, and the isolated stable
//! islands of low-immersion helical milling (Zatarain et al. 2006; Insperger et al. 2003) on the
//! single-DOF benchmark (Insperger & Stépán 2004) at 5 % down milling, 2 teeth, a 6 mm tool with
//! a 30 deg helix: a depth map of |mu| at 17 000-18 500 rpm ('.' stable, '#' unstable) for the
//! straight and the helical cutter. Last, the time of a 200-speed SDM lobe diagram of seed
//! 001's mill with four pitch delays (70-110-70-110 deg) and a 30 deg helix in 20 slices.
//! `cargo run --release -p chatter-stability --example helix_lobes`.

use chatter_dynamics::{Operation, examples};
use chatter_progress::Silent;
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::monodromy::Discretization;
use chatter_stability::prepared::Method;
use chatter_stability::speed_grid::default_speeds_rpm;
use std::time::Instant;

#[path = "../tests/common/cutters.rs"]
mod cutters;
use cutters::{cutter, first_crossing_m};

/// The scan step of the first crossing: 0.05 mm, finer than any band of either sign here. The
/// boundary search of `Method::prepare` assumes no unstable band below its crossing and steps
/// over the narrow one at 17 600 rpm.
const SCAN_STEP_M: f64 = 0.05e-3;

fn main() {
    let base = examples::insperger_benchmark(0.05);
    println!("SDM limiting depth (mm) against the axial slices, 6 mm tool, 30 deg helix");
    let speeds = [9000.0, 12_000.0, 17_600.0, 22_000.0];
    print!("slices");
    for s in speeds {
        print!(",{s:.0} rpm");
    }
    println!();
    let sdm = Discretization::semi();
    for slices in [1, 2, 5, 10, 20, 40, 80] {
        let model = cutter(&base, 6.0, &[30.0], slices, None);
        print!("{slices}");
        for s in speeds {
            print!(
                ",{:.4}",
                first_crossing_m(&sdm, &model, s, SCAN_STEP_M) * 1e3
            );
        }
        println!();
    }
    for (label, helix) in [("straight", 0.0), ("30 deg helix", 30.0)] {
        let model = cutter(&base, 6.0, &[helix], 20, None);
        println!("\n{label}: |mu| < 1 '.', else '#'; depth 0.25-10 mm by 0.25 mm");
        for i in 0..=10 {
            let rpm = 17_000.0 + 150.0 * i as f64;
            let line: String = (1..=40)
                .map(|k| {
                    let mu = sdm
                        .dominant_multiplier(&model, rpm, 0.25e-3 * k as f64)
                        .expect("a multiplier");
                    if mu.modulus() < 1.0 { '.' } else { '#' }
                })
                .collect();
            println!("{rpm:7.0} {line}");
        }
    }
    let mill = examples::schmitz_2023_milling();
    let Operation::Milling(m) = mill.operation() else {
        unreachable!("a milling model")
    };
    let pitched_deg = Some(&[70.0, 110.0, 70.0, 110.0][..]);
    let pitched = mill
        .with_operation(Operation::Milling(
            m.clone()
                .with_pitch_deg(pitched_deg)
                .expect("valid pitches"),
        ))
        .expect("a valid model");
    let speeds = default_speeds_rpm(&mill);
    println!(
        "\n200-speed SDM lobe diagrams of 001 ({:.0}-{:.0} rpm)",
        speeds[0],
        speeds[speeds.len() - 1]
    );
    for (label, model) in [
        ("70-110-70-110, straight", pitched.clone()),
        (
            "70-110-70-110, 30 deg helix, 20 slices",
            cutter(&pitched, 12.7, &[30.0], 20, pitched_deg),
        ),
    ] {
        let start = Instant::now();
        let lobes = Method::Sdm
            .prepare(&model, &BoundaryOptions::default())
            .and_then(|s| s.lobes(&speeds, &Silent))
            .expect("lobes");
        let lowest = lobes
            .iter()
            .map(|p| p.depth_m)
            .fold(f64::INFINITY, f64::min);
        println!(
            "{label}: {:.2} s, lowest limit {:.4} mm",
            start.elapsed().as_secs_f64(),
            lowest * 1e3
        );
    }
}
