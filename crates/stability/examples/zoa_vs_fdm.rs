//! Compare zero-order and full-discretization limiting depths of the single-DOF benchmark.
use chatter_dynamics::examples;
use chatter_stability::boundary::{BoundaryOptions, Silent, lobe_diagram};
use chatter_stability::monodromy::Discretization;
use chatter_stability::zero_order::zoa_lobes;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let which = std::env::args().nth(1).unwrap_or_default();
    let (model, speeds): (_, Vec<f64>) = if which == "turning" {
        (
            examples::ahmadi_2022_turning(),
            (0..=11).map(|i| 6900.0 + 50.0 * i as f64).collect(),
        )
    } else {
        (
            examples::insperger_benchmark(1.0),
            (0..=40).map(|i| 5000.0 + 500.0 * i as f64).collect(),
        )
    };
    let z = zoa_lobes(&model, &speeds)?;
    let f = lobe_diagram(
        &Discretization::full(),
        &model,
        &speeds,
        &BoundaryOptions::default(),
        &Silent,
    )?;
    for (a, b) in z.iter().zip(&f) {
        println!(
            "{:>6.0} zoa {:.4} fdm {:.4} ({:+.1} %) {:.0} Hz {:.0} Hz",
            a.speed_rpm,
            a.depth_mm(),
            b.depth_mm(),
            100.0 * (a.depth_m - b.depth_m) / b.depth_m,
            a.chatter_hz,
            b.chatter_hz
        );
    }
    Ok(())
}
