//! The localized posterior predictive check: does the misfit concentrate in one band of speeds?
//!
//! The global check (`check`) sums each observable's discrepancy over the whole
//! campaign, so an effect confined to a band of speeds (cutting coefficients doubled within
//! +-8 % of one speed, damping raised in a band, cutting coefficients rising at low cutting
//! speed) hides among the many observations it does not touch. This check scans every band of
//! speeds instead (a scan statistic, Kulldorff 1997, "A spatial scan statistic"; the maximum over
//! the bands is its own multiplicity correction):
//!
//! - every observation gives standardized discrepancies: a cut's label its surprisal
//!   -ln p(y) minus the expected surprisal (the entropy), over the surprisal's standard deviation
//!   sqrt(p (1 - p)) |ln(p / (1 - p))|; a chatter frequency, a pole frequency and a pole damping
//!   ratio their squared standardized residual capped at `OUTLIER_CAP` (10.83, as the global check) (one outlier is
//!   allowed, as in the global check), minus 1, over sqrt 2;
//! - the observations are ordered by speed and every run of consecutive speeds holding at least
//!   [`MIN_BAND`] discrepancies and at most half of them is a band, scored by the sum of its
//!   discrepancies over the square root of their number;
//! - the statistic is the largest band score; its p-value is the share of replicated campaigns
//!   (labels drawn from each cut's chatter probability, squared residuals from chi^2_1, the
//!   same items) whose largest band score is at least as large, averaged over posterior samples.
//!
//! The band of the largest score is reported, so an `unexplained` verdict names where the model
//! fails.

use crate::check::OUTLIER_CAP;
use crate::data::Dataset;
use crate::likelihood::{NoiseModel, nearest_chatter_residual, pole_residuals, terms};
use crate::predict::Prediction;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use serde::Serialize;

/// Fewest discrepancies in a band: a single observation is the lapse's business, not a region's.
pub const MIN_BAND: usize = 3;

/// Replicated campaigns behind the p-value, shared out over the posterior samples.
const REPLICATES: usize = 400;

/// The result of the localized check.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LocalCheck {
    /// Posterior predictive p-value of the largest band score.
    pub p_value: f64,
    /// The largest band score (sum of standardized discrepancies over the square root of their
    /// number), at the posterior sample of median score.
    pub score: f64,
    /// Lowest speed of that band (rpm).
    pub from_rpm: f64,
    /// Highest speed of that band (rpm).
    pub to_rpm: f64,
    /// Observations in that band (cuts and poles).
    pub observations: usize,
}

/// How a discrepancy is replicated under the model.
#[derive(Debug, Clone, Copy)]
enum Item {
    /// A cut's label with chatter probability p (observed: chattered or not).
    Label { p: f64, chattered: bool },
    /// A squared standardized residual (chi^2_1 under the model).
    Squared(f64),
}

/// The standardized surprisal of a label with chatter probability `p`.
fn label_discrepancy(p: f64, chattered: bool) -> f64 {
    let p = p.clamp(1e-12, 1.0 - 1e-12);
    let surprisal = -if chattered { p.ln() } else { (1.0 - p).ln() };
    let entropy = -(p * p.ln() + (1.0 - p) * (1.0 - p).ln());
    let sd = (p * (1.0 - p)).sqrt() * (p / (1.0 - p)).ln().abs();
    if sd < 1e-9 {
        0.0
    } else {
        (surprisal - entropy) / sd
    }
}

/// The standardized capped squared residual.
fn squared_discrepancy(z2: f64) -> f64 {
    (z2.min(OUTLIER_CAP) - 1.0) / std::f64::consts::SQRT_2
}

