//! Reproduce seed 000 Section 6.3: iTMCMC over (theta_omega_2, theta_zeta_2, theta_phi_2,
//! sigma_R^2) with the paper's priors, for the model classes alpha = 2^-5.5 ... 2^2.
use chatter_bayes::prior::{IndependentPrior, Marginal};
use chatter_bayes::tmcmc::{Silent, TmcmcOptions, class_probabilities, tmcmc};
use chatter_dynamics::{Parameter, examples};
use chatter_updating::turning::{TurningPoleLikelihood, expand_repetitions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = examples::ahmadi_2022_turning();
    let poles = expand_repetitions(&examples::ahmadi_2022_turning_observations().poles);
    let params: Vec<Parameter> = ["theta_omega_2", "theta_zeta_2", "theta_phi_2"]
        .iter()
        .map(|s| s.parse())
        .collect::<Result<_, _>>()?;
    let prior = IndependentPrior::new(vec![
        Marginal::TruncatedNormal {
            mean: 0.0,
            sd: 0.001f64.sqrt(),
            low: -0.03,
            high: 0.03,
        },
        Marginal::TruncatedNormal {
            mean: 0.0,
            sd: 0.05f64.sqrt(),
            low: -0.8,
            high: 0.8,
        },
        Marginal::TruncatedNormal {
            mean: 0.0,
            sd: 0.05f64.sqrt(),
            low: -0.8,
            high: 0.8,
        },
        Marginal::Uniform {
            low: 1e-10,
            high: 0.1,
        },
    ])?;
    let alphas: Vec<f64> = (0..16).map(|k| 2f64.powf(-5.5 + 0.5 * k as f64)).collect();
    let only: Option<f64> = std::env::args().nth(1).and_then(|a| a.parse().ok());
    let mut evid = Vec::new();
    for &alpha in &alphas {
        if only.is_some_and(|o| (o - alpha).abs() > 1e-9) {
            continue;
        }
        let like = TurningPoleLikelihood::new(model.clone(), params.clone(), poles.clone(), alpha)?;
        let f = |t: &[f64]| like.ln_likelihood(t);
        let t0 = std::time::Instant::now();
        let run = tmcmc(
            &prior,
            &f,
            &TmcmcOptions {
                samples: 5000,
                seed: 1,
                ..Default::default()
            },
            &Silent,
        )?;
        let m = run.samples.mean();
        let c = run.samples.covariance();
        println!(
            "alpha {alpha:.4}: lnZ {:.2} fit {:.2} gain {:.2} mean [{:.4}, {:.4}, {:.4}, {:.2e}] var [{:.1e} {:.1e} {:.1e}] ({:.1} s, {} stages)",
            run.log_evidence,
            run.data_fit(),
            run.information_gain(),
            m[0],
            m[1],
            m[2],
            m[3],
            c[(0, 0)],
            c[(1, 1)],
            c[(2, 2)],
            t0.elapsed().as_secs_f64(),
            run.betas.len() - 1
        );
        evid.push(run.log_evidence);
    }
    println!("class probabilities {:?}", class_probabilities(&evid));
    Ok(())
}
