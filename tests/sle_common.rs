//! Shared by the `sle` test and the `sle_sim` example: the surface location error of the Fourier
//! solution (`chatter_dynamics::sle`) against the simulator's steady state.

use chatter_dynamics::simulate::simulate;
use chatter_dynamics::sle::surface_location_error;
use chatter_dynamics::{MillingDirection, ModalModel, Operation, examples};

#[allow(dead_code)]
#[path = "transient.rs"]
mod transient;
use transient::deterministic;

/// Seed 001's mill (4 teeth, 20 % radial immersion) in `direction`.
pub fn mill(direction: MillingDirection) -> ModalModel {
    let model = examples::schmitz_2023_milling();
    let Operation::Milling(m) = model.operation() else {
        unreachable!("001 is a milling model")
    };
    let cutter = chatter_dynamics::Milling::new(
        m.teeth(),
        m.radial_immersion(),
        direction,
        m.tool_diameter_m(),
        None,
    )
    .unwrap();
    model.with_operation(Operation::Milling(cutter)).unwrap()
}

/// Feed per tooth of the comparisons (m).
pub const FEED_M: f64 = 0.1e-3;

/// (Fourier SLE, simulated SLE) in m at `rpm` and `depth_m`: the simulator's surface-normal
/// displacement n_g . x sampled when a tooth is at the generating angle (a whole number of
/// output samples: 200 per tooth period), averaged over the last 20 of 400 tooth periods.
pub fn sle_pair(model: &ModalModel, rpm: f64, depth_m: f64) -> (f64, f64) {
    let fourier = surface_location_error(model, rpm, depth_m, FEED_M).unwrap();
    let Operation::Milling(m) = model.operation() else {
        unreachable!("a milling model")
    };
    let tau = model.operation().delay_s(rpm);
    let per_tooth = 200;
    let periods = 400;
    let mut s = deterministic(rpm, depth_m, periods as f64 * tau, per_tooth as f64 / tau);
    s.feed_per_tooth_m = FEED_M;
    let sim = simulate(model, &s).unwrap();
    // tooth 0 is at the generating angle phi_g at t = phi_g / Omega: 0 or half a revolution
    let offset = match m.direction() {
        MillingDirection::Up => 0,
        MillingDirection::Down => per_tooth * m.teeth() / 2,
    };
    let (s_g, c_g) = fourier.generating_angle_rad.sin_cos();
    let values: Vec<f64> = (periods - 25..periods - 5)
        .map(|k| {
            let i = offset % per_tooth + k * per_tooth;
            s_g * sim.channels[0].data[i] + c_g * sim.channels[1].data[i]
        })
        .collect();
    let simulated = values.iter().sum::<f64>() / values.len() as f64;
    (fourier.sle_m, simulated)
}
