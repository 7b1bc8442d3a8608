//! Sampled stability boundaries: the limiting depth of every parameter sample at every speed of a
//! grid, with the samples' probabilities. One type and one computation serve the Monte Carlo
//! probability-of-stability map of `chatter-uncertainty` (Schmitz et al. 2022, seed 004, Fig. 2;
//! equally likely samples of a prior or a posterior), the random-walk paths of
//! [`crate::ensemble::BoundaryEnsemble`] (Karandikar, Tyler and Schmitz, seed 003; weighted by
//! the cuts) and the boundaries `chatter plan` exports.
//!
//! The probability that a cut (Omega, b) is stable is the probability of the samples whose
//! boundary lies above it, P_s(Omega, b) = sum_s P_s 1[b < b_lim,s(Omega)] (003 Eq. 7, 004
//! Eq. 8): one limiting depth per sample and speed (a root find) is far cheaper than every grid
//! cell, and it makes P_s exactly monotone in depth.
//!
//! A sample whose parameters give no valid model (outside the support, e.g. a negative damping
//! ratio) or whose boundary search fails at a speed is recorded as a [`SampleFailure`], never as
//! a stable or an unstable boundary: its limit is NaN, P_s at that speed is over the samples that
//! succeeded there, and the counts are reported ([`SampledBoundaries::failures_per_speed`],
//! [`StabilityMap::samples_per_speed`]). One failure does not stop the map.

use crate::error::{Result, UpdatingError};
use crate::parameters::Parameterization;
use chatter_dynamics::ModalModel;
use chatter_progress::Observer;
use chatter_stability::StabilityError;
use chatter_stability::boundary::LobePoint;
use chatter_stability::prepared::SolverOptions;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Per-sample limiting depths (and chatter frequencies) on a common speed grid, with the
/// samples' probabilities.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SampledBoundaries {
    /// Speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// Probability of each sample (sum 1; equal for draws of a distribution).
    pub probabilities: Vec<f64>,
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
    /// The parameters give no valid model (outside the prior's support), or one the method does
    /// not apply to.
    InvalidSample,
    /// The stability solver failed (no convergence, overflow).
    Numerical,
}

