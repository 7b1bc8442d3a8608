//! The observation model: how a machine variant's predictions explain each observation.
//!
//! - A cut at depth b and speed Omega, with the predicted limiting depth b_lim(Omega), chatters
//!   with probability p = lapse + (1 - 2 lapse) Phi(ln(b / b_lim) / w): a probit in the signed
//!   log-depth distance to the boundary with width w (label noise near the boundary) and a small
//!   lapse rate for outright mislabels.
//! - A chatter frequency f is Gaussian around the predicted f_c with standard deviation s_c,
//!   folded over the tooth-passing (milling) or spindle (turning) harmonics: the density is
//!   sum_m N(f - f_c + m f_tp; 0, s_c^2) over the nearest images. Where the cut lies above
//!   further lobes (near lobe intersections) they may chatter too: the density is a mixture
//!   of the lowest lobe (weight 1) and the next ones (weight 1/2 times the probability that the
//!   cut is above them).
//! - A pole's frequency and damping ratio are Gaussian around the predicted pole with the
//!   observation's standard deviations (or the defaults); a milling pole's principal frequency is
//!   folded into [0, f_tp / 2] like the data. Where another closed-loop pole decays nearly as
//!   slowly as the dominant one, the identification may report either: a mixture (weights 1 and
//!   1/2).

use crate::data::Dataset;
use crate::error::{GapError, Result};
use crate::machine::{BoundaryPoint, Machine, PoleConvention, PredictedPole};
use chatter_bayes::prior::erfc;
use serde::{Deserialize, Serialize};

/// The noise assumed in the observations. Defaults in [`NoiseModel::default`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseModel {
    /// Width w of the probit in ln(b / b_lim): label noise near the boundary.
    pub label_width_log_depth: f64,
    /// Probability of an outright mislabel anywhere.
    pub lapse: f64,
    /// Standard deviation of chatter frequencies as a fraction of the dominant natural frequency.
    pub chatter_std_fraction: f64,
    /// Default standard deviation of pole frequencies (fraction of the dominant natural
    /// frequency) where the observation gives none.
    pub pole_frequency_std_fraction: f64,
    /// Default standard deviation of pole damping ratios: relative part ...
    pub pole_damping_std_relative: f64,
    /// ... plus this absolute floor.
    pub pole_damping_std_floor: f64,
}

impl Default for NoiseModel {
    /// Width 0.08 (8 % in depth), lapse 0.01, chatter 0.5 % of f_n, pole frequency 0.3 % of f_n,
    /// pole damping 15 % + 0.002.
    fn default() -> Self {
        Self {
            label_width_log_depth: 0.08,
            lapse: 0.01,
            chatter_std_fraction: 0.005,
            pole_frequency_std_fraction: 0.003,
            pole_damping_std_relative: 0.15,
            pole_damping_std_floor: 0.002,
        }
    }
}

impl NoiseModel {
    /// Check every field.
    pub fn validated(self) -> Result<Self> {
        let check = |field: &str, v: f64, ok: bool| {
            if ok && v.is_finite() {
                Ok(())
            } else {
                Err(GapError::InvalidInput {
                    field: format!("noise.{field}"),
                    value: v,
                    expected: "a positive value (lapse in [0, 0.5))",
                })
            }
        };
        check(
            "label_width_log_depth",
            self.label_width_log_depth,
            self.label_width_log_depth > 0.0,
        )?;
        check("lapse", self.lapse, (0.0..0.5).contains(&self.lapse))?;
        check(
            "chatter_std_fraction",
            self.chatter_std_fraction,
            self.chatter_std_fraction > 0.0,
        )?;
        check(
            "pole_frequency_std_fraction",
            self.pole_frequency_std_fraction,
            self.pole_frequency_std_fraction > 0.0,
        )?;
        check(
            "pole_damping_std_relative",
            self.pole_damping_std_relative,
            self.pole_damping_std_relative >= 0.0,
        )?;
        check(
            "pole_damping_std_floor",
            self.pole_damping_std_floor,
            self.pole_damping_std_floor > 0.0,
        )?;
        Ok(self)
    }

    /// Probability that a cut at ln(b / b_lim) = `log_distance` chatters.
    pub(crate) fn chatter_probability(&self, log_distance: f64) -> f64 {
        let phi = if log_distance.is_nan() {
            0.5
        } else {
            0.5 * erfc(-log_distance / (self.label_width_log_depth * std::f64::consts::SQRT_2))
        };
        self.lapse + (1.0 - 2.0 * self.lapse) * phi
    }
}

/// What a machine variant predicts for a dataset.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Prediction {
    /// Limiting depth at each cut (m; drift included).
    pub cut_limit_m: Vec<f64>,
    /// Chatter frequency at each cut's speed (Hz; NaN where unbounded).
    pub cut_chatter_hz: Vec<f64>,
    /// Every lobe at each cut's speed (drift included).
    pub cut_lobes: Vec<BoundaryPoint>,
    /// Harmonic spacing at each cut: tooth-passing (milling) or spindle (turning) frequency.
    pub cut_fold_hz: Vec<f64>,
    /// The poles each identification may report, with weights (dominant first; empty where
    /// the continuation failed).
    pub poles: Vec<Vec<(PredictedPole, f64)>>,
    /// Fold of each pole's principal frequency (Hz), milling only.
    pub pole_fold_hz: Vec<Option<f64>>,
}

