//! Monte Carlo probability-of-stability maps (Schmitz et al. 2022, seed 004, Fig. 2).
//!
//! Each parameter sample (from a prior or a posterior) gives its own stability boundary
//! b_lim,s(Omega). The probability that a cut (Omega, b) is stable is the fraction of samples whose
//! boundary lies above it, P_s(Omega, b) = (1/S) sum_s 1[b < b_lim,s(Omega)]: computing one limiting
//! depth per sample and speed (a root find) is far cheaper than evaluating every grid cell, and it
//! makes P_s exactly monotone in depth. The chatter frequency on each sample's boundary gives the
//! distribution of the expected chatter frequency along speed.

use crate::error::{Result, UncertaintyError};
use chatter_dynamics::{ModalModel, Parameter};
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use nalgebra::{DMatrix, DVector};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Per-sample limiting depths (and chatter frequencies) on a common speed grid.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledBoundaries {
    /// Speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// `limits_mm[s][i]`: limiting depth of sample s at `speeds_rpm[i]`.
    pub limits_mm: Vec<Vec<f64>>,
    /// `chatter_hz[s][i]`: chatter frequency on that boundary.
    pub chatter_hz: Vec<Vec<f64>>,
}

/// P_s on a speed x depth grid.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityMap {
    /// Speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// Depths (mm).
    pub depths_mm: Vec<f64>,
    /// `p_stable[i][j]` at `speeds_rpm[i]`, `depths_mm[j]`.
    pub p_stable: Vec<Vec<f64>>,
}

/// Quantiles of a quantity along speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuantileBand {
    /// Spindle speed.
    pub speed_rpm: f64,
    /// 5 % quantile.
    pub q05: f64,
    /// Median.
    pub q50: f64,
    /// 95 % quantile.
    pub q95: f64,
}

impl SampledBoundaries {
    /// Validate shapes: every sample has one limit and one frequency per speed.
    pub fn new(
        speeds_rpm: Vec<f64>,
        limits_mm: Vec<Vec<f64>>,
        chatter_hz: Vec<Vec<f64>>,
    ) -> Result<Self> {
        if limits_mm.is_empty() {
            return Err(UncertaintyError::InvalidInput {
                field: "samples",
                message: "no samples".into(),
            });
        }
        let n = speeds_rpm.len();
        if limits_mm
            .iter()
            .chain(&chatter_hz)
            .any(|row| row.len() != n)
            || chatter_hz.len() != limits_mm.len()
        {
            return Err(UncertaintyError::InvalidInput {
                field: "samples",
                message: format!("every sample needs {n} limits and {n} chatter frequencies"),
            });
        }
        Ok(Self {
            speeds_rpm,
            limits_mm,
            chatter_hz,
        })
    }

    /// P_s(speed, depth) on `depths_mm`.
    pub fn stability_map(&self, depths_mm: &[f64]) -> StabilityMap {
        let s = self.limits_mm.len() as f64;
        let p_stable = (0..self.speeds_rpm.len())
            .map(|i| {
                depths_mm
                    .iter()
                    .map(|&b| self.limits_mm.iter().filter(|l| b < l[i]).count() as f64 / s)
                    .collect()
            })
            .collect();
        StabilityMap {
            speeds_rpm: self.speeds_rpm.clone(),
            depths_mm: depths_mm.to_vec(),
            p_stable,
        }
    }

    /// Depth (mm) at which P_s equals `p` at each speed: the (1 - p) quantile of the sampled
    /// limits. p = 0.5 gives the median boundary.
    pub fn probability_contour(&self, p: f64) -> Vec<(f64, f64)> {
        self.speeds_rpm
            .iter()
            .enumerate()
            .map(|(i, &speed)| {
                let col: Vec<f64> = self.limits_mm.iter().map(|l| l[i]).collect();
                (speed, quantile(col, 1.0 - p))
            })
            .collect()
    }

    /// 5/50/95 % quantiles of the chatter frequency along speed.
    pub fn chatter_frequency_bands(&self) -> Vec<QuantileBand> {
        self.band(&self.chatter_hz)
    }

    /// 5/50/95 % quantiles of the limiting depth along speed (mm).
    pub fn depth_bands(&self) -> Vec<QuantileBand> {
        self.band(&self.limits_mm)
    }

    fn band(&self, rows: &[Vec<f64>]) -> Vec<QuantileBand> {
        self.speeds_rpm
            .iter()
            .enumerate()
            .map(|(i, &speed_rpm)| {
                let col: Vec<f64> = rows.iter().map(|r| r[i]).collect();
                QuantileBand {
                    speed_rpm,
                    q05: quantile(col.clone(), 0.05),
                    q50: quantile(col.clone(), 0.5),
                    q95: quantile(col, 0.95),
                }
            })
            .collect()
    }
}

