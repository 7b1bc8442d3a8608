//! Lobe diagrams of seed 001's mill as an even-pitch cutter and as variable-pitch cutters
//! (70-110-70-110 and 80-95-85-100 deg): the time of a 200-speed diagram with FDM and SDM (four
//! delays, the monodromy over the revolution) and the lowest and highest limiting depths over
//! the speeds. `cargo run --release -p chatter-stability --example variable_pitch_lobes`.

use chatter_dynamics::{ModalModel, Operation, examples};
use chatter_progress::Silent;
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::prepared::Method;
use chatter_stability::speed_grid::default_speeds_rpm;
use std::time::Instant;

fn with_pitch(model: &ModalModel, pitch_deg: Option<&[f64]>) -> ModalModel {
    let Operation::Milling(m) = model.operation() else {
        unreachable!("001 is a milling model")
    };
    model
        .with_operation(Operation::Milling(
            m.clone().with_pitch_deg(pitch_deg).expect("valid pitches"),
        ))
        .expect("valid model")
}

fn main() {
    let base = examples::schmitz_2023_milling();
    let speeds = default_speeds_rpm(&base);
    println!(
        "{} speeds, {:.0}-{:.0} rpm",
        speeds.len(),
        speeds[0],
        speeds[speeds.len() - 1]
    );
    println!("pitch_deg,method,seconds,lowest_limit_mm,at_rpm,highest_limit_mm,at_rpm");
    for pitch in [
        None,
        Some([70.0, 110.0, 70.0, 110.0]),
        Some([80.0, 95.0, 85.0, 100.0]),
    ] {
        let model = with_pitch(&base, pitch.as_ref().map(|p| &p[..]));
        for method in [Method::Fdm, Method::Sdm] {
            let start = Instant::now();
            let solver = method
                .prepare(&model, &BoundaryOptions::default())
                .expect("prepared");
            let lobes = solver.lobes(&speeds, &Silent).expect("lobes");
            let seconds = start.elapsed().as_secs_f64();
            let finite = lobes.iter().filter(|p| p.depth_m.is_finite());
            let low = finite
                .clone()
                .min_by(|a, b| a.depth_m.total_cmp(&b.depth_m))
                .expect("a finite limit");
            let high = finite
                .max_by(|a, b| a.depth_m.total_cmp(&b.depth_m))
                .expect("a finite limit");
            println!(
                "\"{pitch:?}\",{},{seconds:.2},{:.4},{:.0},{:.4},{:.0}",
                method.name(),
                low.depth_m * 1e3,
                low.speed_rpm,
                high.depth_m * 1e3,
                high.speed_rpm
            );
        }
    }
}
