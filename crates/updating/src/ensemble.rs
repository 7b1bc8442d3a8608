//! Weighted ensembles of sampled stability boundaries: random-walk path updating with value of
//! information (Karandikar, Tyler and Schmitz, seed 003) and risk-based test selection at maximum
//! material removal rate (Schmitz et al. 2022, seed 004).
//!
//! Each path i is a parameter sample theta_i (e.g. kt, kn and the process-damping coefficient C)
//! drawn from the prior, with its limiting depth b_i(n) over a spindle-speed grid computed with
//! [`SolverOptions`]. Before testing every path is equally likely, P_i = 1/n. A cut result a
//! multiplies P_i by its likelihood l_i (003 Eq. 3-4 or 004 Eq. 5, [`CutKernel`]) and the
//! probabilities are renormalized (003 Eq. 2; 004 Eq. 6-7 with the prior ensemble standing in for
//! the rejection-filtered samples). Posterior moments of a parameter follow 003 Eq. 5-6:
//!
//! mu_C = sum_i C_i P_i,   sigma_C = sqrt(sum_i (C_i - mu_C)^2 P_i).
//!
//! The probability of stability at (n, b) is P_s = sum_i P_i [b < b_i(n)].
//!
//! Value of information (003): a test at (n, b) is stable with probability P_s; either result
//! updates the paths and changes sigma_C. The expected percent reduction is
//! P_s r_stable + (1 - P_s) r_unstable with r = 100 (1 - sigma_C,after / sigma_C); the next test
//! maximizes it over the speed x depth grid, and testing stops when the best expected reduction
//! is small.
//!
//! A path whose boundary cannot be computed at a speed (the solver fails, or refuses the
//! path's model) is dropped from the ensemble with its probability and recorded as a
//! [`SampleFailure`] ([`BoundaryEnsemble::failures`]): it is read neither as stable nor as
//! unstable, and the other paths go on. P_s, the moments and the value of information are then
//! over the paths that have a boundary at every speed of the grid, as for the Monte Carlo map
//! ([`crate::sampled`]), which keeps a sample's other speeds because it is not reweighted.
//!
//! Risk-based selection (004 Section 3): on the contour P_s = P_test (for each speed, the deepest
//! grid depth with P_s >= P_test) the test is the point of maximum material removal rate; testing
//! stops when the next test would improve the best stable MRR by less than 10 %.

use crate::classes::{Sampler, SamplerOptions};
use crate::cuts::{CutKernel, CutsLikelihood};
use crate::error::{Result, UpdatingError};
use crate::joint_prior::{SampledPrior, sample_posterior_whitened};
use crate::parameters::Parameterization;
use crate::sampled::{SampleFailure, SampledBoundaries, boundary_of};
use chatter_bayes::Prior;
use chatter_bayes::samples::SampleSet;
use chatter_bayes::special::normalized_weights;
use chatter_dynamics::{Cut, ModalModel, Operation};
use chatter_progress::{Observer, Silent};
use chatter_stability::boundary::LobePoint;
use chatter_stability::prepared::SolverOptions;
use rand::SeedableRng;
use rand::rngs::StdRng;
use rayon::prelude::*;
use std::f64::consts::PI;

/// A proposed test cut.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TestPlan {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Depth of cut (mm).
    pub depth_mm: f64,
    /// Probability that the cut is stable under the current paths.
    pub p_stable: f64,
    /// Expected percent reduction of the parameter's standard deviation (value of information).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expected_reduction_percent: Option<f64>,
    /// Material removal rate (cm^3/min) where the model's geometry gives one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mrr_cm3_per_min: Option<f64>,
    /// Risk-based test: whether the depth lies on the P_s = P_test contour (false: the contour
    /// lies above the deepest candidate depth, which is proposed instead, with its P_s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub on_contour: Option<bool>,
}

