//! The updating job: from a model and observations to the posterior, the selected model class and
//! the updated model (what `chatter update` runs).
//!
//! The data decide the likelihood: identified poles of a turning model use the
//! characteristic-equation likelihood ([`crate::turning`], 000), identified poles of a milling
//! model the Floquet-multiplier likelihood ([`crate::milling`], 002), both over model classes
//! alpha; cut results alone use the cut likelihood ([`crate::cuts`], 004 Eq. 5 with its
//! s_S = 0.125 mm and s_fc = 50 Hz) as a single class.
//! Parameters, priors and classes default to the papers' ([`crate::defaults`]).

use crate::classes::SamplerOptions;
use crate::cuts::{CutKernel, CutsLikelihood};
use crate::defaults::{
    MILLING_ERROR_VARIANCE, TURNING_ERROR_VARIANCE, default_parameters, error_variance_prior,
    milling_alphas, parameter_prior, turning_alphas,
};
use crate::error::{Result, UpdatingError};
use crate::joint_prior::{
    JointNormal, SampledPrior, sample_posterior_whitened, select_model_class_whitened,
};
use crate::milling::MillingPoleLikelihood;
use crate::parameters::{ModelParameter, Parameterization};
use crate::turning::{ResidualForm, TurningPoleLikelihood, expand_repetitions};
use chatter_bayes::Prior;
use chatter_bayes::prior::Marginal;
use chatter_bayes::samples::SampleSet;
use chatter_dynamics::{Cut, ModalModel, Observations, Operation, PoleObservation};
use chatter_progress::Observer;
use chatter_stability::monodromy::Discretization;
use chatter_stability::prepared::{Method, SolverOptions};
use nalgebra::DMatrix;
use std::collections::BTreeMap;

/// Priors by parameter name (a priors file); parameters not named keep their defaults.
/// Each entry is a [`Marginal`] in its serde form, e.g.
/// `{"kind": "truncated_normal", "mean": 0, "sd": 0.03, "low": -0.03, "high": 0.03}`.
pub type PriorOverrides = BTreeMap<String, Marginal>;

/// Which data the job updates on.
#[derive(Debug, Clone)]
enum Data {
    TurningPoles(Vec<crate::turning::ObservedPole>),
    MillingPoles(Vec<PoleObservation>),
    Cuts(Vec<Cut>),
}

/// What the user may set; `None` takes the papers' defaults.
#[derive(Debug, Clone, Default)]
pub struct UpdateSettings {
    /// Parameters to update.
    pub parameters: Option<Vec<ModelParameter>>,
    /// Priors by name.
    pub priors: PriorOverrides,
    /// A correlated normal prior over some of the parameters (a prior file
    /// `{parameter_names, mean, covariance}`, e.g. 004's RCSA prior), which then sets their
    /// prior; without `parameters` its names are the updated parameters. The samplers run in
    /// its whitened coordinates ([`crate::joint_prior`]).
    pub joint_prior: Option<JointNormal>,
    /// Model classes alpha.
    pub classes: Option<Vec<f64>>,
    /// Stability method of the cut likelihood (default [`SolverOptions`]'s: the full
    /// discretization; 004 used the zero-order method). Cut results only.
    pub method: Option<Method>,
    /// Milling poles: replace the exact multipliers by a GP surrogate trained on this many
    /// points of the prior box ([`crate::surrogate`], 002 Section 2.2). Ignored otherwise.
    pub surrogate_training_points: Option<usize>,
}

/// A validated updating job.
#[derive(Debug, Clone)]
pub struct UpdateJob {
    parameterization: Parameterization,
    prior: SampledPrior,
    names: Vec<String>,
    alphas: Vec<f64>,
    data: Data,
    /// Stability solver of the cut likelihood.
    solver: SolverOptions,
    surrogate_training_points: Option<usize>,
    poles: Vec<PoleObservation>,
}

