//! Reproduce seed 000 Section 6.3: iTMCMC over (theta_omega_2, theta_zeta_2, theta_phi_2,
//! sigma_R^2) with the paper's priors, for the model classes alpha = 2^-5.5 ... 2^2.
//!
//! `cargo run --release -p chatter-updating --example ahmadi2022 [SAMPLES] [ALPHA]`
use chatter_dynamics::examples;
use chatter_progress::Silent;
use chatter_updating::classes::{Sampler, SamplerOptions, sample_posterior};
use chatter_updating::defaults::turning_alphas;
use chatter_updating::turning::{ResidualForm, TurningPoleLikelihood};
use chatter_updating::update::{UpdateJob, UpdateSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let samples: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(5000);
    let only: Option<f64> = args.next().and_then(|a| a.parse().ok());
    let model = examples::ahmadi_2022_turning();
    let obs = examples::ahmadi_2022_turning_observations();
    // the job holds the paper's defaults: mode-2 parameters, Section 6.3 priors
    let job = UpdateJob::new(&model, &obs, &UpdateSettings::default())?;
    let params = chatter_updating::parameters::Parameterization::new(
        model.clone(),
        job.parameter_names()[..3]
            .iter()
            .map(|s| s.parse())
            .collect::<Result<_, _>>()?,
    )?;
    let poles = chatter_updating::turning::expand_repetitions(&obs.poles);
    let mut evidences = Vec::new();
    for alpha in turning_alphas() {
        if only.is_some_and(|o| (o - alpha).abs() > 1e-9) {
            continue;
        }
        let like = TurningPoleLikelihood::new(
            params.clone(),
            poles.clone(),
            alpha,
            ResidualForm::PoleError,
        )?;
        let t0 = std::time::Instant::now();
        let options = SamplerOptions {
            sampler: Sampler::Itmcmc,
            samples,
            seed: 1,
        };
        let post = sample_posterior(job.prior(), &like, &options, &Silent)?;
        let m = post.samples.mean();
        let c = post.samples.covariance();
        println!(
            "alpha {alpha:.4}: lnZ {:.2} fit {:.2} mean [{:.4}, {:.4}, {:.4}, {:.2e}] \
             var [{:.1e} {:.1e} {:.1e}] cov [{:.1e} {:.1e} {:.1e}] ({:.1} s)",
            post.log_evidence,
            post.data_fit.unwrap_or(f64::NAN),
            m[0],
            m[1],
            m[2],
            m[3],
            c[(0, 0)],
            c[(1, 1)],
            c[(2, 2)],
            c[(0, 1)],
            c[(0, 2)],
            c[(1, 2)],
            t0.elapsed().as_secs_f64(),
        );
        evidences.push(post.log_evidence);
    }
    println!(
        "class probabilities {:?}",
        chatter_bayes::tmcmc::class_probabilities(&evidences)
    );
    Ok(())
}
