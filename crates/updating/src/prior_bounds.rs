//! Posteriors that pile against a bound of their prior.
//!
//! A posterior whose mass collects at the edge of a bounded prior (uniform or truncated normal)
//! is decided by the bound, not by the data: the prior range was too narrow. On the seed-000
//! update the error variance sigma_R^2 does this against the paper's bound 0.1 (000 Section 6.3:
//! U[1e-10, 0.1]; posterior median about 0.099), and widening the bound changes the selected
//! model class. [`prior_bound_pileups`] flags such parameters so that the user can widen the
//! prior (`chatter update --priors`).
//!
//! Criterion: more than [`PILEUP_SHARE`] of the posterior mass lies within [`EDGE_FRACTION`] of
//! the prior range from a bound. A posterior well inside the range has (almost) none there; one
//! cut off by the bound has a density at the bound at least as high as anywhere, so a share of
//! the order of its width over the strip.

use chatter_bayes::prior::Marginal;
use chatter_bayes::samples::SampleSet;

/// Width of the strip next to a bound, as a fraction of the prior range.
pub const EDGE_FRACTION: f64 = 0.01;
/// Posterior share inside the strip above which a parameter is flagged.
pub const PILEUP_SHARE: f64 = 0.1;

/// Which bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Bound {
    /// The lower bound.
    Lower,
    /// The upper bound.
    Upper,
}

/// A parameter whose posterior piles against a prior bound.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BoundPileup {
    /// Parameter name.
    pub parameter: String,
    /// Which bound.
    pub bound: Bound,
    /// The bound's value.
    pub bound_value: f64,
    /// Posterior median.
    pub posterior_median: f64,
    /// Posterior share within [`EDGE_FRACTION`] of the range from the bound.
    pub share_at_bound: f64,
}

fn bounds(m: &Marginal) -> Option<(f64, f64)> {
    match *m {
        Marginal::Uniform { low, high } | Marginal::TruncatedNormal { low, high, .. } => {
            Some((low, high))
        }
        Marginal::Normal { .. } | Marginal::LogNormal { .. } => None,
    }
}

/// The parameters (names in sample order) whose posterior `samples` pile against a bound of
/// their prior `marginals`.
pub fn prior_bound_pileups(
    names: &[String],
    marginals: &[Marginal],
    samples: &SampleSet,
) -> Vec<BoundPileup> {
    let mut out = Vec::new();
    for (k, (name, m)) in names.iter().zip(marginals).enumerate() {
        let Some((lo, hi)) = bounds(m) else { continue };
        let edge = EDGE_FRACTION * (hi - lo);
        let share = |near: &dyn Fn(f64) -> bool| -> f64 {
            samples
                .samples()
                .iter()
                .zip(samples.weights())
                .filter(|(s, _)| near(s[k]))
                .map(|(_, w)| w)
                .sum()
        };
        for (bound, value, s) in [
            (Bound::Lower, lo, share(&|x| x <= lo + edge)),
            (Bound::Upper, hi, share(&|x| x >= hi - edge)),
        ] {
            if s > PILEUP_SHARE {
                out.push(BoundPileup {
                    parameter: name.clone(),
                    bound,
                    bound_value: value,
                    posterior_median: samples.quantile(k, 0.5),
                    share_at_bound: s,
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A posterior cut off at the upper bound of U[0, 1] (uniform on [0.95, 1]: 20 % in the
    /// 0.01 strip) is flagged; one well inside is not, nor is an unbounded normal prior.
    #[test]
    fn flags_mass_at_a_bound_only() {
        let names = vec!["a".to_string(), "b".to_string(), "c".to_string()];
        let marginals = [
            Marginal::Uniform {
                low: 0.0,
                high: 1.0,
            },
            Marginal::Uniform {
                low: 0.0,
                high: 1.0,
            },
            Marginal::Normal { mean: 0.0, sd: 1.0 },
        ];
        let n = 1000;
        let rows: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                let u = (i as f64 + 0.5) / n as f64;
                vec![0.95 + 0.05 * u, 0.4 + 0.2 * u, 5.0]
            })
            .collect();
        let set = SampleSet::equally_weighted(rows).unwrap();
        let flags = prior_bound_pileups(&names, &marginals, &set);
        assert_eq!(flags.len(), 1, "{flags:?}");
        assert_eq!(flags[0].parameter, "a");
        assert_eq!(flags[0].bound, Bound::Upper);
        assert!((flags[0].share_at_bound - 0.2).abs() < 0.01);
    }
}
