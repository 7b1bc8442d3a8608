//! The small eigenproblem never aborts (issue 14): the dominant multiplier of full and
//! semi-discretization on random 1-4 mode milling and turning cases (see
//! `common/random_models.rs` for the ranges) with zero failures. The test runs the first
//! [`CASES`] cases of the seeded sequence; the ignored `ten_thousand_random_cases_never_fail`
//! (`cargo test -p chatter-stability --test eigen_robustness -- --ignored`) and `cargo run
//! --profile test -p chatter-stability --example eigen_robustness -- 10000` run the issue's
//! 10 000.

#![allow(clippy::unwrap_used)]

mod common;

use common::random_models::{case, check};
use rayon::prelude::*;

/// Cases in the test (the example runs 10 000 of the same sequence).
const CASES: u64 = 1000;
/// Seed of the sequence, shared with the example.
const SEED: u64 = 14;

/// Run the first `cases` cases; a panic listing every failure.
fn assert_no_failure(cases: u64) {
    let failures: Vec<String> = (0..cases)
        .into_par_iter()
        .filter_map(|i| check(i, &case(SEED, i)).err())
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {cases} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn random_cases_never_fail() {
    assert_no_failure(CASES);
}

/// The issue's property test: 10 000 random 1-4 mode milling and turning models, zero
/// eigen-solver failures (ignored by default: several minutes on 2 cores).
#[test]
#[ignore = "10 000 cases: several minutes on 2 cores"]
fn ten_thousand_random_cases_never_fail() {
    assert_no_failure(10_000);
}

/// Issue 14's machine (3 teeth, 75 % down milling, x/y modes at 918.8 and 889.3 Hz): the lobes
/// at 23 500 and 23 501 rpm stopped with "Hessenberg QR did not converge: 8 x 8 Arnoldi matrix"
/// at zero depth. Both schemes now give the limiting depth, 1.0158 mm by FDM (the value the CLI
/// printed after the fix; FDM and SDM agree within 0.2 %, their first-order discretization
/// difference at the automatic resolution).
#[test]
fn issue_14_lobes_run() {
    use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
    use chatter_stability::monodromy::Discretization;
    let model = chatter_dynamics::examples::issue_14_mill();
    let options = BoundaryOptions::default();
    for speed in [23_500.0, 23_501.0] {
        let fdm = limiting_depth(&Discretization::full(), &model, speed, &options).unwrap();
        let sdm = limiting_depth(&Discretization::semi(), &model, speed, &options).unwrap();
        assert!(
            (fdm.depth_mm() - 1.0158).abs() < 1e-3,
            "{speed} rpm: {}",
            fdm.depth_mm()
        );
        assert!((sdm.depth_mm() - fdm.depth_mm()).abs() < 2e-3 * fdm.depth_mm());
    }
}

/// The issue's lobes through the prepared solvers that `chatter lobes` runs: FDM and SDM over
/// the default lobe speeds of the mill plus the issue's 23 500 and 23 501 rpm, every speed a
/// finite positive limit (no abort, no speed read as unbounded below the 100 mm ceiling).
#[test]
fn issue_14_prepared_lobes_run() {
    use chatter_stability::boundary::BoundaryOptions;
    use chatter_stability::prepared::Method;
    use chatter_stability::speed_grid::lobe_speeds_rpm;
    let model = chatter_dynamics::examples::issue_14_mill();
    let mut speeds = lobe_speeds_rpm(&model);
    speeds.extend([23_500.0, 23_501.0]);
    for method in [Method::Fdm, Method::Sdm] {
        let solver = method.prepare(&model, &BoundaryOptions::default()).unwrap();
        let lobes = solver.lobes(&speeds, &chatter_progress::Silent).unwrap();
        for p in &lobes {
            assert!(
                p.depth_m.is_finite() && p.depth_m > 0.0,
                "{method:?} {} rpm: {p:?}",
                p.speed_rpm
            );
        }
        let issue: Vec<f64> = lobes[lobes.len() - 2..]
            .iter()
            .map(|p| p.depth_mm())
            .collect();
        eprintln!(
            "{method:?}: {} speeds, issue's speeds {issue:?} mm",
            lobes.len()
        );
    }
}
