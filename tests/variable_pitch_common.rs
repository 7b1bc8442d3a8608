//! Shared by the `variable_pitch_sim` test and example: the boundary of a variable-pitch cutter
//! from FDM, SDM and the simulator's start-up transients.

use chatter_dynamics::simulate::simulate;
use chatter_dynamics::{ModalModel, Operation, examples};
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::prepared::Method;

#[path = "transient.rs"]
mod transient;
use transient::{deterministic, fit_multiplier};

/// The alternating and a non-alternating pitch set of the issue.
pub const PITCHES: [[f64; 4]; 2] = [[70.0, 110.0, 70.0, 110.0], [80.0, 95.0, 85.0, 100.0]];

/// Seed 001's mill with `pitch_deg`.
pub fn mill(pitch_deg: &[f64]) -> ModalModel {
    let model = examples::schmitz_2023_milling();
    let Operation::Milling(m) = model.operation() else {
        unreachable!("001 is a milling model")
    };
    model
        .with_operation(Operation::Milling(
            m.clone().with_pitch_deg(Some(pitch_deg)).unwrap(),
        ))
        .unwrap()
}

/// One speed's boundaries (m) and the largest lost-contact fraction of the two simulations.
pub struct Boundary {
    pub fdm_m: f64,
    pub sdm_m: f64,
    pub simulated_m: f64,
    pub lost_contact: f64,
}

/// |mu| over one revolution from the simulator's transient at `depth_m` (samples once per
/// revolution, both coordinates, revolutions 6..40), and the lost-contact fraction.
pub fn simulated_multiplier(model: &ModalModel, rpm: f64, depth_m: f64) -> (f64, f64) {
    let rev = 60.0 / rpm;
    let per_rev = 40;
    let mut s = deterministic(rpm, depth_m, 42.0 * rev, per_rev as f64 / rev);
    s.feed_per_tooth_m = 0.2e-3;
    let sim = simulate(model, &s).unwrap();
    let seq =
        |c: usize| -> Vec<f64> { (6..40).map(|k| sim.channels[c].data[k * per_rev]).collect() };
    (
        fit_multiplier(&[seq(0), seq(1)]).norm(),
        sim.lost_contact_fraction,
    )
}

/// FDM's and SDM's limiting depth at `rpm` and the simulator's: ln|mu| at 0.9 and 1.1 times the
/// FDM depth, interpolated linearly to zero.
pub fn boundary_against_simulator(pitch_deg: &[f64], rpm: f64) -> Boundary {
    let model = mill(pitch_deg);
    let options = BoundaryOptions::default();
    let fdm_m = Method::Fdm
        .prepare(&model, &options)
        .unwrap()
        .limiting_depth(rpm)
        .unwrap()
        .depth_m;
    let sdm_m = Method::Sdm
        .prepare(&model, &options)
        .unwrap()
        .limiting_depth(rpm)
        .unwrap()
        .depth_m;
    let (b0, b1) = (0.9 * fdm_m, 1.1 * fdm_m);
    let (m0, l0) = simulated_multiplier(&model, rpm, b0);
    let (m1, l1) = simulated_multiplier(&model, rpm, b1);
    let (g0, g1) = (m0.ln(), m1.ln());
    Boundary {
        fdm_m,
        sdm_m,
        simulated_m: b0 - g0 * (b1 - b0) / (g1 - g0),
        lost_contact: l0.max(l1),
    }
}
