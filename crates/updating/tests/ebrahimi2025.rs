//! Seed 002, numerical simulation (Section 3.1): poles "identified" at the Table 1 cutting
//! conditions of a simulated SDOF milling system (194 Hz, zeta 0.005, 2.35 N/um, Kt 650 and
//! Kn 110 MPa, two-flute slotting) are computed here from the model itself, with the Table 1
//! standard deviations as scatter; the exact-monodromy likelihood with uniform priors then brings
//! the parameter variations back to zero, as in the paper (Fig. 7).

#![allow(clippy::unwrap_used)]

use chatter_bayes::prior::{IndependentPrior, Marginal};
use chatter_dynamics::{ModalModel, PoleObservation};
use chatter_progress::Silent;
use chatter_stability::monodromy::Discretization;
use chatter_updating::classes::{Sampler, SamplerOptions, sample_posterior};
use chatter_updating::milling::MillingPoleLikelihood;
use chatter_updating::parameters::{Parameterization, parse_model_parameters};

fn simulated_setup() -> ModalModel {
    chatter_updating::ebrahimi2025::simulated_model(
        chatter_updating::ebrahimi2025::STATED_FREQUENCY_HZ,
    )
    .unwrap()
}

#[test]
fn simulated_poles_bring_the_parameters_back_to_nominal() {
    let model = simulated_setup();
    let p = Parameterization::new(
        model,
        parse_model_parameters("theta_omega_1,theta_zeta_1,theta_k_1").unwrap(),
    )
    .unwrap();
    // Table 1 conditions and standard deviations (frequency Hz, damping)
    let table = [
        (2000.0, 0.4, 0.0182, 0.0143),
        (2000.0, 0.6, 0.0362, 0.0133),
        (2000.0, 0.8, 0.0889, 0.0047),
        (2100.0, 0.3, 0.0102, 0.0063),
        (2100.0, 0.4, 0.0041, 0.0037),
    ];
    let solver = Discretization::full();
    let mut poles: Vec<PoleObservation> = table
        .iter()
        .map(|&(speed_rpm, depth_mm, sf, sz)| PoleObservation {
            speed_rpm,
            depth_mm,
            frequency_hz: 0.0,
            damping_ratio: 0.0,
            frequency_std_hz: Some(sf),
            damping_std: Some(sz),
            repetitions: Some(10),
            sequence: None,
            radial_immersion: None,
            note: None,
        })
        .collect();
    let exact = MillingPoleLikelihood::new(p.clone(), &poles, 0.1, solver).unwrap();
    for (pole, (f, z)) in poles
        .iter_mut()
        .zip(exact.predicted_poles(&[0.0, 0.0, 0.0]).unwrap())
    {
        pole.frequency_hz = f;
        pole.damping_ratio = z;
    }
    let like = MillingPoleLikelihood::new(p, &poles, 0.1, solver).unwrap();
    let prior = IndependentPrior::new(vec![
        Marginal::Uniform {
            low: -0.3,
            high: 0.3,
        },
        Marginal::Uniform {
            low: -0.3,
            high: 0.3,
        },
        Marginal::Uniform {
            low: -0.3,
            high: 0.3,
        },
        Marginal::Uniform {
            low: 1e-10,
            high: 1.0,
        },
    ])
    .unwrap();
    let options = SamplerOptions {
        sampler: Sampler::Tmcmc,
        samples: 150,
        seed: 2,
    };
    let post = sample_posterior(&prior, &like, &options, &Silent).unwrap();
    let m = post.samples.mean();
    let c = post.samples.covariance();
    eprintln!(
        "posterior mean {:.4?}, sd {:.1e} {:.1e} {:.1e}",
        &m[..3],
        c[(0, 0)].sqrt(),
        c[(1, 1)].sqrt(),
        c[(2, 2)].sqrt()
    );
    // zero within the posterior spread; the frequency is pinned hardest (002 Fig. 7)
    for k in 0..3 {
        assert!(m[k].abs() < 2.5 * c[(k, k)].sqrt() + 1e-4, "{k}: {}", m[k]);
    }
    assert!(m[0].abs() < 0.002 && m[1].abs() < 0.1 && m[2].abs() < 0.06);
    assert!(c[(0, 0)] < 0.01 * c[(1, 1)].min(c[(2, 2)]));
}

