//! Print limiting depths of the single-DOF milling benchmark with FDM and SDM at several m.
use chatter_dynamics::examples;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::monodromy::{Discretization, steps};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    for ad in [1.0, 0.05] {
        let model = examples::insperger_benchmark(ad);
        for rpm in [5000.0, 10000.0, 15000.0, 20000.0, 25000.0] {
            let mut line = format!("a/D={ad} {rpm} rpm:");
            for m in [steps::<20>(), steps::<40>(), steps::<80>(), steps::<160>()] {
                for d in [
                    Discretization::full().with_steps(m),
                    Discretization::semi().with_steps(m),
                ] {
                    let p = limiting_depth(&d, &model, rpm, &BoundaryOptions::default())?;
                    line += &format!(" {:.4}", p.depth_m * 1e3);
                }
            }
            let a = limiting_depth(
                &Discretization::full(),
                &model,
                rpm,
                &BoundaryOptions::default(),
            )?;
            line += &format!(" | auto {:.4} mm {:.1} Hz", a.depth_m * 1e3, a.chatter_hz);
            println!("{line}");
        }
    }
    let t = examples::ahmadi_2022_turning();
    for rpm in [6950.0, 7150.0, 7300.0, 7500.0] {
        let p = limiting_depth(
            &Discretization::full(),
            &t,
            rpm,
            &BoundaryOptions::default(),
        )?;
        println!(
            "turning {rpm}: {:.4} mm {:.1} Hz",
            p.depth_m * 1e3,
            p.chatter_hz
        );
    }
    Ok(())
}
