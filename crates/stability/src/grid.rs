//! The grid of the discretizations over one principal period (see [`crate::monodromy`]; the
//! delay, or the revolution of a variable-pitch cutter): the period is cut at every tooth entry
//! and exit, so that H(t) is smooth on each segment; a segment where no
//! tooth cuts (free flight) is crossed in one exact step, cutting segments get steps in
//! proportion to their length ([`crate::step::StepPlan`]).

use chatter_dynamics::{ModalModel, Operation};
use std::f64::consts::PI;

/// Grid of one principal period tau at `speed_rpm`: the segments (start, end, whether a tooth
/// cuts).
pub(crate) fn segments(model: &ModalModel, speed_rpm: f64, tau: f64) -> Vec<(f64, f64, bool)> {
    let mut cuts = vec![0.0, tau];
    if let Operation::Milling(m) = model.operation() {
        let omega = 2.0 * PI * speed_rpm / 60.0;
        let (entry, exit) = m.entry_exit_rad();
        let teeth = m.teeth();
        for j in 0..teeth {
            let offset = m.tooth_offset_rad(j);
            for angle in [entry, exit] {
                // times in [0, tau) at which tooth j reaches `angle` (mod 2 pi)
                let t0 = (angle - offset).rem_euclid(2.0 * PI) / omega;
                let t = t0.rem_euclid(tau);
                if t > 1e-12 * tau && t < tau * (1.0 - 1e-12) {
                    cuts.push(t);
                }
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-12 * tau);
    cuts.windows(2)
        .map(|w| {
            let mid = 0.5 * (w[0] + w[1]);
            let h = model.directional_matrix(mid, speed_rpm);
            (w[0], w[1], h.abs().max() > 0.0)
        })
        .collect()
}
