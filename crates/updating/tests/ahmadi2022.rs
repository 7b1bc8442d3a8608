//! Seed 000 reproduced: Table 2 poles, Table 1 model, Section 6.3 priors, iTMCMC over the 16
//! model classes alpha = 2^-5.5 ... 2^2 (fewer samples per class than the paper's 5000; the
//! `ahmadi2022` example and the bench run 5000).
//!
//! Paper: evidence peaks at alpha = 0.5; posterior mean (0.0067, 0.1385, 0.0549), covariance
//! Eq. 34 (variances 3.5e-7, 4.2e-3, 9.4e-4); the updated model predicts the 7300 rpm behaviour
//! (the nominal model over-estimates the limiting width there by about 30 %).

#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples;
use chatter_progress::Silent;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::frequency_domain::{FrequencyDomain, dominant_pole};
use chatter_updating::classes::{Sampler, SamplerOptions};
use chatter_updating::update::{UpdateJob, UpdateSettings};

#[test]
fn ahmadi_2022_is_reproduced() {
    let model = examples::ahmadi_2022_turning();
    let obs = examples::ahmadi_2022_turning_observations();
    let job = UpdateJob::new(&model, &obs, &UpdateSettings::default()).unwrap();
    let options = SamplerOptions {
        sampler: Sampler::Itmcmc,
        samples: 600,
        seed: 7,
    };
    let result = job.run(&options, &Silent).unwrap();
    let evidence: Vec<f64> = result.classes.iter().map(|c| c.log_evidence).collect();
    let alphas: Vec<f64> = result.classes.iter().filter_map(|c| c.alpha).collect();
    let selected = result.selected_alpha.unwrap();
    let m = &result.posterior_mean;
    let c = &result.posterior_covariance;
    eprintln!("log evidence {evidence:.2?}");
    eprintln!("selected alpha {selected}: mean {m:.4?}");
    eprintln!(
        "variances {:.1e} {:.1e} {:.1e}, covariances {:.1e} {:.1e} {:.1e}",
        c[(0, 0)],
        c[(1, 1)],
        c[(2, 2)],
        c[(0, 1)],
        c[(0, 2)],
        c[(1, 2)]
    );
    // evidence: an interior maximum next to the paper's 0.5 (we get 1.0, 0.5 within a few nats)
    assert!((0.5..=1.0).contains(&selected), "{selected}");
    let best = evidence.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let at_half = evidence[alphas.iter().position(|a| (a - 0.5).abs() < 1e-9).unwrap()];
    assert!(best - at_half < 10.0);
    assert!(evidence[0] < best - 100.0 && evidence[15] < best - 5.0);
    // posterior mean near (0.0067, 0.1385, 0.0549), within about two posterior sd
    let paper_posterior = examples::ahmadi_2022_posterior();
    for (k, paper) in paper_posterior.mean.iter().enumerate() {
        let sd = c[(k, k)].sqrt();
        assert!(
            (m[k] - paper).abs() < 2.5 * sd,
            "{k}: {} vs {paper} (sd {sd})",
            m[k]
        );
    }
    // covariance of the magnitude of Eq. 34, with its signs
    for (k, row) in paper_posterior.covariance.iter().enumerate() {
        let paper = row[k];
        let ratio = c[(k, k)] / paper;
        assert!((0.25..4.0).contains(&ratio), "{k}: {}", c[(k, k)]);
    }
    assert!(c[(0, 1)] < 0.0 && c[(0, 2)] < 0.0 && c[(1, 2)] > 0.0);
    // the updated model predicts the observed poles better than the nominal one
    let miss = |m: &chatter_dynamics::ModalModel| -> f64 {
        obs.poles
            .iter()
            .map(|p| {
                let d = dominant_pole(m, p.speed_rpm, p.depth_mm * 1e-3).unwrap();
                (d.frequency_hz - p.frequency_hz).abs()
            })
            .sum()
    };
    let (before, after) = (miss(&model), miss(&result.updated_model));
    eprintln!("pole frequency misses {before:.1} Hz -> {after:.1} Hz");
    assert!(after < 0.5 * before);
    // 7300 rpm: the nominal limit is about 30 % above the updated one; every tested width
    // (P1-P5) stays stable
    let lim = |m: &chatter_dynamics::ModalModel, s: f64| {
        limiting_depth(&FrequencyDomain, m, s, &BoundaryOptions::default())
            .unwrap()
            .depth_m
    };
    let ratio = lim(&model, 7300.0) / lim(&result.updated_model, 7300.0);
    eprintln!("nominal / updated limiting width at 7300 rpm: {ratio:.3}");
    assert!((1.15..1.45).contains(&ratio), "{ratio}");
    for p in &obs.poles {
        assert!(p.depth_mm * 1e-3 < lim(&result.updated_model, p.speed_rpm));
    }
    // the 7300 rpm cuts (not used in updating): the nominal model calls both stable, the
    // updated one separates the stable from the chattering cut
    for c in obs.cuts.iter().filter(|c| c.speed_rpm == 7300.0) {
        assert!(c.depth_mm * 1e-3 < lim(&model, 7300.0));
        let predicted_stable = c.depth_mm * 1e-3 < lim(&result.updated_model, 7300.0);
        assert_eq!(predicted_stable, c.stable, "{c:?}");
    }
}
