//! The next test cut (what `chatter plan` runs): sampled boundaries given the cuts made so far,
//! then value of information (003: prior paths reweighted by the cuts) or risk-based selection at
//! maximum material removal rate (004: paths drawn from the posterior by rejection sampling and
//! parallel adaptive MCMC), with the papers' stopping rules.

use crate::cuts::CutKernel;
use crate::defaults::{default_parameters, parameter_prior};
use crate::ensemble::{BoundaryEnsemble, TestPlan, material_removal_rate_cm3_per_min};
use crate::error::{Result, UpdatingError};
use crate::joint_prior::{JointNormal, SampledPrior};
use crate::parameters::{ModelParameter, Parameterization};
use crate::sampled::SampledBoundaries;
use crate::update::PriorOverrides;
use chatter_bayes::prior::Marginal;
use chatter_dynamics::{ModalModel, Observations};
use chatter_progress::Observer;
use chatter_stability::prepared::{Method, SolverOptions};

/// How the next test is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Strategy {
    /// Largest expected percent reduction of a parameter's standard deviation (003).
    ValueOfInformation,
    /// Largest material removal rate on the P_s = P_test contour (004).
    MaterialRemovalRate,
}

/// Stop value of information below this expected reduction (percent).
pub const VOI_STOP_PERCENT: f64 = 2.0;
/// Stop risk-based testing when the next MRR improves the best stable one by less than this.
pub const MRR_STOP_IMPROVEMENT: f64 = 0.10;

/// Settings of a plan; `None` takes the defaults.
#[derive(Debug, Clone)]
pub struct PlanSettings {
    /// Strategy.
    pub strategy: Strategy,
    /// P_test of the risk-based strategy (004 uses 0.5).
    pub p_test: f64,
    /// Parameters (default: kt, kn and C when the model has process damping).
    pub parameters: Option<Vec<ModelParameter>>,
    /// Priors by name.
    pub priors: PriorOverrides,
    /// A correlated normal prior over some sampled parameters (004's RCSA prior); without
    /// `parameters` its names are the sampled parameters.
    pub joint_prior: Option<JointNormal>,
    /// The parameter whose uncertainty the value of information reduces (default C when
    /// sampled, else the first parameter).
    pub target: Option<ModelParameter>,
    /// Number of sampled boundaries.
    pub paths: usize,
    /// Candidate speeds (default: the observed cut speeds +- 25 %, 41 speeds).
    pub speeds_rpm: Option<Vec<f64>>,
    /// Candidate depths in m (default: 60 depths up to twice the deepest cut).
    pub depths_m: Option<Vec<f64>>,
    /// Feed per tooth (m) for the material removal rate.
    pub feed_per_tooth_m: f64,
    /// Stability method of the sampled boundaries (default [`SolverOptions`]'s: the full
    /// discretization; 004 used the zero-order method).
    pub method: Option<Method>,
    /// Seed of the prior samples.
    pub seed: u64,
    /// Cap on the number of test cuts: the stopping rule fires once this many cuts were made
    /// (default [`DEFAULT_MAX_TESTS`]).
    pub max_tests: usize,
    /// The cut likelihood's widths (003's sigma, 004's s_S and s_fc); default the strategy's
    /// paper ([`CutKernel::karandikar`] for value of information, [`CutKernel::schmitz`] for MRR).
    pub kernel: Option<CutKernel>,
}

/// Default cap on test cuts of a campaign.
pub const DEFAULT_MAX_TESTS: usize = 10;

impl Default for PlanSettings {
    fn default() -> Self {
        Self {
            strategy: Strategy::MaterialRemovalRate,
            p_test: 0.5,
            parameters: None,
            priors: PriorOverrides::new(),
            joint_prior: None,
            target: None,
            paths: 300,
            speeds_rpm: None,
            depths_m: None,
            feed_per_tooth_m: 0.1e-3,
            method: None,
            seed: 0,
            max_tests: DEFAULT_MAX_TESTS,
            kernel: None,
        }
    }
}

/// The proposed cut and whether the stopping rule says testing is done.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PlanOutcome {
    /// The next cut (None when no candidate qualifies).
    pub next_cut: Option<TestPlan>,
    /// The stopping rule fired (the gain of the next cut is small, or the cap on test cuts is
    /// reached).
    pub stop: bool,
    /// Why testing should stop, when it should.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stop_reason: Option<String>,
    /// Cuts used to update the samples.
    pub cuts_used: usize,
    /// Sampled parameter names.
    pub parameter_names: Vec<String>,
    /// Posterior mean after the cuts (003 Eq. 5).
    pub posterior_mean: Vec<f64>,
    /// Posterior standard deviation (003 Eq. 6).
    pub posterior_sd: Vec<f64>,
    /// Best material removal rate among the stable cuts (cm^3/min), where computable.
    pub best_stable_mrr_cm3_per_min: Option<f64>,
    /// Kish effective number of samples after the updates.
    pub effective_samples: f64,
    /// Sampled paths dropped because their stability boundary failed (never read as stable or
    /// unstable; `boundaries.failures` names them).
    pub failed_paths: usize,
    /// The sampled boundaries after the updates (written as CSV by `chatter plan
    /// --boundaries-out`; not in the JSON).
    #[serde(skip)]
    pub boundaries: SampledBoundaries,
}

