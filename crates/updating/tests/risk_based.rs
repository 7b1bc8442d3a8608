//! Seed 004: risk-based test selection. On a synthetic machine with known parameters, tests are
//! chosen at the maximum material removal rate on the P_s = 50 % contour of the current sampled
//! boundaries; after each result (stable, or chatter with its frequency) the samples are drawn
//! anew from the posterior of 004 Eq. 5-7 (s_S = 0.125 mm, s_fc = 50 Hz) by rejection sampling
//! and parallel adaptive MCMC (004 Section 5), and testing stops when the next test would improve
//! the best stable MRR by less than 10 %. The true boundary comes from semi-discretization at 150
//! cutting steps per tooth period (converged to better than 0.1 % on such a mill, see
//! `chatter-stability`'s conformance test); the paths use the library's default, full
//! discretization at its automatic resolution (zero-order paths overestimate the lobe peak at
//! 17 500 rpm and need more than 8 tests).

#![allow(clippy::unwrap_used)]

use chatter_bayes::prior::Marginal;
use chatter_dynamics::{
    Cut, CuttingCoefficients, Milling, MillingDirection, ModalModel, Mode, ModeShape, Operation,
};
use chatter_progress::Silent;
use chatter_stability::boundary::BoundaryOptions as SearchOptions;
use chatter_stability::monodromy::{Discretization, steps};
use chatter_stability::prepared::SolverOptions;
use chatter_stability::prepared::{PreparedDiscretization, PreparedSolver};
use chatter_updating::cuts::CutKernel;
use chatter_updating::ensemble::{BoundaryEnsemble, material_removal_rate_cm3_per_min};
use chatter_updating::joint_prior::SampledPrior;
use chatter_updating::parameters::{Parameterization, parse_model_parameters};

/// A 3-flute 12.7 mm endmill at 75 % radial immersion (004), two tool modes.
fn machine() -> ModalModel {
    let mode = |coordinate| {
        Mode::new(
            900.0,
            0.03,
            ModeShape::Directional {
                coordinate,
                stiffness_n_per_m: 8e6,
            },
        )
        .unwrap()
    };
    let op = Operation::Milling(
        Milling::new(3, 0.75, MillingDirection::Down, Some(12.7e-3), None).unwrap(),
    );
    ModalModel::new(
        Some("synthetic 004 machine".into()),
        op,
        CuttingCoefficients::new(700e6, 210e6).unwrap(),
        vec![mode(0), mode(1)],
        None,
    )
    .unwrap()
}

/// Sampled boundaries per round.
const PATHS: usize = 100;

#[test]
fn risk_based_selection_reaches_the_best_stable_mrr() {
    let names = "kt_n_per_mm2,kn_n_per_mm2,theta_omega_1,theta_omega_2";
    let p = Parameterization::new(machine(), parse_model_parameters(names).unwrap()).unwrap();
    let truth_theta = [820.0, 180.0, 0.04, -0.03];
    let truth = p.model(&truth_theta).unwrap();
    let speeds: Vec<f64> = (0..17).map(|i| 8000.0 + 1000.0 * i as f64).collect();
    let depths: Vec<f64> = (1..=80).map(|i| i as f64 * 0.1e-3).collect();
    let true_lobes = PreparedDiscretization::new(
        Discretization::semi().with_steps(steps::<150>()),
        &truth,
        &SearchOptions::default(),
    )
    .unwrap()
    .lobes(&speeds, &chatter_progress::Silent)
    .unwrap();
    let feed = 0.1e-3;
    let mrr = |s: f64, d: f64| material_removal_rate_cm3_per_min(&truth, s, d, feed).unwrap();
    // the best stable MRR on the test grid
    let best_possible = true_lobes
        .iter()
        .filter_map(|l| {
            depths
                .iter()
                .filter(|&&d| d < l.depth_m)
                .map(|&d| mrr(l.speed_rpm, d))
                .reduce(f64::max)
        })
        .fold(0.0, f64::max);

    let prior = SampledPrior::new(
        p.clone(),
        vec![
            Marginal::Normal {
                mean: 700.0,
                sd: 70.0,
            },
            Marginal::Normal {
                mean: 210.0,
                sd: 21.0,
            },
            Marginal::Uniform {
                low: -0.05,
                high: 0.05,
            },
            Marginal::Uniform {
                low: -0.05,
                high: 0.05,
            },
        ],
        &Default::default(),
        None,
    )
    .unwrap();
    let options = SolverOptions::default().with_max_depth_m(10e-3);
    let mut samples =
        BoundaryEnsemble::from_prior(p.clone(), &prior, PATHS, &speeds, options, 5, &Silent)
            .unwrap();
    let mut cuts = Vec::new();
    let kernel = CutKernel::schmitz();
    let mut best_stable: f64 = 0.0;
    let mut tests = 0;
    for _ in 0..10 {
        let plan = samples
            .risk_based_test(&depths, 0.5, feed)
            .unwrap()
            .unwrap();
        let plan_mrr = plan.mrr_cm3_per_min.unwrap();
        if best_stable > 0.0 && plan_mrr < 1.1 * best_stable {
            break;
        }
        let limit = true_lobes
            .iter()
            .find(|l| l.speed_rpm == plan.speed_rpm)
            .unwrap();
        let stable = plan.depth_mm * 1e-3 < limit.depth_m;
        let cut = Cut {
            speed_rpm: plan.speed_rpm,
            depth_mm: plan.depth_mm,
            stable,
            chatter_hz: (!stable).then_some(limit.chatter_hz),
            sequence: None,
            radial_immersion: None,
            note: None,
            evidence: None,
        };
        cuts.push(cut);
        // 004 Section 5: the next boundaries come from the posterior given every cut so far
        samples = BoundaryEnsemble::from_posterior(
            p.clone(),
            &prior,
            &cuts,
            &kernel,
            PATHS,
            &speeds,
            options,
            5,
            &Silent,
        )
        .unwrap();
        tests += 1;
        if stable {
            best_stable = best_stable.max(plan_mrr);
        }
        eprintln!(
            "test {tests}: {:.0} rpm {:.1} mm P_s {:.2} MRR {plan_mrr:.1} cm3/min {} (ESS {:.0})",
            plan.speed_rpm,
            plan.depth_mm,
            plan.p_stable,
            if stable { "stable" } else { "chatter" },
            samples.effective_sample_size()
        );
    }
    eprintln!("best stable MRR {best_stable:.1} of {best_possible:.1} cm3/min after {tests} tests");
    assert!(
        best_stable >= 0.9 * best_possible,
        "{best_stable} vs {best_possible}"
    );
    assert!(tests <= 8, "{tests} tests");
}
