//! The recommendation with a posterior (`chatter_jobs::recommend`) on seed 001's mill (4 teeth,
//! 20 % down milling, 750 Hz, the pocket near 11 300 rpm), with a posterior folder written as
//! `chatter update` writes one: 40 samples of the stiffness and damping of both modes.
//!
//! The recommendation takes, at each speed, the (k+1)-th smallest of the samples' limiting
//! depths (FDM, automatic resolution, Richardson-extrapolated root search), k = floor(P S). It
//! is checked against brute force by another method: at the chosen speed, each sample's model
//! evaluated directly by the semi-discretization (SDM, fixed 200 steps, no search, no
//! extrapolation) at 0.98 and 1.02 times the chosen depth. At most k samples may chatter below
//! and at least k + 1 above: the 2 % margin covers FDM-against-SDM differences (both converge to
//! the same boundary; the conformance tolerance between them is 1 %) and the
//! extrapolation error (0.2 % on the single-DOF benchmark).
#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples;
use chatter_jobs::recommend::{Basis, Evidence, Recommend, RecommendRequest};
use chatter_stability::StabilitySolver;
use chatter_stability::prepared::Method;
use chatter_uncertainty::montecarlo::gaussian_draws;
use chatter_uncertainty::parameters::ParameterDistribution;
use std::fmt::Write as _;
use std::path::Path;

const NAMES: [&str; 4] = ["theta_k_1", "theta_zeta_1", "theta_k_2", "theta_zeta_2"];
const SAMPLES: usize = 40;
const SPEEDS_RPM: [f64; 6] = [10_600.0, 10_900.0, 11_200.0, 11_500.0, 11_800.0, 12_100.0];

/// A posterior folder: `summary.json` (mean 0, sd 5 % on stiffness, 10 % on damping) and
/// `posterior.csv` with `SAMPLES` seeded draws and their weights.
fn posterior_folder(dir: &Path) {
    let sd = [0.05, 0.10, 0.05, 0.10];
    let covariance =
        nalgebra::DMatrix::from_fn(4, 4, |i, j| if i == j { sd[i] * sd[i] } else { 0.0 });
    let draws = gaussian_draws(&[0.0; 4], &covariance, SAMPLES, 7).unwrap();
    let mut csv = NAMES.join(",") + ",weight\n";
    for d in &draws {
        let row: Vec<String> = d.iter().map(|v| format!("{v:e}")).collect();
        writeln!(csv, "{},{:e}", row.join(","), 1.0 / SAMPLES as f64).unwrap();
    }
    std::fs::write(dir.join("posterior.csv"), csv).unwrap();
    let summary = serde_json::json!({
        "parameter_names": NAMES,
        "posterior_mean": vec![0.0; 4],
        "posterior_covariance": (0..4)
            .map(|i| (0..4).map(|j| covariance[(i, j)]).collect::<Vec<_>>())
            .collect::<Vec<_>>(),
    });
    std::fs::write(dir.join("summary.json"), summary.to_string()).unwrap();
}

fn request(risk: f64) -> RecommendRequest {
    RecommendRequest {
        max_depth_mm: 20.0,
        risk: Some(risk),
        speeds_rpm: Some(SPEEDS_RPM.to_vec()),
        samples: Some(SAMPLES),
        ..Default::default()
    }
}