/// Candidate speeds and depths when the settings give none. With cuts: the cut speeds +- 25 %
/// (41 speeds) and 60 depths up to twice the deepest cut. Before the first cut (planning from
/// the prior): 41 speeds over the model's default lobe range (`chatter-stability`'s
/// `lobe_speeds_rpm`; with process damping, which acts at low speed, down to a fortieth of
/// its top instead of a tenth) and 60 depths up to twice the deepest nominal limit there.
fn grid_default(model: &ModalModel, observations: &Observations) -> Result<(Vec<f64>, Vec<f64>)> {
    let cuts = &observations.cuts;
    let spread = |lo: f64, hi: f64| chatter_dynamics::grid::evenly_spaced(lo, hi, 41);
    if cuts.is_empty() {
        let range = chatter_stability::speed_grid::lobe_speeds_rpm(model);
        let hi = range.last().copied().unwrap_or(1000.0);
        let lo = if model.process_damping_n_per_m().is_some() {
            hi / 40.0
        } else {
            range.first().copied().unwrap_or(hi / 10.0)
        };
        let speeds = spread(lo, hi);
        let nominal = SolverOptions::default()
            .prepare_on_grid_of(model, model)?
            .limiting_depths(&speeds)?;
        let Some(deepest) = chatter_stability::speed_grid::deepest_limit_m(&nominal) else {
            return Err(UpdatingError::InvalidInput {
                field: "depths",
                message: "the nominal model is stable at every candidate speed up to the depth \
                          ceiling; give the speeds and depths"
                    .into(),
            });
        };
        let depths = chatter_stability::speed_grid::depth_grid_to(2.0 * deepest, 60);
        return Ok((speeds, depths));
    }
    let lo = cuts
        .iter()
        .map(|c| c.speed_rpm)
        .fold(f64::INFINITY, f64::min)
        * 0.75;
    let hi = cuts.iter().map(|c| c.speed_rpm).fold(0.0, f64::max) * 1.25;
    let deepest = cuts.iter().map(|c| c.depth_mm).fold(0.0, f64::max) * 1e-3;
    let depths = chatter_stability::speed_grid::depth_grid_to(2.0 * deepest, 60);
    Ok((spread(lo, hi), depths))
}

