//! The monodromy eigen-solver where the Floquet multipliers cluster near one modulus (issue 14):
//! turning and milling with process damping at long delays, where the restart of Arnoldi from
//! one Ritz vector stalled and the gap proving ground's truth failed. Krylov–Schur must find the
//! dominant multiplier, checked against computations that do not use it. The characteristic-root
//! search of `frequency_domain` is checked on the same lathe, where its continuation fails.

#![allow(clippy::unwrap_used)]

use chatter_dynamics::{ModalModel, examples};
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::frequency_domain::FrequencyDomain;
use chatter_stability::monodromy::{Discretization, steps};

/// det D(lambda) of the characteristic equation on the real axis, 2 x 2 in modal coordinates:
/// D = lambda^2 I + 2 Z Omega lambda + Omega^2 + b W (1 - e^{-lambda tau}) + lambda b P with
/// W = Phi^T H Phi and P = Phi^T D Phi (the model's constant turning matrices; 000 Eq. 5,
/// 003 Eq. 1).
fn characteristic_determinant(model: &ModalModel, speed_rpm: f64, b: f64, lambda: f64) -> f64 {
    let phi = model.shape_matrix();
    let w = phi.transpose() * model.directional_matrix(0.0, speed_rpm) * &phi;
    let p = phi.transpose() * model.process_damping_matrix(0.0, speed_rpm) * &phi;
    let tau = model.operation().delay_s(speed_rpm);
    let (omegas, zetas) = (model.omegas_rad_s(), model.damping_ratios());
    let d = |i: usize, j: usize| {
        let diagonal = if i == j {
            lambda * lambda + 2.0 * zetas[i] * omegas[i] * lambda + omegas[i] * omegas[i]
        } else {
            0.0
        };
        diagonal + b * w[(i, j)] * (1.0 - (-lambda * tau).exp()) + lambda * b * p[(i, j)]
    };
    d(0, 0) * d(1, 1) - d(0, 1) * d(1, 0)
}

