//! How far the gap shrinks on held-out observations once the winning effect is added.
//!
//! The observations (cuts and poles together) are split into folds: k folds at random, or
//! contiguous bands of the distinct spindle speeds (leave one speed band out). For each fold the
//! winning class is fitted to the other folds and predicts the held-out ones through its
//! posterior predictive distribution; "before" is the nominal model. The metrics, pooled over
//! the folds:
//! - balanced misclassification rate of the cuts, (false stable rate + false chatter rate) / 2,
//!   a cut counting as predicted chatter where its predictive chatter probability exceeds 1/2;
//! - log predictive density per held-out observation (a cut with its chatter frequency, or a
//!   pole), ln mean_s p(y_i | theta_s);
//! - RMS chatter-frequency residual (folded; against the posterior median prediction);
//! - RMS pole frequency and damping residuals.

use crate::classes::{EffectClass, Nominal};
use crate::data::Dataset;
use crate::diagnose::{DiagnoseOptions, Validation, class_seed, fit, posterior_predictions};
use crate::error::Result;
use crate::likelihood::{NoiseModel, terms};
use crate::predict::{Prediction, predict};
use crate::regions::{residuals, rms};
use chatter_bayes::special::log_mean_exp;
use rand::SeedableRng;
use rand::rngs::StdRng;
use rand::seq::SliceRandom;
use serde::Serialize;

/// A metric before and after adding the winning effect.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Metric {
    /// With the nominal model.
    pub before: f64,
    /// With the winning class fitted to the other folds.
    pub after: f64,
}

/// The held-out metrics (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Shrink {
    /// Balanced misclassification rate of the cuts.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub balanced_misclassification: Option<Metric>,
    /// Log predictive density per held-out observation.
    pub log_predictive_density_per_observation: Metric,
    /// RMS chatter-frequency residual (Hz).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms_chatter_residual_hz: Option<Metric>,
    /// RMS pole-frequency residual (Hz).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms_pole_frequency_residual_hz: Option<Metric>,
    /// RMS pole-damping residual.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms_pole_damping_residual: Option<Metric>,
}

/// How the shrinkage was measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ValidationReport {
    /// `k_fold` or `speed_bands`.
    pub scheme: &'static str,
    /// Number of folds.
    pub folds: usize,
    /// The class fitted in each fold.
    pub class: EffectClass,
}

/// Pooled held-out quantities of one model.
#[derive(Debug, Default)]
struct Pool {
    /// (observed unstable, predicted unstable) per cut.
    labels: Vec<(bool, bool)>,
    /// ln predictive density per observation.
    lpd: Vec<f64>,
    chatter: Vec<f64>,
    pole_frequency: Vec<f64>,
    pole_damping: Vec<f64>,
}

impl Pool {
    /// Add the held-out `data` under the predictions of posterior samples (one for the nominal).
    fn add(&mut self, predictions: &[Prediction], data: &Dataset, noise: &NoiseModel) {
        if predictions.is_empty() {
            return;
        }
        let all: Vec<_> = predictions.iter().map(|p| terms(p, data, noise)).collect();
        let log_mean =
            |values: &mut dyn Iterator<Item = f64>| log_mean_exp(&values.collect::<Vec<f64>>());
        for (i, c) in data.cuts.iter().enumerate() {
            self.lpd.push(log_mean(&mut all.iter().map(|t| t.cut(i))));
            let p = predictions
                .iter()
                .map(|pr| {
                    noise.chatter_probability(pr.cuts[i].map_or(f64::NAN, |q| q.log_distance()))
                })
                .sum::<f64>()
                / predictions.len() as f64;
            self.labels.push((!c.stable, p > 0.5));
        }
        for i in 0..data.poles.len() {
            self.lpd.push(log_mean(&mut all.iter().map(|t| t.pole(i))));
        }
        // residuals against the median prediction
        let res: Vec<_> = predictions
            .iter()
            .map(|p| residuals(p, data, noise))
            .collect();
        let median = |mut v: Vec<f64>| -> Option<f64> {
            v.retain(|x| x.is_finite());
            v.sort_by(f64::total_cmp);
            (!v.is_empty()).then(|| v[v.len() / 2])
        };
        for i in 0..data.cuts.len() {
            if let Some(r) = median(
                res.iter()
                    .filter_map(|r| r.cuts[i].chatter_residual_hz)
                    .collect(),
            ) {
                self.chatter.push(r);
            }
        }
        for i in 0..data.poles.len() {
            if let Some(r) = median(
                res.iter()
                    .map(|r| r.poles[i].frequency_residual_hz)
                    .collect(),
            ) {
                self.pole_frequency.push(r);
            }
            if let Some(r) = median(res.iter().map(|r| r.poles[i].damping_residual).collect()) {
                self.pole_damping.push(r);
            }
        }
    }

    fn balanced_misclassification(&self) -> Option<f64> {
        let unstable = self.labels.iter().filter(|l| l.0).count();
        let stable = self.labels.len() - unstable;
        let missed = self.labels.iter().filter(|l| l.0 && !l.1).count();
        let false_alarms = self.labels.iter().filter(|l| !l.0 && l.1).count();
        match (unstable, stable) {
            (0, 0) => None,
            (0, s) => Some(false_alarms as f64 / s as f64),
            (u, 0) => Some(missed as f64 / u as f64),
            (u, s) => Some(0.5 * (missed as f64 / u as f64 + false_alarms as f64 / s as f64)),
        }
    }
}

