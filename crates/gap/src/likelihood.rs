//! The observation model: how a machine variant's predictions ([`crate::predict`]) explain
//! each observation.
//!
//! - A cut at depth b with signed log-depth distance d = ln(b / b_lim) to the predicted
//!   boundary (from the Floquet multiplier at the cut itself) chatters with probability
//!   p = lapse + (1 - 2 lapse) Phi(d / w): a probit with width w (label noise near the boundary,
//!   and the discretization's error in depth) and a small lapse rate for outright mislabels.
//! - A chatter frequency f is a mixture over the branches a chattering cut may vibrate on
//!   ([`crate::predict`]): for turning each branch is uniform between its axis crossing and its
//!   root at the cut's depth, blurred by N(0, s_c^2); for milling it is Gaussian around the
//!   dominant multiplier's frequency at the cut's depth with standard deviation s_c, the residual
//!   folded over the tooth-passing harmonics and taken against the nearer of the images
//!   k f_tp +- f_mu (a wrapped normal).
//! - A pole's frequency and damping ratio are Gaussian around the predicted pole, mixed with equal
//!   weights over the candidates a turning identification may report (each mode's pole and the
//!   resonance); a milling pole's principal frequency is folded into [0, f_tp / 2] like the data.
//!   The frequency's standard deviation is s f (f the pole's own frequency for turning, the
//!   dominant natural frequency for a lifted milling pole, never below a reported
//!   `frequency_std_hz`) with one relative scale s shared by the campaign's poles and unknown:
//!   it is integrated out over a log-uniform prior on [`NoiseModel::pole_frequency_scale_min`,
//!   `pole_frequency_scale_max`] (0.2-3 %) on a grid of [`POLE_SCALE_POINTS`] points. How well
//!   an identification places a pole depends on the shop's records (length, excitation, the
//!   method), which the diagnosis cannot know: a fixed 0.3 % (before) failed every pole check of
//!   an outside lathe identified to 1 %, and a fixed 1 % would hide a 2 % shift from a campaign
//!   identified to 0.2 %. A class whose poles fit to 0.3 % gains the evidence of the narrow
//!   scale (Occam's razor on s) without any single setting being right for every shop. The
//!   per-pole terms are the chain-rule factors ln p(y_i | y_1..y_{i-1}) of the marginal, so
//!   they still sum to the total.

use crate::data::{Dataset, PolePoint};
use crate::error::{GapError, Result};
use crate::predict::{ChatterBranch, CutPrediction, PredictedPole, Prediction};
use chatter_bayes::special::{erfc, log_sum_exp, normal_cdf};
use serde::{Deserialize, Serialize};

/// The noise assumed in the observations. Defaults in [`NoiseModel::default`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseModel {
    /// Width w of the probit in ln(b / b_lim): label noise near the boundary.
    pub label_width_log_depth: f64,
    /// Probability that an observation is an outlier: an outright mislabel anywhere, or a
    /// chatter frequency or pole that belongs to something else (a nonlinear limit cycle that
    /// settled on another root, a spurious identified pole); such an observation is uniform
    /// over its range (the chatter frequency over one tooth-passing interval or [0, 2 f], the
    /// pole frequency over [0, 2 f]).
    pub lapse: f64,
    /// Standard deviation of chatter frequencies as a fraction of the dominant natural frequency.
    pub chatter_std_fraction: f64,
    /// Lower end of the relative pole-frequency noise scale s (module docs).
    pub pole_frequency_scale_min: f64,
    /// Upper end of the relative pole-frequency noise scale s.
    pub pole_frequency_scale_max: f64,
    /// Default standard deviation of pole damping ratios: relative part ...
    pub pole_damping_std_relative: f64,
    /// ... plus this absolute floor.
    pub pole_damping_std_floor: f64,
}