/// One sample without a boundary at one speed (or at all).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SampleFailure {
    /// Index of the sample.
    pub sample: usize,
    /// The speed (rpm) where it failed; `None` when the whole sample failed.
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
    /// `p_stable[i][j]` at `speeds_rpm[i]`, `depths_mm[j]`: the probability of the samples with
    /// a boundary at that speed whose limit lies above the depth, over the probability of those
    /// samples; NaN when none has one.
    pub p_stable: Vec<Vec<f64>>,
    /// Samples with a boundary at each speed.
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
    /// Equally likely samples; validates shapes: every sample has one limit and one frequency per
    /// speed.
    pub fn new(
        speeds_rpm: Vec<f64>,
        limits_mm: Vec<Vec<f64>>,
        chatter_hz: Vec<Vec<f64>>,
    ) -> Result<Self> {
        if limits_mm.is_empty() {
            return Err(UpdatingError::InvalidInput {
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
            return Err(UpdatingError::InvalidInput {
                field: "samples",
                message: format!("every sample needs {n} limits and {n} chatter frequencies"),
            });
        }
        let s = limits_mm.len();
        Ok(Self {
            speeds_rpm,
            probabilities: vec![1.0 / s as f64; s],
            limits_mm,
            chatter_hz,
            failures: Vec::new(),
        })
    }

    /// The same boundaries with sample probabilities `probabilities` (one per sample, finite,
    /// non-negative, not all zero; normalized here).
    pub fn with_probabilities(self, probabilities: Vec<f64>) -> Result<Self> {
        let total: f64 = probabilities.iter().sum();
        if probabilities.len() != self.limits_mm.len()
            || probabilities.iter().any(|p| !(p.is_finite() && *p >= 0.0))
            || !(total > 0.0 && total.is_finite())
        {
            return Err(UpdatingError::InvalidInput {
                field: "probabilities",
                message: format!(
                    "{} finite non-negative probabilities, not all zero, expected for {} samples",
                    probabilities.len(),
                    self.limits_mm.len()
                ),
            });
        }
        Ok(Self {
            probabilities: probabilities.iter().map(|p| p / total).collect(),
            ..self
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

    /// P_s at speed index `i` and depth `depth_mm`: the probability of the samples with a
    /// boundary there whose limit lies above the depth, over the probability of the samples with
    /// a boundary there (NaN when none has one).
    pub fn probability_of_stability(&self, i: usize, depth_mm: f64) -> f64 {
        let (mut above, mut with_boundary) = (0.0, 0.0);
        for (l, p) in self.limits_mm.iter().zip(&self.probabilities) {
            if l[i].is_nan() {
                continue;
            }
            with_boundary += p;
            if depth_mm < l[i] {
                above += p;
            }
        }
        if with_boundary > 0.0 {
            (above / with_boundary).clamp(0.0, 1.0)
        } else {
            f64::NAN
        }
    }

    /// P_s(speed, depth) on `depths_mm` ([`Self::probability_of_stability`] at every speed).
    pub fn stability_map(&self, depths_mm: &[f64]) -> StabilityMap {
        let samples_per_speed: Vec<usize> = (0..self.speeds_rpm.len())
            .map(|i| self.limits_mm.iter().filter(|l| !l[i].is_nan()).count())
            .collect();
        let p_stable = (0..self.speeds_rpm.len())
            .map(|i| {
                depths_mm
                    .iter()
                    .map(|&b| self.probability_of_stability(i, b))
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
            .map(|(i, &speed)| (speed, self.quantile_at(&self.limits_mm, i, 1.0 - p)))
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
            .map(|(i, &speed_rpm)| QuantileBand {
                speed_rpm,
                q05: self.quantile_at(rows, i, 0.05),
                q50: self.quantile_at(rows, i, 0.5),
                q95: self.quantile_at(rows, i, 0.95),
            })
            .collect()
    }

    /// The `q` quantile of the finite values of `rows[.][i]`: with equal probabilities the
    /// type-7 interpolation ([`quantile`]), otherwise the weighted quantile
    /// ([`chatter_bayes::special::weighted_quantile`]).
    fn quantile_at(&self, rows: &[Vec<f64>], i: usize, q: f64) -> f64 {
        let equal = self
            .probabilities
            .iter()
            .all(|p| *p == self.probabilities[0]);
        if equal {
            return quantile(rows.iter().map(|r| r[i]).collect(), q);
        }
        let weighted: Vec<(f64, f64)> = rows
            .iter()
            .zip(&self.probabilities)
            .map(|(r, p)| (r[i], *p))
            .filter(|(v, _)| v.is_finite())
            .collect();
        chatter_bayes::special::weighted_quantile(weighted, q)
    }
}

pub use chatter_bayes::special::quantile;

/// The boundary of one sampled model at `speeds_rpm` by the prepared method of `options`:
/// `Err` when the method cannot be prepared for the model, otherwise one result per speed.
///
/// With `grid`, the discretizations take that model's step grid at every speed
/// ([`SolverOptions::prepare_on_grid_of`]): the paths of an ensemble then share the grid of the
/// cut likelihoods that reweight them, and their limits are smooth in the parameters. Without,
/// each model has its own automatic resolution, Richardson-extrapolated from m and 2m steps
/// ([`chatter_stability::prepared::PreparedDiscretization`]): on the single-DOF benchmark (full
/// immersion, 1 / 10 / 5 % on frequency, damping and stiffness, 60 samples x 7 speeds) the
/// median limit is within 0.03 % of a converged semi-discretization where the nominal grid is
/// 0.6-2.1 % high (`examples/montecarlo_prepared.rs` of `chatter-uncertainty`).
pub fn boundary_of(
    options: &SolverOptions,
    model: &ModalModel,
    grid: Option<&ModalModel>,
    speeds_rpm: &[f64],
) -> Result<Vec<Result<LobePoint>>> {
    let solver = match grid {
        Some(grid) => options.prepare_on_grid_of(model, grid)?,
        None => options.method.prepare(model, &options.boundary)?,
    };
    Ok(speeds_rpm
        .iter()
        .map(|&s| solver.limiting_depth(s).map_err(UpdatingError::from))
        .collect())
}

impl SampleFailure {
    /// The failure of sample `sample` (at `speed_rpm`, or None for the whole sample) by
    /// `error`, classified by [`failure_kind`].
    pub(crate) fn new(sample: usize, speed_rpm: Option<f64>, error: &UpdatingError) -> Self {
        Self {
            sample,
            speed_rpm,
            kind: failure_kind(error),
            message: error.to_string(),
        }
    }
}

/// Which failure an error is: no convergence is numerical; the rest (no valid model, an
/// unstable structure, a model the method does not apply to) is the sample's.
fn failure_kind(error: &UpdatingError) -> FailureKind {
    match error {
        UpdatingError::Stability(StabilityError::NoConvergence { .. }) => FailureKind::Numerical,
        _ => FailureKind::InvalidSample,
    }
}

/// The boundary of the model of each parameter sample `thetas[s]` (see
/// [`Parameterization::model`]) at every speed, by the prepared method of `options` at each
/// model's own automatic resolution, extrapolated ([`boundary_of`] without a grid), in parallel
/// over samples; the result does not depend on the thread count. The samples are equally
/// likely. `observer` hears of each sample done.
///
/// A sample that gives no valid model, or whose boundary search fails at a speed, is recorded in
/// [`SampledBoundaries::failures`] with a NaN limit and the map goes on; only invalid options
/// (which would fail every sample alike) and a cancel by `observer` are errors.
pub fn sample_boundaries(
    parameterization: &Parameterization,
    thetas: &[Vec<f64>],
    speeds_rpm: &[f64],
    options: &SolverOptions,
    observer: &dyn Observer,
) -> Result<SampledBoundaries> {
    // options are checked once, so that a bad option is an error and not S x speeds failures
    options.boundary.validate()?;
    let done = AtomicUsize::new(0);
    let failed = SampleFailure::new;
    // per sample: (limit mm, chatter Hz) per speed, and its failures
    type Row = (Vec<(f64, f64)>, Vec<SampleFailure>);
    let rows: Vec<Row> = thetas
        .par_iter()
        .enumerate()
        .map(|(k, theta)| {
            let boundary = chatter_progress::check(observer)
                .map_err(UpdatingError::from)
                .and_then(|()| parameterization.model(theta))
                .and_then(|m| boundary_of(options, &m, None, speeds_rpm));
            let row = match boundary {
                Err(e) => (
                    vec![(f64::NAN, f64::NAN); speeds_rpm.len()],
                    vec![failed(k, None, &e)],
                ),
                Ok(points) => {
                    let mut failures = Vec::new();
                    let points = points
                        .into_iter()
                        .zip(speeds_rpm)
                        .map(|(point, &s)| match point {
                            Ok(p) => (p.depth_mm(), p.chatter_hz),
                            Err(e) => {
                                failures.push(failed(k, Some(s), &e));
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
    // samples skipped after a cancel would otherwise read as failures
    chatter_progress::check(observer)?;
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

    /// Weighted samples: P_s is the probability of the samples above the depth, and the median
    /// is the weighted one (here the 2 mm sample carries 0.6).
    #[test]
    fn weights_set_the_map_and_the_quantiles() {
        let s = SampledBoundaries::new(
            vec![1000.0],
            vec![vec![1.0], vec![2.0], vec![3.0], vec![f64::NAN]],
            vec![vec![500.0]; 4],
        )
        .unwrap()
        .with_probabilities(vec![1.0, 6.0, 2.0, 1.0])
        .unwrap();
        // the failed sample (NaN) is left out: 0.9 of probability has a boundary
        assert!((s.probability_of_stability(0, 1.5) - 0.8 / 0.9).abs() < 1e-12);
        assert!((s.probability_of_stability(0, 2.5) - 0.2 / 0.9).abs() < 1e-12);
        assert_eq!(s.probability_contour(0.5)[0].1, 2.0);
        assert!(s.clone().with_probabilities(vec![1.0; 3]).is_err());
        assert!(s.with_probabilities(vec![0.0; 4]).is_err());
    }

    /// A sample outside the support (a negative damping ratio) is a failure of the whole sample
    /// at every speed: the map goes on, P_s is over the other samples (exactly 1 below their
    /// common limit and 0 above it, never raised by the failure), and no convergence is the
    /// numerical kind.
    #[test]
    fn failures_are_counted_not_read_as_stable() {
        use crate::parameters::ModelParameter;
        use chatter_dynamics::examples;
        let model = examples::insperger_benchmark(1.0);
        let p = Parameterization::new(
            model,
            vec![ModelParameter::Modal("theta_zeta_1".parse().unwrap())],
        )
        .unwrap();
        let thetas = vec![vec![0.0], vec![-3.0], vec![0.0], vec![-3.0]];
        let speeds = [5000.0, 9000.0];
        let options = SolverOptions::default();
        let sampled =
            sample_boundaries(&p, &thetas, &speeds, &options, &chatter_progress::Silent).unwrap();
        assert_eq!(sampled.failures_per_speed(), vec![2, 2]);
        assert_eq!(sampled.failures.len(), 2);
        assert!(sampled.failures.iter().all(|f| f.speed_rpm.is_none()
            && f.kind == FailureKind::InvalidSample
            && [1, 3].contains(&f.sample)));
        let map = sampled.stability_map(&[0.0, 1e3]);
        assert_eq!(map.samples_per_speed, vec![2, 2]);
        for (i, row) in map.p_stable.iter().enumerate() {
            assert_eq!(row, &vec![1.0, 0.0]);
            let limit = sampled.limits_mm[0][i];
            assert_eq!(sampled.probability_of_stability(i, 0.999 * limit), 1.0);
            assert_eq!(sampled.probability_of_stability(i, 1.001 * limit), 0.0);
        }
        let no_convergence = UpdatingError::Stability(StabilityError::NoConvergence {
            solver: "fdm",
            detail: "test".into(),
        });
        assert_eq!(failure_kind(&no_convergence), FailureKind::Numerical);
    }

    #[test]
    fn rejects_ragged_samples() {
        assert!(SampledBoundaries::new(vec![1.0, 2.0], vec![vec![1.0]], vec![vec![1.0]]).is_err());
        assert!(SampledBoundaries::new(vec![1.0], vec![], vec![]).is_err());
    }
}