/// Seed 002, experimental case (Section 3.2): the hammer-test model (195.3 Hz, zeta 0.004,
/// 2.34 N/um) updated from the Table 2 poles with the paper's uniform priors (theta_omega and
/// theta_k on +-0.1, theta_zeta on +-0.5, sigma_w^2 on (0, 1]) and the exact monodromy likelihood.
///
/// The paper selects alpha = 0.006 and reports the mean (3.6e-3, 0.35, 0.003); we select
/// alpha = 0.1 with mean about (0.016, 0.49, -0.099), theta_zeta and theta_k near their prior
/// bounds. The difference lies in the data rather than the sampler: the Table 2 damping ratios of
/// P1-P3 (0.088, 0.0722, 0.0501) and four of its standard deviations repeat Table 1 (the
/// simulation) digit for digit, and the paper's own posterior mean predicts P1-P3 at 13.3-13.6 Hz
/// where the table has 10.6-11.5 Hz (in the simulated case, too, Table 1 sits a constant 1.2 Hz
/// below the monodromy poles of the stated model while its damping ratios agree). What the update
/// must do regardless is asserted: it pulls the predicted poles onto the identified frequencies
/// and turns the model's verdict on the seven stable cuts from mostly unstable to stable.
#[test]
fn experimental_update_fits_the_identified_poles_and_the_stable_cuts() {
    use chatter_dynamics::examples;
    use chatter_stability::StabilitySolver;
    use chatter_updating::update::{UpdateJob, UpdateSettings};

    let model = examples::ebrahimi_2025_milling();
    let obs = examples::ebrahimi_2025_milling_observations();
    let settings = UpdateSettings {
        classes: Some(vec![0.01, 0.1, 1.0]),
        ..Default::default()
    };
    let job = UpdateJob::new(&model, &obs, &settings).unwrap();
    assert_eq!(
        job.parameter_names(),
        ["theta_omega_1", "theta_zeta_1", "theta_k_1", "sigma_w2_hz2"]
    );
    let options = SamplerOptions {
        sampler: Sampler::Tmcmc,
        samples: 200,
        seed: 3,
    };
    let result = job.run(&options, &Silent).unwrap();
    let evidence: Vec<f64> = result.classes.iter().map(|c| c.log_evidence).collect();
    let m = &result.posterior_mean;
    eprintln!(
        "log evidence {evidence:.1?}, alpha {:?}, mean {m:.4?}",
        result.selected_alpha
    );
    // an interior evidence maximum
    assert_eq!(result.selected_alpha, Some(0.1));
    assert!(evidence[1] > evidence[0] + 50.0 && evidence[1] > evidence[2] + 50.0);
    // the natural frequency rose (the paper's theta_omega is positive too)
    assert!(m[0] > 0.005 && m[0] < 0.03, "{}", m[0]);

    let p = Parameterization::new(
        model.clone(),
        parse_model_parameters("theta_omega_1,theta_zeta_1,theta_k_1").unwrap(),
    )
    .unwrap();
    let like = MillingPoleLikelihood::new(p, &obs.poles, 0.1, Discretization::full()).unwrap();
    let rms = |theta: &[f64]| {
        let predicted = like.predicted_poles(theta).unwrap();
        let sum: f64 = predicted
            .iter()
            .zip(&obs.poles)
            .map(|((f, _), o)| (f - o.frequency_hz).powi(2))
            .sum();
        (sum / predicted.len() as f64).sqrt()
    };
    let (before, after) = (rms(&[0.0, 0.0, 0.0]), rms(&m[..3]));
    eprintln!("rms frequency error: hammer model {before:.2} Hz, updated {after:.2} Hz");
    assert!(before > 2.0 && after < 0.2 * before);

    // the seven cuts P1-P7 were all stable
    let stable_count = |model: &ModalModel| {
        obs.cuts
            .iter()
            .filter(|c| {
                let mu = Discretization::full()
                    .dominant_multiplier(model, c.speed_rpm, c.depth_mm * 1e-3)
                    .unwrap();
                mu.modulus() < 1.0
            })
            .count()
    };
    assert!(obs.cuts.iter().all(|c| c.stable) && obs.cuts.len() == 7);
    let (nominal, updated) = (stable_count(&model), stable_count(&result.updated_model));
    eprintln!("stable cuts predicted stable: hammer model {nominal}/7, updated {updated}/7");
    assert!(nominal <= 2 && updated >= 6);
}

/// Seed 002, Section 2.2 (issue 18): the GP surrogate the CLI uses by default (200 training
/// points, refined per class) stands in for the exact-monodromy likelihood. On the experimental
/// case, class alpha = 0.1 (the one selected), the surrogate's posterior mean lies within one
/// exact-posterior standard deviation of the exact-likelihood posterior mean in every parameter
/// (the tolerance). Reduced to 300 TMCMC samples per run; the full-size comparison is
/// `cargo run --release -p chatter-updating --example ebrahimi2025_surrogate`.
#[test]
fn surrogate_posterior_mean_is_within_one_exact_sd() {
    use chatter_dynamics::examples;
    use chatter_updating::surrogate::DEFAULT_TRAINING_POINTS;
    use chatter_updating::update::{UpdateJob, UpdateSettings};

    let model = examples::ebrahimi_2025_milling();
    let obs = examples::ebrahimi_2025_milling_observations();
    let options = SamplerOptions {
        sampler: Sampler::Tmcmc,
        samples: 300,
        seed: 1,
    };
    let run = |surrogate: Option<usize>| {
        let settings = UpdateSettings {
            classes: Some(vec![0.1]),
            surrogate_training_points: surrogate,
            ..Default::default()
        };
        UpdateJob::new(&model, &obs, &settings)
            .unwrap()
            .run(&options, &Silent)
            .unwrap()
    };
    let (gp, exact) = (run(Some(DEFAULT_TRAINING_POINTS)), run(None));
    let report = gp.surrogate.unwrap();
    eprintln!("surrogate {report:?}");
    for (k, name) in exact.parameter_names.iter().enumerate() {
        let sd = exact.posterior_covariance[(k, k)].sqrt();
        let shift = (gp.posterior_mean[k] - exact.posterior_mean[k]) / sd;
        eprintln!(
            "{name}: surrogate {:.5}, exact {:.5} +- {sd:.5}: shift {shift:+.2} sd",
            gp.posterior_mean[k], exact.posterior_mean[k]
        );
        assert!(shift.abs() <= 1.0, "{name}: {shift} exact sd");
    }
}
