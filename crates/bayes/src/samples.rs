//! Weighted sample sets: mean, covariance, quantiles, effective sample size.

use crate::error::{BayesError, Result};
use nalgebra::{DMatrix, DVector};

/// Samples with normalized weights.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleSet {
    samples: Vec<Vec<f64>>,
    weights: Vec<f64>,
}

impl SampleSet {
    /// Weighted samples (weights >= 0, not all zero; same dimension everywhere).
    pub fn new(samples: Vec<Vec<f64>>, weights: Vec<f64>) -> Result<Self> {
        let d = samples.first().map_or(0, Vec::len);
        if samples.is_empty()
            || d == 0
            || samples.iter().any(|s| s.len() != d)
            || weights.len() != samples.len()
        {
            return Err(BayesError::InvalidInput {
                field: "samples",
                message: "non-empty samples of one dimension with one weight each expected".into(),
            });
        }
        let total: f64 = weights.iter().sum();
        if !(total > 0.0 && total.is_finite()) || weights.iter().any(|w| *w < 0.0) {
            return Err(BayesError::InvalidInput {
                field: "weights",
                message: "weights must be >= 0 with a positive finite sum".into(),
            });
        }
        Ok(Self {
            samples,
            weights: weights.iter().map(|w| w / total).collect(),
        })
    }
    /// Equal weights.
    pub fn equally_weighted(samples: Vec<Vec<f64>>) -> Result<Self> {
        let n = samples.len();
        Self::new(samples, vec![1.0; n])
    }
    /// The samples.
    pub fn samples(&self) -> &[Vec<f64>] {
        &self.samples
    }
    /// Normalized weights.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
    /// Dimension.
    pub fn dimension(&self) -> usize {
        self.samples[0].len()
    }
    /// Weighted mean.
    pub fn mean(&self) -> Vec<f64> {
        let mut m = vec![0.0; self.dimension()];
        for (s, w) in self.samples.iter().zip(&self.weights) {
            for (mi, si) in m.iter_mut().zip(s) {
                *mi += w * si;
            }
        }
        m
    }
    /// Weighted covariance.
    pub fn covariance(&self) -> DMatrix<f64> {
        let d = self.dimension();
        let m = DVector::from_vec(self.mean());
        let mut c = DMatrix::zeros(d, d);
        for (s, w) in self.samples.iter().zip(&self.weights) {
            let x = DVector::from_column_slice(s) - &m;
            c += &x * x.transpose() * *w;
        }
        c
    }
    /// Weighted quantile of one coordinate.
    pub fn quantile(&self, coordinate: usize, q: f64) -> f64 {
        let pairs = self
            .samples
            .iter()
            .map(|s| s[coordinate])
            .zip(self.weights.iter().copied())
            .collect();
        crate::special::weighted_quantile(pairs, q)
    }
    /// Kish effective sample size 1 / sum w^2.
    pub fn effective_sample_size(&self) -> f64 {
        1.0 / self.weights.iter().map(|w| w * w).sum::<f64>()
    }
}
