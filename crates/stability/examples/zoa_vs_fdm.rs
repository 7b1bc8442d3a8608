//! Compare zero-order and full-discretization limiting depths of the single-DOF benchmark
//! (`turning`: the seed-000 lathe; `flexure`: the 003-like flexure with and without process
//! damping C = 2.5e5 N/m against FDM at 1600 steps, issue 14).
use chatter_dynamics::examples;
use chatter_progress::Silent;
use chatter_stability::boundary::{BoundaryOptions, lobe_diagram};
use chatter_stability::monodromy::{Discretization, steps};
use chatter_stability::zero_order::zoa_lobes;

/// The 003-like flexure: zero-order (process damping by the rotation-averaged projector) against
/// converged FDM (1600 cutting steps, within 0.05 % of 3200), with and without process damping.
fn flexure() -> Result<(), Box<dyn std::error::Error>> {
    use chatter_stability::boundary::limiting_depth;
    use chatter_stability::zero_order::{ZeroOrderOptions, limiting_depths};
    let speeds = [300.0, 400.0, 600.0, 1000.0, 1500.0, 2000.0, 2500.0, 3000.0];
    let fdm = Discretization::full().with_steps(steps::<1600>());
    for c in [Some(2.5e5), None] {
        let model = examples::process_damping_flexure(c);
        let zoa = limiting_depths(&model, &speeds, &ZeroOrderOptions::unbounded())?;
        for (z, &speed) in zoa.iter().zip(&speeds) {
            let f = limiting_depth(&fdm, &model, speed, &BoundaryOptions::default())?;
            println!(
                "C {:>8.1e} {speed:>6.0} rpm: zoa {:.4} fdm {:.4} mm ({:+.1} %)",
                c.unwrap_or(0.0),
                z.depth_mm(),
                f.depth_mm(),
                100.0 * (z.depth_m - f.depth_m) / f.depth_m
            );
        }
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let which = std::env::args().nth(1).unwrap_or_default();
    if which == "flexure" {
        return flexure();
    }
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
