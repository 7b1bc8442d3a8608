//! The localized posterior predictive check: does the misfit concentrate in one band of speeds?
//!
//! The global check (`check`) sums each observable's discrepancy over the whole
//! campaign, so an effect confined to a band of speeds (cutting coefficients raised within a few
//! per cent of one speed, damping raised in a band, cutting coefficients rising at low cutting
//! speed) hides among the many observations it does not touch. This check scans every band of
//! speeds instead, with the likelihood-ratio scan statistic of Kulldorff (1997, "A spatial scan
//! statistic"): in each band the alternative is that the model is off there by a common amount,
//! the null that it is right, and the maximum over the bands carries its own multiplicity
//! correction.
//!
//! - Labels: inside the band the true boundary lies a common factor e^delta from the predicted
//!   one, so each cut's log-depth distance d = ln(b / b_lim) becomes d + delta (a regional error
//!   of the cutting coefficient, the damping or the stiffness moves the limit so). The band's
//!   label statistic is max over delta of sum [ln p(y_i | d_i + delta) - ln p(y_i | d_i)], delta
//!   on a grid of +-`DELTA_GRID` (0 included, so it is >= 0); p is the likelihood's probit
//!   with its lapse, so one mislabel gains at most ln(1 / lapse).
//! - Chatter frequencies, pole frequencies and pole damping ratios: their standardized
//!   residuals z_i, each clipped to +-sqrt(`OUTLIER_CAP`) as the global check caps them, are
//!   off by a common mean in the band; each kind adds its Gaussian likelihood ratio
//!   (sum z_i)^2 / (2 n).
//! - Every run of consecutive speeds holding at least [`MIN_BAND`] observations and at most half
//!   of them is a band; the statistic is the largest band's likelihood ratio. Its p-value is the
//!   share of replicated campaigns (labels drawn from each cut's chatter probability, residuals
//!   from N(0, 1) and clipped, the same items) whose largest band statistic is at least as large,
//!   pooled over the posterior samples (`REPLICATES` in all, enough to resolve the Bonferroni
//!   level of the check).
//!
//! The band of the largest statistic is reported, so an `unexplained` verdict names where the
//! model fails.

use crate::check::OUTLIER_CAP;
use crate::data::Dataset;
use crate::likelihood::{NoiseModel, nearest_chatter_residual, pole_residuals, terms};
use crate::predict::Prediction;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use serde::Serialize;

/// Fewest observations in a band: a single observation is the lapse's business, not a region's.
pub const MIN_BAND: usize = 3;

/// Replicated campaigns behind the p-value, shared out over the posterior samples: with 4000
/// the smallest p-value, 1/4001, lies well below the check's Bonferroni level 0.01 / 5.
const REPLICATES: usize = 4000;

/// The positive regional log-depth offsets delta tried for the labels (each also negated): a
/// boundary 5 % to a factor 4 off, about 1.3 label widths apart near zero.
const DELTA_GRID: [f64; 10] = [0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.55, 0.75, 1.0, 1.4];

/// The result of the localized check.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LocalCheck {
    /// Posterior predictive p-value of the largest band statistic.
    pub p_value: f64,
    /// The largest band statistic (the ln likelihood ratio of a common regional offset), at the
    /// posterior sample of median statistic.
    pub score: f64,
    /// Lowest speed of that band (rpm).
    pub from_rpm: f64,
    /// Highest speed of that band (rpm).
    pub to_rpm: f64,
    /// Observations in that band (cuts and poles).
    pub observations: usize,
}

/// Kinds of standardized residuals, each with its own regional mean offset.
const RESIDUAL_KINDS: usize = 3;

/// One observation of the scan.
#[derive(Debug, Clone, Copy)]
enum Item {
    /// A cut's label: its predicted log-depth distance and whether it chattered.
    Label { log_distance: f64, chattered: bool },
    /// A standardized residual of one kind (chatter frequency, pole frequency, pole damping).
    Residual { kind: usize, z: f64 },
}

