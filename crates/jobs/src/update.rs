//! The updating job (`chatter update`, `chatter.update`): the papers' likelihoods over model
//! classes ([`chatter_updating::update::UpdateJob`]) with the request's sampler, samples and
//! seed, plus the prior draws shown beside the posterior.

use crate::error::{Result, count};
use chatter_dynamics::{ModalModel, Observations};
use chatter_progress::Observer;
use chatter_updating::classes::{Sampler, SamplerOptions};
use chatter_updating::joint_prior::JointNormal;
use chatter_updating::parameters::ModelParameter;
use chatter_updating::update::{PriorOverrides, UpdateJob, UpdateResult, UpdateSettings};

/// Prior draws returned beside the posterior (the corner plot's grey cloud, ArviZ's `prior`).
pub const PRIOR_DRAWS: usize = 2000;
/// Default samples per class.
pub const DEFAULT_SAMPLES: usize = 5000;
/// Most samples per class.
pub const MAX_SAMPLES: usize = 1_000_000;

/// What an update was asked; [`UpdateRequest::new`] gives the CLI's defaults.
#[derive(Debug, Clone)]
pub struct UpdateRequest {
    /// Posterior sampler.
    pub sampler: Sampler,
    /// Samples per class (10 to 1 000 000).
    pub samples: usize,
    /// Seed of the sampler and of the prior draws.
    pub seed: u64,
    /// Parameters to update (default: the papers').
    pub parameters: Option<Vec<ModelParameter>>,
    /// Priors by parameter name.
    pub priors: PriorOverrides,
    /// A correlated normal prior over some parameters (e.g. 004's RCSA prior file).
    pub joint_prior: Option<JointNormal>,
    /// Stability method of the cut likelihood (cut results only; default the full
    /// discretization).
    pub method: Option<chatter_stability::prepared::Method>,
    /// Model classes alpha (default: the papers').
    pub classes: Option<Vec<f64>>,
    /// Milling poles: GP surrogate training points (`None`: the exact multiplier per sample).
    pub surrogate_points: Option<usize>,
}

impl UpdateRequest {
    /// iTMCMC, 5000 samples per class, the papers' parameters, priors and classes, the GP
    /// surrogate with its default training points.
    pub fn new(seed: u64) -> Self {
        Self {
            sampler: Sampler::Itmcmc,
            samples: DEFAULT_SAMPLES,
            seed,
            parameters: None,
            priors: PriorOverrides::new(),
            joint_prior: None,
            method: None,
            classes: None,
            surrogate_points: Some(chatter_updating::surrogate::DEFAULT_TRAINING_POINTS),
        }
    }
}

/// A prepared update: the validated job and the request.
#[derive(Debug, Clone)]
pub struct PreparedUpdate {
    job: UpdateJob,
    request: UpdateRequest,
}

/// The posterior with the prior draws.
#[derive(Debug, Clone)]
pub struct UpdateOutcome {
    /// Samples, classes, evidence, updated model.
    pub result: UpdateResult,
    /// [`PRIOR_DRAWS`] draws of the prior of the sampled parameters, seeded by the request.
    pub prior_draws: Vec<Vec<f64>>,
}

impl PreparedUpdate {
    /// Validate the request against the model and observations (cheap: nothing sampled).
    pub fn new(
        model: &ModalModel,
        observations: &Observations,
        request: UpdateRequest,
    ) -> Result<Self> {
        count(
            "samples",
            request.samples,
            10,
            MAX_SAMPLES,
            "samples per class",
        )?;
        if let Some(n) = request.surrogate_points {
            count("surrogate_points", n, 10, 1_000_000, "GP training points")?;
        }
        let settings = UpdateSettings {
            parameters: request.parameters.clone(),
            priors: request.priors.clone(),
            joint_prior: request.joint_prior.clone(),
            method: request.method,
            classes: request.classes.clone(),
            surrogate_training_points: request.surrogate_points,
        };
        let job = UpdateJob::new(model, observations, &settings)?;
        if request.classes.is_some() && job.alphas().is_empty() {
            return Err(crate::JobError::Invalid {
                field: "classes",
                value: format!("{:?}", request.classes.as_deref().unwrap_or_default()),
                expected: "no classes: the observations have no poles, and the cut likelihood \
                           (004) has no model classes"
                    .into(),
            });
        }
        Ok(Self { job, request })
    }

    /// The validated job (parameter names, classes, prior).
    pub fn job(&self) -> &UpdateJob {
        &self.job
    }

    /// Sample every class, summarize the selected one, draw the prior.
    pub fn run(&self, observer: &dyn Observer) -> Result<UpdateOutcome> {
        let options = SamplerOptions {
            sampler: self.request.sampler,
            samples: self.request.samples,
            seed: self.request.seed,
        };
        let result = self.job.run(&options, observer)?;
        let prior_draws = self.job.prior_draws(PRIOR_DRAWS, self.request.seed);
        Ok(UpdateOutcome {
            result,
            prior_draws,
        })
    }
}

/// The warnings of an update, in the one wording that `chatter update` prints (after
/// `warning: `), its report page shows and the Python package returns: every model class whose
/// likelihood failed numerically (those evaluations are rejected and counted, never read as a
/// fit), then every parameter whose posterior piles against a bound of its prior (000 Section
/// 6.3).
pub fn warnings(result: &UpdateResult) -> Vec<String> {
    let failures = result.classes.iter().filter_map(|c| {
        let n = c.numerical_failures.filter(|&n| n > 0)?;
        let class = c.alpha.map_or(String::new(), |a| format!(" alpha {a}"));
        Some(format!(
            "model class{class}: {n} likelihood evaluations failed numerically (rejected and \
             counted; `numerical_failures` in summary.json)"
        ))
    });
    let pileups = result.prior_bound_pileups.iter().map(|p| {
        format!(
            "{}: {:.0} % of the posterior lies at the {} bound {} of its prior (median {}): the \
             prior decides this parameter, not the data; widen it with --priors",
            p.parameter,
            100.0 * p.share_at_bound,
            match p.bound {
                chatter_updating::prior_bounds::Bound::Lower => "lower",
                chatter_updating::prior_bounds::Bound::Upper => "upper",
            },
            p.bound_value,
            p.posterior_median
        )
    });
    failures.chain(pileups).collect()
}
