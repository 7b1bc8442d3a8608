//! Shared by the `variable_pitch_sim` test and example: the boundary of a variable-pitch cutter
//! from FDM, SDM and the simulator's start-up transients.

use chatter_dynamics::simulate::simulate;
use chatter_dynamics::{ModalModel, Operation, examples};
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::prepared::Method;

#[allow(dead_code)]
#[path = "transient.rs"]
mod transient;
use transient::{deterministic, fit_multiplier};

/// The alternating and a non-alternating pitch set of the issue.
pub const PITCHES: [[f64; 4]; 2] = [[70.0, 110.0, 70.0, 110.0], [80.0, 95.0, 85.0, 100.0]];

/// Seed 001's mill with `pitch_deg`, its x mode alone: a y mode moves the chip at the
/// zero-thickness exit of down milling (the modulation is cos(phi) dy there), where the tooth
/// then loses contact in every transient and the start-up multiplier is not the linear one
/// (001 with both modes lost contact for 6-52 % of the engaged time); with the x mode the
/// modulation is sin(phi) dx, which vanishes with the chip.
pub fn mill(pitch_deg: &[f64]) -> ModalModel {
    let model = examples::schmitz_2023_milling();
    let model = model.with_modes(vec![model.modes()[0]]).unwrap();
    let Operation::Milling(m) = model.operation() else {
        unreachable!("001 is a milling model")
    };
    model
        .with_operation(Operation::Milling(
            m.clone().with_pitch_deg(Some(pitch_deg)).unwrap(),
        ))
        .unwrap()
}

/// One speed's figures: FDM's and SDM's limiting depths (m), the dominant multiplier's modulus
/// over one revolution at 0.85 and 0.95 times the FDM depth from FDM and from the simulator, the
/// boundary the simulator's two moduli give (ln|mu| linear in depth, extrapolated to 0), and the
/// largest lost-contact fraction of the two simulations.
pub struct Boundary {
    pub fdm_m: f64,
    pub sdm_m: f64,
    pub fdm_modulus: [f64; 2],
    pub simulated_modulus: [f64; 2],
    pub simulated_m: f64,
    pub lost_contact: f64,
}

/// The fractions of the FDM depth at which the moduli are compared.
pub const DEPTH_FRACTIONS: [f64; 2] = [0.85, 0.95];

/// |mu| over one revolution from the simulator's transient at `depth_m` (samples once per
/// revolution, revolutions 20..80, after the start-up's loss of contact has died out), and the
/// lost-contact fraction of the whole record.
pub fn simulated_multiplier(model: &ModalModel, rpm: f64, depth_m: f64) -> (f64, f64) {
    let rev = 60.0 / rpm;
    let per_rev = 40;
    let mut s = deterministic(rpm, depth_m, 82.0 * rev, per_rev as f64 / rev);
    s.feed_per_tooth_m = 0.2e-3;
    let sim = simulate(model, &s).unwrap();
    let seq: Vec<f64> = (20..80)
        .map(|k| sim.channels[0].data[k * per_rev])
        .collect();
    (fit_multiplier(&[seq]).norm(), sim.lost_contact_fraction)
}

/// The figures of [`Boundary`] at `rpm`.
pub fn boundary_against_simulator(pitch_deg: &[f64], rpm: f64) -> Boundary {
    let model = mill(pitch_deg);
    let options = BoundaryOptions::default();
    let fdm = Method::Fdm.prepare(&model, &options).unwrap();
    let fdm_m = fdm.limiting_depth(rpm).unwrap().depth_m;
    let sdm_m = Method::Sdm
        .prepare(&model, &options)
        .unwrap()
        .limiting_depth(rpm)
        .unwrap()
        .depth_m;
    let depths = DEPTH_FRACTIONS.map(|f| f * fdm_m);
    let fdm_modulus = depths.map(|b| fdm.dominant_multiplier(rpm, b).unwrap().modulus());
    let runs = depths.map(|b| simulated_multiplier(&model, rpm, b));
    let g = runs.map(|r| r.0.ln());
    Boundary {
        fdm_m,
        sdm_m,
        fdm_modulus,
        simulated_modulus: runs.map(|r| r.0),
        simulated_m: depths[0] - g[0] * (depths[1] - depths[0]) / (g[1] - g[0]),
        lost_contact: runs[0].1.max(runs[1].1),
    }
}