/// Predictions of `machine` for `data`.
pub(crate) fn predict(machine: &Machine, data: &Dataset) -> Prediction {
    let boundary = if data.cuts.is_empty() {
        Vec::new()
    } else {
        machine.boundary(&data.requests)
    };
    let mut cut_lobes = Vec::with_capacity(data.cuts.len());
    let mut cut_fold_hz = Vec::with_capacity(data.cuts.len());
    for c in &data.cuts {
        let lobes = boundary
            .get(c.request)
            .map_or(BoundaryPoint::UNBOUNDED, |p| {
                p.scaled_depth(machine.drift_factor(c.u))
            });
        cut_lobes.push(lobes);
        cut_fold_hz.push(1.0 / machine.delay_s(c.speed_rpm));
    }
    let cut_limit_m = cut_lobes.iter().map(|p| p.depth_m).collect();
    let cut_chatter_hz = cut_lobes.iter().map(|p| p.chatter_hz).collect();
    let poles = data
        .poles
        .iter()
        .map(|p| machine.poles(p.speed_rpm, p.depth_m, p.geometry, p.u))
        .collect();
    let pole_fold_hz = data
        .poles
        .iter()
        .map(|p| {
            (machine.convention == PoleConvention::Lifted)
                .then(|| 1.0 / machine.delay_s(p.speed_rpm))
        })
        .collect();
    Prediction {
        cut_limit_m,
        cut_chatter_hz,
        cut_lobes,
        cut_fold_hz,
        poles,
        pole_fold_hz,
    }
}

/// Mixture weight of a higher lobe's chatter frequency relative to the lowest lobe's.
const HIGHER_LOBE_WEIGHT: f64 = 0.5;

/// ln sqrt(2 pi).
const LN_SQRT_2PI: f64 = 0.918_938_533_204_672_8;

/// ln N(r; 0, s^2).
fn ln_normal(r: f64, s: f64) -> f64 {
    -0.5 * (r / s).powi(2) - s.ln() - LN_SQRT_2PI
}

/// ln of the density of a residual folded with period `fold` (wrapped normal over the nearest
/// images; one image when the others are beyond 8 standard deviations).
fn ln_wrapped_normal(r: f64, s: f64, fold: f64) -> f64 {
    let r = folded(r, fold);
    if 0.5 * fold - r.abs() > 8.0 * s {
        ln_normal(r, s)
    } else {
        log_sum_exp(&[
            ln_normal(r, s),
            ln_normal(r - fold, s),
            ln_normal(r + fold, s),
        ])
    }
}

fn log_sum_exp(x: &[f64]) -> f64 {
    let m = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !m.is_finite() {
        return m;
    }
    m + x.iter().map(|v| (v - m).exp()).sum::<f64>().ln()
}

/// A chatter-frequency residual folded into [-f_tp / 2, f_tp / 2].
pub(crate) fn folded(residual_hz: f64, fold_hz: f64) -> f64 {
    residual_hz - fold_hz * (residual_hz / fold_hz).round()
}

/// The residual candidates of a pole frequency (the direct difference first).
fn pole_frequency_images(observed: f64, predicted: f64, fold: Option<f64>) -> Vec<f64> {
    match fold {
        None => vec![observed - predicted],
        Some(ft) => vec![
            observed - predicted,
            observed + predicted,
            observed - (ft - predicted),
        ],
    }
}

/// The pole-frequency residual: the image of the prediction nearest the observation.
pub(crate) fn pole_frequency_residual(observed: f64, predicted: f64, fold: Option<f64>) -> f64 {
    pole_frequency_images(observed, predicted, fold)
        .into_iter()
        .min_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap_or(f64::NAN)
}

/// The candidate pole that best explains an observed pole (highest weighted density), with the
/// frequency residual (nearest image) and the damping residual.
pub(crate) fn matched_pole(
    observed_hz: f64,
    observed_damping: f64,
    frequency_std_hz: f64,
    damping_std: f64,
    candidates: &[(PredictedPole, f64)],
    fold: Option<f64>,
) -> Option<(f64, f64)> {
    candidates
        .iter()
        .map(|(q, w)| {
            let rf = pole_frequency_residual(observed_hz, q.frequency_hz, fold);
            let rz = observed_damping - q.damping_ratio;
            let score =
                w.ln() - 0.5 * (rf / frequency_std_hz).powi(2) - 0.5 * (rz / damping_std).powi(2);
            (score, rf, rz)
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, rf, rz)| (rf, rz))
}

/// Log-likelihood of each observation.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Terms {
    /// Each cut's label.
    pub label: Vec<f64>,
    /// Each cut's chatter frequency (None without one).
    pub chatter: Vec<Option<f64>>,
    /// Each pole (frequency and damping ratio together).
    pub pole: Vec<f64>,
}