/// The fold of every cut and every pole.
fn folds(
    data: &Dataset,
    validation: Validation,
    seed: u64,
) -> Option<(Vec<usize>, Vec<usize>, usize)> {
    match validation {
        Validation::Off => None,
        Validation::KFold { folds } => {
            let n = data.cuts.len() + data.poles.len();
            let mut order: Vec<usize> = (0..n).collect();
            order.shuffle(&mut StdRng::seed_from_u64(seed ^ 0x5EED_F01D));
            let mut fold = vec![0; n];
            for (k, &i) in order.iter().enumerate() {
                fold[i] = k % folds;
            }
            let poles = fold.split_off(data.cuts.len());
            Some((fold, poles, folds))
        }
        Validation::SpeedBands { bands } => {
            let mut speeds: Vec<f64> = data
                .cuts
                .iter()
                .map(|c| c.speed_rpm)
                .chain(data.poles.iter().map(|p| p.speed_rpm))
                .collect();
            speeds.sort_by(f64::total_cmp);
            speeds.dedup();
            let bands = bands.min(speeds.len()).max(1);
            let band = |s: f64| -> usize {
                let i = speeds.iter().position(|x| *x == s).unwrap_or(0);
                i * bands / speeds.len()
            };
            Some((
                data.cuts.iter().map(|c| band(c.speed_rpm)).collect(),
                data.poles.iter().map(|p| band(p.speed_rpm)).collect(),
                bands,
            ))
        }
    }
}

/// The held-out shrinkage of the gap with `class`, or None when validation is off.
pub(crate) fn shrink(
    class: EffectClass,
    nominal: &Nominal,
    data: &Dataset,
    options: &DiagnoseOptions,
    observer: &dyn chatter_progress::Observer,
) -> Result<Option<(Shrink, ValidationReport)>> {
    let Some((cut_fold, pole_fold, k)) = folds(data, options.validation, options.seed) else {
        return Ok(None);
    };
    let (mut before, mut after) = (Pool::default(), Pool::default());
    for fold in 0..k {
        let pick = |f: &[usize], inside: bool| -> Vec<usize> {
            (0..f.len()).filter(|&i| (f[i] == fold) == inside).collect()
        };
        let test = data.subset(&pick(&cut_fold, true), &pick(&pole_fold, true));
        let train = data.subset(&pick(&cut_fold, false), &pick(&pole_fold, false));
        if test.len() == 0 || train.len() == 0 {
            continue;
        }
        before.add(&[predict(&nominal.variant(), &test)], &test, &options.noise);
        let fitted = fit(
            class,
            nominal,
            &train,
            options,
            options.validation_samples,
            class_seed(options.seed, class, fold + 1),
            observer,
        )?;
        after.add(
            &posterior_predictions(&fitted, &test),
            &test,
            &options.noise,
        );
        observer.steps_done(fold + 1, k);
    }
    let metric = |b: Option<f64>, a: Option<f64>| match (b, a) {
        (Some(before), Some(after)) => Some(Metric { before, after }),
        _ => None,
    };
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let shrink = Shrink {
        balanced_misclassification: metric(
            before.balanced_misclassification(),
            after.balanced_misclassification(),
        ),
        log_predictive_density_per_observation: Metric {
            before: mean(&before.lpd),
            after: mean(&after.lpd),
        },
        rms_chatter_residual_hz: metric(rms(&before.chatter), rms(&after.chatter)),
        rms_pole_frequency_residual_hz: metric(
            rms(&before.pole_frequency),
            rms(&after.pole_frequency),
        ),
        rms_pole_damping_residual: metric(rms(&before.pole_damping), rms(&after.pole_damping)),
    };
    let report = ValidationReport {
        scheme: match options.validation {
            Validation::SpeedBands { .. } => "speed_bands",
            _ => "k_fold",
        },
        folds: k,
        class,
    };
    Ok(Some((shrink, report)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::{HiddenEffect, Scenario, nominal_milling, synthesize};

    #[test]
    fn folds_cover_every_observation_and_bands_are_contiguous() {
        let model = nominal_milling().unwrap();
        let obs = synthesize(&model, &Scenario::new(HiddenEffect::ParameterError, 2)).unwrap();
        let data = Dataset::new(&model, &obs, &NoiseModel::default(), 750.0).unwrap();
        let (cuts, poles, k) = folds(&data, Validation::KFold { folds: 4 }, 1).unwrap();
        assert_eq!(k, 4);
        assert_eq!(cuts.len(), data.cuts.len());
        assert_eq!(poles.len(), data.poles.len());
        let n = data.len();
        for f in 0..4 {
            let size = cuts.iter().chain(&poles).filter(|x| **x == f).count();
            assert!(size == n / 4 || size == n / 4 + 1);
        }
        let (cuts, _, k) = folds(&data, Validation::SpeedBands { bands: 3 }, 1).unwrap();
        assert_eq!(k, 3);
        for (a, fa) in data.cuts.iter().zip(&cuts) {
            for (b, fb) in data.cuts.iter().zip(&cuts) {
                if a.speed_rpm < b.speed_rpm {
                    assert!(fa <= fb);
                }
            }
        }
        assert!(folds(&data, Validation::Off, 1).is_none());
    }

    #[test]
    fn balanced_misclassification_weights_both_kinds() {
        let pool = Pool {
            labels: vec![(true, true), (true, false), (false, false), (false, false)],
            ..Pool::default()
        };
        // half the chatters missed, no false alarms
        assert!((pool.balanced_misclassification().unwrap() - 0.25).abs() < 1e-12);
    }
}