#[test]
fn posterior_cut_holds_its_risk_by_brute_force_and_risk_is_monotone() {
    let model = examples::schmitz_2023_milling();
    let dir = tempfile::tempdir().unwrap();
    posterior_folder(dir.path());
    let evidence = Evidence::posterior(dir.path()).unwrap();
    let risk = 0.1;
    let job = Recommend::new(&model, evidence.clone(), request(risk)).unwrap();
    let outcome = job.run(&chatter_progress::Silent).unwrap();
    let cut = &outcome.cut;
    eprintln!("{outcome:#?}");
    assert_eq!(
        outcome.basis,
        Basis::Posterior {
            samples: SAMPLES,
            failures: 0
        }
    );
    assert_eq!(cut.limited_by, "stability", "{cut:?}");
    assert!((cut.speed_rpm / 11_300.0 - 1.0).abs() < 0.03, "{cut:?}");
    let k = (risk * SAMPLES as f64).floor() as usize;
    let p = outcome.probability_of_stability.unwrap();
    assert!(p >= 1.0 - risk, "{p}");
    assert!(cut.reasons.iter().any(|r| r.contains("posterior samples")));

    // brute force: every sample's model by SDM at fixed 200 steps, just below and above the cut
    let distribution = ParameterDistribution::from_posterior_dir(dir.path()).unwrap();
    let samples = distribution.samples.clone().unwrap();
    let parameterization = distribution.parameterization(&model).unwrap();
    let sdm = Method::Sdm
        .discretization()
        .unwrap()
        .with_steps(std::num::NonZeroUsize::new(200).unwrap());
    let chattering = |depth_mm: f64| {
        samples
            .iter()
            .filter(|theta| {
                let m = parameterization.model(theta).unwrap();
                sdm.dominant_multiplier(&m, cut.speed_rpm, depth_mm * 1e-3)
                    .unwrap()
                    .modulus()
                    >= 1.0
            })
            .count()
    };
    let below = chattering(0.98 * cut.depth_mm);
    let above = chattering(1.02 * cut.depth_mm);
    eprintln!(
        "k = {k}: {below} of {SAMPLES} chatter at 0.98 b, {above} at 1.02 b (b = {:.4} mm)",
        cut.depth_mm
    );
    assert!(below <= k, "{below} > {k}");
    assert!(above > k, "{above} <= {k}");

    // risk monotonicity: a smaller risk gives a shallower or equal stable depth at every speed
    // and a material removal rate no higher
    let mut previous: Option<(Vec<f64>, f64)> = None;
    for risk in [0.4, 0.2, 0.1, 0.05, 0.01] {
        let o = Recommend::new(&model, evidence.clone(), request(risk))
            .unwrap()
            .run(&chatter_progress::Silent)
            .unwrap();
        let depths: Vec<f64> = o.stable_depths.iter().map(|d| d.stable_depth_m).collect();
        let score = o.cut.depth_mm * o.cut.speed_rpm;
        if let Some((d0, s0)) = &previous {
            assert!(depths.iter().zip(d0).all(|(a, b)| a <= b), "risk {risk}");
            assert!(score <= *s0, "risk {risk}");
        }
        assert!(o.probability_of_stability.unwrap() >= 1.0 - risk);
        previous = Some((depths, score));
    }
}

#[test]
fn bad_requests_name_the_field() {
    let model = examples::schmitz_2023_milling();
    let dir = tempfile::tempdir().unwrap();
    posterior_folder(dir.path());
    let evidence = Evidence::posterior(dir.path()).unwrap();
    for risk in [0.0, 1.0, -0.1, f64::NAN] {
        let e = Recommend::new(&model, evidence.clone(), request(risk))
            .err()
            .unwrap()
            .to_string();
        assert!(e.starts_with("risk "), "{e}");
        assert!(e.contains("(0, 1)"), "{e}");
    }
    // the nominal derating keeps its (0, 0.5]
    let e = Recommend::new(
        &model,
        Evidence::Nominal,
        RecommendRequest {
            samples: None,
            ..request(0.7)
        },
    )
    .err()
    .unwrap()
    .to_string();
    assert!(e.contains("(0, 0.5]"), "{e}");
    // options the evidence does not use
    let e = Recommend::new(
        &model,
        evidence.clone(),
        RecommendRequest {
            limit_sd_percent: Some(10.0),
            ..request(0.1)
        },
    )
    .err()
    .unwrap()
    .to_string();
    assert!(
        e.contains("limit_sd_percent is not used with a posterior"),
        "{e}"
    );
    // a folder without posterior.csv
    std::fs::remove_file(dir.path().join("posterior.csv")).unwrap();
    let e = Evidence::posterior(dir.path()).err().unwrap().to_string();
    assert!(
        e.contains("posterior.csv") && e.contains("not found"),
        "{e}"
    );
}