impl Terms {
    /// The total log-likelihood.
    pub fn total(&self) -> f64 {
        self.label.iter().sum::<f64>()
            + self.chatter.iter().flatten().sum::<f64>()
            + self.pole.iter().sum::<f64>()
    }

    /// ln p of cut `i` (label and chatter frequency together).
    pub fn cut(&self, i: usize) -> f64 {
        self.label[i] + self.chatter[i].unwrap_or(0.0)
    }

    /// ln p of pole `i` (frequency and damping together).
    pub fn pole(&self, i: usize) -> f64 {
        self.pole[i]
    }
}

/// Per-observation log-likelihoods of `data` under `prediction`.
pub(crate) fn terms(prediction: &Prediction, data: &Dataset, noise: &NoiseModel) -> Terms {
    let n = data.cuts.len();
    let mut label = Vec::with_capacity(n);
    let mut chatter = Vec::with_capacity(n);
    for (i, c) in data.cuts.iter().enumerate() {
        let p = noise.chatter_probability((c.depth_m / prediction.cut_limit_m[i]).ln());
        label.push(if c.stable { (1.0 - p).ln() } else { p.ln() });
        chatter.push(c.chatter_hz.map(|f| {
            let ft = prediction.cut_fold_hz[i];
            let lobes = &prediction.cut_lobes[i];
            // the lowest lobe chatters; a higher lobe the cut lies above may (weight 1/2 times
            // the probability that the cut is above it)
            let mut ln = Vec::with_capacity(3);
            let mut total = 0.0;
            for (k, (b, fc)) in lobes.lobes().enumerate() {
                let w = if k == 0 {
                    1.0
                } else {
                    HIGHER_LOBE_WEIGHT * (1.0 - noise.chatter_probability((b / c.depth_m).ln()))
                };
                ln.push(w.ln() + ln_wrapped_normal(f - fc, data.chatter_std_hz, ft));
                total += w;
            }
            if ln.is_empty() {
                // no lobe at this speed: any frequency in a harmonic interval
                -ft.ln()
            } else {
                log_sum_exp(&ln) - total.ln()
            }
        }));
    }
    let pole = data
        .poles
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let candidates = &prediction.poles[i];
            if candidates.is_empty() {
                // the model has no pole to offer: a flat density over the plausible range
                return -(2.0 * p.frequency_hz.max(1.0)).ln();
            }
            let total: f64 = candidates.iter().map(|c| c.1).sum();
            let ln: Vec<f64> = candidates
                .iter()
                .flat_map(|(q, w)| {
                    let z = ln_normal(p.damping_ratio - q.damping_ratio, p.damping_std);
                    pole_frequency_images(
                        p.frequency_hz,
                        q.frequency_hz,
                        prediction.pole_fold_hz[i],
                    )
                    .into_iter()
                    .map(move |r| w.ln() + z + ln_normal(r, p.frequency_std_hz))
                })
                .collect();
            log_sum_exp(&ln) - total.ln()
        })
        .collect();
    Terms {
        label,
        chatter,
        pole,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chatter_probability_is_a_probit_with_lapses() {
        let noise = NoiseModel::default();
        // erfc is good to 1.2e-7 relative
        assert!((noise.chatter_probability(0.0) - 0.5).abs() < 1e-6);
        let (lo, hi) = (
            noise.chatter_probability(-1.0),
            noise.chatter_probability(1.0),
        );
        assert!((lo - noise.lapse).abs() < 1e-6 && (hi - 1.0 + noise.lapse).abs() < 1e-6);
        let d = 0.08;
        assert!((noise.chatter_probability(d) + noise.chatter_probability(-d) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn residuals_fold_over_harmonics() {
        assert!((folded(95.0, 100.0) + 5.0).abs() < 1e-12);
        assert!((folded(-260.0, 100.0) - 40.0).abs() < 1e-12);
        // a principal frequency near 0 may be the mirror image of the prediction
        assert!((pole_frequency_residual(2.0, 3.0, Some(100.0)) + 1.0).abs() < 1e-12);
        assert!((pole_frequency_residual(1.0, 1.5, Some(100.0)) + 0.5).abs() < 1e-12);
        assert!((pole_frequency_residual(49.0, 48.0, Some(100.0)) - 1.0).abs() < 1e-12);
        assert!((pole_frequency_residual(49.0, 49.5, Some(100.0)) + 0.5).abs() < 1e-12);
        assert!((pole_frequency_residual(801.0, 800.0, None) - 1.0).abs() < 1e-12);
        // the wrapped density integrates to one over a period
        let (s, ft) = (30.0, 100.0);
        let n = 20_000;
        let integral: f64 = (0..n)
            .map(|i| ln_wrapped_normal(-50.0 + 100.0 * (i as f64 + 0.5) / n as f64, s, ft).exp())
            .sum::<f64>()
            * 100.0
            / n as f64;
        assert!((integral - 1.0).abs() < 1e-6, "{integral}");
    }

    #[test]
    fn invalid_noise_is_rejected() {
        let noise = NoiseModel {
            label_width_log_depth: 0.0,
            ..NoiseModel::default()
        };
        assert!(noise.validated().is_err());
    }
}
