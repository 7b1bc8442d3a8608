//! Which closed-loop pole an identification of a stable turning cut sees (issue 31 item 1),
//! shared by `tests/turning_poles.rs` and `examples/turning_poles.rs`.
//!
//! A stable cut is simulated in the time domain as the proving ground's pole tests are
//! ([`crate::shop::record`]: `chatter_dynamics::simulate` at its automatic internal step, seeded
//! broadband force on both coordinates, 5 N spindle-harmonic forcing, 10 % measurement noise,
//! accelerations at 5 kHz), then read with the library calls of `chatter oma` on a turning
//! record (`chatter_jobs::oma::analyse_record`): chatter detection with the spindle frequency
//! known, then `chatter_oma::identify` with `IdentifyOptions::spindle` (modified LSCE with the
//! spindle harmonics that are spectral lines imposed, automatic decimation, 10 random segments
//! with segment seed 0, as the CLI). Beside it, from the characteristic equation (000 Eq. 5-6) at
//! the same speed and width: every root of the chain near the modes
//! (`chatter_stability::frequency_domain::characteristic_roots`, rightmost first), the
//! resonance the diagnosis uses today (`dominant_resonance_pole`) and each mode's continued pole
//! (`mode_poles`), and the peak of the closed-loop response to the broadband force
//! ([`closed_loop_peak`]), which the characteristic roots do not need.
//!
//! Frequencies of roots are |Im lambda| / 2 pi (what the outside generator reports), of
//! identified poles |lambda| / 2 pi (what `chatter oma` reports); they differ by a factor
//! sqrt(1 - zeta^2), below 0.05 % at the damping ratios here (< 0.03).

use crate::shop::record;
use chatter_dynamics::ModalModel;
use chatter_oma::detection::{DetectionOptions, Verdict, detect};
use chatter_oma::identify::PoleEstimate;
use chatter_oma::{IdentifyOptions, identify};
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::frequency_domain::{
    ClosedLoopPole, FrequencyDomain, characteristic_roots, dominant_resonance_pole, mode_poles,
};
use num_complex::Complex64;
use std::f64::consts::PI;

/// The public lathe of the outside proving ground (two modes, 450 Hz / 0.025 and
/// 700 Hz / 0.035), read in place (never copied into the repository).
pub const PUBLIC_LATHE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/gap_public/public_11/model.json"
);

/// Frequency resolution of the closed-loop response scan (Hz).
const SCAN_STEP_HZ: f64 = 0.05;

/// The public lathe's nominal model.
pub fn public_lathe() -> ModalModel {
    ModalModel::from_path(PUBLIC_LATHE)
        .unwrap_or_else(|e| panic!("{PUBLIC_LATHE}: {e} (the outside proving ground is needed)"))
}

/// The chain a frequency lies on: the index of the mode with the nearest natural frequency.
pub fn chain_of(model: &ModalModel, frequency_hz: f64) -> usize {
    (0..model.modes().len())
        .min_by(|&a, &b| {
            let d = |i: usize| (model.modes()[i].frequency_hz() - frequency_hz).abs();
            d(a).total_cmp(&d(b))
        })
        .unwrap_or(0)
}

/// The frequency |Im lambda| / 2 pi (Hz) of a root.
pub fn im_hz(p: &ClosedLoopPole) -> f64 {
    p.lambda.im.abs() / (2.0 * PI)
}

/// What the characteristic equation says at one cut.
#[derive(Debug, Clone)]
pub struct Roots {
    /// Every root the grid reaches, rightmost first (the dominant pole of 000 Eq. 5-6).
    pub chain: Vec<ClosedLoopPole>,
    /// The resonance of today's pole likelihood (`dominant_resonance_pole`).
    pub resonance: Option<ClosedLoopPole>,
    /// Each mode's continued pole (`mode_poles`), `None` where the continuation fails.
    pub modes: Vec<Option<ClosedLoopPole>>,
    /// Peak of the closed-loop acceleration response ([`closed_loop_peak`]): frequency (Hz) and
    /// half-power damping ratio.
    pub response_peak: (f64, f64),
}

impl Roots {
    /// The roots at `speed_rpm` and width `width_m`.
    pub fn at(model: &ModalModel, speed_rpm: f64, width_m: f64) -> Self {
        Self {
            chain: characteristic_roots(model, speed_rpm, width_m).unwrap(),
            resonance: dominant_resonance_pole(model, speed_rpm, width_m).ok(),
            modes: mode_poles(model, speed_rpm, width_m).unwrap(),
            response_peak: closed_loop_peak(model, speed_rpm, width_m),
        }
    }

    /// The rightmost root.
    pub fn rightmost(&self) -> &ClosedLoopPole {
        &self.chain[0]
    }

    /// The rightmost root of chain `chain` ([`chain_of`]) among the lightly damped ones
    /// (damping below 0.2: the chain's members, not the far-left roots).
    pub fn rightmost_of_chain(&self, model: &ModalModel, chain: usize) -> Option<&ClosedLoopPole> {
        self.chain.iter().find(|r| {
            r.lambda.im > 0.0 && r.damping_ratio < 0.2 && chain_of(model, im_hz(r)) == chain
        })
    }