/// Propose the next cut from the model, the cuts made so far and the settings.
pub fn plan_next_cut(
    model: &ModalModel,
    observations: &Observations,
    settings: &PlanSettings,
    observer: &dyn Observer,
) -> Result<PlanOutcome> {
    if !(settings.feed_per_tooth_m.is_finite() && settings.feed_per_tooth_m > 0.0) {
        return Err(UpdatingError::InvalidInput {
            field: "feed_per_tooth",
            message: format!("{}; expected > 0", settings.feed_per_tooth_m),
        });
    }
    let parameters = match (&settings.parameters, &settings.joint_prior) {
        (Some(p), _) => p.clone(),
        (None, Some(joint)) => joint.parameters()?,
        (None, None) => default_parameters(model, &[])?,
    };
    let p = Parameterization::new(model.clone(), parameters)?;
    let names = p.names();
    let marginals: Vec<Marginal> = p
        .parameters()
        .iter()
        .map(|q| parameter_prior(*q, model))
        .collect();
    let prior = SampledPrior::new(
        p.clone(),
        marginals,
        &settings.priors,
        settings.joint_prior.as_ref(),
    )?;
    let (speeds, depths) = match (&settings.speeds_rpm, &settings.depths_m) {
        (Some(s), Some(d)) => (s.clone(), d.clone()),
        (s, d) => {
            let (ds, dd) = grid_default(model, observations)?;
            (s.clone().unwrap_or(ds), d.clone().unwrap_or(dd))
        }
    };
    let max_depth = depths.iter().copied().fold(0.0, f64::max);
    let solver = settings
        .method
        .map_or_else(SolverOptions::default, SolverOptions::new);
    let options = solver.with_max_depth_m((2.0 * max_depth).max(1e-3));
    let kernel = settings
        .kernel
        .unwrap_or(match settings.strategy {
            Strategy::ValueOfInformation => CutKernel::karandikar(),
            Strategy::MaterialRemovalRate => CutKernel::schmitz(),
        })
        .validated()?;
    let ensemble = match settings.strategy {
        // 003: fixed prior paths, reweighted by every cut
        Strategy::ValueOfInformation => {
            let mut ensemble = BoundaryEnsemble::from_prior(
                p.clone(),
                &prior,
                settings.paths,
                &speeds,
                options,
                settings.seed,
                observer,
            )?;
            for cut in &observations.cuts {
                ensemble.update(cut, &kernel)?;
            }
            ensemble
        }
        // 004: paths drawn from the posterior by rejection sampling and adaptive MCMC
        Strategy::MaterialRemovalRate => BoundaryEnsemble::from_posterior(
            p.clone(),
            &prior,
            &observations.cuts,
            &kernel,
            settings.paths,
            &speeds,
            options,
            settings.seed,
            observer,
        )?,
    };
    let moments = (0..p.dimension())
        .map(|k| ensemble.moments(k))
        .collect::<Result<Vec<_>>>()?;
    let best_stable = observations
        .cuts
        .iter()
        .filter(|c| c.stable)
        .filter_map(|c| {
            material_removal_rate_cm3_per_min(
                model,
                c.speed_rpm,
                c.depth_mm * 1e-3,
                settings.feed_per_tooth_m,
            )
        })
        .reduce(f64::max);
    let (next_cut, stop) = match settings.strategy {
        Strategy::ValueOfInformation => {
            let target = settings
                .target
                .or_else(|| {
                    p.index_of(ModelParameter::ProcessDampingNPerM)
                        .map(|_| ModelParameter::ProcessDampingNPerM)
                })
                .unwrap_or(p.parameters()[0]);
            let index = p
                .index_of(target)
                .ok_or_else(|| UpdatingError::InvalidInput {
                    field: "target",
                    message: format!("`{target}` is not a sampled parameter"),
                })?;
            let plan = ensemble.value_of_information(&depths, index, &kernel)?;
            let stop =
                plan.is_none_or(|t| t.expected_reduction_percent.unwrap_or(0.0) < VOI_STOP_PERCENT);
            (plan, stop)
        }
        Strategy::MaterialRemovalRate => {
            let plan =
                ensemble.risk_based_test(&depths, settings.p_test, settings.feed_per_tooth_m)?;
            let stop = match (plan.and_then(|t| t.mrr_cm3_per_min), best_stable) {
                (Some(next), Some(best)) => next < (1.0 + MRR_STOP_IMPROVEMENT) * best,
                (None, _) => plan.is_none(),
                (Some(_), None) => false,
            };
            (plan, stop)
        }
    };
    let capped = observations.cuts.len() >= settings.max_tests;
    let stop_reason = if capped {
        Some(format!(
            "{} cuts made: the cap of {} test cuts is reached",
            observations.cuts.len(),
            settings.max_tests
        ))
    } else if stop {
        Some(match settings.strategy {
            Strategy::ValueOfInformation => {
                format!("the next cut's expected reduction is below {VOI_STOP_PERCENT} %")
            }
            Strategy::MaterialRemovalRate if next_cut.is_none() => {
                "no candidate reaches P_s >= P_test".to_string()
            }
            Strategy::MaterialRemovalRate => format!(
                "the next cut's MRR is less than {} % above the best stable cut's",
                100.0 * MRR_STOP_IMPROVEMENT
            ),
        })
    } else {
        None
    };
    Ok(PlanOutcome {
        next_cut,
        stop: stop || capped,
        stop_reason,
        cuts_used: observations.cuts.len(),
        parameter_names: names,
        posterior_mean: moments.iter().map(|m| m.0).collect(),
        posterior_sd: moments.iter().map(|m| m.1).collect(),
        best_stable_mrr_cm3_per_min: best_stable,
        effective_samples: ensemble.effective_sample_size(),
        failed_paths: ensemble.failures().len(),
        boundaries: ensemble.boundaries()?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;
    use chatter_progress::Silent;

    #[test]
    fn both_strategies_propose_a_cut_on_the_grid() {
        let model = examples::ebrahimi_2025_milling();
        let obs = examples::ebrahimi_2025_milling_observations();
        for strategy in [Strategy::ValueOfInformation, Strategy::MaterialRemovalRate] {
            let settings = PlanSettings {
                strategy,
                paths: 60,
                ..Default::default()
            };
            let out = plan_next_cut(&model, &obs, &settings, &Silent).unwrap();
            let cut = out.next_cut.unwrap();
            assert!(cut.speed_rpm >= 2100.0 * 0.75 - 1e-9 && cut.speed_rpm <= 2400.0 * 1.25 + 1e-9);
            assert_eq!(out.parameter_names, ["kt_n_per_mm2", "kn_n_per_mm2"]);
            assert_eq!(out.cuts_used, 7);
            assert!(out.best_stable_mrr_cm3_per_min.is_some());
        }
        // before the first cut the grid comes from the model and the paths from the prior
        let empty = Observations::default();
        let settings = PlanSettings {
            paths: 30,
            ..Default::default()
        };
        let first = plan_next_cut(&model, &empty, &settings, &Silent).unwrap();
        assert_eq!(first.cuts_used, 0);
        assert!(first.next_cut.is_some());
    }
}
