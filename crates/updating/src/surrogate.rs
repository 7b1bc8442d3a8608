//! Gaussian-process surrogate of the dominant milling multiplier (Ebrahimi-Tirtashi and Ahmadi
//! 2025, seed 002, Sections 2.2 and 3.3).
//!
//! The exact milling likelihood ([`crate::milling`]) computes the dominant eigenvalue of the
//! discretized monodromy operator at every identified condition for every theta the sampler
//! proposes. 002 replaces it by a Matérn GPR trained once on the exact model at parameter sets
//! that cover the prior's range. Here, per condition, two GPs (Matérn 5/2, constant mean,
//! [`chatter_bayes::gp`]) learn the real and imaginary parts of the dominant multiplier mu(theta_m)
//! (upper half-plane representative); the pole's frequency and damping follow from the
//! predicted mu as for the exact one (002 Section 2.1). Re mu and Im mu are smooth in theta
//! where the lifted frequency and damping are not (the principal frequency folds at half the
//! tooth frequency), so they are the better regression targets for the same information.
//!
//! The kernel hyperparameters maximize the marginal likelihood of the first
//! [`HYPERPARAMETER_POINTS`] training points (L-BFGS from 2 starts, at most 100 iterations);
//! the GP is then conditioned on all of them.
//!
//! A GP over the whole prior box is not accurate enough for the sharp likelihood of identified
//! poles (on 002's experimental case its held-out frequency error is about 0.2 Hz rms against a
//! scatter of 0.01-0.09 Hz in Table 2). [`refined_for_class`] therefore refines it per model
//! class around that class's posterior with local GPs trained on exact evaluations; the update
//! reports the refined surrogate's likelihood error at posterior samples.
//!
//! The training points are the first n points of the Halton sequence (bases 2, 3, 5, ...)
//! scaled to the prior box: deterministic, space filling, usable for any n (002 uses a uniform
//! grid of 1000 to 3375 points). The box of a bounded prior is its support; an unbounded
//! marginal is cut at mean +- 4 sd (normal) or its 4-sigma range (log-normal), where the GP
//! extrapolates beyond.
//!
//! [`PoleSurrogate::check`] reports the surrogate's error against the exact model at held-out
//! points of the same box (the Halton points after the training ones).

use crate::error::{Result, UpdatingError};
use crate::milling::{MillingPoleLikelihood, multiplier_frequency_damping};
use chatter_bayes::gp::{GaussianProcess, GpOptions};
use chatter_bayes::prior::Marginal;
use chatter_stability::DominantMultiplier;
use num_complex::Complex64;
use rayon::prelude::*;
use std::sync::Arc;

/// Default number of training points.
pub const DEFAULT_TRAINING_POINTS: usize = 200;
/// Training points whose log marginal likelihood sets the kernel hyperparameters (the first
/// ones of the Halton design, itself space filling); the GP is then conditioned on all points.
/// Fitting costs O(n^3) per optimizer iteration, conditioning O(n^3) once.
pub const HYPERPARAMETER_POINTS: usize = 120;
/// Default number of held-out points of [`PoleSurrogate::check`].
pub const DEFAULT_CHECK_POINTS: usize = 100;

/// The box [low, high] of one prior marginal that the training points cover.
pub fn prior_box(m: &Marginal) -> (f64, f64) {
    match *m {
        Marginal::Uniform { low, high } => (low, high),
        Marginal::TruncatedNormal {
            mean,
            sd,
            low,
            high,
        } => (low.max(mean - 4.0 * sd), high.min(mean + 4.0 * sd)),
        Marginal::Normal { mean, sd } => (mean - 4.0 * sd, mean + 4.0 * sd),
        Marginal::LogNormal { mu, sigma } => ((mu - 4.0 * sigma).exp(), (mu + 4.0 * sigma).exp()),
    }
}

const PRIMES: [u32; 12] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37];

/// Radical inverse of `i` in `base` (the Halton coordinate).
fn radical_inverse(mut i: usize, base: u32) -> f64 {
    let b = base as usize;
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= base as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

/// Halton points `from..to` (1-based indices, skipping the origin) scaled to `boxes`.
pub fn halton_points(boxes: &[(f64, f64)], from: usize, to: usize) -> Result<Vec<Vec<f64>>> {
    if boxes.len() > PRIMES.len() {
        return Err(UpdatingError::InvalidInput {
            field: "parameters",
            message: format!(
                "{} parameters; the surrogate's Halton design covers at most {}",
                boxes.len(),
                PRIMES.len()
            ),
        });
    }
    Ok((from..to)
        .map(|i| {
            boxes
                .iter()
                .zip(PRIMES)
                .map(|(&(lo, hi), p)| lo + (hi - lo) * radical_inverse(i + 1, p))
                .collect()
        })
        .collect())
}

/// One GP per condition for Re mu and one for Im mu.
#[derive(Debug, Clone)]
pub struct PoleSurrogate {
    models: Vec<[GaussianProcess; 2]>,
    periods_s: Vec<f64>,
    boxes: Vec<(f64, f64)>,
    training_points: usize,
    fallback: Option<Arc<PoleSurrogate>>,
}

/// Errors of the surrogate against the exact model at held-out points.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SurrogateCheck {
    /// Training points that entered the fit (failed exact evaluations are left out).
    pub training_points: usize,
    /// Held-out points compared.
    pub held_out_points: usize,
    /// Root-mean-square error of the pole frequency over conditions and points (Hz).
    pub rms_frequency_error_hz: f64,
    /// Largest frequency error (Hz).
    pub max_frequency_error_hz: f64,
    /// Root-mean-square error of the pole damping ratio.
    pub rms_damping_error: f64,
    /// Largest damping-ratio error.
    pub max_damping_error: f64,
}