    /// The root nearest `frequency_hz` in |Im| among those with damping below `max_damping`
    /// (the chain's members, not the far-left roots), and its rank by real part (0: rightmost).
    pub fn nearest(&self, frequency_hz: f64, max_damping: f64) -> Option<(usize, &ClosedLoopPole)> {
        self.chain
            .iter()
            .enumerate()
            .filter(|(_, r)| r.damping_ratio < max_damping && r.lambda.im > 0.0)
            .min_by(|a, b| {
                (im_hz(a.1) - frequency_hz)
                    .abs()
                    .total_cmp(&(im_hz(b.1) - frequency_hz).abs())
            })
    }
}

/// The peak of the closed-loop acceleration response of the cut to a white force of equal
/// density on both coordinates (the simulator's broadband forcing), summed over both output
/// channels: sum_ij w^4 |G_cl,ij(i w)|^2 with G_cl = (I + b (1 - e^{-i w tau}) G D)^{-1} G, G
/// the receptance and D the directional matrix (the cutting force is -b D (x - x_tau)).
/// Scanned every [`SCAN_STEP_HZ`] from 0.7 times the lowest to 1.3 times the highest natural
/// frequency; returns the peak frequency (Hz) and its half-power damping (half the width of the
/// band above half the peak's power, divided by the frequency).
pub fn closed_loop_peak(model: &ModalModel, speed_rpm: f64, width_m: f64) -> (f64, f64) {
    let tau = model.operation().delay_s(speed_rpm);
    let d = model.average_directional_matrix();
    let f_lo = 0.7
        * model
            .modes()
            .iter()
            .map(|m| m.frequency_hz())
            .fold(f64::INFINITY, f64::min);
    let f_hi = 1.3
        * model
            .modes()
            .iter()
            .map(|m| m.frequency_hz())
            .fold(0.0, f64::max);
    let n = ((f_hi - f_lo) / SCAN_STEP_HZ).ceil() as usize;
    let power = |f: f64| -> f64 {
        let w = 2.0 * PI * f;
        let g = model.receptance_matrix(f);
        let c = width_m * (Complex64::new(1.0, 0.0) - Complex64::new(0.0, -w * tau).exp());
        // A = I + c G D
        let gd = |i: usize, j: usize| g[i][0] * d[(0, j)] + g[i][1] * d[(1, j)];
        let a = [
            [Complex64::new(1.0, 0.0) + c * gd(0, 0), c * gd(0, 1)],
            [c * gd(1, 0), Complex64::new(1.0, 0.0) + c * gd(1, 1)],
        ];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let inv = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ];
        // G_cl = A^-1 G, summed |.|^2 over its four entries
        let total: f64 = inv
            .iter()
            .flat_map(|row| (0..2).map(move |j| (row[0] * g[0][j] + row[1] * g[1][j]).norm_sqr()))
            .sum();
        total * w.powi(4)
    };
    let values: Vec<f64> = (0..=n)
        .map(|k| power(f_lo + k as f64 * SCAN_STEP_HZ))
        .collect();
    let (k, &peak) = values
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .unwrap();
    let half = 0.5 * peak;
    let lo = (0..k).rev().find(|&i| values[i] < half).unwrap_or(0);
    let hi = (k..=n).find(|&i| values[i] < half).unwrap_or(n);
    let f = f_lo + k as f64 * SCAN_STEP_HZ;
    (f, 0.5 * (hi - lo) as f64 * SCAN_STEP_HZ / f)
}

/// The limiting width (m) at `speed_rpm` (frequency-domain solver).
pub fn limit_m(model: &ModalModel, speed_rpm: f64) -> f64 {
    limiting_depth(
        &FrequencyDomain,
        model,
        speed_rpm,
        &BoundaryOptions::default(),
    )
    .unwrap()
    .depth_m
}

/// One simulated record read as `chatter oma` reads it.
#[derive(Debug, Clone)]
pub struct Identified {
    /// Seed of the simulation.
    pub seed: u64,
    /// Whether detection called the record stable (`chatter oma` refuses it otherwise).
    pub stable: bool,
    /// The LSCE pole: mean and spread over the segments; `None` when the identification failed.
    pub pole: Option<PoleEstimate>,
    /// The spectral peak under the pole (frequency Hz, half-power damping).
    pub peak: Option<(f64, f64)>,
    /// Why the identification failed.
    pub error: Option<String>,
}

/// The cut at `speed_rpm` and `width_m` simulated for `duration_s` with `seed` and identified.
pub fn identify_cut(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
    duration_s: f64,
    seed: u64,
) -> Identified {
    let signals = record(model, speed_rpm, width_m, duration_s, seed);
    let f0 = speed_rpm / 60.0;
    let stable = detect(&signals, &DetectionOptions::new(f0))
        .map(|d| d.verdict == Verdict::Stable)
        .unwrap_or(false);
    match identify(&signals, &IdentifyOptions::spindle(f0)) {
        Ok(id) => Identified {
            seed,
            stable,
            pole: Some(id.estimate),
            peak: id.spectral_peak.map(|p| (p.frequency_hz, p.damping_ratio)),
            error: None,
        },
        Err(e) => Identified {
            seed,
            stable,
            pole: None,
            peak: None,
            error: Some(e.to_string()),
        },
    }
}
