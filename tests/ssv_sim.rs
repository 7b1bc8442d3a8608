//! Spindle-speed variation against the time-domain simulator, which steps uniformly in the tooth
//! angle under the sinusoidal speed (each step lasting its own true time, the modal transitions
//! recomputed per step): the dominant multiplier over the modulation period from the SSV
//! discretization (`chatter_stability::ssv`, SDM, multipliers over T_m) against the one fitted to
//! the simulator's start-up transient (samples once per T_m, periods 20..80, as
//! `variable_pitch_sim.rs` does), at 6 points: seed 001's mill (x mode, as there, so that the
//! cut stays in contact) at 3 speeds and amplitude ratios 0.1 and 0.2, frequency ratio 1 (T_m is
//! one revolution, four tooth periods), each at 0.9 of the SSV limiting depth. Tolerance 3 % of
//! |mu| (the issue's; measured: within 1.2 %, the largest at A = 0.2, 5000 rpm).
#![allow(clippy::unwrap_used)]

use chatter_dynamics::simulate::simulate;
use chatter_dynamics::{ModalModel, examples};
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::monodromy::Discretization;
use chatter_stability::ssv::{SpeedVariation, VariedSpeed};

#[allow(dead_code)]
#[path = "transient.rs"]
mod transient;
use transient::{deterministic, fit_multiplier};

fn mill() -> ModalModel {
    let model = examples::schmitz_2023_milling();
    model.with_modes(vec![model.modes()[0]]).unwrap()
}

/// |mu| over the modulation period `period_s` from the simulator's transient (periods 20..80)
/// and the lost-contact fraction.
fn simulated(
    model: &ModalModel,
    rpm: f64,
    depth_m: f64,
    ssv: (f64, f64),
    period_s: f64,
) -> (f64, f64) {
    let per_period = 40;
    let mut s = deterministic(rpm, depth_m, 82.0 * period_s, per_period as f64 / period_s);
    s.feed_per_tooth_m = 0.2e-3;
    s.speed_variation = Some(ssv);
    let sim = simulate(model, &s).unwrap();
    let seq: Vec<f64> = (20..80)
        .map(|k| sim.channels[0].data[k * per_period])
        .collect();
    (fit_multiplier(&[seq]).norm(), sim.lost_contact_fraction)
}

#[test]
fn simulated_growth_agrees_with_the_ssv_discretization() {
    let model = mill();
    let options = BoundaryOptions::default();
    for amplitude in [0.1, 0.2] {
        let solver = VariedSpeed {
            discretization: Discretization::semi(),
            variation: SpeedVariation::new(amplitude, 1.0).unwrap(),
        };
        for rpm in [5000.0, 7000.0, 9000.0] {
            let limit = limiting_depth(&solver, &model, rpm, &options)
                .unwrap()
                .depth_m;
            let depth = 0.9 * limit;
            let mu = solver.dominant_multiplier(&model, rpm, depth).unwrap();
            let (sim, lost) = simulated(&model, rpm, depth, (amplitude, 1.0), mu.period_s);
            eprintln!(
                "A {amplitude} {rpm} rpm: limit {:.4} mm; |mu| over T_m SDM {:.4} simulated \
                 {sim:.4}; lost contact {lost:.1e}",
                limit * 1e3,
                mu.modulus()
            );
            assert!(lost < 1e-2, "{lost}");
            assert!(
                (sim / mu.modulus() - 1.0).abs() < 0.03,
                "A {amplitude} {rpm}: simulated {sim} vs SDM {}",
                mu.modulus()
            );
        }
    }
}