/// Linear-interpolated quantile (type 7) of finite values; NaN when there are none.
pub fn quantile(mut values: Vec<f64>, q: f64) -> f64 {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let h = (values.len() - 1) as f64 * q.clamp(0.0, 1.0);
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    values[lo] + (h - lo as f64) * (values[hi] - values[lo])
}

/// One draw per sample of theta ~ N(`mean`, `covariance`), seeded: theta = mean + L z with L the
/// Cholesky factor of the covariance and z standard normal. The draws do not depend on threads.
pub fn gaussian_draws(
    mean: &[f64],
    covariance: &DMatrix<f64>,
    samples: usize,
    seed: u64,
) -> Result<Vec<Vec<f64>>> {
    let d = mean.len();
    if covariance.shape() != (d, d) {
        return Err(UncertaintyError::InvalidInput {
            field: "covariance",
            message: format!(
                "a {d} x {d} matrix expected for {d} parameters, got {} x {}",
                covariance.nrows(),
                covariance.ncols()
            ),
        });
    }
    let l = covariance
        .clone()
        .cholesky()
        .ok_or_else(|| UncertaintyError::InvalidInput {
            field: "covariance",
            message: "not symmetric positive definite".into(),
        })?
        .l();
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    Ok((0..samples)
        .map(|_| {
            let z = DVector::from_fn(d, |_, _| StandardNormal.sample(&mut rng));
            let t = &l * z;
            mean.iter().zip(t.iter()).map(|(m, t)| m + t).collect()
        })
        .collect())
}

/// The boundary of `model` perturbed by each parameter sample `thetas[s]` (see
/// [`chatter_dynamics::ModalModel::perturbed`]) at every speed, in parallel over samples; the
/// result does not depend on the thread count. `progress(done, total)` is called per sample.
pub fn sample_boundaries<S: StabilitySolver + ?Sized>(
    solver: &S,
    model: &ModalModel,
    parameters: &[Parameter],
    thetas: &[Vec<f64>],
    speeds_rpm: &[f64],
    options: &BoundaryOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<SampledBoundaries> {
    use rayon::prelude::*;
    let done = AtomicUsize::new(0);
    let rows = thetas
        .par_iter()
        .map(|theta| {
            let m =
                model
                    .perturbed(parameters, theta)
                    .map_err(|e| UncertaintyError::InvalidInput {
                        field: "samples",
                        message: e.to_string(),
                    })?;
            let row = speeds_rpm
                .iter()
                .map(|&s| limiting_depth(solver, &m, s, options))
                .collect::<std::result::Result<Vec<_>, _>>()?;
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, thetas.len());
            Ok(row)
        })
        .collect::<Result<Vec<_>>>()?;
    let limits = rows
        .iter()
        .map(|r| r.iter().map(|p| p.depth_mm()).collect())
        .collect();
    let hz = rows
        .iter()
        .map(|r| r.iter().map(|p| p.chatter_hz).collect())
        .collect();
    SampledBoundaries::new(speeds_rpm.to_vec(), limits, hz)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampled() -> SampledBoundaries {
        // 101 samples of a flat boundary at 1.0 + k/100 mm
        let speeds = vec![1000.0, 2000.0];
        let limits: Vec<Vec<f64>> = (0..=100).map(|k| vec![1.0 + k as f64 / 100.0; 2]).collect();
        let hz = vec![vec![500.0, 600.0]; 101];
        SampledBoundaries::new(speeds, limits, hz).unwrap()
    }

    #[test]
    fn map_is_one_below_zero_above_and_monotone() {
        let s = sampled();
        let depths: Vec<f64> = (0..=60).map(|j| j as f64 * 0.05).collect();
        let map = s.stability_map(&depths);
        for row in &map.p_stable {
            assert_eq!(row[0], 1.0);
            assert_eq!(*row.last().unwrap(), 0.0);
            assert!(row.windows(2).all(|w| w[1] <= w[0]));
        }
        let median = s.probability_contour(0.5);
        assert!((median[0].1 - 1.5).abs() < 1e-12);
    }

    #[test]
    fn rejects_ragged_samples() {
        assert!(SampledBoundaries::new(vec![1.0, 2.0], vec![vec![1.0]], vec![vec![1.0]]).is_err());
        assert!(SampledBoundaries::new(vec![1.0], vec![], vec![]).is_err());
    }
}
