//! Monte Carlo probability-of-stability maps (Schmitz et al. 2022, seed 004, Fig. 2).
//!
//! Each parameter sample (from a prior or a posterior) gives its own stability boundary
//! b_lim,s(Omega). The probability that a cut (Omega, b) is stable is the fraction of samples whose
//! boundary lies above it, P_s(Omega, b) = (1/S) sum_s 1[b < b_lim,s(Omega)]: computing one limiting
//! depth per sample and speed (a root find) is far cheaper than evaluating every grid cell, and it
//! makes P_s exactly monotone in depth. The chatter frequency on each sample's boundary gives the
//! distribution of the expected chatter frequency along speed.
//!
//! A sample whose parameters give no valid model (outside the support, e.g. a negative damping
//! ratio) or whose boundary search fails numerically at a speed is recorded as a
//! [`SampleFailure`], never as a stable or an unstable boundary: its limit is NaN, P_s at that
//! speed is the fraction over the samples that succeeded there, and the counts are reported
//! ([`SampledBoundaries::failures_per_speed`], [`StabilityMap::samples_per_speed`]). One failure
//! does not stop the map.

use crate::error::{Result, UncertaintyError};
use chatter_progress::Observer;
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_updating::parameters::Parameterization;
use nalgebra::{DMatrix, DVector};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Per-sample limiting depths (and chatter frequencies) on a common speed grid.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledBoundaries {
    /// Speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// `limits_mm[s][i]`: limiting depth of sample s at `speeds_rpm[i]`; `f64::INFINITY` when
    /// stable up to the search ceiling, NaN when the sample failed there (see `failures`).
    pub limits_mm: Vec<Vec<f64>>,
    /// `chatter_hz[s][i]`: chatter frequency on that boundary.
    pub chatter_hz: Vec<Vec<f64>>,
    /// The samples (and speeds) that gave no boundary, in sample then speed order.
    pub failures: Vec<SampleFailure>,
}

/// Why a sample gave no boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum FailureKind {
    /// The parameters give no valid model (outside the prior's support): the whole sample.
    InvalidSample,
    /// The stability solver failed at one speed (no convergence, overflow).
    Numerical,
}

/// One sample without a boundary at one speed (or at all).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SampleFailure {
    /// Index of the sample in the draws.
    pub sample: usize,
    /// The speed (rpm) where it failed; `None` when the whole sample is invalid.
    pub speed_rpm: Option<f64>,
    /// Which kind of failure.
    pub kind: FailureKind,
    /// The error message.
    pub message: String,
}