impl PoleSurrogate {
    /// Train on the exact multipliers of `likelihood` at `n` Halton points of `boxes` (one box per
    /// model parameter), in parallel; points where the exact solver fails are left out.
    pub fn train(
        likelihood: &MillingPoleLikelihood,
        boxes: &[(f64, f64)],
        n: usize,
    ) -> Result<Self> {
        if boxes.len() != likelihood.parameterization().dimension() {
            return Err(UpdatingError::InvalidInput {
                field: "surrogate box",
                message: format!(
                    "{} boxes for {} model parameters",
                    boxes.len(),
                    likelihood.parameterization().dimension()
                ),
            });
        }
        if n < 10 {
            return Err(UpdatingError::InvalidInput {
                field: "surrogate training points",
                message: format!("{n}; at least 10 expected"),
            });
        }
        let points = halton_points(boxes, 0, n)?;
        let exact: Vec<(Vec<f64>, Vec<DominantMultiplier>)> = points
            .into_par_iter()
            .filter_map(|x| likelihood.exact_multipliers(&x).ok().map(|mu| (x, mu)))
            .collect();
        if exact.len() < 10 {
            return Err(UpdatingError::InvalidInput {
                field: "surrogate training points",
                message: format!(
                    "the exact model failed at {} of {n} training points",
                    n - exact.len()
                ),
            });
        }
        let inputs: Vec<Vec<f64>> = exact.iter().map(|e| e.0.clone()).collect();
        let conditions = exact[0].1.len();
        let periods_s = exact[0].1.iter().map(|m| m.period_s).collect();
        let models = (0..conditions)
            .into_par_iter()
            .map(|c| {
                let fit = |part: fn(Complex64) -> f64| {
                    let y: Vec<f64> = exact.iter().map(|e| part(e.1[c].value)).collect();
                    let k = y.len().min(HYPERPARAMETER_POINTS);
                    let options = GpOptions {
                        starts: 2,
                        max_iterations: 100,
                        ..GpOptions::default()
                    };
                    let h = GaussianProcess::fit(&inputs[..k], &y[..k], &options)?;
                    GaussianProcess::with_hyperparameters(
                        &inputs,
                        &y,
                        options.kernel,
                        options.mean,
                        h.hyperparameters(),
                    )
                };
                Ok([fit(|z| z.re)?, fit(|z| z.im)?])
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            models,
            periods_s,
            boxes: boxes.to_vec(),
            training_points: inputs.len(),
            fallback: None,
        })
    }

    /// The same surrogate answering only inside its box, and `fallback` outside.
    pub fn with_fallback(mut self, fallback: Arc<PoleSurrogate>) -> Self {
        self.fallback = Some(fallback);
        self
    }

    fn covers(&self, theta_m: &[f64]) -> bool {
        self.boxes
            .iter()
            .zip(theta_m)
            .all(|(&(lo, hi), &x)| x >= lo && x <= hi)
    }

    /// Predicted dominant multipliers at every condition for the model parameters `theta_m`.
    pub fn multipliers(&self, theta_m: &[f64]) -> Result<Vec<DominantMultiplier>> {
        if let Some(f) = self.fallback.as_ref().filter(|_| !self.covers(theta_m)) {
            return f.multipliers(theta_m);
        }
        self.models
            .iter()
            .zip(&self.periods_s)
            .map(|([re, im], &period)| {
                let z = Complex64::new(re.predict_mean(theta_m)?, im.predict_mean(theta_m)?);
                Ok(DominantMultiplier::new(z, period))
            })
            .collect()
    }

    /// Predicted (frequency Hz, damping ratio) at every condition.
    pub fn poles(&self, theta_m: &[f64]) -> Result<Vec<(f64, f64)>> {
        Ok(self
            .multipliers(theta_m)?
            .iter()
            .map(multiplier_frequency_damping)
            .collect())
    }

    /// Training points used.
    pub fn training_points(&self) -> usize {
        self.training_points
    }

