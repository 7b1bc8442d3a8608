//! Seed 003: random-walk path updating of the process-damping coefficient C and value-of-
//! information test selection, on cut results generated from a known C.
//!
//! The machine is the 003-like flexure of `chatter_dynamics::examples::process_damping_flexure`
//! (228 Hz, single-tooth 18.54 mm cutter, 50 % up milling; the flexure's stiffness and damping
//! are not given in the text and are chosen there), kt, kn and the
//! priors of 003 (kt ~ N(2111.2, 78.3), kn ~ N(1052.6, 27.9) N/mm^2, C ~ U(0.5e5, 10e5) N/m,
//! sigma = 0.5 mm, depths up to 7.5 mm). The cut results come from the true C = 2.5e5 N/m with the
//! iterative process-damping algorithm of `chatter-stability` (not the path solver).

#![allow(clippy::unwrap_used)]

use chatter_bayes::prior::{IndependentPrior, Marginal};
use chatter_dynamics::{Cut, ModalModel, examples};
use chatter_stability::process_damping::process_damping_limiting_depth;
use chatter_updating::boundary::BoundaryOptions;
use chatter_updating::cuts::CutKernel;
use chatter_updating::ensemble::{BoundaryEnsemble, Silent};
use chatter_updating::parameters::{Parameterization, parse_model_parameters};
use std::collections::BTreeMap;

const TRUE_C: f64 = 2.5e5;

fn flexure() -> ModalModel {
    examples::process_damping_flexure(Some(TRUE_C))
}

/// The machine: stable below the true process-damped limit (cached per speed).
struct Machine {
    model: ModalModel,
    limits: BTreeMap<u64, f64>,
}

impl Machine {
    fn cut(&mut self, speed_rpm: f64, depth_mm: f64) -> Cut {
        let model = &self.model;
        let limit = *self.limits.entry(speed_rpm.to_bits()).or_insert_with(|| {
            process_damping_limiting_depth(model, speed_rpm)
                .unwrap()
                .depth_m
        });
        Cut {
            speed_rpm,
            depth_mm,
            stable: depth_mm * 1e-3 < limit,
            chatter_hz: None,
            sequence: None,
            radial_immersion: None,
            note: None,
            evidence: None,
        }
    }
}

fn prior_paths(speeds: &[f64]) -> BoundaryEnsemble {
    let p = Parameterization::new(
        flexure(),
        parse_model_parameters("kt_n_per_mm2,kn_n_per_mm2,c_n_per_m").unwrap(),
    )
    .unwrap();
    let prior = IndependentPrior::new(vec![
        Marginal::Normal {
            mean: 2111.2,
            sd: 78.3,
        },
        Marginal::Normal {
            mean: 1052.6,
            sd: 27.9,
        },
        Marginal::Uniform {
            low: 0.5e5,
            high: 10e5,
        },
    ])
    .unwrap();
    let options = BoundaryOptions {
        max_depth_m: 7.5e-3,
        ..Default::default()
    };
    BoundaryEnsemble::from_prior(p, &prior, 300, speeds, options, 11, &Silent).unwrap()
}

#[test]
fn paths_recover_c_and_value_of_information_needs_few_cuts() {
    let speeds: Vec<f64> = (0..13).map(|i| 300.0 + 100.0 * i as f64).collect();
    let depths: Vec<f64> = (1..=50).map(|i| i as f64 * 0.15e-3).collect();
    let kernel = CutKernel::karandikar();
    let c = 2;
    let mut machine = Machine {
        model: flexure(),
        limits: BTreeMap::new(),
    };
    let prior = prior_paths(&speeds);
    let (mean0, sd0) = prior.moments(c).unwrap();

    // a 6 x 8 grid of cuts, as a test plan without value of information
    let mut grid = prior.clone();
    for speed in [300.0, 500.0, 700.0, 900.0, 1100.0, 1300.0] {
        for k in 1..=8 {
            let cut = machine.cut(speed, 0.5 * k as f64);
            grid.update(&cut, &kernel).unwrap();
        }
    }
    let (grid_mean, grid_sd) = grid.moments(c).unwrap();

    // value of information: the best expected reduction of sigma_C, until it is below 2 %
    let mut voi = prior;
    let mut history = Vec::new();
    for _ in 0..20 {
        let plan = voi
            .value_of_information(&depths, c, &kernel)
            .unwrap()
            .unwrap();
        if plan.expected_reduction_percent.unwrap() < 2.0 {
            break;
        }
        let cut = machine.cut(plan.speed_rpm, plan.depth_mm);
        voi.update(&cut, &kernel).unwrap();
        history.push((plan, voi.moments(c).unwrap()));
    }
    let (voi_mean, voi_sd) = voi.moments(c).unwrap();
    let to_grid_sd = history
        .iter()
        .position(|(_, (_, sd))| *sd <= grid_sd)
        .map(|k| k + 1);
    eprintln!("prior C {mean0:.3e} +- {sd0:.3e}");
    eprintln!("grid (48 cuts): C {grid_mean:.3e} +- {grid_sd:.3e}");
    for (plan, (m, s)) in &history {
        eprintln!(
            "  {:.0} rpm {:.2} mm P_s {:.2} E[red] {:.1} % -> C {m:.3e} +- {s:.3e}",
            plan.speed_rpm,
            plan.depth_mm,
            plan.p_stable,
            plan.expected_reduction_percent.unwrap()
        );
    }
    eprintln!(
        "VOI ({} cuts): C {voi_mean:.3e} +- {voi_sd:.3e}; grid sd reached after {to_grid_sd:?}",
        history.len()
    );
    // both recover the true C
    for (m, s) in [(grid_mean, grid_sd), (voi_mean, voi_sd)] {
        assert!((m - TRUE_C).abs() < 0.15 * TRUE_C + 2.0 * s, "{m} +- {s}");
        assert!(s < 0.4 * sd0);
    }
    // value of information reaches the grid's certainty with far fewer cuts
    let n = to_grid_sd.unwrap_or(usize::MAX);
    assert!(n <= 16, "{n} cuts vs 48");
}