impl Default for NoiseModel {
    /// Width 0.08 (8 % in depth), lapse 0.01, chatter 0.5 % of f_n, pole frequency noise
    /// between 0.2 % and 3 % (module docs), pole damping 15 % + 0.002.
    fn default() -> Self {
        Self {
            label_width_log_depth: 0.08,
            lapse: 0.01,
            chatter_std_fraction: 0.005,
            pole_frequency_scale_min: 0.002,
            pole_frequency_scale_max: 0.03,
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
            "pole_frequency_scale_min",
            self.pole_frequency_scale_min,
            self.pole_frequency_scale_min > 0.0,
        )?;
        check(
            "pole_frequency_scale_max",
            self.pole_frequency_scale_max,
            self.pole_frequency_scale_max >= self.pole_frequency_scale_min,
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

    /// The grid of relative pole-frequency noise scales integrated over: the midpoints of
    /// [`POLE_SCALE_POINTS`] equal steps of ln s between the two ends (one point when they are
    /// equal).
    pub fn pole_scales(&self) -> Vec<f64> {
        let (lo, hi) = (
            self.pole_frequency_scale_min.ln(),
            self.pole_frequency_scale_max.ln(),
        );
        let n = if hi > lo { POLE_SCALE_POINTS } else { 1 };
        (0..n)
            .map(|k| (lo + (hi - lo) * (k as f64 + 0.5) / n as f64).exp())
            .collect()
    }

    /// Probability that a cut at ln(b / b_lim) = `log_distance` chatters.
    pub(crate) fn chatter_probability(&self, log_distance: f64) -> f64 {
        let phi = if log_distance.is_nan() {
            0.5
        } else {
            normal_cdf(log_distance / self.label_width_log_depth)
        };
        self.lapse + (1.0 - 2.0 * self.lapse) * phi
    }
}

/// Grid points of the pole-frequency noise scale: steps of 25 % in s over the default range,
/// where a likelihood of 8 poles changes by well under a nat between neighbours.
pub const POLE_SCALE_POINTS: usize = 12;

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

/// The frequency residual (nearest image) and damping residual of an observed pole against a
/// predicted one.
pub(crate) fn pole_residuals(
    observed_hz: f64,
    observed_damping: f64,
    predicted: &PredictedPole,
    fold: Option<f64>,
) -> (f64, f64) {
    (
        pole_frequency_residual(observed_hz, predicted.frequency_hz, fold),
        observed_damping - predicted.damping_ratio,
    )
}

/// Log-likelihood of each observation.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Terms {
    /// Each cut's label.
    pub label: Vec<f64>,
    /// Each cut's chatter frequency (None without one).
    pub chatter: Vec<Option<f64>>,
    /// Each pole (frequency and damping ratio together): the chain-rule factor
    /// ln p(y_i | y_1..y_{i-1}) after the noise scale is integrated out.
    pub pole: Vec<f64>,
    /// Posterior root-mean-square of the relative pole-frequency noise scale s given the poles
    /// (NaN without poles): the scale the checks and residual summaries use.
    pub pole_scale: f64,
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

/// ln of the density of a chatter frequency `f` on `branch` with spread `s`: milling folds the
/// residual against the branch's frequency over the tooth-passing harmonics and takes the nearer
/// of the images k f_tp + f_mu and k f_tp - f_mu; turning takes f uniform between the branch's
/// axis crossing and its root at the cut's depth, blurred by N(0, s^2).
fn ln_chatter_density(f: f64, branch: &ChatterBranch, s: f64, fold: Option<f64>) -> f64 {
    match fold {
        Some(ft) => {
            let r = chatter_residual(f, branch.at_depth_hz, Some(ft));
            ln_wrapped_normal(r, s, ft)
        }
        None => ln_blurred_segment(f, branch.crossing_hz, branch.at_depth_hz, s),
    }
}

/// ln of the density at `f` of a value uniform between `a` and `b` plus N(0, s^2) noise:
/// ln[(Phi((f - lo) / s) - Phi((f - hi) / s)) / (hi - lo)], the normal density when the segment
/// is shorter than s / 1000. The difference is taken between upper tails (f above the
/// segment's middle) or lower tails, so that it keeps its relative accuracy far outside.
fn ln_blurred_segment(f: f64, a: f64, b: f64, s: f64) -> f64 {
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    let width = hi - lo;
    if width < 1e-3 * s {
        return ln_normal(f - 0.5 * (lo + hi), s);
    }
    let tail = |z: f64| 0.5 * erfc(z / std::f64::consts::SQRT_2);
    let mass = if f >= 0.5 * (lo + hi) {
        tail((f - hi) / s) - tail((f - lo) / s)
    } else {
        tail((lo - f) / s) - tail((hi - f) / s)
    };
    mass.max(f64::MIN_POSITIVE).ln() - width.ln()
}

/// The residual of an observed chatter frequency against the nearest frequency the branches of
/// `q` admit (0 inside a turning branch's segment).
pub(crate) fn nearest_chatter_residual(f: f64, q: &CutPrediction, fold: Option<f64>) -> f64 {
    q.chatter_branches()
        .map(|b| match fold {
            Some(_) => chatter_residual(f, b.at_depth_hz, fold),
            None => {
                let (lo, hi) = (
                    b.crossing_hz.min(b.at_depth_hz),
                    b.crossing_hz.max(b.at_depth_hz),
                );
                f - f.clamp(lo, hi)
            }
        })
        .min_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap_or(f64::NAN)
}

/// The chatter-frequency residual: folded and against the nearer image for milling.
pub(crate) fn chatter_residual(f: f64, predicted: f64, fold: Option<f64>) -> f64 {
    match fold {
        Some(ft) => {
            let a = folded(f - predicted, ft);
            let b = folded(f + predicted, ft);
            if a.abs() <= b.abs() { a } else { b }
        }
        None => f - predicted,
    }
}

/// ln[(1 - lapse) p + lapse u] from ln p and ln u: an observation that is an outlier with
/// probability `lapse` and then uniform over its range.
fn with_lapse(ln_p: f64, ln_uniform: f64, lapse: f64) -> f64 {
    log_sum_exp(&[(1.0 - lapse).ln() + ln_p, lapse.ln() + ln_uniform])
}

/// ln 1/2: a label the model cannot predict (solver failure).
const LN_HALF: f64 = -std::f64::consts::LN_2;

/// Per-observation log-likelihoods of `data` under `prediction`. An observation whose prediction
/// failed gets a neutral term (label probability 1/2, flat frequency over one harmonic interval
/// or over [0, 2 f]); the failure is counted by the caller.
pub(crate) fn terms(prediction: &Prediction, data: &Dataset, noise: &NoiseModel) -> Terms {
    let n = data.cuts.len();
    let mut label = Vec::with_capacity(n);
    let mut chatter = Vec::with_capacity(n);
    for (i, c) in data.cuts.iter().enumerate() {
        let predicted = prediction.cuts[i];
        label.push(match predicted {
            Some(q) => {
                let p = noise.chatter_probability(q.log_distance());
                if c.stable { (1.0 - p).ln() } else { p.ln() }
            }
            None => LN_HALF,
        });
        let fold = prediction.cut_fold_hz[i];
        chatter.push(c.chatter_hz.map(|f| {
            let uniform = -fold.unwrap_or(2.0 * f.max(1.0)).ln();
            match predicted {
                Some(q) => {
                    let ln: Vec<f64> = q
                        .chatter_branches()
                        .map(|b| {
                            b.weight.ln() + ln_chatter_density(f, b, data.chatter_std_hz, fold)
                        })
                        .collect();
                    let ln_mixture = log_sum_exp(&ln);
                    with_lapse(ln_mixture, uniform, noise.lapse)
                }
                None => uniform,
            }
        }));
    }
    let scales = &data.pole_scales;
    // cumulative ln p(y_1..y_i | s_k) of the poles at every scale of the grid
    let mut cumulative = vec![0.0; scales.len()];
    let mean_exp = |v: &[f64]| log_sum_exp(v) - (v.len() as f64).ln();
    let mut pole = Vec::with_capacity(data.poles.len());
    for (i, p) in data.poles.iter().enumerate() {
        let before = mean_exp(&cumulative);
        for (k, &scale) in scales.iter().enumerate() {
            cumulative[k] += ln_pole(p, scale, prediction, i, noise.lapse);
        }
        pole.push(mean_exp(&cumulative) - before);
    }
    let pole_scale = if data.poles.is_empty() {
        f64::NAN
    } else {
        let top = cumulative.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let weights: Vec<f64> = cumulative.iter().map(|c| (c - top).exp()).collect();
        let total: f64 = weights.iter().sum();
        (weights
            .iter()
            .zip(scales)
            .map(|(w, s)| w * s * s)
            .sum::<f64>()
            / total)
            .sqrt()
    };
    Terms {
        label,
        chatter,
        pole,
        pole_scale,
    }
}

/// ln p of pole `i` of the data at relative frequency noise `scale`: a Gaussian in frequency
/// (over the images of a folded prediction) and damping, mixed with equal weights over the
/// candidates, with the lapse; uniform (frequency over [0, 2 f], damping over a unit interval)
/// where the prediction failed.
fn ln_pole(p: &PolePoint, scale: f64, prediction: &Prediction, i: usize, lapse: f64) -> f64 {
    let uniform = -(2.0 * p.frequency_hz.max(1.0)).ln();
    let candidates = &prediction.pole_candidates[i];
    if candidates.is_empty() {
        return uniform;
    }
    let frequency_std = p.frequency_std_hz(scale);
    let ln_weight = -(candidates.len() as f64).ln();
    let ln: Vec<f64> = candidates
        .iter()
        .flat_map(|q| {
            let z = ln_normal(p.damping_ratio - q.damping_ratio, p.damping_std);
            pole_frequency_images(p.frequency_hz, q.frequency_hz, prediction.pole_fold_hz[i])
                .into_iter()
                .map(move |r| ln_weight + z + ln_normal(r, frequency_std))
        })
        .collect();
    with_lapse(log_sum_exp(&ln), uniform, lapse)
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

    /// Poles identified with 1 % frequency noise: the chain-rule terms sum to the marginal over
    /// the noise scale, and the scale's posterior sits near 1 % (0.7-1.4 %, the spread of an
    /// estimate from 8 residuals).
    #[test]
    fn the_pole_noise_scale_is_integrated_out() {
        use chatter_dynamics::{Observations, PoleObservation};
        let machine = &crate::generator::proving_machines().unwrap()[3];
        let f0 = 450.0;
        // residuals in units of 1 % of f0, root mean square 1
        let z = [0.5, -1.2, 1.4, -0.3, 0.9, -1.1, 0.2, 1.3];
        let rms = (z.iter().map(|x| x * x).sum::<f64>() / z.len() as f64).sqrt();
        let poles = z
            .iter()
            .map(|x| PoleObservation {
                speed_rpm: 3000.0,
                depth_mm: 1.0,
                frequency_hz: f0 * (1.0 + 0.01 * x / rms),
                damping_ratio: 0.01,
                frequency_std_hz: None,
                damping_std: None,
                repetitions: None,
                sequence: None,
                radial_immersion: None,
                note: None,
            })
            .collect();
        let observations = Observations {
            cuts: Vec::new(),
            poles,
            signals: Vec::new(),
        };
        let noise = NoiseModel::default();
        let data = Dataset::new(&machine.model, &observations, &noise, f0).unwrap();
        let candidate = PredictedPole {
            frequency_hz: f0,
            damping_ratio: 0.01,
        };
        let prediction = Prediction {
            cuts: Vec::new(),
            cut_fold_hz: Vec::new(),
            poles: vec![Some(candidate); z.len()],
            pole_candidates: vec![vec![candidate]; z.len()],
            pole_fold_hz: vec![None; z.len()],
            failures: 0,
        };
        let t = terms(&prediction, &data, &noise);
        let joint: Vec<f64> = data
            .pole_scales
            .iter()
            .map(|&s| {
                (0..z.len())
                    .map(|i| ln_pole(&data.poles[i], s, &prediction, i, noise.lapse))
                    .sum()
            })
            .collect();
        let marginal = log_sum_exp(&joint) - (joint.len() as f64).ln();
        assert!((t.pole.iter().sum::<f64>() - marginal).abs() < 1e-9);
        assert!((0.007..0.014).contains(&t.pole_scale), "{}", t.pole_scale);
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
