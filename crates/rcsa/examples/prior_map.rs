//! 004's prior and probabilistic stability map (Fig. 2) for the example assembly: writes the
//! prior file, prints the ensemble spread, the time of 4000 boundaries over 200 speeds, the 0.5
//! contour against the mean boundary and the chatter-frequency quantiles.
//!
//! `cargo run --release -p chatter-rcsa --example prior_map [OUT_PRIOR.json]`

use chatter_rcsa::Assembly;
use chatter_rcsa::prior::{
    PRIOR_PARAMETER_NAMES, PriorSettings, model_of, prior_boundaries, rcsa_prior,
    three_flute_milling,
};
use std::path::Path;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/schmitz2022_rcsa_assembly.json");
    let assembly = Assembly::from_path(&path)?;
    let t = Instant::now();
    let prior = rcsa_prior(&assembly, &PriorSettings::default())?;
    println!(
        "FRF ensemble (200 RCSA FRFs + two-mode fits): {:.2} s",
        t.elapsed().as_secs_f64()
    );
    for (i, name) in PRIOR_PARAMETER_NAMES.iter().enumerate() {
        let sd = prior.covariance[(i, i)].sqrt();
        println!(
            "{name:>14}: mean {:.5e}  sd {:.3e}  ({:.2} %)",
            prior.mean[i],
            sd,
            100.0 * sd / prior.mean[i].abs()
        );
    }
    if let Some(out) = std::env::args().nth(1) {
        std::fs::write(&out, serde_json::to_string_pretty(&prior.to_json())?)?;
        println!("prior written to {out}");
    }
    let operation = three_flute_milling(0.75)?;
    let speeds: Vec<f64> = (0..200)
        .map(|i| 5000.0 + 20000.0 * i as f64 / 199.0)
        .collect();
    let t = Instant::now();
    let sampled = prior_boundaries(&prior, &operation, &speeds, 4000, 7)?;
    println!(
        "4000 boundaries x 200 speeds: {:.2} s, {} failed draws",
        t.elapsed().as_secs_f64(),
        sampled.failures.len()
    );
    let mean =
        chatter_stability::zero_order::zoa_lobes(&model_of(&prior.mean, &operation)?, &speeds)?;
    let contour = sampled.probability_contour(0.5);
    let worst = contour
        .iter()
        .zip(&mean)
        .map(|(c, m)| (c.1 - m.depth_mm()).abs() / m.depth_mm())
        .fold(0.0, f64::max);
    let min_mean = mean
        .iter()
        .map(|p| p.depth_mm())
        .fold(f64::INFINITY, f64::min);
    println!(
        "mean boundary: minimum {min_mean:.3} mm; 0.5 contour vs mean boundary: largest relative gap {worst:.3}"
    );
    let bands = sampled.chatter_frequency_bands();
    for b in bands.iter().step_by(40) {
        println!(
            "{:7.0} rpm: chatter {:.0} / {:.0} / {:.0} Hz (5/50/95 %)",
            b.speed_rpm, b.q05, b.q50, b.q95
        );
    }
    Ok(())
}
