//! Reproduce seed 002 Section 3.2: the experimental Table 2 poles with uniform priors, TMCMC over
//! the model classes alpha = sigma_zeta / sigma_w from 0.001 to 1, the likelihood evaluated
//! exactly from the full-discretization monodromy operator (no surrogate).
//!
//! `cargo run --release -p chatter-updating --example ebrahimi2025 [SAMPLES] [ALPHA]`
use chatter_dynamics::examples;
use chatter_progress::Silent;
use chatter_stability::monodromy::Discretization;
use chatter_updating::classes::{Sampler, SamplerOptions, sample_posterior};
use chatter_updating::defaults::milling_alphas;
use chatter_updating::milling::MillingPoleLikelihood;
use chatter_updating::parameters::{Parameterization, parse_model_parameters};
use chatter_updating::update::{UpdateJob, UpdateSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let samples: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(5000);
    let only: Option<f64> = args.next().and_then(|a| a.parse().ok());
    let model = examples::ebrahimi_2025_milling();
    let obs = examples::ebrahimi_2025_milling_observations();
    let job = UpdateJob::new(&model, &obs, &UpdateSettings::default())?;
    let params = Parameterization::new(
        model.clone(),
        parse_model_parameters(&job.parameter_names()[..3].join(","))?,
    )?;
    let mut alphas = milling_alphas();
    if let Some(a) = only {
        alphas = vec![a];
    }
    let like0 =
        MillingPoleLikelihood::new(params.clone(), &obs.poles, 1.0, Discretization::full())?;
    println!(
        "nominal poles {:?}",
        like0.predicted_poles(&[0.0, 0.0, 0.0])?
    );
    println!(
        "paper-mean poles {:?}",
        like0.predicted_poles(&[3.6e-3, 0.35, 0.003])?
    );
    for alpha in alphas {
        let like =
            MillingPoleLikelihood::new(params.clone(), &obs.poles, alpha, Discretization::full())?;
        let t0 = std::time::Instant::now();
        let options = SamplerOptions {
            sampler: Sampler::Tmcmc,
            samples,
            seed: 1,
        };
        let post = sample_posterior(job.prior(), &like, &options, &Silent)?;
        let m = post.samples.mean();
        let c = post.samples.covariance();
        println!(
            "alpha {alpha:.4}: lnZ {:.2} mean [{:.4}, {:.4}, {:.4}, {:.2e}] var [{:.1e} {:.1e} {:.1e}] ({:.1} s)",
            post.log_evidence,
            m[0],
            m[1],
            m[2],
            m[3],
            c[(0, 0)],
            c[(1, 1)],
            c[(2, 2)],
            t0.elapsed().as_secs_f64(),
        );
    }
    Ok(())
}
