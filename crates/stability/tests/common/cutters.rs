//! The helical and variable-pitch cutters of the helix tests and the `helix_lobes` example, and
//! their reference boundary: the first crossing of |mu| = 1 by a plain scan and bisection (no
//! guided search, so it finds the narrow bands the prepared search may step over).

use chatter_dynamics::{Milling, ModalModel, Operation};
use chatter_stability::StabilitySolver;
use chatter_stability::monodromy::Discretization;

/// `model` with a `diameter_mm` tool, helix `helix_deg` (one or per tooth), `slices` axial
/// slices and `pitch_deg` (None: even).
pub fn cutter(
    model: &ModalModel,
    diameter_mm: f64,
    helix_deg: &[f64],
    slices: usize,
    pitch_deg: Option<&[f64]>,
) -> ModalModel {
    let Operation::Milling(m) = model.operation() else {
        panic!("a milling model")
    };
    let milling = Milling::new(
        m.teeth(),
        m.radial_immersion(),
        m.direction(),
        Some(diameter_mm * 1e-3),
        None,
    )
    .and_then(|h| h.with_helix_deg(Some(helix_deg)))
    .and_then(|h| h.with_axial_slices(Some(slices)))
    .and_then(|h| h.with_pitch_deg(pitch_deg))
    .expect("a valid cutter");
    model
        .with_operation(Operation::Milling(milling))
        .expect("a valid model")
}

/// The first depth (m) with |mu| >= 1 from zero: a scan by `step_m` (finer than any band of
/// either sign), then 40 bisections.
pub fn first_crossing_m(
    solver: &Discretization,
    model: &ModalModel,
    speed_rpm: f64,
    step_m: f64,
) -> f64 {
    let unstable = |b: f64| {
        solver
            .dominant_multiplier(model, speed_rpm, b)
            .expect("a multiplier")
            .modulus()
            >= 1.0
    };
    let mut hi = step_m;
    while !unstable(hi) {
        hi += step_m;
    }
    let mut lo = hi - step_m;
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if unstable(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}