    /// Errors against the exact model of `likelihood` at `n` held-out Halton points (those after
    /// the training points).
    pub fn check(&self, likelihood: &MillingPoleLikelihood, n: usize) -> Result<SurrogateCheck> {
        let start = self.training_points.max(1);
        let points = halton_points(&self.boxes, start + 1000, start + 1000 + n)?;
        let errors: Vec<(f64, f64)> = points
            .into_par_iter()
            .filter_map(|x| {
                let exact = likelihood.exact_multipliers(&x).ok()?;
                let approx = self.poles(&x).ok()?;
                Some(
                    exact
                        .iter()
                        .map(multiplier_frequency_damping)
                        .zip(approx)
                        .map(|(e, a)| ((e.0 - a.0).abs(), (e.1 - a.1).abs()))
                        .collect::<Vec<_>>(),
                )
            })
            .flatten()
            .collect();
        let k = errors.len().max(1) as f64;
        let rms = |f: fn(&(f64, f64)) -> f64| {
            (errors.iter().map(|e| f(e).powi(2)).sum::<f64>() / k).sqrt()
        };
        let max = |f: fn(&(f64, f64)) -> f64| errors.iter().map(f).fold(0.0, f64::max);
        Ok(SurrogateCheck {
            training_points: self.training_points,
            held_out_points: errors.len() / self.models.len().max(1),
            rms_frequency_error_hz: rms(|e| e.0),
            max_frequency_error_hz: max(|e| e.0),
            rms_damping_error: rms(|e| e.1),
            max_damping_error: max(|e| e.1),
        })
    }
}

/// Pilot posterior samples of each refinement stage of [`refined_for_class`] (fewer when the
/// update itself draws fewer, but at least [`MIN_PILOT_SAMPLES`]).
pub const PILOT_SAMPLES: usize = 300;
/// Fewest pilot samples of a refinement stage.
pub const MIN_PILOT_SAMPLES: usize = 50;
/// Refinement stages of [`refined_for_class`].
pub const REFINEMENTS: usize = 2;
/// Training points of each local surrogate of [`refined_for_class`].
pub const LOCAL_TRAINING_POINTS: usize = 100;

/// The surrogate refined around the posterior of one model class. The likelihood of identified
/// milling poles is sharp (frequency scatter of 0.01-0.09 Hz in 002 Table 2), far sharper than a
/// GP over the whole prior box resolves; so, [`REFINEMENTS`] times, [`PILOT_SAMPLES`] posterior
/// samples are drawn (TMCMC) with the current surrogate, and a new surrogate of
/// [`LOCAL_TRAINING_POINTS`] exact evaluations is trained on the box they span widened by its
/// own width on each side (within the prior box), answering inside that box and deferring to
/// the previous one outside. `likelihood` fixes the class (alpha) and the conditions; `samples`
/// is the size of the final posterior sample (it caps the pilots).
pub fn refined_for_class(
    likelihood: &MillingPoleLikelihood,
    global: Arc<PoleSurrogate>,
    prior: &crate::joint_prior::SampledPrior,
    samples: usize,
    seed: u64,
) -> Result<Arc<PoleSurrogate>> {
    let d = likelihood.parameterization().dimension();
    let prior_boxes: Vec<(f64, f64)> = prior.marginals()[..d].iter().map(prior_box).collect();
    let options = crate::classes::SamplerOptions {
        sampler: crate::classes::Sampler::Tmcmc,
        samples: PILOT_SAMPLES.min(samples.max(MIN_PILOT_SAMPLES)),
        seed,
    };
    let mut current = global;
    for _ in 0..REFINEMENTS {
        let like = likelihood.clone().with_surrogate(current.clone());
        let pilot = crate::joint_prior::sample_posterior_whitened(
            prior,
            like,
            &options,
            &chatter_progress::Silent,
        )?;
        let boxes: Vec<(f64, f64)> = (0..d)
            .map(|k| {
                let (lo, hi) = pilot
                    .samples
                    .samples()
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |a, s| {
                        (a.0.min(s[k]), a.1.max(s[k]))
                    });
                let (plo, phi) = prior_boxes[k];
                let w = (hi - lo).max(1e-4 * (phi - plo));
                ((lo - w).max(plo), (hi + w).min(phi))
            })
            .collect();
        let local = PoleSurrogate::train(likelihood, &boxes, LOCAL_TRAINING_POINTS)?;
        current = Arc::new(local.with_fallback(current));
    }
    Ok(current)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton_points_fill_the_box() {
        let pts = halton_points(&[(-1.0, 1.0), (0.0, 10.0)], 0, 4).unwrap();
        // radical inverses of 1..4 in base 2: 1/2, 1/4, 3/4, 1/8; base 3: 1/3, 2/3, 1/9, 4/9
        let expect = [
            (0.5, 1.0 / 3.0),
            (0.25, 2.0 / 3.0),
            (0.75, 1.0 / 9.0),
            (0.125, 4.0 / 9.0),
        ];
        for (p, (a, b)) in pts.iter().zip(expect) {
            assert!((p[0] - (-1.0 + 2.0 * a)).abs() < 1e-15);
            assert!((p[1] - 10.0 * b).abs() < 1e-14);
        }
    }
}