/// One model class in the result.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ClassSummary {
    /// alpha (None for the cut likelihood, which has no classes).
    pub alpha: Option<f64>,
    /// ln p(D | M).
    pub log_evidence: f64,
    /// p(M | D).
    pub probability: f64,
    /// Likelihood evaluations of the sampler that failed numerically (iTMCMC / TMCMC).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub numerical_failures: Option<usize>,
    /// E[ln p(D | theta, M)] over the posterior: the data fit of 000 Eq. 33 (iTMCMC / TMCMC).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub data_fit: Option<f64>,
    /// E[ln p(theta | D, M) / p(theta | M)] = data fit - ln p(D | M): the information gain of
    /// 000 Eq. 33, in nats.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub information_gain: Option<f64>,
}

/// The result of a job.
#[derive(Debug, Clone)]
pub struct UpdateResult {
    /// Sampled parameter names (model parameters, then the error variance where there is one).
    pub parameter_names: Vec<String>,
    /// Posterior samples of the selected class.
    pub samples: SampleSet,
    /// Posterior mean, same order as the names.
    pub posterior_mean: Vec<f64>,
    /// Posterior covariance.
    pub posterior_covariance: DMatrix<f64>,
    /// Every class.
    pub classes: Vec<ClassSummary>,
    /// The selected alpha.
    pub selected_alpha: Option<f64>,
    /// The model at the posterior mean of the model parameters.
    pub updated_model: ModalModel,
    /// Parameters whose posterior piles against a bound of its prior (the prior decides them).
    pub prior_bound_pileups: Vec<crate::prior_bounds::BoundPileup>,
    /// The surrogate's errors, when one replaced the exact likelihood.
    pub surrogate: Option<SurrogateReport>,
    /// Identified poles against those of the nominal and the updated model (empty for cuts).
    pub pole_table: Vec<PoleComparison>,
}

/// A posterior's `summary.json`: what `chatter update` writes beside `posterior.csv` and what
/// the bands read back (`chatter_uncertainty::parameters::ParameterDistribution::from_posterior_dir`).
/// A reader needs only the names and the moments; the classes, the selected alpha, the pile-ups
/// and the surrogate report are written for people and skipped when read. The fields are in
/// the file's key order (alphabetical).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PosteriorSummary {
    /// Every model class (written only).
    #[serde(skip_deserializing)]
    pub classes: Vec<ClassSummary>,
    /// Sampled parameter names, in the order of the mean and the covariance.
    pub parameter_names: Vec<String>,
    /// Posterior covariance, row by row.
    pub posterior_covariance: Vec<Vec<f64>>,
    /// Posterior mean.
    pub posterior_mean: Vec<f64>,
    /// Parameters whose posterior piles against a bound of its prior (written only).
    #[serde(skip_deserializing)]
    pub prior_bound_pileups: Vec<crate::prior_bounds::BoundPileup>,
    /// The selected alpha (written only).
    #[serde(skip_deserializing)]
    pub selected_alpha: Option<f64>,
    /// The surrogate's errors, when one replaced the exact likelihood (written only).
    #[serde(skip_deserializing)]
    pub surrogate: Option<SurrogateReport>,
}

impl PosteriorSummary {
    /// The summary of an update.
    pub fn of(result: &UpdateResult) -> Self {
        let c = &result.posterior_covariance;
        Self {
            classes: result.classes.clone(),
            parameter_names: result.parameter_names.clone(),
            posterior_covariance: (0..c.nrows())
                .map(|i| (0..c.ncols()).map(|j| c[(i, j)]).collect())
                .collect(),
            posterior_mean: result.posterior_mean.clone(),
            prior_bound_pileups: result.prior_bound_pileups.clone(),
            selected_alpha: result.selected_alpha,
            surrogate: result.surrogate,
        }
    }
}

