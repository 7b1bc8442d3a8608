//! Helical cutters (`operation.helix_deg`, `operation.axial_slices`) in the semi-discretization:
//! the convergence of the limiting depth in the number of axial slices, and the isolated stable
//! islands of low-immersion helical milling (Zatarain et al. 2006; Insperger et al. 2003) on the
//! single-DOF benchmark (Insperger & Stépán 2004) at 5 % down milling, 2 teeth, a 6 mm tool with
//! a 30 deg helix: a depth map of |mu| at 17 000-18 500 rpm ('.' stable, '#' unstable) for the
//! straight and the helical cutter. Last, the time of a 200-speed SDM lobe diagram of seed
//! 001's mill with four pitch delays (70-110-70-110 deg) and a 30 deg helix in 20 slices.
//! `cargo run --release -p chatter-stability --example helix_lobes`.

use chatter_dynamics::{Milling, ModalModel, Operation, examples};
use chatter_progress::Silent;
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::monodromy::Discretization;
use chatter_stability::prepared::Method;
use chatter_stability::speed_grid::default_speeds_rpm;
use std::time::Instant;

/// `model` with a `diameter_mm` tool of helix `helix_deg` cut in `slices` axial slices.
fn helical(model: &ModalModel, diameter_mm: f64, helix_deg: f64, slices: usize) -> ModalModel {
    let Operation::Milling(m) = model.operation() else {
        unreachable!("a milling model")
    };
    let milling = Milling::new(
        m.teeth(),
        m.radial_immersion(),
        m.direction(),
        Some(diameter_mm * 1e-3),
        None,
    )
    .and_then(|h| h.with_helix_deg(Some(&[helix_deg])))
    .and_then(|h| h.with_axial_slices(Some(slices)))
    .and_then(|h| h.with_pitch_deg(m.pitch_deg().as_deref()))
    .expect("a valid helical cutter");
    model
        .with_operation(Operation::Milling(milling))
        .expect("a valid model")
}

/// The first depth (m) with |mu| = 1 from zero: a scan by 0.05 mm (finer than any band of
/// either sign here), then 40 bisections. The boundary search of `Method::prepare` assumes no
/// unstable band below its crossing and steps over the narrow one at 17 600 rpm.
fn first_crossing_m(solver: &Discretization, model: &ModalModel, speed_rpm: f64) -> f64 {
    let unstable = |b: f64| {
        solver
            .dominant_multiplier(model, speed_rpm, b)
            .expect("a multiplier")
            .modulus()
            >= 1.0
    };
    let step = 0.05e-3;
    let mut hi = step;
    while !unstable(hi) {
        hi += step;
    }
    let mut lo = hi - step;
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if unstable(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

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
        let model = helical(&base, 6.0, 30.0, slices);
        print!("{slices}");
        for s in speeds {
            print!(",{:.4}", first_crossing_m(&sdm, &model, s) * 1e3);
        }
        println!();
    }
    for (label, helix) in [("straight", 0.0), ("30 deg helix", 30.0)] {
        let model = helical(&base, 6.0, helix, 20);
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
    let pitched = mill
        .with_operation(Operation::Milling(
            m.clone()
                .with_pitch_deg(Some(&[70.0, 110.0, 70.0, 110.0]))
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
            helical(&pitched, 12.7, 30.0, 20),
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
