//! The posterior predictive check that decides whether the best class explains the data.
//!
//! For each observable type the discrepancy is the deviance T = -2 sum ln p(y_i | theta) of the
//! labels, and the sum of squared standardized residuals of chatter frequencies, pole
//! frequencies and pole damping ratios. Over posterior samples theta_s, the p-value is the
//! posterior probability that replicated data are at least as discrepant: labels are
//! replicated by drawing from each cut's chatter probability, and the Gaussian sums follow
//! chi-square laws (Wilson-Hilferty). Each squared standardized residual is capped at
//! [`OUTLIER_CAP`], the 99.9 % point of chi^2_1: the likelihood lets an observation be an outlier
//! with the lapse probability (a limit cycle settled on another root, a spurious identified
//! pole), so one outlier alone must not fail the check, while many large residuals still do;
//! against the uncapped chi-square law the p-value is lenient, never smaller than without the
//! cap. A fifth p-value is the localized check's ([`crate::local`]): the misfit of the worst band
//! of speeds. The best class fails when the smallest p-value is below the family-wise level
//! divided by the number of p-values (Bonferroni).

use crate::data::Dataset;
use crate::likelihood::{NoiseModel, nearest_chatter_residual, pole_residuals, terms};
use crate::local::{LocalCheck, local_check};
use crate::predict::Prediction;
use chatter_bayes::special::normal_cdf;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use serde::Serialize;

/// Cap of one squared standardized residual: the 99.9 % point of chi^2_1.
pub const OUTLIER_CAP: f64 = 10.83;

/// Label replications per posterior sample.
const REPLICATES: usize = 40;

/// The posterior predictive p-value of each observable type (None without such observations).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PredictiveCheck {
    /// Cut labels (stable / chatter).
    pub cut_labels: Option<f64>,
    /// Chatter frequencies.
    pub chatter_frequencies: Option<f64>,
    /// Pole frequencies.
    pub pole_frequencies: Option<f64>,
    /// Pole damping ratios.
    pub pole_damping: Option<f64>,
    /// The localized check: the band of speeds where the misfit concentrates most, and its
    /// p-value ([`crate::local`]).
    pub local: Option<LocalCheck>,
    /// The family-wise level the smallest p-value is held to.
    pub level: f64,
    /// Whether the class explains the data at that level.
    pub passed: bool,
}

impl PredictiveCheck {
    /// The p-values of the check (None for observable types without observations).
    fn p_values(&self) -> [Option<f64>; 5] {
        [
            self.cut_labels,
            self.chatter_frequencies,
            self.pole_frequencies,
            self.pole_damping,
            self.local.map(|l| l.p_value),
        ]
    }

    /// The level each p-value is held to: the family-wise level over their number (Bonferroni).
    fn bonferroni_level(&self) -> f64 {
        self.level / self.p_values().iter().flatten().count().max(1) as f64
    }

    /// The band of speeds (rpm) whose localized check fails at the Bonferroni level: where the
    /// misfit concentrates beyond what the noise allows ([`crate::local`]).
    pub fn failing_band(&self) -> Option<(f64, f64)> {
        self.local
            .filter(|l| l.p_value < self.bonferroni_level())
            .map(|l| (l.from_rpm, l.to_rpm))
    }
}

/// P(chi^2_n >= t) by the Wilson-Hilferty approximation.
fn chi_square_tail(t: f64, n: usize) -> f64 {
    let n = n as f64;
    let v = 2.0 / (9.0 * n);
    let z = ((t / n).cbrt() - (1.0 - v)) / v.sqrt();
    normal_cdf(-z)
}

/// The check over posterior-sample predictions of `data`.
pub(crate) fn predictive_check(
    predictions: &[Prediction],
    data: &Dataset,
    noise: &NoiseModel,
    level: f64,
    seed: u64,
) -> PredictiveCheck {
    let mut label_p = Vec::new();
    let mut chatter_p = Vec::new();
    let mut pole_f_p = Vec::new();
    let mut pole_z_p = Vec::new();
    for (s, pred) in predictions.iter().enumerate() {
        // labels: deviance of the data against replicated labels
        if !data.cuts.is_empty() {
            let q: Vec<f64> = pred
                .cuts
                .iter()
                .map(|q| noise.chatter_probability(q.map_or(f64::NAN, |q| q.log_distance())))
                .collect();
            let deviance = |unstable: &dyn Fn(usize) -> bool| -> f64 {
                q.iter()
                    .enumerate()
                    .map(|(i, &p)| -2.0 * if unstable(i) { p.ln() } else { (1.0 - p).ln() })
                    .sum()
            };
            let observed = deviance(&|i| !data.cuts[i].stable);
            let mut rng =
                StdRng::seed_from_u64(seed ^ (s as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
            let mut exceed = 0usize;
            for _ in 0..REPLICATES {
                let draws: Vec<bool> = q.iter().map(|&p| rng.random::<f64>() < p).collect();
                if deviance(&|i| draws[i]) >= observed {
                    exceed += 1;
                }
            }
            label_p.push(exceed as f64 / REPLICATES as f64);
        }
        // chatter frequencies
        let chatter: Vec<f64> = data
            .cuts
            .iter()
            .enumerate()
            .filter_map(|(i, c)| {
                let f = c.chatter_hz?;
                let q = pred.cuts[i]?;
                let r = nearest_chatter_residual(f, &q, pred.cut_fold_hz[i]);
                Some((r / data.chatter_std_hz).powi(2).min(OUTLIER_CAP))
            })
            .collect();
        if !chatter.is_empty() {
            chatter_p.push(chi_square_tail(chatter.iter().sum(), chatter.len()));
        }
        if !data.poles.is_empty() {
            let scale = terms(pred, data, noise).pole_scale;
            let (mut tf, mut tz) = (0.0, 0.0);
            for (i, p) in data.poles.iter().enumerate() {
                match pred.poles[i] {
                    Some(q) => {
                        let (rf, rz) = pole_residuals(
                            p.frequency_hz,
                            p.damping_ratio,
                            &q,
                            pred.pole_fold_hz[i],
                        );
                        tf += (rf / p.frequency_std_hz(scale)).powi(2).min(OUTLIER_CAP);
                        tz += (rz / p.damping_std).powi(2).min(OUTLIER_CAP);
                    }
                    // a failed prediction is neither a misfit nor a fit
                    None => {
                        tf += 1.0;
                        tz += 1.0;
                    }
                }
            }
            pole_f_p.push(chi_square_tail(tf, data.poles.len()));
            pole_z_p.push(chi_square_tail(tz, data.poles.len()));
        }
    }
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    let local = local_check(predictions, data, noise, seed);
    let mut check = PredictiveCheck {
        cut_labels: mean(&label_p),
        chatter_frequencies: mean(&chatter_p),
        pole_frequencies: mean(&pole_f_p),
        pole_damping: mean(&pole_z_p),
        local,
        level,
        passed: false,
    };
    let smallest = check
        .p_values()
        .iter()
        .flatten()
        .copied()
        .fold(1.0, f64::min);
    check.passed = smallest >= check.bonferroni_level();
    check
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi_square_tail_is_close_to_exact() {
        // chi^2_2 tail is exp(-t / 2)
        for t in [0.5, 2.0, 6.0, 12.0] {
            let exact = (-t / 2.0f64).exp();
            assert!((chi_square_tail(t, 2) - exact).abs() < 0.02, "{t}");
        }
        // median of chi^2_30 is about 29.34
        assert!((chi_square_tail(29.34, 30) - 0.5).abs() < 0.01);
    }
}