/// An identified pole beside the model's prediction before and after updating.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PoleComparison {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Depth or width of cut (mm).
    pub depth_mm: f64,
    /// Identified frequency (Hz; lifted principal frequency for milling).
    pub identified_hz: f64,
    /// Identified damping ratio.
    pub identified_damping: f64,
    /// Nominal model's frequency (Hz).
    pub nominal_hz: f64,
    /// Nominal model's damping ratio.
    pub nominal_damping: f64,
    /// Updated model's (posterior mean) frequency (Hz).
    pub updated_hz: f64,
    /// Updated model's damping ratio.
    pub updated_damping: f64,
}

/// How well the GP surrogate stood in for the exact milling likelihood.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SurrogateReport {
    /// Pole errors of the global surrogate (before refinement) at held-out points of the prior
    /// box.
    pub held_out: crate::surrogate::SurrogateCheck,
    /// Posterior samples of the selected class at which the likelihoods were compared.
    pub posterior_points: usize,
    /// Mean |ln L_surrogate - ln L_exact| over those samples.
    pub mean_abs_ln_likelihood_error: f64,
    /// Largest |ln L_surrogate - ln L_exact|.
    pub max_abs_ln_likelihood_error: f64,
}

/// Posterior samples at which the surrogate's likelihood is compared with the exact one.
const SURROGATE_POSTERIOR_CHECKS: usize = 50;

impl UpdateJob {
    /// Validate model, observations and settings into a job.
    pub fn new(
        model: &ModalModel,
        observations: &Observations,
        settings: &UpdateSettings,
    ) -> Result<Self> {
        let poles = &observations.poles;
        if poles.is_empty() && observations.cuts.is_empty() {
            return Err(UpdatingError::Observations(
                "no identified poles and no cuts to update on".into(),
            ));
        }
        let parameters = match &settings.parameters {
            Some(p) if !p.is_empty() => p.clone(),
            Some(_) => {
                return Err(UpdatingError::InvalidInput {
                    field: "parameters",
                    message: "empty list".into(),
                });
            }
            None => match &settings.joint_prior {
                Some(joint) => joint.parameters()?,
                None => default_parameters(model, poles)?,
            },
        };
        let parameterization = Parameterization::new(model.clone(), parameters)?;
        let mut names = parameterization.names();
        let mut marginals: Vec<Marginal> = parameterization
            .parameters()
            .iter()
            .map(|p| parameter_prior(*p, model))
            .collect();
        let turning = matches!(model.operation(), Operation::Turning(_));
        let (data, alphas) = if poles.is_empty() {
            (Data::Cuts(observations.cuts.clone()), Vec::new())
        } else {
            names.push(
                if turning {
                    TURNING_ERROR_VARIANCE
                } else {
                    MILLING_ERROR_VARIANCE
                }
                .to_string(),
            );
            marginals.push(error_variance_prior(model));
            let alphas = settings.classes.clone().unwrap_or_else(|| {
                if turning {
                    turning_alphas()
                } else {
                    milling_alphas()
                }
            });
            let data = if turning {
                Data::TurningPoles(expand_repetitions(poles))
            } else {
                Data::MillingPoles(poles.clone())
            };
            (data, alphas)
        };
        if let (Some(method), false) = (settings.method, matches!(data, Data::Cuts(_))) {
            return Err(UpdatingError::InvalidInput {
                field: "method",
                message: format!(
                    "{}: the stability method applies to cut results only, and these \
                     observations have identified poles (their likelihoods use the exact poles)",
                    method.name()
                ),
            });
        }
        if let Some(a) = alphas.iter().find(|a| !(a.is_finite() && **a > 0.0)) {
            return Err(UpdatingError::InvalidInput {
                field: "classes",
                message: format!("alpha {a}; expected > 0"),
            });
        }
        let nuisance = &names[parameterization.dimension()..];
        let prior = SampledPrior::with_nuisance(
            parameterization.clone(),
            marginals,
            nuisance,
            &settings.priors,
            settings.joint_prior.as_ref(),
        )?;
        Ok(Self {
            parameterization,
            prior,
            names,
            alphas,
            data,
            solver: settings
                .method
                .map_or_else(SolverOptions::default, SolverOptions::new),
            surrogate_training_points: settings.surrogate_training_points,
            poles: poles.clone(),
        })
    }