/// Material removal rate (cm^3/min) of a cut: milling b a_e f_z N n with a_e the radial width
/// (radial immersion times tool diameter); turning b f pi D n (f the feed per revolution,
/// `feed_per_tooth_m`). None without the diameter.
pub fn material_removal_rate_cm3_per_min(
    model: &ModalModel,
    speed_rpm: f64,
    depth_m: f64,
    feed_per_tooth_m: f64,
) -> Option<f64> {
    let m3_per_min = match model.operation() {
        Operation::Milling(m) => {
            let ae = m.radial_immersion() * m.tool_diameter_m()?;
            depth_m * ae * feed_per_tooth_m * m.teeth() as f64 * speed_rpm
        }
        Operation::Turning(t) => {
            depth_m * feed_per_tooth_m * PI * t.workpiece_diameter_m()? * speed_rpm
        }
    };
    Some(m3_per_min * 1e6)
}

/// The limiting depths of every path at one speed.
#[derive(Debug, Clone, PartialEq)]
struct Column {
    speed_rpm: f64,
    points: Vec<LobePoint>,
}

/// A weighted ensemble of sampled stability boundaries.
#[derive(Debug, Clone)]
pub struct BoundaryEnsemble {
    parameterization: Parameterization,
    samples: Vec<Vec<f64>>,
    models: Vec<ModalModel>,
    columns: Vec<Column>,
    ln_weights: Vec<f64>,
    options: SolverOptions,
    /// Index of each path among the samples the ensemble was built from.
    path_ids: Vec<usize>,
    failures: Vec<SampleFailure>,
}

/// One path's limiting depths at the new speeds, or the speed (None: all) and error of its
/// failure.
type PathRow = std::result::Result<Vec<LobePoint>, (Option<f64>, UpdatingError)>;