/// Every observation's items with their speeds, ordered by speed.
fn items(prediction: &Prediction, data: &Dataset, noise: &NoiseModel) -> Vec<(f64, Item)> {
    let mut out = Vec::new();
    for (i, c) in data.cuts.iter().enumerate() {
        let Some(q) = prediction.cuts[i] else {
            continue;
        };
        out.push((
            c.speed_rpm,
            Item::Label {
                p: noise.chatter_probability(q.log_distance()),
                chattered: !c.stable,
            },
        ));
        if let Some(f) = c.chatter_hz {
            let r = nearest_chatter_residual(f, &q, prediction.cut_fold_hz[i]);
            out.push((
                c.speed_rpm,
                Item::Squared((r / data.chatter_std_hz).powi(2)),
            ));
        }
    }
    if !data.poles.is_empty() {
        let scale = terms(prediction, data, noise).pole_scale;
        for (i, p) in data.poles.iter().enumerate() {
            let Some(q) = prediction.poles[i] else {
                continue;
            };
            let (rf, rz) = pole_residuals(
                p.frequency_hz,
                p.damping_ratio,
                &q,
                prediction.pole_fold_hz[i],
            );
            out.push((
                p.speed_rpm,
                Item::Squared((rf / p.frequency_std_hz(scale)).powi(2)),
            ));
            out.push((p.speed_rpm, Item::Squared((rz / p.damping_std).powi(2))));
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// The largest band score of `values` (ordered by `speeds`) and its band (first, last index):
/// bands start and end between distinct speeds.
fn largest_band(speeds: &[f64], values: &[f64]) -> (f64, usize, usize) {
    let n = values.len();
    let mut prefix = vec![0.0; n + 1];
    for (k, v) in values.iter().enumerate() {
        prefix[k + 1] = prefix[k] + v;
    }
    let starts: Vec<usize> = (0..n)
        .filter(|&k| k == 0 || speeds[k] != speeds[k - 1])
        .collect();
    let mut best = (f64::NEG_INFINITY, 0, 0);
    for &a in &starts {
        for &end in starts.iter().filter(|&&e| e > a).chain(std::iter::once(&n)) {
            let len = end - a;
            if len < MIN_BAND || 2 * len > n {
                continue;
            }
            let score = (prefix[end] - prefix[a]) / (len as f64).sqrt();
            if score > best.0 {
                best = (score, a, end - 1);
            }
        }
    }
    best
}

/// The localized check over posterior-sample predictions of `data` (None with too few
/// observations to form a band).
pub(crate) fn local_check(
    predictions: &[Prediction],
    data: &Dataset,
    noise: &NoiseModel,
    seed: u64,
) -> Option<LocalCheck> {
    let per_sample = (REPLICATES / predictions.len().max(1)).max(4);
    let mut exceed = 0usize;
    let mut total = 0usize;
    let mut observed = Vec::new();
    for (s, prediction) in predictions.iter().enumerate() {
        let items = items(prediction, data, noise);
        if items.len() < 2 * MIN_BAND {
            continue;
        }
        let speeds: Vec<f64> = items.iter().map(|(v, _)| *v).collect();
        let values: Vec<f64> = items
            .iter()
            .map(|(_, item)| match *item {
                Item::Label { p, chattered } => label_discrepancy(p, chattered),
                Item::Squared(z2) => squared_discrepancy(z2),
            })
            .collect();
        let (score, a, b) = largest_band(&speeds, &values);
        let mut rng = StdRng::seed_from_u64(seed ^ (s as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
        for _ in 0..per_sample {
            let replicated: Vec<f64> = items
                .iter()
                .map(|(_, item)| match *item {
                    Item::Label { p, .. } => label_discrepancy(p, rng.random::<f64>() < p),
                    Item::Squared(_) => {
                        let z: f64 = rng.sample(StandardNormal);
                        squared_discrepancy(z * z)
                    }
                })
                .collect();
            exceed += usize::from(largest_band(&speeds, &replicated).0 >= score);
            total += 1;
        }
        observed.push((score, speeds[a], speeds[b], b + 1 - a));
    }
    if observed.is_empty() {
        return None;
    }
    observed.sort_by(|x, y| x.0.total_cmp(&y.0));
    let (score, from_rpm, to_rpm, observations) = observed[observed.len() / 2];
    Some(LocalCheck {
        p_value: (1 + exceed) as f64 / (1 + total) as f64,
        score,
        from_rpm,
        to_rpm,
        observations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn label_discrepancy_is_standardized() {
        // at p = 1/2 every label is equally surprising: no discrepancy
        assert_eq!(label_discrepancy(0.5, true), 0.0);
        // mean 0 and variance 1 under the model's own labels
        for p in [0.02, 0.3, 0.7, 0.9] {
            let (a, b) = (label_discrepancy(p, true), label_discrepancy(p, false));
            let mean = p * a + (1.0 - p) * b;
            let var = p * a * a + (1.0 - p) * b * b - mean * mean;
            assert!(
                mean.abs() < 1e-12 && (var - 1.0).abs() < 1e-9,
                "{p}: {mean} {var}"
            );
        }
    }

    #[test]
    fn the_largest_band_is_found_between_distinct_speeds() {
        let speeds = [1.0, 2.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];
        let values = [0.0, 3.0, 3.0, 3.0, 0.0, 0.0, 0.0, 0.0];
        let (score, a, b) = largest_band(&speeds, &values);
        assert_eq!((a, b), (1, 3));
        assert!((score - 9.0 / 3f64.sqrt()).abs() < 1e-12);
        // too few observations for any band
        assert_eq!(
            largest_band(&speeds[..5], &values[..5]).0,
            f64::NEG_INFINITY
        );
    }
}
