//! Zero-order lobes straight from an FRF: the seed-001 milling model's receptance written as a
//! universal file, read back and turned into lobes without a modal fit; then a modal fit of the
//! same FRF.
//!
//! `cargo run -p chatter-frf --example measured_lobes`

use chatter_dynamics::examples;
use chatter_frf::uff::{Uff58Record, parse_uff58, to_uff58_string};
use chatter_frf::{FitOptions, Frf, fit_modes};
use chatter_stability::zero_order::{ZeroOrderOptions, measured_limiting_depths};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = examples::schmitz_2023_milling();
    let grid: Vec<f64> = (0..=2500).map(f64::from).collect();
    let frf = Frf::from_model(&model, 0, 0, grid.clone())?;
    let text = to_uff58_string(&[Uff58Record::receptance(&frf, "tip xx", (1, 1), (1, 1))]);
    let back =
        parse_uff58(text.as_bytes(), Path::new("tip.uff"))?[0].to_frf(Path::new("tip.uff"))?;
    println!(
        "UFF 58: {} lines, {} frequencies read back",
        text.lines().count(),
        back.len()
    );
    // the model's modes move x and y alike: the same FRF serves both directions
    let receptance = model.sampled_receptance(grid)?;
    let speeds: Vec<f64> = (0..9).map(|i| 4000.0 + 1000.0 * f64::from(i)).collect();
    let lobes = measured_limiting_depths(
        model.operation(),
        model.cutting(),
        &receptance,
        &speeds,
        &ZeroOrderOptions::unbounded(),
    )?;
    for l in &lobes {
        println!(
            "{:6.0} rpm: {:.3} mm, chatter {:.0} Hz",
            l.speed_rpm,
            l.depth_mm(),
            l.chatter_hz
        );
    }
    let fit = fit_modes(&back, 300.0, 1500.0, &FitOptions::default())?;
    for m in &fit.modes {
        println!(
            "fitted mode {:.1} Hz, zeta {:.4}, k {:?} N/m (NRMSE {:.2e})",
            m.pole.frequency_hz, m.pole.damping_ratio, m.stiffness_n_per_m, fit.relative_misfit
        );
    }
    Ok(())
}