/// A random stream per path, independent of the thread that computes it.
fn path_stream(seed: u64, path: usize) -> StdRng {
    let mut z = seed ^ (path as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    StdRng::seed_from_u64(z ^ (z >> 31))
}

impl BoundaryEnsemble {
    /// Paths from given parameter samples, equally likely, with their boundaries at
    /// `speeds_rpm`. Samples whose model cannot be built are errors; paths whose boundary
    /// fails are dropped and counted ([`Self::failures`]).
    pub fn from_samples(
        parameterization: Parameterization,
        samples: Vec<Vec<f64>>,
        speeds_rpm: &[f64],
        options: SolverOptions,
        observer: &dyn Observer,
    ) -> Result<Self> {
        let n = samples.len();
        Self::weighted(
            parameterization,
            samples,
            vec![-(n as f64).ln(); n],
            speeds_rpm,
            options,
            observer,
        )
    }

    /// Paths with log weights `ln_weights` (normalized on use).
    fn weighted(
        parameterization: Parameterization,
        samples: Vec<Vec<f64>>,
        ln_weights: Vec<f64>,
        speeds_rpm: &[f64],
        options: SolverOptions,
        observer: &dyn Observer,
    ) -> Result<Self> {
        if samples.is_empty() {
            return Err(UpdatingError::InvalidInput {
                field: "paths",
                message: "no samples".into(),
            });
        }
        let models = samples
            .iter()
            .map(|t| parameterization.model(t))
            .collect::<Result<Vec<_>>>()?;
        let mut ensemble = Self {
            path_ids: (0..samples.len()).collect(),
            parameterization,
            samples,
            models,
            columns: Vec::new(),
            ln_weights,
            options,
            failures: Vec::new(),
        };
        ensemble.add_speeds(speeds_rpm, observer)?;
        Ok(ensemble)
    }

    /// Paths from a weighted posterior sample set (e.g. the unique samples of adaptive MCMC with
    /// their multiplicities), P_i proportional to the weights.
    pub fn from_sample_set(
        parameterization: Parameterization,
        set: &SampleSet,
        speeds_rpm: &[f64],
        options: SolverOptions,
        observer: &dyn Observer,
    ) -> Result<Self> {
        let total: f64 = set.weights().iter().sum();
        Self::weighted(
            parameterization,
            set.samples().to_vec(),
            set.weights().iter().map(|w| (w / total).ln()).collect(),
            speeds_rpm,
            options,
            observer,
        )
    }

    /// Paths drawn from the posterior given the cuts made so far (004 Section 5): prior draws
    /// filtered by rejection sampling with the cut-result likelihood (004 Eq. 5-7), then parallel
    /// adaptive MCMC (Eq. 8) until `paths` unique samples. Unlike [`Self::update`], which
    /// reweights fixed prior paths (003), the paths follow the posterior however many cuts have
    /// been made. Without cuts, `paths` prior draws. Where rejection sampling keeps too few prior
    /// draws to start the chains (a sharply peaked likelihood), iTMCMC draws the paths instead.
    /// The samplers run in the prior's whitened coordinates ([`crate::joint_prior`]), so a
    /// nearly singular correlated prior (004's RCSA ensemble) does not stall the chains.
    #[allow(clippy::too_many_arguments)]
    pub fn from_posterior(
        parameterization: Parameterization,
        prior: &SampledPrior,
        cuts: &[Cut],
        kernel: &CutKernel,
        paths: usize,
        speeds_rpm: &[f64],
        options: SolverOptions,
        seed: u64,
        observer: &dyn Observer,
    ) -> Result<Self> {
        if cuts.is_empty() {
            return Self::from_prior(
                parameterization,
                prior,
                paths,
                speeds_rpm,
                options,
                seed,
                observer,
            );
        }
        let likelihood =
            CutsLikelihood::new(parameterization.clone(), cuts.to_vec(), *kernel, options)?;
        let draw = |sampler| {
            let settings = SamplerOptions {
                sampler,
                samples: paths,
                seed,
            };
            sample_posterior_whitened(
                prior,
                likelihood.clone(),
                &settings,
                &chatter_progress::Silent,
            )
        };
        let posterior = match draw(Sampler::Amcmc) {
            Err(UpdatingError::InvalidInput {
                field: "samples", ..
            }) => draw(Sampler::Itmcmc)?,
            other => other?,
        };
        let set = posterior.samples;
        Self::from_sample_set(parameterization, &set, speeds_rpm, options, observer)
    }

    /// `paths` samples drawn from `prior` (path i from its own stream of `seed`).
    pub fn from_prior<P: Prior>(
        parameterization: Parameterization,
        prior: &P,
        paths: usize,
        speeds_rpm: &[f64],
        options: SolverOptions,
        seed: u64,
        observer: &dyn Observer,
    ) -> Result<Self> {
        if prior.dimension() != parameterization.dimension() {
            return Err(UpdatingError::InvalidInput {
                field: "prior",
                message: format!(
                    "{} marginals for {} parameters",
                    prior.dimension(),
                    parameterization.dimension()
                ),
            });
        }
        let samples = (0..paths)
            .map(|i| prior.sample(&mut path_stream(seed, i)))
            .collect();
        Self::from_samples(parameterization, samples, speeds_rpm, options, observer)
    }

    /// Compute the paths at more speeds (those already present are kept). A path whose
    /// boundary fails at one of them is dropped and counted ([`Self::failures`]); it is an
    /// error only when no path is left, or for invalid options and a cancel.
    pub fn add_speeds(&mut self, speeds_rpm: &[f64], observer: &dyn Observer) -> Result<()> {
        let mut new: Vec<f64> = speeds_rpm
            .iter()
            .copied()
            .filter(|s| self.column_index(*s).is_none())
            .collect();
        new.sort_by(f64::total_cmp);
        new.dedup();
        if new.is_empty() {
            return Ok(());
        }
        // options are checked once, so that a bad option is an error, not every path's failure
        self.options.boundary.validate()?;
        let done = std::sync::atomic::AtomicUsize::new(0);
        let total = self.models.len();
        let grid = self.parameterization.nominal();
        let rows: Vec<PathRow> = self
            .models
            .par_iter()
            .map(|m| {
                let row = match chatter_progress::check(observer)
                    .map_err(UpdatingError::from)
                    .and_then(|()| boundary_of(&self.options, m, Some(grid), &new))
                {
                    Err(e) => Err((None, e)),
                    Ok(points) => points
                        .into_iter()
                        .zip(&new)
                        .map(|(point, &s)| point.map_err(|e| (Some(s), e)))
                        .collect(),
                };
                let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                observer.steps_done(k, total);
                row
            })
            .collect();
        // paths skipped after a cancel would otherwise read as failures
        chatter_progress::check(observer)?;
        self.add_rows(&new, rows)
    }

    /// Add the columns of `new` speeds from one row per path; drop the failed paths.
    fn add_rows(&mut self, new: &[f64], rows: Vec<PathRow>) -> Result<()> {
        let keep: Vec<bool> = rows.iter().map(|r| r.is_ok()).collect();
        let before = self.failures.len();
        let mut per_path = Vec::with_capacity(rows.len());
        for (row, &id) in rows.into_iter().zip(&self.path_ids) {
            match row {
                Ok(points) => per_path.push(points),
                Err((speed_rpm, e)) => {
                    self.failures.push(SampleFailure::new(id, speed_rpm, &e));
                }
            }
        }
        if per_path.is_empty() {
            return Err(UpdatingError::InvalidInput {
                field: "paths",
                message: format!(
                    "the stability boundary of every path failed; the first failure: {}",
                    self.failures.get(before).map_or("", |f| f.message.as_str())
                ),
            });
        }
        if keep.contains(&false) {
            retain_kept(&mut self.path_ids, &keep);
            retain_kept(&mut self.samples, &keep);
            retain_kept(&mut self.models, &keep);
            retain_kept(&mut self.ln_weights, &keep);
            for column in &mut self.columns {
                retain_kept(&mut column.points, &keep);
            }
        }
        for (j, &speed_rpm) in new.iter().enumerate() {
            self.columns.push(Column {
                speed_rpm,
                points: per_path.iter().map(|row| row[j]).collect(),
            });
        }
        self.columns
            .sort_by(|a, b| a.speed_rpm.total_cmp(&b.speed_rpm));
        Ok(())
    }

    /// The paths dropped because their boundary failed (index among the samples the ensemble
    /// was built from, the speed, the kind and the message), in the order they failed.
    pub fn failures(&self) -> &[SampleFailure] {
        &self.failures
    }

    fn column_index(&self, speed_rpm: f64) -> Option<usize> {
        self.columns.iter().position(|c| c.speed_rpm == speed_rpm)
    }

    fn column(&self, speed_rpm: f64) -> Result<&Column> {
        self.column_index(speed_rpm)
            .map(|k| &self.columns[k])
            .ok_or_else(|| UpdatingError::InvalidInput {
                field: "speed_rpm",
                message: format!("{speed_rpm} rpm is not on the ensemble's speed grid"),
            })
    }

    /// Number of paths.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether there are no paths (never true for a built ensemble).
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The parameter samples.
    pub fn samples(&self) -> &[Vec<f64>] {
        &self.samples
    }

    /// The parameterization.
    pub fn parameterization(&self) -> &Parameterization {
        &self.parameterization
    }

    /// The speeds with computed boundaries, ascending.
    pub fn speeds_rpm(&self) -> Vec<f64> {
        self.columns.iter().map(|c| c.speed_rpm).collect()
    }

    /// The paths' boundaries at the grid's speeds ([`Self::speeds_rpm`]) with their current
    /// probabilities ([`Self::probabilities`]), as [`SampledBoundaries`] (limits in mm, infinite
    /// where the path has no boundary below the depth ceiling). Its failures are the dropped
    /// paths ([`Self::failures`]), which have no row.
    pub fn boundaries(&self) -> Result<SampledBoundaries> {
        let rows = |f: fn(&LobePoint) -> f64| -> Vec<Vec<f64>> {
            (0..self.samples.len())
                .map(|i| self.columns.iter().map(|c| f(&c.points[i])).collect())
                .collect()
        };
        SampledBoundaries::new(
            self.speeds_rpm(),
            rows(LobePoint::depth_mm),
            rows(|p| p.chatter_hz),
        )?
        .with_probabilities(self.probabilities())
        .map(|b| b.with_failures(self.failures.clone()))
    }

    /// Path probabilities P_i (sum 1).
    pub fn probabilities(&self) -> Vec<f64> {
        normalized_weights(&self.ln_weights)
    }

    /// Kish effective number of paths, (sum P)^2 / sum P^2.
    pub fn effective_sample_size(&self) -> f64 {
        let p = self.probabilities();
        1.0 / p.iter().map(|x| x * x).sum::<f64>()
    }

    /// Posterior mean and standard deviation of parameter `index` (003 Eq. 5-6).
    pub fn moments(&self, index: usize) -> Result<(f64, f64)> {
        self.check_index(index)?;
        Ok(self.moments_with(&self.probabilities(), index))
    }

    fn moments_with(&self, p: &[f64], index: usize) -> (f64, f64) {
        let mean: f64 = self.samples.iter().zip(p).map(|(s, w)| s[index] * w).sum();
        let var: f64 = self
            .samples
            .iter()
            .zip(p)
            .map(|(s, w)| (s[index] - mean).powi(2) * w)
            .sum();
        (mean, var.max(0.0).sqrt())
    }

    fn check_index(&self, index: usize) -> Result<()> {
        if index >= self.parameterization.dimension() {
            return Err(UpdatingError::InvalidInput {
                field: "parameter index",
                message: format!(
                    "{index}; the ensemble has {} parameters",
                    self.parameterization.dimension()
                ),
            });
        }
        Ok(())
    }

    /// Probability of stability P_s at (speed on the grid, depth in m).
    pub fn probability_of_stability(&self, speed_rpm: f64, depth_m: f64) -> Result<f64> {
        let column = self.column(speed_rpm)?;
        Ok(stable_probability(&self.probabilities(), column, depth_m))
    }

    /// Multiply the path probabilities by the likelihood of `cut` (its speed is added to the grid
    /// when missing). Errors when no path is compatible with the result.
    pub fn update(&mut self, cut: &Cut, kernel: &CutKernel) -> Result<()> {
        let kernel = kernel.validated()?;
        self.add_speeds(&[cut.speed_rpm], &Silent)?;
        let column = self.column(cut.speed_rpm)?;
        let updated: Vec<f64> = self
            .ln_weights
            .iter()
            .zip(&column.points)
            .map(|(w, p)| w + kernel.ln_likelihood(cut, p))
            .collect();
        if updated.iter().all(|w| !w.is_finite()) {
            return Err(UpdatingError::Observations(format!(
                "no path is compatible with the cut at {} rpm, {} mm",
                cut.speed_rpm, cut.depth_mm
            )));
        }
        let m = updated.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        self.ln_weights = updated.iter().map(|w| w - m).collect();
        Ok(())
    }

    /// P_s and the expected percent reduction of the standard deviation of parameter `index`
    /// for a test at (speed on the grid, depth in m) (003, value of information).
    pub fn expected_reduction(
        &self,
        speed_rpm: f64,
        depth_m: f64,
        index: usize,
        kernel: &CutKernel,
    ) -> Result<(f64, f64)> {
        self.check_index(index)?;
        let kernel = kernel.validated()?;
        let p = self.probabilities();
        let (_, sd) = self.moments_with(&p, index);
        let column = self.column(speed_rpm)?;
        Ok(self.reduction_at(&p, sd, column, depth_m, index, &kernel))
    }

    fn reduction_at(
        &self,
        p: &[f64],
        sd: f64,
        column: &Column,
        depth_m: f64,
        index: usize,
        kernel: &CutKernel,
    ) -> (f64, f64) {
        let ps = stable_probability(p, column, depth_m);
        if sd.is_nan() || sd <= 0.0 {
            return (ps, 0.0);
        }
        let reduction = |stable: bool| -> f64 {
            let cut = Cut::labelled(column.speed_rpm, depth_m * 1e3, stable);
            let w: Vec<f64> = p
                .iter()
                .zip(&column.points)
                .map(|(pi, pt)| pi * kernel.ln_likelihood(&cut, pt).exp())
                .collect();
            let total: f64 = w.iter().sum();
            if total.is_nan() || total <= 0.0 {
                return 0.0;
            }
            let post: Vec<f64> = w.iter().map(|x| x / total).collect();
            100.0 * (1.0 - self.moments_with(&post, index).1 / sd)
        };
        (ps, ps * reduction(true) + (1.0 - ps) * reduction(false))
    }

    /// The test of maximum expected percent reduction of the standard deviation of parameter
    /// `index` over the speed grid x `depths_m` (003). None when the grid is empty.
    pub fn value_of_information(
        &self,
        depths_m: &[f64],
        index: usize,
        kernel: &CutKernel,
    ) -> Result<Option<TestPlan>> {
        self.check_index(index)?;
        let kernel = kernel.validated()?;
        let p = self.probabilities();
        let (_, sd) = self.moments_with(&p, index);
        let best = self
            .columns
            .par_iter()
            .flat_map_iter(|column| {
                let p = &p;
                let kernel = &kernel;
                depths_m.iter().map(move |&d| {
                    let (ps, r) = self.reduction_at(p, sd, column, d, index, kernel);
                    TestPlan {
                        on_contour: None,
                        speed_rpm: column.speed_rpm,
                        depth_mm: d * 1e3,
                        p_stable: ps,
                        expected_reduction_percent: Some(r),
                        mrr_cm3_per_min: None,
                    }
                })
            })
            .collect::<Vec<_>>()
            .into_iter()
            .max_by(|a, b| {
                a.expected_reduction_percent
                    .unwrap_or(0.0)
                    .total_cmp(&b.expected_reduction_percent.unwrap_or(0.0))
            });
        Ok(best)
    }

    /// The test of maximum material removal rate on the P_s = `p_test` contour (004): for every
    /// speed the contour depth b* = sup{b : P_s(b) >= p_test}, where P_s(b) is the weight of the
    /// paths whose limiting depth exceeds b (the weighted (1 - p_test) quantile of the path
    /// limits, so P_s(b*) exceeds p_test by less than the largest path weight), then the speed
    /// of largest depth x speed (the MRR at fixed radial width and feed). A contour above the
    /// deepest of `depths_m` is capped there and flagged `on_contour: false`. None when no speed
    /// has a depth in `depths_m` range with P_s >= p_test.
    pub fn risk_based_test(
        &self,
        depths_m: &[f64],
        p_test: f64,
        feed_per_tooth_m: f64,
    ) -> Result<Option<TestPlan>> {
        if !(p_test > 0.0 && p_test < 1.0) {
            return Err(UpdatingError::InvalidInput {
                field: "p_test",
                message: format!("{p_test}; expected in (0, 1)"),
            });
        }
        let ceiling = depths_m.iter().copied().fold(0.0, f64::max);
        let floor = depths_m.iter().copied().fold(f64::INFINITY, f64::min);
        let p = self.probabilities();
        let mut best: Option<TestPlan> = None;
        for column in &self.columns {
            let Some(contour) = contour_depth(&p, column, p_test) else {
                continue;
            };
            let (d, on_contour) = if contour > ceiling {
                (ceiling, false)
            } else {
                (contour, true)
            };
            if !(d >= floor && d > 0.0) {
                continue;
            }
            let better =
                best.is_none_or(|b| d * column.speed_rpm > b.depth_mm * 1e-3 * b.speed_rpm);
            if better {
                best = Some(TestPlan {
                    speed_rpm: column.speed_rpm,
                    depth_mm: d * 1e3,
                    p_stable: stable_probability(&p, column, d),
                    expected_reduction_percent: None,
                    mrr_cm3_per_min: material_removal_rate_cm3_per_min(
                        self.parameterization.nominal(),
                        column.speed_rpm,
                        d,
                        feed_per_tooth_m,
                    ),
                    on_contour: Some(on_contour),
                });
            }
        }
        Ok(best)
    }
}

/// Keep the entries of `values` whose `keep` flag is set (one flag per entry, in order).
fn retain_kept<T>(values: &mut Vec<T>, keep: &[bool]) {
    let mut flags = keep.iter();
    values.retain(|_| flags.next().copied().unwrap_or(true));
}

/// sup{b : P_s(b) >= p_test} for one speed, just below the limit of the path where the
/// cumulative weight of deeper paths falls under p_test (P_s(b) = weight of paths with limit > b);
/// None when P_s < p_test already at depth 0.
fn contour_depth(p: &[f64], column: &Column, p_test: f64) -> Option<f64> {
    let mut limits: Vec<(f64, f64)> = column
        .points
        .iter()
        .zip(p)
        .map(|(pt, &w)| (pt.depth_m, w))
        .filter(|(d, _)| !d.is_nan())
        .collect();
    limits.sort_by(|a, b| a.0.total_cmp(&b.0));
    // above[k] = weight of paths k.. (limits >= limits[k])
    let mut above = 1.0f64.min(limits.iter().map(|l| l.1).sum());
    for &(d, w) in &limits {
        // just below d every path from here on is deeper: P_s = above
        // (with a round-off margin: a tail weighing exactly p_test still qualifies)
        if above >= p_test - 1e-12 && above - w < p_test - 1e-12 {
            return Some(d * (1.0 - 1e-9));
        }
        above -= w;
    }
    None
}

fn stable_probability(p: &[f64], column: &Column, depth_m: f64) -> f64 {
    stable_share(p, column.points.iter().map(|pt| pt.depth_m), depth_m)
}

/// The probability of the paths (probabilities `p`) whose limiting depth `limits_m` lies above
/// `depth_m`: P_s of 003 Eq. 7 / 004 Eq. 8.
fn stable_share(p: &[f64], limits_m: impl Iterator<Item = f64>, depth_m: f64) -> f64 {
    p.iter()
        .zip(limits_m)
        .filter(|(_, limit)| depth_m < *limit)
        .map(|(w, _)| w)
        .sum::<f64>()
        .clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parameters::parse_model_parameters;
    use chatter_bayes::prior::{IndependentPrior, Marginal};
    use chatter_dynamics::examples;

    fn small() -> BoundaryEnsemble {
        let model = examples::ebrahimi_2025_milling();
        let p =
            Parameterization::new(model, parse_model_parameters("kn_n_per_mm2").unwrap()).unwrap();
        let prior = IndependentPrior::new(vec![Marginal::Uniform {
            low: 80.0,
            high: 140.0,
        }])
        .unwrap();
        BoundaryEnsemble::from_prior(
            p,
            &prior,
            40,
            &[2100.0, 2400.0],
            SolverOptions::default(),
            3,
            &Silent,
        )
        .unwrap()
    }

    #[test]
    fn updates_follow_bayes_rule_and_keep_probabilities() {
        let mut e = small();
        assert_eq!(e.len(), 40);
        let p0 = e.probabilities();
        assert!((p0.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let (mean0, sd0) = e.moments(0).unwrap();
        // an unstable cut at the median limiting depth favours large kn (slotting: A_0 xx ~ kn)
        let median_mm = (1..500)
            .map(|i| i as f64 * 0.01)
            .find(|d| e.probability_of_stability(2100.0, d * 1e-3).unwrap() <= 0.5)
            .unwrap();
        let cut = Cut::labelled(2100.0, median_mm, false);
        let kernel = CutKernel {
            sigma_depth_m: 0.02e-3,
            sigma_chatter_hz: None,
        };
        let (ps, r) = e
            .expected_reduction(2100.0, median_mm * 1e-3, 0, &kernel)
            .unwrap();
        assert!((0.0..=1.0).contains(&ps) && r.is_finite());
        e.update(&cut, &kernel).unwrap();
        let (mean1, sd1) = e.moments(0).unwrap();
        assert!(mean1 > mean0 && sd1 < sd0, "{mean0} {mean1} {sd0} {sd1}");
        assert!(e.effective_sample_size() < 40.0);
        // probability of stability falls with depth
        let a = e.probability_of_stability(2400.0, 0.3e-3).unwrap();
        let b = e.probability_of_stability(2400.0, 3e-3).unwrap();
        assert!(a >= b);
        assert!(e.probability_of_stability(1234.0, 1e-3).is_err());
        // a cut off the grid adds its speed
        let off = Cut {
            speed_rpm: 2200.0,
            ..cut
        };
        e.update(&off, &kernel).unwrap();
        assert_eq!(e.speeds_rpm(), vec![2100.0, 2200.0, 2400.0]);
        assert!(e.moments(3).is_err());
    }

    /// Injected solver failures (no convergence for paths 7 and 20 at a new speed): the two
    /// paths are dropped and counted, the others keep their columns and share the probability,
    /// and P_s is over them; with every path failing, the ensemble says so.
    #[test]
    fn a_failed_path_is_dropped_and_counted_not_read_as_stable() {
        use crate::sampled::FailureKind;
        use chatter_stability::StabilityError;
        let mut e = small();
        let before = e.boundaries().unwrap();
        let samples = e.samples().to_vec();
        let failed = || {
            UpdatingError::Stability(StabilityError::NoConvergence {
                solver: "fdm",
                detail: "injected".into(),
            })
        };
        // path i has its limit at 1 + i / 40 mm at 3000 rpm
        let rows: Vec<PathRow> = (0..40)
            .map(|i| match i {
                7 | 20 => Err((Some(3000.0), failed())),
                _ => Ok(vec![LobePoint {
                    speed_rpm: 3000.0,
                    depth_m: 1e-3 * (1.0 + i as f64 / 40.0),
                    chatter_hz: 500.0,
                }]),
            })
            .collect();
        e.add_rows(&[3000.0], rows).unwrap();
        assert_eq!(e.len(), 38);
        let kept = |i: &usize| ![7, 20].contains(i);
        assert_eq!(e.failures().len(), 2);
        for (f, i) in e.failures().iter().zip([7, 20]) {
            assert_eq!((f.sample, f.speed_rpm), (i, Some(3000.0)));
            assert_eq!(f.kind, FailureKind::Numerical);
        }
        let want: Vec<Vec<f64>> = (0..40).filter(kept).map(|i| samples[i].clone()).collect();
        assert_eq!(e.samples(), want.as_slice());
        assert!(
            e.probabilities()
                .iter()
                .all(|p| (p - 1.0 / 38.0).abs() < 1e-15)
        );
        // the old columns stay aligned with their paths
        let after = e.boundaries().unwrap();
        let old: Vec<f64> = (0..40)
            .filter(kept)
            .map(|i| before.limits_mm[i][0])
            .collect();
        let now: Vec<f64> = after.limits_mm.iter().map(|l| l[0]).collect();
        assert_eq!(now, old);
        assert_eq!(after.failures.len(), 2);
        // P_s at 1.5 mm: paths 21..=39 lie above, 19 of the 38 left
        let ps = e.probability_of_stability(3000.0, 1.5e-3).unwrap();
        assert!((ps - 0.5).abs() < 1e-12, "{ps}");
        let every: Vec<PathRow> = (0..38).map(|_| Err((None, failed()))).collect();
        let error = e.add_rows(&[3500.0], every).unwrap_err().to_string();
        assert!(
            error.contains("every path failed") && error.contains("injected"),
            "{error}"
        );
    }

    #[test]
    fn risk_based_test_sits_on_the_contour() {
        let e = small();
        let depths: Vec<f64> = (1..=60).map(|i| i as f64 * 0.1e-3).collect();
        let plan = e.risk_based_test(&depths, 0.5, 0.1e-3).unwrap().unwrap();
        // on the contour: P_s within one path weight (1/40) above 0.5, below it just deeper
        assert_eq!(plan.on_contour, Some(true));
        assert!(
            plan.p_stable >= 0.5 && plan.p_stable < 0.5 + 1.0 / 40.0 + 1e-9,
            "{plan:?}"
        );
        let deeper = e
            .probability_of_stability(plan.speed_rpm, plan.depth_mm * 1e-3 * (1.0 + 1e-6))
            .unwrap();
        assert!(deeper < 0.5 - 1e-12, "{deeper}");
        assert!(plan.mrr_cm3_per_min.is_some_and(|m| m > 0.0));
        assert!(e.risk_based_test(&depths, 1.5, 0.1e-3).is_err());
    }
}
