//! Helical cutters against the time-domain simulator, which cuts each axial slice of each tooth
//! on its own surface (the slice's helix lag rounded to the simulator's step): the dominant
//! multiplier over one revolution fitted to the simulator's start-up transient (revolutions
//! 20..80 as `variable_pitch_sim.rs` does for a decaying one, 3..14 for a growing one, before the
//! teeth leave the cut) against SDM's over the same revolution
//! (|mu_tooth|^2, two teeth), on the low-immersion benchmark with a 6 mm, 30 deg helix cutter
//! (20 slices) at 17 600 rpm below the unstable band, twice inside it and inside the stable
//! island above it (`crates/stability/tests/helix.rs`), and at 12 000 rpm at 0.9 of the limit.
//! Tolerance 1 % of |mu| (measured: within 0.15 %), the accuracy of SDM's automatic grid on the
//! limiting depth; the simulator's first-order-hold steps and its lags rounded to a step are
//! finer. The simulator must also place every point on the same side of |mu| = 1 as SDM, so
//! that the island is seen by both.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::simulate::simulate;
use chatter_dynamics::{Milling, ModalModel, Operation, examples};
use chatter_stability::StabilitySolver;
use chatter_stability::monodromy::Discretization;

#[allow(dead_code)]
#[path = "transient.rs"]
mod transient;
use transient::{deterministic, fit_multiplier};

fn helical_benchmark() -> ModalModel {
    let base = examples::insperger_benchmark(0.05);
    let Operation::Milling(m) = base.operation() else {
        unreachable!("a milling model")
    };
    let milling = Milling::new(m.teeth(), 0.05, m.direction(), Some(6e-3), None)
        .unwrap()
        .with_helix_deg(Some(&[30.0]))
        .unwrap()
        .with_axial_slices(Some(20))
        .unwrap();
    base.with_operation(Operation::Milling(milling)).unwrap()
}

/// |mu| over one revolution from the simulator's transient over `revolutions`, and the
/// lost-contact fraction of the record up to their end.
fn simulated_multiplier(
    model: &ModalModel,
    rpm: f64,
    depth_m: f64,
    revolutions: std::ops::Range<usize>,
) -> (f64, f64) {
    let rev = 60.0 / rpm;
    let per_rev = 40;
    let length = revolutions.end as f64 + 2.0;
    let mut s = deterministic(rpm, depth_m, length * rev, per_rev as f64 / rev);
    s.feed_per_tooth_m = 0.2e-3;
    let sim = simulate(model, &s).unwrap();
    let seq: Vec<f64> = revolutions
        .map(|k| sim.channels[0].data[k * per_rev])
        .collect();
    (fit_multiplier(&[seq]).norm(), sim.lost_contact_fraction)
}

#[test]
fn simulated_growth_agrees_with_sdm_on_the_island() {
    let model = helical_benchmark();
    let sdm = Discretization::semi();
    for (rpm, depth_mm) in [
        (17_600.0, 1.8),
        (17_600.0, 2.6),
        (17_600.0, 4.0),
        (17_600.0, 4.9),
        (12_000.0, 1.5),
    ] {
        let depth_m = depth_mm * 1e-3;
        let tooth = sdm.dominant_multiplier(&model, rpm, depth_m).unwrap();
        let expected = tooth.modulus().powi(2);
        // a growing transient is fitted before it leaves the cut (lost contact below 1 %)
        let window = if expected < 1.0 { 20..80 } else { 3..14 };
        let (simulated, lost) = simulated_multiplier(&model, rpm, depth_m, window);
        assert!(lost < 1e-2, "{rpm} {depth_mm}: lost contact {lost}");
        eprintln!(
            "{rpm} rpm, {depth_mm} mm: |mu_rev| SDM {expected:.4}, simulated {simulated:.4}; \
             lost contact {lost:.1e}"
        );
        assert!(
            (simulated / expected - 1.0).abs() < 0.01,
            "{rpm} {depth_mm}: simulated {simulated} vs SDM {expected}"
        );
        assert_eq!(simulated < 1.0, expected < 1.0, "{rpm} {depth_mm}");
    }
}