/// Largest standardized residual kept: sqrt of the global check's outlier cap.
fn clip(z: f64) -> f64 {
    let cap = OUTLIER_CAP.sqrt();
    z.clamp(-cap, cap)
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
                log_distance: q.log_distance(),
                chattered: !c.stable,
            },
        ));
        if let Some(f) = c.chatter_hz {
            let r = nearest_chatter_residual(f, &q, prediction.cut_fold_hz[i]);
            out.push((
                c.speed_rpm,
                Item::Residual {
                    kind: 0,
                    z: clip(r / data.chatter_std_hz),
                },
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
                Item::Residual {
                    kind: 1,
                    z: clip(rf / p.frequency_std_hz(scale)),
                },
            ));
            out.push((
                p.speed_rpm,
                Item::Residual {
                    kind: 2,
                    z: clip(rz / p.damping_std),
                },
            ));
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// The scan over one campaign's items: bands and the label gains per offset, fixed across
/// replications.
struct Scan {
    /// Bands as (first item, one past the last).
    bands: Vec<(usize, usize)>,
    /// The offsets: 0, then +-[`DELTA_GRID`].
    deltas: Vec<f64>,
    /// Per label item and offset: ln p(y | d + delta) - ln p(y | d) for y = chatter, y = stable.
    gains: Vec<Option<Vec<[f64; 2]>>>,
    /// Per item: its residual kind.
    kinds: Vec<Option<usize>>,
}

impl Scan {
    fn new(speeds: &[f64], items: &[Item], noise: &NoiseModel) -> Self {
        let n = items.len();
        let starts: Vec<usize> = (0..n)
            .filter(|&k| k == 0 || speeds[k] != speeds[k - 1])
            .collect();
        let mut bands = Vec::new();
        for &a in &starts {
            for &end in starts.iter().filter(|&&e| e > a).chain(std::iter::once(&n)) {
                let len = end - a;
                if len >= MIN_BAND && 2 * len <= n {
                    bands.push((a, end));
                }
            }
        }
        let deltas: Vec<f64> = std::iter::once(0.0)
            .chain(DELTA_GRID.iter().flat_map(|&d| [d, -d]))
            .collect();
        let ln_p = |d: f64, chattered: bool| {
            let p = noise.chatter_probability(d);
            if chattered { p.ln() } else { (1.0 - p).ln() }
        };
        let gains = items
            .iter()
            .map(|item| match *item {
                Item::Label { log_distance, .. } => Some(
                    deltas
                        .iter()
                        .map(|&delta| {
                            let d = log_distance + delta;
                            [
                                ln_p(d, true) - ln_p(log_distance, true),
                                ln_p(d, false) - ln_p(log_distance, false),
                            ]
                        })
                        .collect(),
                ),
                Item::Residual { .. } => None,
            })
            .collect();
        let kinds = items
            .iter()
            .map(|item| match *item {
                Item::Residual { kind, .. } => Some(kind),
                Item::Label { .. } => None,
            })
            .collect();
        Self {
            bands,
            deltas,
            gains,
            kinds,
        }
    }

    /// The largest band statistic for the labels `chattered` (per item; ignored for residuals)
    /// and residuals `z` (per item; ignored for labels), with its band.
    fn largest(&self, chattered: &[bool], z: &[f64]) -> (f64, usize, usize) {
        let n = chattered.len();
        let m = self.deltas.len();
        // prefix sums of the label gains per offset, and of residuals and counts per kind
        let mut label = vec![0.0; (n + 1) * m];
        let mut sums = vec![[0.0; RESIDUAL_KINDS]; n + 1];
        let mut counts = vec![[0usize; RESIDUAL_KINDS]; n + 1];
        for k in 0..n {
            let (row, next) = label.split_at_mut((k + 1) * m);
            let row = &row[k * m..];
            match &self.gains[k] {
                Some(g) => {
                    let y = usize::from(!chattered[k]);
                    for j in 0..m {
                        next[j] = row[j] + g[j][y];
                    }
                }
                None => next[..m].copy_from_slice(row),
            }
            sums[k + 1] = sums[k];
            counts[k + 1] = counts[k];
            if let Some(kind) = self.kinds[k] {
                sums[k + 1][kind] += z[k];
                counts[k + 1][kind] += 1;
            }
        }
        let mut best = (f64::NEG_INFINITY, 0, 0);
        for &(a, end) in &self.bands {
            let labels = (0..m)
                .map(|j| label[end * m + j] - label[a * m + j])
                .fold(0.0, f64::max);
            let residuals: f64 = (0..RESIDUAL_KINDS)
                .filter(|&t| counts[end][t] > counts[a][t])
                .map(|t| {
                    let s = sums[end][t] - sums[a][t];
                    s * s / (2.0 * (counts[end][t] - counts[a][t]) as f64)
                })
                .sum();
            let score = labels + residuals;
            if score > best.0 {
                best = (score, a, end - 1);
            }
        }
        best
    }
}

/// The localized check over posterior-sample predictions of `data` (None with too few
/// observations to form a band).
pub(crate) fn local_check(
    predictions: &[Prediction],
    data: &Dataset,
    noise: &NoiseModel,
    seed: u64,
) -> Option<LocalCheck> {
    let per_sample = REPLICATES.div_ceil(predictions.len().max(1)).max(4);
    let mut exceed = 0usize;
    let mut total = 0usize;
    let mut observed = Vec::new();
    for (s, prediction) in predictions.iter().enumerate() {
        let items = items(prediction, data, noise);
        if items.len() < 2 * MIN_BAND {
            continue;
        }
        let speeds: Vec<f64> = items.iter().map(|(v, _)| *v).collect();
        let items: Vec<Item> = items.into_iter().map(|(_, item)| item).collect();
        let scan = Scan::new(&speeds, &items, noise);
        let (chattered, z): (Vec<bool>, Vec<f64>) = items
            .iter()
            .map(|item| match *item {
                Item::Label { chattered, .. } => (chattered, 0.0),
                Item::Residual { z, .. } => (false, z),
            })
            .unzip();
        let (score, a, b) = scan.largest(&chattered, &z);
        let mut rng = StdRng::seed_from_u64(seed ^ (s as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
        let (mut chattered, mut z) = (chattered, z);
        for _ in 0..per_sample {
            for (k, item) in items.iter().enumerate() {
                match *item {
                    Item::Label { log_distance, .. } => {
                        chattered[k] =
                            rng.random::<f64>() < noise.chatter_probability(log_distance);
                    }
                    Item::Residual { .. } => z[k] = clip(rng.sample(StandardNormal)),
                }
            }
            exceed += usize::from(scan.largest(&chattered, &z).0 >= score);
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

    fn labels(distances: &[f64], chattered: &[bool]) -> Vec<Item> {
        distances
            .iter()
            .zip(chattered)
            .map(|(&log_distance, &chattered)| Item::Label {
                log_distance,
                chattered,
            })
            .collect()
    }

    #[test]
    fn a_band_of_wrong_labels_is_found_and_scored_by_its_likelihood_ratio() {
        let noise = NoiseModel::default();
        let speeds: Vec<f64> = (0..20).map(f64::from).collect();
        let distances = vec![-0.3; 20];
        // cuts 8-11 chatter 26 % below the predicted limit, the rest are stable as predicted
        let chattered: Vec<bool> = (0..20).map(|k| (8..12).contains(&k)).collect();
        let items = labels(&distances, &chattered);
        let scan = Scan::new(&speeds, &items, &noise);
        let (score, a, b) = scan.largest(&chattered, &[0.0; 20]);
        assert_eq!((a, b), (8, 11));
        // the best offset moves the boundary below the cuts: four labels go from about the
        // lapse (1 %) to nearly certain, a ratio of at least 4 ln 50
        assert!(score > 4.0 * 50f64.ln(), "{score}");
        // the labels as predicted: an offset gains almost nothing
        let agreeing = vec![false; 20];
        let (score, _, _) = scan.largest(&agreeing, &[0.0; 20]);
        assert!((0.0..0.01).contains(&score), "{score}");
    }

    #[test]
    fn residual_bands_score_the_gaussian_ratio_of_their_mean() {
        let noise = NoiseModel::default();
        let speeds: Vec<f64> = (0..10).map(f64::from).collect();
        let items: Vec<Item> = (0..10)
            .map(|_| Item::Residual { kind: 1, z: 0.0 })
            .collect();
        let scan = Scan::new(&speeds, &items, &noise);
        let mut z = vec![0.0; 10];
        z[2..5].copy_from_slice(&[2.0, 2.0, 2.0]);
        let (score, a, b) = scan.largest(&[false; 10], &z);
        assert_eq!((a, b), (2, 4));
        // (sum z)^2 / (2 n) = 36 / 6
        assert!((score - 6.0).abs() < 1e-12, "{score}");
        // residuals are clipped to the global check's outlier cap
        assert!((clip(100.0) - OUTLIER_CAP.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn bands_start_and_end_between_distinct_speeds_and_hold_at_most_half() {
        let noise = NoiseModel::default();
        let speeds = [1.0, 2.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];
        let items: Vec<Item> = (0..8).map(|_| Item::Residual { kind: 0, z: 0.0 }).collect();
        let scan = Scan::new(&speeds, &items, &noise);
        assert!(scan.bands.iter().all(|&(a, end)| {
            end - a >= MIN_BAND
                && 2 * (end - a) <= 8
                && (a == 0 || speeds[a] != speeds[a - 1])
                && (end == 8 || speeds[end] != speeds[end - 1])
        }));
        assert!(!scan.bands.iter().any(|&(a, _)| a == 2));
        // too few observations for any band
        let few = Scan::new(&speeds[..5], &items[..5], &noise);
        assert!(few.bands.is_empty());
    }
}
