//! The grid of the discretizations over one principal period (see [`crate::monodromy`]; the
//! delay, or the revolution of a variable-pitch cutter): the period is cut at every tooth entry
//! and exit, so that H(t) is smooth on each segment; a segment where no
//! tooth cuts (free flight) is crossed in one exact step, cutting segments get steps in
//! proportion to their length ([`crate::step::StepPlan`]).

use chatter_dynamics::{CuttingEdge, ModalModel, Operation};
use std::f64::consts::PI;

/// Grid of one principal period tau at `speed_rpm`: the segments (start, end, whether a tooth
/// cuts), cut at the straight teeth's entries and exits ([`edge_segments`] of the cutting edges at
/// zero depth).
pub(crate) fn segments(model: &ModalModel, speed_rpm: f64, tau: f64) -> Vec<(f64, f64, bool)> {
    match model.operation() {
        Operation::Milling(m) => edge_segments(model, speed_rpm, tau, &m.cutting_edges(0.0)),
        Operation::Turning(_) => edge_segments(model, speed_rpm, tau, &[]),
    }
}

/// Grid of one principal period tau at `speed_rpm` cut at every entry and exit of the cutting
/// edge elements `edges` (a helical cutter's slices: H(t) is smooth between them); a segment
/// cuts when some element is in the cut at its middle. No edges: one segment (turning).
pub(crate) fn edge_segments(
    model: &ModalModel,
    speed_rpm: f64,
    tau: f64,
    edges: &[CuttingEdge],
) -> Vec<(f64, f64, bool)> {
    let mut cuts = vec![0.0, tau];
    if let Operation::Milling(m) = model.operation() {
        let omega = 2.0 * PI * speed_rpm / 60.0;
        let (entry, exit) = m.entry_exit_rad();
        for edge in edges {
            for angle in [entry, exit] {
                cuts.extend(crossing_time(angle - edge.lead_rad, omega, tau));
            }
        }
    }
    between(cuts, tau, |mid| match model.operation() {
        Operation::Turning(_) => model.directional_matrix(mid, speed_rpm).abs().max() > 0.0,
        Operation::Milling(_) => edges
            .iter()
            .any(|e| model.edge_directional_matrix(e, mid, speed_rpm).abs().max() > 0.0),
    })
}

/// The time in (0, tau) at which a point `angle_rad` ahead of the edge is reached (mod 2 pi)
/// turning at `omega` rad/s, folded into the period tau; None at the period's ends (within
/// 1e-12 tau), which are cuts already.
fn crossing_time(angle_rad: f64, omega: f64, tau: f64) -> Option<f64> {
    let t = (angle_rad.rem_euclid(2.0 * PI) / omega).rem_euclid(tau);
    (t > 1e-12 * tau && t < tau * (1.0 - 1e-12)).then_some(t)
}

/// The segments between the sorted `cuts` of one period tau (cuts closer than 1e-12 tau merged),
/// each marked by `cutting` at its middle.
fn between(mut cuts: Vec<f64>, tau: f64, cutting: impl Fn(f64) -> bool) -> Vec<(f64, f64, bool)> {
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-12 * tau);
    cuts.windows(2)
        .map(|w| (w[0], w[1], cutting(0.5 * (w[0] + w[1]))))
        .collect()
}

/// Grid of one principal period tau at `speed_rpm` for a helical cutter's elements `edges`: cut
/// only where a tooth's engagement begins and ends, the entry of its leading slice and the exit
/// of its trailing one (the envelope [entry + lag_min, exit + lag_max] of the tooth angle), so
/// the steps do not crowd at every slice's entry and exit; inside the envelope the slices' entries
/// and exits fall inside steps, whose coefficients are sampled there ([`crate::step::StepPlan`]),
/// and a step where no slice cuts has zero coefficients. A segment cuts when its middle lies in
/// some tooth's envelope.
pub(crate) fn envelope_segments(
    model: &ModalModel,
    speed_rpm: f64,
    tau: f64,
    edges: &[CuttingEdge],
) -> Vec<(f64, f64, bool)> {
    let Operation::Milling(m) = model.operation() else {
        return edge_segments(model, speed_rpm, tau, edges);
    };
    let omega = 2.0 * PI * speed_rpm / 60.0;
    let (entry, exit) = m.entry_exit_rad();
    // per tooth: its lead without lag and the smallest and largest lag of its slices
    let envelopes: Vec<(f64, f64, f64)> = (0..m.teeth())
        .filter_map(|j| {
            let lags = edges
                .iter()
                .filter(|e| e.tooth == j)
                .map(|e| m.tooth_offset_rad(j) - e.lead_rad);
            let (lo, hi) = lags.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), l| {
                (lo.min(l), hi.max(l))
            });
            lo.is_finite().then_some((m.tooth_offset_rad(j), lo, hi))
        })
        .collect();
    let mut cuts = vec![0.0, tau];
    for &(offset, lo, hi) in &envelopes {
        for angle in [entry + lo, exit + hi] {
            cuts.extend(crossing_time(angle - offset, omega, tau));
        }
    }
    between(cuts, tau, |mid| {
        envelopes.iter().any(|&(offset, lo, hi)| {
            let span = exit + hi - (entry + lo);
            span >= 2.0 * PI || (omega * mid + offset - (entry + lo)).rem_euclid(2.0 * PI) <= span
        })
    })
}
