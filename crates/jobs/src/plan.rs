//! The planning job (`chatter plan`, `chatter.plan`): the request in the units users write
//! (rpm, mm) converted once to [`PlanSettings`] for [`plan_next_cut`].

use crate::error::{JobError, Result, count};
use chatter_dynamics::{ModalModel, Observations};
use chatter_progress::Observer;
use chatter_updating::cuts::CutKernel;
use chatter_updating::joint_prior::JointNormal;

use chatter_updating::parameters::ModelParameter;
use chatter_updating::plan::{PlanOutcome, PlanSettings, Strategy, plan_next_cut};
use chatter_updating::update::PriorOverrides;

/// What a plan was asked, in rpm and mm; [`PlanRequest::new`] gives the CLI's defaults.
#[derive(Debug, Clone)]
pub struct PlanRequest {
    /// Value of information (003) or material removal rate on the P_test contour (004).
    pub strategy: Strategy,
    /// P_test of the contour (mrr); default 0.5.
    pub p_test: f64,
    /// Sampled parameters (default kt, kn and C with process damping).
    pub parameters: Option<Vec<ModelParameter>>,
    /// Priors by name.
    pub priors: PriorOverrides,
    /// A correlated normal prior over some sampled parameters (004's RCSA prior file).
    pub joint_prior: Option<JointNormal>,
    /// The parameter whose uncertainty value of information reduces.
    pub target: Option<ModelParameter>,
    /// Sampled stability boundaries (10 to 100 000).
    pub paths: usize,
    /// Candidate speeds (rpm); default the cut speeds +- 25 %.
    pub speeds_rpm: Option<Vec<f64>>,
    /// Candidate depths (mm); default up to twice the deepest cut. Depths <= 0 are dropped.
    pub depths_mm: Option<Vec<f64>>,
    /// Feed per tooth (mm) of the material removal rate.
    pub feed_per_tooth_mm: f64,
    /// Stability method of the sampled boundaries (default the full discretization).
    pub method: Option<chatter_stability::prepared::Method>,
    /// Seed of the prior samples.
    pub seed: u64,
    /// Cap on test cuts.
    pub max_tests: usize,
    /// Width of the cut likelihood in depth (mm): 003's sigma or 004's s_S; default the
    /// strategy's paper (0.5 mm for voi, 0.125 mm for mrr).
    pub sigma_depth_mm: Option<f64>,
    /// 004's s_fc (Hz), the allowed chatter-frequency disagreement (mrr only); default 50 Hz.
    pub sigma_chatter_hz: Option<f64>,
}

impl PlanRequest {
    /// 300 paths, P_test 0.5, feed 0.1 mm, the default cap, seed 0.
    pub fn new(strategy: Strategy) -> Self {
        let d = PlanSettings::default();
        Self {
            strategy,
            p_test: d.p_test,
            parameters: None,
            priors: PriorOverrides::new(),
            joint_prior: None,
            target: None,
            paths: d.paths,
            speeds_rpm: None,
            depths_mm: None,
            feed_per_tooth_mm: d.feed_per_tooth_m * 1e3,
            method: d.method,
            seed: d.seed,
            max_tests: d.max_tests,
            sigma_depth_mm: None,
            sigma_chatter_hz: None,
        }
    }

    /// The settings in SI units.
    pub fn settings(&self) -> Result<PlanSettings> {
        count("paths", self.paths, 10, 100_000, "sampled boundaries")?;
        if !(self.p_test > 0.0 && self.p_test < 1.0) {
            return Err(JobError::Invalid {
                field: "p_test",
                value: self.p_test.to_string(),
                expected: "a probability between 0 and 1".into(),
            });
        }
        let paper = match self.strategy {
            Strategy::ValueOfInformation => CutKernel::karandikar(),
            Strategy::MaterialRemovalRate => CutKernel::schmitz(),
        };
        let kernel = CutKernel {
            sigma_depth_m: self
                .sigma_depth_mm
                .map_or(paper.sigma_depth_m, |mm| mm * 1e-3),
            sigma_chatter_hz: self.sigma_chatter_hz.or(paper.sigma_chatter_hz),
        };
        Ok(PlanSettings {
            strategy: self.strategy,
            p_test: self.p_test,
            parameters: self.parameters.clone(),
            priors: self.priors.clone(),
            joint_prior: self.joint_prior.clone(),
            target: self.target,
            paths: self.paths,
            speeds_rpm: self.speeds_rpm.clone(),
            depths_m: self
                .depths_mm
                .as_ref()
                .map(|d| d.iter().filter(|v| **v > 0.0).map(|v| v * 1e-3).collect()),
            feed_per_tooth_m: self.feed_per_tooth_mm * 1e-3,
            method: self.method,
            seed: self.seed,
            max_tests: self.max_tests,
            kernel: Some(kernel),
        })
    }
}

/// The next test cut.
pub fn plan(
    model: &ModalModel,
    observations: &Observations,
    request: &PlanRequest,
    observer: &dyn Observer,
) -> Result<PlanOutcome> {
    Ok(plan_next_cut(
        model,
        observations,
        &request.settings()?,
        observer,
    )?)
}

/// The warnings of a plan, in the one wording that `chatter plan` prints (after `warning: `),
/// its report page shows and the Python package returns: sampled paths dropped because their
/// stability boundary failed, then a next cut proposed at the deepest candidate depth because
/// the P_s = `p_test` contour lies above the grid (a clipped grid).
pub fn warnings(outcome: &PlanOutcome, request: &PlanRequest) -> Vec<String> {
    let failed = outcome.boundaries.failures.first().map(|first| {
        format!(
            "{} of {} sampled paths were dropped because their stability boundary failed (first: \
             {}); P_s and the next cut are over the other paths (`failed_paths` in the JSON)",
            outcome.failed_paths,
            outcome.failed_paths + outcome.boundaries.limits_mm.len(),
            first.message
        )
    });
    let clipped = outcome
        .next_cut
        .iter()
        .filter(|t| t.on_contour == Some(false))
        .map(|t| {
            format!(
                "the P_s = {} contour at {} rpm lies above the deepest candidate depth (a \
                 clipped grid): {} mm is proposed there (P_s {:.3}), not a cut on the contour; \
                 give deeper --depths",
                request.p_test, t.speed_rpm, t.depth_mm, t.p_stable
            )
        });
    failed.into_iter().chain(clipped).collect()
}
