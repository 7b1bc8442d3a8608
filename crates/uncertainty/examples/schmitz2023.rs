//! Schmitz (2023, seed 001) Sec. 4 reproduced: the example's zero-order lobes with Type B offsets
//! of 100 rpm and 0.2 mm, the paper's stated results beside ours with the tolerance
//! ([`chatter_uncertainty::geometric::schmitz2023::checks`]), and optionally every point of the
//! mean boundary with Eq. 2's theta, Eq. 1's d and the two raw Eq. 10-11 roots as CSV.
//!
//! Run with `cargo run --release -p chatter-uncertainty --example schmitz2023 [-- POINTS.csv]`.

use chatter_uncertainty::geometric::schmitz2023::{checks, example_boundaries};
use std::fmt::Write as _;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let bands = example_boundaries()?;
    let rows = checks(&bands);
    println!("quantity | paper | ours | tolerance | within");
    for r in &rows {
        println!(
            "{} | {} | {:.3} | {:.3} | {}",
            r.quantity,
            r.paper,
            r.ours,
            r.tolerance,
            r.within()
        );
    }
    let within = rows.iter().filter(|r| r.within()).count();
    println!("{within} of {} within tolerance", rows.len());
    if let Some(path) = std::env::args().nth(1) {
        let mut csv = String::from(
            "speed_rpm,depth_mm,theta_deg,distance,upper_speed_rpm,upper_depth_mm,\
             lower_speed_rpm,lower_depth_mm\n",
        );
        for p in &bands.points {
            writeln!(
                csv,
                "{},{},{},{},{},{},{},{}",
                p.speed_rpm,
                p.depth_mm,
                p.theta_deg,
                p.distance,
                p.upper.0,
                p.upper.1,
                p.lower.0,
                p.lower.1
            )?;
        }
        std::fs::write(&path, csv)?;
        println!("wrote {path}");
    }
    if within < rows.len() {
        return Err(format!("{} rows outside their tolerance", rows.len() - within).into());
    }
    Ok(())
}