    /// Sampled parameter names (model parameters, then the error variance).
    pub fn parameter_names(&self) -> &[String] {
        &self.names
    }

    /// The model classes (empty for cut results).
    pub fn alphas(&self) -> &[f64] {
        &self.alphas
    }

    /// The joint prior (marginals, or a correlated block times marginals).
    pub fn prior(&self) -> &SampledPrior {
        &self.prior
    }

    /// `n` independent draws from the joint prior (seeded), e.g. to plot beside the posterior
    /// (000 Fig. 5).
    pub fn prior_draws(&self, n: usize, seed: u64) -> Vec<Vec<f64>> {
        use rand::SeedableRng;
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        (0..n).map(|_| self.prior.sample(&mut rng)).collect()
    }

    /// Sample every class and summarize the selected one.
    pub fn run(&self, options: &SamplerOptions, observer: &dyn Observer) -> Result<UpdateResult> {
        let p = &self.parameterization;
        let mut surrogate = None;
        let (samples, classes, selected_alpha) = match &self.data {
            Data::Cuts(cuts) => {
                observer.class_started(0, 1, f64::NAN);
                let like = CutsLikelihood::new(
                    p.clone(),
                    cuts.clone(),
                    CutKernel::schmitz(),
                    self.solver,
                )?;
                let post = sample_posterior_whitened(&self.prior, like, options, observer)?;
                let class = ClassSummary {
                    alpha: None,
                    log_evidence: post.log_evidence,
                    probability: 1.0,
                    numerical_failures: post.numerical_failures,
                    data_fit: post.data_fit,
                    information_gain: post.data_fit.map(|f| f - post.log_evidence),
                };
                (post.samples, vec![class], None)
            }
            Data::TurningPoles(poles) => {
                let make = |alpha| {
                    TurningPoleLikelihood::new(
                        p.clone(),
                        poles.clone(),
                        alpha,
                        ResidualForm::PoleError,
                    )
                };
                summarize(select_model_class_whitened(
                    &self.prior,
                    &self.alphas,
                    make,
                    options,
                    observer,
                )?)
            }
            Data::MillingPoles(poles) => {
                let exact =
                    MillingPoleLikelihood::new(p.clone(), poles, 1.0, Discretization::full())?;
                let global = match self.surrogate_training_points {
                    Some(n) => {
                        let boxes: Vec<(f64, f64)> = self.prior.marginals()[..p.dimension()]
                            .iter()
                            .map(crate::surrogate::prior_box)
                            .collect();
                        Some(std::sync::Arc::new(crate::surrogate::PoleSurrogate::train(
                            &exact, &boxes, n,
                        )?))
                    }
                    None => None,
                };
                let refined = std::sync::Mutex::new(Vec::new());
                let make = |alpha: f64| {
                    let like = MillingPoleLikelihood::new(
                        p.clone(),
                        poles,
                        alpha,
                        Discretization::full(),
                    )?;
                    Ok(match &global {
                        Some(g) => {
                            let s = crate::surrogate::refined_for_class(
                                &like,
                                g.clone(),
                                &self.prior,
                                options.samples,
                                options.seed,
                            )?;
                            if let Ok(mut r) = refined.lock() {
                                r.push((alpha, s.clone()));
                            }
                            like.with_surrogate(s)
                        }
                        None => like,
                    })
                };
                let (samples, classes, alpha) = summarize(select_model_class_whitened(
                    &self.prior,
                    &self.alphas,
                    make,
                    options,
                    observer,
                )?);
                let chosen = refined
                    .into_inner()
                    .ok()
                    .and_then(|r| r.into_iter().find(|(a, _)| Some(*a) == alpha));
                if let (Some((a, g)), Some(global)) = (chosen, &global) {
                    surrogate = Some(surrogate_report(&g, global, poles, p, a, &samples)?);
                }
                (samples, classes, alpha)
            }
        };
        let mean = samples.mean();
        let updated_model = p.model(&mean[..p.dimension()])?;
        let pole_table = self.pole_table(&mean[..p.dimension()])?;
        let prior_bound_pileups = crate::prior_bounds::prior_bound_pileups(
            &self.names,
            &self.prior.marginals(),
            &samples,
        );
        Ok(UpdateResult {
            pole_table,
            prior_bound_pileups,
            surrogate,
            parameter_names: self.names.clone(),
            posterior_covariance: samples.covariance(),
            posterior_mean: mean,
            samples,
            classes,
            selected_alpha,
            updated_model,
        })
    }
}