/// The conditions where the gap truth (semi-discretization at 3364 steps per delay, operator
/// dimension 6732) stopped with "40 restarts of a 20-dimensional Krylov space" before
/// Krylov–Schur: the proving ground's lathe with the process damping of its 1x
/// (C = 8.78e5 N/m) and 2x (1.76e6 N/m) effects at 1200 rpm. The dominant multiplier there is
/// real, the quasi-static regeneration (|mu| near b k_c / (k + b k_c)), at the head of a ring of
/// multipliers e^{lambda_j tau} from the chain of roots spaced 2 pi / tau apart, within 2e-4 of
/// one modulus. Reference: the largest real root of det D(lambda) = 0 by bisection on the real
/// axis (no discretization, no Krylov iteration), mu = e^{lambda tau}, to 1e-6 (the
/// semi-discretization's error at this resolution, 1e-8 against the full discretization at the
/// same steps). That this real multiplier is the dominant one is checked on the dense operator
/// of a coarser grid (420 steps, dimension 844) by faer's eigenvalues, to 1e-6.
#[test]
fn lathe_with_process_damping_at_low_speed() {
    let speed = 1200.0;
    for (c, depth_m) in [
        (8.779_455e5, 0.05),
        (1.755_891e6, 0.015),
        (1.755_891e6, 0.02),
    ] {
        let model = examples::proving_ground_lathe(Some(c));
        let tau = model.operation().delay_s(speed);
        // bisection for the largest real root: det D > 0 at lambda = 0 (static stiffness) and
        // changes sign at the quasi-static root
        let f = |l: f64| characteristic_determinant(&model, speed, depth_m, l);
        let mut hi = 0.0;
        let mut lo = -0.5 / tau;
        while f(lo) > 0.0 {
            hi = lo;
            lo *= 2.0;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if f(mid) > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let expected = (0.5 * (lo + hi) * tau).exp();
        let op = Discretization::semi()
            .with_steps(steps::<3364>())
            .monodromy(&model, speed, depth_m)
            .unwrap();
        assert_eq!(op.dimension(), 6732);
        let mu = op.dominant_eigenvalue().unwrap();
        assert!(
            (mu - expected).norm() < 1e-6,
            "C {c:e}, b {depth_m}: {mu} vs {expected}"
        );
        // the characteristic-root search finds the same real root (it started only on the
        // imaginary axis before and reported |mu| 0.65 for 0.75)
        let root = FrequencyDomain
            .dominant_multiplier(&model, speed, depth_m)
            .unwrap();
        assert!(
            (root.modulus() - expected).abs() < 1e-6,
            "C {c:e}, b {depth_m}: characteristic root {} vs {expected}",
            root.modulus()
        );
        if depth_m == 0.015 {
            let coarse = Discretization::semi()
                .with_steps(steps::<420>())
                .monodromy(&model, speed, depth_m)
                .unwrap()
                .dense();
            let d = coarse.nrows();
            let top = faer::Mat::<f64>::from_fn(d, d, |i, j| coarse[(i, j)])
                .eigenvalues()
                .unwrap()
                .iter()
                .map(|z| z.norm())
                .fold(0.0, f64::max);
            assert!((top - expected).abs() < 1e-6, "dense {top} vs {expected}");
        }
    }
}

/// The 003-type flexure at 300 rpm (C = 2.5e5 N/m, one tooth, 45 vibration cycles per delay):
/// FDM at its automatic resolution has a 276-dimensional operator whose multipliers cluster
/// (1-40 ms per eigenvalue with the old restart). The dominant multiplier must be the largest
/// modulus of all eigenvalues of the dense operator (faer's dense solver, to 1e-8 relative: the
/// operator is far from normal) at depths around the limit (2.94 mm).
#[test]
fn flexure_at_300_rpm_matches_dense_eigenvalues() {
    let model = examples::process_damping_flexure(Some(2.5e5));
    let speed = 300.0;
    let fdm = Discretization::full();
    for depth_m in [1e-3, 2.9e-3, 3.5e-3] {
        let op = fdm.monodromy(&model, speed, depth_m).unwrap();
        let mu = op.dominant_eigenvalue().unwrap();
        let dense = op.dense();
        let d = dense.nrows();
        let values = faer::Mat::<f64>::from_fn(d, d, |i, j| dense[(i, j)])
            .eigenvalues()
            .unwrap();
        let top = values.iter().map(|z| z.norm()).fold(0.0, f64::max);
        assert!(
            (mu.norm() - top).abs() < 1e-8 * top,
            "b {depth_m} (dimension {d}): {} vs {top}",
            mu.norm()
        );
    }
}

/// Two modes (640 Hz along the feed, 700 Hz / 0.035 at 30 degrees) at 2300 rpm: the
/// continuation from the damped 700 Hz pole fails (e^{-lambda tau} ~ 55 at its real part,
/// Newton wanders), which used to fail the whole call. The grid starts still find the
/// dominant root; |mu| = |e^{lambda tau}| agrees with FDM at 4000 steps within 2e-3 (its
/// first-order error, measured 3e-4 against SDM at 4x resolution) at 0.5x, 1x and 2x the
/// limiting depth.
#[test]
fn dominant_root_survives_a_failed_continuation() {
    let model = examples::proving_ground_lathe(None);
    let speed = 2300.0;
    let fdm = Discretization::full().with_steps(steps::<4000>());
    let limit = limiting_depth(&fdm, &model, speed, &BoundaryOptions::default())
        .unwrap()
        .depth_m;
    for ratio in [0.5, 1.0, 2.0] {
        let exact = FrequencyDomain
            .dominant_multiplier(&model, speed, ratio * limit)
            .unwrap()
            .modulus();
        let reference = fdm
            .dominant_multiplier(&model, speed, ratio * limit)
            .unwrap()
            .modulus();
        assert!(
            (exact - reference).abs() < 2e-3,
            "x{ratio}: {exact} vs {reference}"
        );
    }
}