/// P_s on a speed x depth grid.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityMap {
    /// Speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// Depths (mm).
    pub depths_mm: Vec<f64>,
    /// `p_stable[i][j]` at `speeds_rpm[i]`, `depths_mm[j]`: the fraction of the samples with a
    /// boundary at that speed whose limit lies above the depth; NaN when none has one.
    pub p_stable: Vec<Vec<f64>>,
    /// Samples with a boundary at each speed (the denominator of `p_stable`).
    pub samples_per_speed: Vec<usize>,
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
            failures: Vec::new(),
        })
    }

    /// The same boundaries with the failures that produced their NaN limits recorded.
    pub fn with_failures(self, failures: Vec<SampleFailure>) -> Self {
        Self { failures, ..self }
    }

    /// Samples without a boundary at each speed (invalid samples count at every speed).
    pub fn failures_per_speed(&self) -> Vec<usize> {
        (0..self.speeds_rpm.len())
            .map(|i| self.limits_mm.iter().filter(|l| l[i].is_nan()).count())
            .collect()
    }

    /// P_s(speed, depth) on `depths_mm`, over the samples with a boundary at each speed.
    pub fn stability_map(&self, depths_mm: &[f64]) -> StabilityMap {
        let samples_per_speed: Vec<usize> = (0..self.speeds_rpm.len())
            .map(|i| self.limits_mm.iter().filter(|l| !l[i].is_nan()).count())
            .collect();
        let p_stable = samples_per_speed
            .iter()
            .enumerate()
            .map(|(i, &used)| {
                depths_mm
                    .iter()
                    .map(|&b| {
                        if used == 0 {
                            return f64::NAN;
                        }
                        // a NaN limit compares false: failures are neither stable nor counted
                        self.limits_mm.iter().filter(|l| b < l[i]).count() as f64 / used as f64
                    })
                    .collect()
            })
            .collect();
        StabilityMap {
            speeds_rpm: self.speeds_rpm.clone(),
            depths_mm: depths_mm.to_vec(),
            p_stable,
            samples_per_speed,
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

/// The boundary of the model of each parameter sample `thetas[s]` (see
/// [`Parameterization::model`]: modal perturbations and the absolute cutting coefficients and
/// process damping, all sampled) at every speed, in parallel over samples; the result does not
/// depend on the thread count. `observer` hears of each sample done.
///
/// A sample that gives no valid model, or whose boundary search fails at a speed, is recorded in
/// [`SampledBoundaries::failures`] with a NaN limit and the map goes on; only invalid options
/// (which would fail every sample alike) are an error.
pub fn sample_boundaries<S: StabilitySolver + ?Sized>(
    solver: &S,
    parameterization: &Parameterization,
    thetas: &[Vec<f64>],
    speeds_rpm: &[f64],
    options: &BoundaryOptions,
    observer: &dyn Observer,
) -> Result<SampledBoundaries> {
    use chatter_stability::StabilityError;
    use rayon::prelude::*;
    // options are checked once, so that a bad option is an error and not S x speeds failures
    options.validate()?;
    let done = AtomicUsize::new(0);
    let failed = |sample: usize, speed_rpm: Option<f64>, kind, message: String| SampleFailure {
        sample,
        speed_rpm,
        kind,
        message,
    };
    // per sample: (limit mm, chatter Hz) per speed, and its failures
    type Row = (Vec<(f64, f64)>, Vec<SampleFailure>);
    let rows: Vec<Row> = thetas
        .par_iter()
        .enumerate()
        .map(|(k, theta)| {
            let row = match parameterization.model(theta) {
                Err(e) => (
                    vec![(f64::NAN, f64::NAN); speeds_rpm.len()],
                    vec![failed(k, None, FailureKind::InvalidSample, e.to_string())],
                ),
                Ok(m) => {
                    let mut failures = Vec::new();
                    let points = speeds_rpm
                        .iter()
                        .map(|&s| match limiting_depth(solver, &m, s, options) {
                            Ok(p) => (p.depth_mm(), p.chatter_hz),
                            Err(e) => {
                                // no convergence is numerical; the rest (an unstable
                                // structure, a model the method does not apply to) is the sample
                                let kind = match e {
                                    StabilityError::NoConvergence { .. } => FailureKind::Numerical,
                                    _ => FailureKind::InvalidSample,
                                };
                                failures.push(failed(k, Some(s), kind, e.to_string()));
                                (f64::NAN, f64::NAN)
                            }
                        })
                        .collect();
                    (points, failures)
                }
            };
            observer.steps_done(done.fetch_add(1, Ordering::Relaxed) + 1, thetas.len());
            row
        })
        .collect();
    let limits = rows
        .iter()
        .map(|r| r.0.iter().map(|p| p.0).collect())
        .collect();
    let hz = rows
        .iter()
        .map(|r| r.0.iter().map(|p| p.1).collect())
        .collect();
    let failures = rows.into_iter().flat_map(|r| r.1).collect();
    Ok(SampledBoundaries::new(speeds_rpm.to_vec(), limits, hz)?.with_failures(failures))
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

    /// A solver whose limiting depth is 1 mm except where the first mode's frequency is raised
    /// by more than 5 % (no convergence) or lowered by more than 5 % (an unsupported model):
    /// the map goes on, the failures are counted per speed and P_s is the fraction over the
    /// samples that succeeded (exactly 1 below 1 mm and 0 above, never inflated by failures).
    #[test]
    fn failures_are_counted_not_read_as_stable() {
        use chatter_dynamics::{ModalModel, Parameter, examples};
        use chatter_stability::{DominantMultiplier, StabilityError};
        use chatter_updating::parameters::ModelParameter;
        use num_complex::Complex64;
        struct Flaky(f64);
        impl StabilitySolver for Flaky {
            fn name(&self) -> &'static str {
                "flaky"
            }
            fn dominant_multiplier(
                &self,
                model: &ModalModel,
                speed_rpm: f64,
                depth_m: f64,
            ) -> chatter_stability::Result<DominantMultiplier> {
                let ratio = model.modes()[0].frequency_hz() / self.0;
                if ratio > 1.05 && speed_rpm > 1500.0 {
                    return Err(StabilityError::NoConvergence {
                        solver: "flaky",
                        detail: "test".into(),
                    });
                }
                if ratio < 0.95 {
                    return Err(StabilityError::Unsupported {
                        method: "flaky",
                        reason: "test".into(),
                    });
                }
                let mu = 0.5 + 0.5 * depth_m / 1e-3;
                Ok(DominantMultiplier::new(
                    Complex64::new(mu, 0.0),
                    model.operation().delay_s(speed_rpm),
                ))
            }
        }
        let model = examples::insperger_benchmark(1.0);
        let solver = Flaky(model.modes()[0].frequency_hz());
        let params: Vec<Parameter> = vec!["theta_omega_1".parse().unwrap()];
        let params =
            Parameterization::new(model.clone(), vec![ModelParameter::Modal(params[0])]).unwrap();
        // 10 samples: 6 nominal, 2 raised by 10 %, 2 lowered by 10 %
        let thetas: Vec<Vec<f64>> = [0.0, 0.0, 0.1, 0.0, -0.1, 0.0, 0.1, 0.0, -0.1, 0.0]
            .iter()
            .map(|&t| vec![t])
            .collect();
        let speeds = [1000.0, 2000.0];
        let sampled = sample_boundaries(
            &solver,
            &params,
            &thetas,
            &speeds,
            &BoundaryOptions::default(),
            &chatter_progress::Silent,
        )
        .unwrap();
        // 1000 rpm: the lowered ones fail; 2000 rpm: the raised ones too
        assert_eq!(sampled.failures_per_speed(), vec![2, 4]);
        assert_eq!(sampled.failures.len(), 6);
        let numerical = sampled
            .failures
            .iter()
            .filter(|f| f.kind == FailureKind::Numerical)
            .count();
        assert_eq!(numerical, 2);
        assert!(
            sampled
                .failures
                .iter()
                .all(|f| [2, 4, 6, 8].contains(&f.sample))
        );
        let map = sampled.stability_map(&[0.5, 0.99, 1.01, 2.0]);
        assert_eq!(map.samples_per_speed, vec![8, 6]);
        for row in &map.p_stable {
            assert_eq!(row, &vec![1.0, 1.0, 0.0, 0.0]);
        }
        // quantiles skip the failures: the median boundary is the 1 mm of the others
        // (Illinois to the default relative tolerance 1e-4)
        for (_, d) in sampled.probability_contour(0.5) {
            assert!((d - 1.0).abs() < 1e-3, "{d}");
        }
    }

    #[test]
    fn rejects_ragged_samples() {
        assert!(SampledBoundaries::new(vec![1.0, 2.0], vec![vec![1.0]], vec![vec![1.0]]).is_err());
        assert!(SampledBoundaries::new(vec![1.0], vec![], vec![]).is_err());
    }
}