impl UpdateJob {
    /// ln p(d_i | theta, M_alpha) of every observation d_i alone at every sample theta (rows:
    /// samples, columns: the identified poles with their repetitions expanded, or the cuts):
    /// the pointwise log-likelihood that LOO and WAIC need. The observations are independent
    /// given theta (000 Eq. 28-31, 002 Eq. 14-15, 004 Eq. 5), so a row sums to ln p(D | theta)
    /// (checked for turning poles, whose terms share the set's residual normalization; milling
    /// poles and cuts are evaluated one observation at a time). Milling poles use the exact
    /// multipliers, not the surrogate. `alpha` is the class (ignored for cuts, which have none).
    pub fn pointwise_log_likelihood(
        &self,
        alpha: Option<f64>,
        samples: &[Vec<f64>],
    ) -> Result<Vec<Vec<f64>>> {
        use chatter_bayes::LogLikelihood;
        use rayon::prelude::*;
        let p = &self.parameterization;
        let alpha = alpha.unwrap_or(1.0);
        let singles: Vec<Box<dyn LogLikelihood>> = match &self.data {
            Data::Cuts(cuts) => cuts
                .iter()
                .map(|c| {
                    CutsLikelihood::new(
                        p.clone(),
                        vec![c.clone()],
                        CutKernel::schmitz(),
                        self.solver,
                    )
                    .map(|l| Box::new(l) as Box<dyn LogLikelihood>)
                })
                .collect::<Result<_>>()?,
            Data::TurningPoles(poles) => {
                // one likelihood of all poles: its residual normalization is the set's
                let all = TurningPoleLikelihood::new(
                    p.clone(),
                    poles.clone(),
                    alpha,
                    ResidualForm::PoleError,
                )?;
                return Ok(samples
                    .par_iter()
                    .map(|theta| all.pointwise_ln_likelihood(theta))
                    .collect());
            }
            Data::MillingPoles(poles) => poles
                .iter()
                .map(|o| {
                    MillingPoleLikelihood::new(
                        p.clone(),
                        std::slice::from_ref(o),
                        alpha,
                        Discretization::full(),
                    )
                    .map(|l| Box::new(l) as Box<dyn LogLikelihood>)
                })
                .collect::<Result<_>>()?,
        };
        Ok(samples
            .par_iter()
            .map(|theta| singles.iter().map(|l| l.ln_likelihood(theta)).collect())
            .collect())
    }
}

