//! Turning cuts past the boundary, simulated and detected the way [`crate::shop::observe`] does,
//! beside the linear branches a chattering cut may vibrate on
//! (`chatter_stability::frequency_domain::chatter_branches`, which the diagnosis's chatter
//! frequency likelihood mixes over); shared by `tests/chatter_frequency.rs` and
//! `examples/chatter_frequency.rs`.

use crate::shop::{CUT_S, record};
use chatter_dynamics::ModalModel;
use chatter_oma::detection::{DetectionOptions, Verdict, detect};
use chatter_stability::frequency_domain::{ChatterBranch, chatter_branches};

/// A simulated cut: what detection reports and where the linear model says it may vibrate.
#[derive(Debug, Clone)]
pub struct SimulatedChatter {
    /// Detected chatter frequency (Hz); `None` for a cut detected stable.
    pub detected_hz: Option<f64>,
    /// The branches, the dominant root's first.
    pub branches: Vec<ChatterBranch>,
}

impl SimulatedChatter {
    /// Distance (Hz) of the detected frequency to the nearest branch segment (between a
    /// branch's axis crossing and its root at the cut's width), and that branch's index.
    pub fn nearest_branch(&self) -> Option<(f64, usize)> {
        let f = self.detected_hz?;
        self.branches
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let (lo, hi) = (
                    b.crossing_hz().min(b.at_width_hz()),
                    b.crossing_hz().max(b.at_width_hz()),
                );
                ((f - f.clamp(lo, hi)).abs(), i)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }
}

/// The turning cut of `model` at `speed_rpm` and `depth_m` simulated (8 s, 10 % noise, spindle
/// harmonics, loss of contact), detected with the spindle frequency known, and its branches.
pub fn simulated_chatter(
    model: &ModalModel,
    speed_rpm: f64,
    depth_m: f64,
    seed: u64,
) -> SimulatedChatter {
    let signals = record(model, speed_rpm, depth_m, CUT_S, seed);
    let f0 = speed_rpm / 60.0;
    let options = DetectionOptions {
        resolution_hz: Some(f0 / 40.0),
        ..DetectionOptions::new(f0)
    };
    let d = detect(&signals, &options).unwrap();
    SimulatedChatter {
        detected_hz: (d.verdict == Verdict::Chatter)
            .then_some(d.chatter_hz)
            .flatten(),
        branches: chatter_branches(model, speed_rpm, depth_m).unwrap(),
    }
}