impl UpdateJob {
    /// (frequency Hz, damping) of the model's pole at every identified condition for `theta_m`
    /// (exact: the characteristic root nearest the identified pole in turning, the dominant
    /// multiplier of the monodromy in milling), in the order of `self.poles`.
    fn predicted(&self, theta_m: &[f64]) -> Result<Vec<(f64, f64)>> {
        let p = &self.parameterization;
        match &self.data {
            Data::Cuts(_) => Ok(Vec::new()),
            Data::MillingPoles(poles) => {
                MillingPoleLikelihood::new(p.clone(), poles, 1.0, Discretization::full())?
                    .predicted_poles(theta_m)
            }
            Data::TurningPoles(expanded) => {
                let like = TurningPoleLikelihood::new(
                    p.clone(),
                    expanded.clone(),
                    1.0,
                    ResidualForm::PoleError,
                )?;
                let roots = like.predicted_poles(theta_m)?;
                self.poles
                    .iter()
                    .map(|o| {
                        roots
                            .iter()
                            .find(|r| r.0 == o.speed_rpm && (r.1 - o.depth_mm * 1e-3).abs() < 1e-12)
                            .map(|r| chatter_dynamics::pole::pole_frequency_damping(r.2))
                            .ok_or_else(|| {
                                UpdatingError::Observations(format!(
                                    "no prediction at {} rpm, {} mm",
                                    o.speed_rpm, o.depth_mm
                                ))
                            })
                    })
                    .collect()
            }
        }
    }

    /// Identified against predicted poles, nominal and at `theta_m`.
    fn pole_table(&self, theta_m: &[f64]) -> Result<Vec<PoleComparison>> {
        if matches!(self.data, Data::Cuts(_)) {
            return Ok(Vec::new());
        }
        let nominal = self.predicted(&self.parameterization.nominal_theta())?;
        let updated = self.predicted(theta_m)?;
        Ok(self
            .poles
            .iter()
            .zip(nominal.iter().zip(&updated))
            .map(|(o, (n, u))| PoleComparison {
                speed_rpm: o.speed_rpm,
                depth_mm: o.depth_mm,
                identified_hz: o.frequency_hz,
                identified_damping: o.damping_ratio,
                nominal_hz: n.0,
                nominal_damping: n.1,
                updated_hz: u.0,
                updated_damping: u.1,
            })
            .collect())
    }
}

/// The surrogate's pole errors at held-out prior points and its likelihood error at posterior
/// samples of the selected class `alpha`.
fn surrogate_report(
    gp: &std::sync::Arc<crate::surrogate::PoleSurrogate>,
    global: &crate::surrogate::PoleSurrogate,
    poles: &[PoleObservation],
    p: &Parameterization,
    alpha: f64,
    samples: &SampleSet,
) -> Result<SurrogateReport> {
    use rayon::prelude::*;
    let exact = MillingPoleLikelihood::new(p.clone(), poles, alpha, Discretization::full())?;
    let approx = exact.clone().with_surrogate(gp.clone());
    let held_out = global.check(&exact, crate::surrogate::DEFAULT_CHECK_POINTS)?;
    let all = samples.samples();
    let step = (all.len() / SURROGATE_POSTERIOR_CHECKS).max(1);
    let errors: Vec<f64> = all
        .par_iter()
        .step_by(step)
        .map(|t| (approx.ln_likelihood(t) - exact.ln_likelihood(t)).abs())
        .filter(|e| e.is_finite())
        .collect();
    let n = errors.len();
    Ok(SurrogateReport {
        held_out,
        posterior_points: n,
        mean_abs_ln_likelihood_error: errors.iter().sum::<f64>() / n.max(1) as f64,
        max_abs_ln_likelihood_error: errors.iter().copied().fold(0.0, f64::max),
    })
}

fn summarize(
    selection: crate::classes::ClassSelection,
) -> (SampleSet, Vec<ClassSummary>, Option<f64>) {
    let classes = selection
        .classes
        .iter()
        .zip(&selection.probabilities)
        .map(|(c, &probability)| ClassSummary {
            alpha: Some(c.alpha),
            log_evidence: c.posterior.log_evidence,
            probability,
            numerical_failures: c.posterior.numerical_failures,
            data_fit: c.posterior.data_fit,
            information_gain: c.posterior.data_fit.map(|f| f - c.posterior.log_evidence),
        })
        .collect();
    let selected = selection.selected_class();
    (
        selected.posterior.samples.clone(),
        classes,
        Some(selected.alpha),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::classes::Sampler;
    use chatter_dynamics::examples;
    use chatter_progress::Silent;

    #[test]
    fn pointwise_log_likelihood_sums_to_the_likelihood_of_all_poles() {
        let model = examples::ahmadi_2022_turning();
        let obs = examples::ahmadi_2022_turning_observations();
        let job = UpdateJob::new(&model, &obs, &UpdateSettings::default()).unwrap();
        let Data::TurningPoles(poles) = &job.data else {
            panic!("seed 000 updates on turning poles")
        };
        let alpha = job.alphas()[3];
        let all = TurningPoleLikelihood::new(
            job.parameterization.clone(),
            poles.clone(),
            alpha,
            ResidualForm::PoleError,
        )
        .unwrap();
        let thetas = job.prior_draws(4, 1);
        let rows = job.pointwise_log_likelihood(Some(alpha), &thetas).unwrap();
        for (theta, row) in thetas.iter().zip(&rows) {
            assert_eq!(row.len(), poles.len());
            let total: f64 = row.iter().sum();
            let expected = all.ln_likelihood(theta);
            // the same terms summed in another order: rounding only
            assert!(
                (total - expected).abs() <= 1e-9 * expected.abs().max(1.0),
                "{total} vs {expected}"
            );
        }
    }

    #[test]
    fn priors_files_parse_strictly_and_name_checks_hold() {
        let text = r#"{"theta_omega_2": {"kind": "truncated_normal", "mean": 0, "sd": 0.01,
                       "low": -0.03, "high": 0.03},
                       "sigma_r2": {"kind": "uniform", "low": 1e-10, "high": 1}}"#;
        let priors: PriorOverrides = serde_json::from_str(text).unwrap();
        let bad = r#"{"theta_omega_2": {"kind": "uniform", "low": 0, "high": 1, "x": 2}}"#;
        assert!(serde_json::from_str::<PriorOverrides>(bad).is_err());
        let model = examples::ahmadi_2022_turning();
        let obs = examples::ahmadi_2022_turning_observations();
        let job = UpdateJob::new(
            &model,
            &obs,
            &UpdateSettings {
                priors: priors.clone(),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(
            job.parameter_names(),
            ["theta_omega_2", "theta_zeta_2", "theta_phi_2", "sigma_r2"]
        );
        assert_eq!(job.alphas().len(), 16);
        assert_eq!(
            job.prior().marginals()[3],
            Marginal::Uniform {
                low: 1e-10,
                high: 1.0
            }
        );
        let mut unknown = priors;
        unknown.insert("theta_k_1".into(), Marginal::Normal { mean: 0.0, sd: 1.0 });
        let settings = UpdateSettings {
            priors: unknown,
            ..Default::default()
        };
        assert!(UpdateJob::new(&model, &obs, &settings).is_err());
        // a stability method is for cut results; poles use their exact likelihoods
        let settings = UpdateSettings {
            method: Some(Method::Zoa),
            ..Default::default()
        };
        let err = UpdateJob::new(&model, &obs, &settings)
            .unwrap_err()
            .to_string();
        assert!(err.contains("method") && err.contains("zoa"), "{err}");
    }

    #[test]
    fn complex_modes_and_residual_terms_take_the_zero_order_cut_likelihood_only() {
        // 004's model with complex modes, and with residual terms in x: FDM names the field,
        // the zero-order cut likelihood samples
        let base = examples::schmitz_2022_rcsa();
        let modes = base
            .modes()
            .iter()
            .map(|m| m.with_residue_phase(0.2).unwrap())
            .collect();
        let complex = base.with_modes(modes).unwrap();
        let residual = chatter_dynamics::ResidualTerms {
            upper_m_per_n: 2e-8,
            lower_per_kg: 0.0,
        };
        let with_residuals = base
            .with_residuals([residual, chatter_dynamics::ResidualTerms::default()])
            .unwrap();
        let mut obs = Observations::default();
        for (depth_mm, stable) in [(2.5, true), (3.5, false)] {
            obs.cuts.push(Cut::labelled(10_985.0, depth_mm, stable));
        }
        let options = SamplerOptions {
            sampler: Sampler::Itmcmc,
            samples: 50,
            seed: 1,
        };
        let parameters = Some(vec![ModelParameter::KtNPerMm2]);
        for (model, field) in [
            (&complex, "modes[0].residue_phase_deg"),
            (&with_residuals, "residuals[x]"),
        ] {
            let job = |method| {
                let settings = UpdateSettings {
                    parameters: parameters.clone(),
                    method: Some(method),
                    ..Default::default()
                };
                UpdateJob::new(model, &obs, &settings).and_then(|job| job.run(&options, &Silent))
            };
            let err = job(Method::Fdm).unwrap_err().to_string();
            assert!(err.contains(field) && err.contains("fdm"), "{err}");
            let result = job(Method::Zoa).unwrap();
            assert!(result.posterior_mean[0].is_finite());
            // plan after the cuts (paths from the posterior), with FDM: the same refusal
            let settings = crate::plan::PlanSettings {
                strategy: crate::plan::Strategy::MaterialRemovalRate,
                parameters: parameters.clone(),
                paths: 20,
                speeds_rpm: Some(vec![10_985.0]),
                depths_m: Some(vec![0.5e-3, 1e-3]),
                method: Some(Method::Fdm),
                ..Default::default()
            };
            let err = crate::plan::plan_next_cut(model, &obs, &settings, &Silent)
                .unwrap_err()
                .to_string();
            assert!(err.contains(field) && err.contains("fdm"), "{err}");
        }
        // identified milling poles: the multiplier likelihood refuses a complex mode up front
        let milling = examples::ebrahimi_2025_milling();
        let modes = milling
            .modes()
            .iter()
            .map(|m| m.with_residue_phase(0.2).unwrap())
            .collect();
        let milling = milling.with_modes(modes).unwrap();
        let poles = examples::ebrahimi_2025_milling_observations();
        let err = UpdateJob::new(&milling, &poles, &UpdateSettings::default())
            .and_then(|job| job.run(&options, &Silent))
            .unwrap_err()
            .to_string();
        assert!(err.contains("modes[0].residue_phase_deg"), "{err}");
    }

    #[test]
    fn cut_results_update_the_cutting_coefficient() {
        // stable at 0.3 mm, chatter at 0.9 mm (2100 rpm) on the 002 machine: kn moves to the
        // values whose limit lies between
        let model = examples::ebrahimi_2025_milling();
        let mut obs = Observations::default();
        for (depth_mm, stable) in [(0.3, true), (0.9, false)] {
            obs.cuts.push(Cut::labelled(2100.0, depth_mm, stable));
        }
        let settings = UpdateSettings {
            parameters: Some(vec![ModelParameter::KnNPerMm2]),
            ..Default::default()
        };
        let job = UpdateJob::new(&model, &obs, &settings).unwrap();
        let options = SamplerOptions {
            sampler: Sampler::Itmcmc,
            samples: 200,
            seed: 1,
        };
        let result = job.run(&options, &Silent).unwrap();
        assert_eq!(result.classes.len(), 1);
        assert!(result.selected_alpha.is_none());
        let limit = |kn: f64| {
            let m = Parameterization::new(model.clone(), vec![ModelParameter::KnNPerMm2])
                .unwrap()
                .model(&[kn])
                .unwrap();
            SolverOptions::default()
                .prepare_on_grid_of(&m, &m)
                .and_then(|solver| solver.limiting_depth(2100.0))
                .unwrap()
                .depth_m
        };
        let b = limit(result.posterior_mean[0]);
        assert!(b > 0.3e-3 && b < 0.9e-3, "{b}");
    }
}
