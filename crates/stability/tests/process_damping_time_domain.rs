//! Process damping in the discretized solvers against an independent time-domain integration
//! (issue 14), on the 003-like flexure (`examples::process_damping_flexure`: 228 Hz mode in x,
//! zeta 0.02, k 5.6e6 N/m, one tooth of an 18.54 mm cutter in 50 % up milling,
//! kt 2111.2 and kn 1052.6 N/mm^2) with C = 2.5e5 N/m.
//!
//! The reference is written here from the equations, not from the crate: the single-mode delay
//! equation
//!
//! q'' + 2 zeta w q' + w^2 q = -b phi^2 [h_xx(t) (q(t) - q(t - tau)) + (C / V) g(t) sin^2(Omega t) q'(t)]
//!
//! with phi = w / sqrt(k), h_xx = g sin(Omega t) (kt cos(Omega t) + kn sin(Omega t)) (the chip
//! thickness direction (sin, cos) of the tooth at angle Omega t from y), g = 1 while the tooth
//! cuts (0 <= Omega t mod 2 pi <= pi / 2 in 50 % up milling) and V = pi D Omega / (2 pi),
//! integrated by the classical Runge-Kutta method with the grid aligned to tooth entry and exit
//! and the delayed state interpolated by cubic Hermite polynomials (fourth order). The energy
//! E = q'^2 + w^2 q^2 at the ends of the delays, after 20 delays of transient, gives the growth
//! per delay (E_end / E_start)^(1 / 2n) over the second half of the run, the power-method
//! estimate of |mu|.

#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples;
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth, limiting_depth_near};
use chatter_stability::monodromy::{Discretization, steps};
use std::f64::consts::PI;

const C_N_PER_M: f64 = 2.5e5;
const FREQUENCY_HZ: f64 = 228.0;
const ZETA: f64 = 0.02;
const STIFFNESS: f64 = 5.6e6;
const KT: f64 = 2111.2e6;
const KN: f64 = 1052.6e6;
const DIAMETER_M: f64 = 18.54e-3;

/// |mu| of the flexure at `speed_rpm`, depth `depth_m`, by RK4 over `measured` delays after the
/// transient (`steps_per_cycle` steps per vibration period, rounded to a multiple of 4 per delay).
fn time_domain_multiplier(
    speed_rpm: f64,
    depth_m: f64,
    steps_per_cycle: f64,
    measured: usize,
) -> f64 {
    let w = 2.0 * PI * FREQUENCY_HZ;
    let phi2 = w * w / STIFFNESS;
    let omega = 2.0 * PI * speed_rpm / 60.0;
    let tau = 60.0 / speed_rpm;
    let v = PI * DIAMETER_M * speed_rpm / 60.0;
    let cv = C_N_PER_M / v;
    // steps per delay, a multiple of 4 so that exit (a quarter turn) is a grid point
    let k = 4 * ((steps_per_cycle * FREQUENCY_HZ * tau / 4.0).ceil() as usize);
    let h = tau / k as f64;
    // (h_xx, d_xx) at time t inside step n (nudged into the step, so a jump at its end is not seen)
    let coefficients = |t: f64, n: usize| {
        let t = t.clamp(n as f64 * h + 1e-9 * h, (n + 1) as f64 * h - 1e-9 * h);
        let angle = (omega * t).rem_euclid(2.0 * PI);
        if angle <= PI / 2.0 {
            let (s, c) = angle.sin_cos();
            (s * (KT * c + KN * s), cv * s * s)
        } else {
            (0.0, 0.0)
        }
    };
    // history: q and q' at every grid point; start from a smooth non-zero history
    let mut q: Vec<f64> = (0..=k)
        .map(|i| 1e-6 * (0.37 * w * i as f64 * h).sin())
        .collect();
    let mut dq: Vec<f64> = (0..=k)
        .map(|i| 1e-6 * 0.37 * w * (0.37 * w * i as f64 * h).cos())
        .collect();
    let delayed = |q: &[f64], dq: &[f64], n: usize, theta: f64| {
        // cubic Hermite between grid points n - k and n - k + 1 at fraction theta
        let (a, b) = (n - k, n - k + 1);
        let (t2, t3) = (theta * theta, theta * theta * theta);
        (2.0 * t3 - 3.0 * t2 + 1.0) * q[a]
            + (t3 - 2.0 * t2 + theta) * h * dq[a]
            + (-2.0 * t3 + 3.0 * t2) * q[b]
            + (t3 - t2) * h * dq[b]
    };
    let transient = 20;
    let mut energies = Vec::new();
    for n in k..k * (transient + measured + 1) {
        let t = n as f64 * h;
        let rhs = |time: f64, theta: f64, x: f64, dx: f64| {
            let (hxx, dxx) = coefficients(time, n);
            let lag = delayed(&q, &dq, n, theta);
            -2.0 * ZETA * w * dx - w * w * x - depth_m * phi2 * (hxx * (x - lag) + dxx * dx)
        };
        let (x, v0) = (q[n], dq[n]);
        let a1 = rhs(t, 0.0, x, v0);
        let (x2, v2) = (x + 0.5 * h * v0, v0 + 0.5 * h * a1);
        let a2 = rhs(t + 0.5 * h, 0.5, x2, v2);
        let (x3, v3) = (x + 0.5 * h * v2, v0 + 0.5 * h * a2);
        let a3 = rhs(t + 0.5 * h, 0.5, x3, v3);
        let (x4, v4) = (x + h * v3, v0 + h * a3);
        let a4 = rhs(t + h, 1.0, x4, v4);
        q.push(x + h / 6.0 * (v0 + 2.0 * v2 + 2.0 * v3 + v4));
        dq.push(v0 + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4));
        if (n + 1) % k == 0 && (n + 1) / k > transient {
            let (x, v) = (q[n + 1], dq[n + 1]);
            energies.push(v * v + w * w * x * x);
        }
    }
    // over the second half only, when the dominant multiplier has taken over
    let half = energies.len() / 2;
    let n = (energies.len() - 1 - half) as f64;
    (energies[energies.len() - 1] / energies[half]).powf(0.5 / n)
}

/// FDM and SDM (converged: 1600 and 3200 cutting steps) and the time-domain multiplier agree.
/// At 0.97 and 1.03 times the FDM limiting depth the integration decays and grows, and its |mu| is
/// within 1e-3 of both discretizations' at both depths (measured 2e-4 to 7e-4: the power-method
/// estimate, slow at 300 rpm where 45 vibration cycles per delay crowd the multipliers near the
/// unit circle, hence 400 to 600 delays; the RK4 error at 80 steps per cycle is about 1e-5).
/// The two limits agree within 0.25 %: FDM at 1600 steps is within 0.05 % of 3200; SDM, which
/// converges more slowly with process damping (second order, but at 300 rpm 12 % high at 200
/// steps, 1.5 % at 800, 0.09 % at 3200, against 3.7 %, 0.2 % and 0.01 % for FDM), is given
/// 3200 steps. This is the issue-14 case (228 Hz, C = 2.5e5 N/m, 300 rpm) where FDM and SDM at
/// their old default resolution gave 2.99 and 3.16 mm; converged, both give 2.936 mm.
#[test]
fn discretizations_with_process_damping_match_time_domain() {
    let model = examples::process_damping_flexure(Some(C_N_PER_M));
    let options = BoundaryOptions::default();
    let fdm = Discretization::full().with_steps(steps::<1600>());
    let sdm = Discretization::semi().with_steps(steps::<3200>());
    for (speed, delays) in [(300.0, 600), (1000.0, 400), (3000.0, 400)] {
        let limit = limiting_depth(&fdm, &model, speed, &options).unwrap();
        let sdm_limit =
            limiting_depth_near(&sdm, &model, speed, Some(limit.depth_m), &options).unwrap();
        assert!(
            (sdm_limit.depth_m - limit.depth_m).abs() < 2.5e-3 * limit.depth_m,
            "{speed} rpm: sdm {} mm, fdm {} mm",
            sdm_limit.depth_mm(),
            limit.depth_mm()
        );
        for factor in [0.97, 1.03] {
            let b = factor * limit.depth_m;
            let direct = time_domain_multiplier(speed, b, 80.0, delays);
            assert_eq!(
                direct > 1.0,
                factor > 1.0,
                "{speed} rpm, {factor} x {} mm: time domain {direct}",
                limit.depth_mm()
            );
            for solver in [&fdm, &sdm] {
                let discretized = solver
                    .dominant_multiplier(&model, speed, b)
                    .unwrap()
                    .modulus();
                assert!(
                    (direct - discretized).abs() < 1e-3,
                    "{speed} rpm, {factor} x {} mm: time domain {direct}, {} {discretized}",
                    limit.depth_mm(),
                    solver.name()
                );
            }
        }
    }
}

/// Issue 14's process-damping criterion, met by switching the samplers: the solver every
/// sampler prepares by default ([`SolverOptions::default`], full discretization at the
/// automatic resolution on the nominal model's grid, as the 003 paths and 004 cut likelihoods
/// run it) is within 3 % of the converged limit on the 003-type flexure from 300 to 3000 rpm.
/// The reference is FDM at 1600 cutting steps (at least 120 per vibration cycle), searched from
/// zero depth to 1e-6: the grid that matches the time-domain integration above. The zero-order
/// method is not used by the samplers there; its error is printed for the record (42 % low at
/// 300 rpm when this was written).
#[test]
fn sampler_solver_within_three_percent_with_process_damping() {
    use chatter_stability::monodromy::steps_at_least;
    use chatter_stability::prepared::{Method, SolverOptions};
    let model = examples::process_damping_flexure(Some(C_N_PER_M));
    let options = SolverOptions::default();
    assert_eq!(options.method, Method::Fdm, "the samplers' default method");
    let sampler = options.prepare_on_grid_of(&model, &model).unwrap();
    let zoa = SolverOptions::new(Method::Zoa)
        .prepare_on_grid_of(&model, &model)
        .unwrap();
    let fine = BoundaryOptions {
        relative_tolerance: 1e-6,
        ..BoundaryOptions::default()
    };
    let mut worst: f64 = 0.0;
    for speed in [
        300.0, 400.0, 500.0, 700.0, 1000.0, 1500.0, 2000.0, 2500.0, 3000.0,
    ] {
        // 50 % up milling, one tooth: the cut lasts a quarter of the revolution
        let cycles = FREQUENCY_HZ * 0.25 * 60.0 / speed;
        let reference = Discretization::full().with_steps(steps_at_least(
            (120.0 * cycles).ceil() as usize,
            steps::<1600>(),
        ));
        let converged = limiting_depth(&reference, &model, speed, &fine)
            .unwrap()
            .depth_m;
        let error = (sampler.limiting_depth(speed).unwrap().depth_m - converged) / converged;
        let zoa_error = (zoa.limiting_depth(speed).unwrap().depth_m - converged) / converged;
        eprintln!(
            "{speed} rpm: converged {:.4} mm, sampler's FDM {:+.2} %, zero-order {:+.1} %",
            converged * 1e3,
            100.0 * error,
            100.0 * zoa_error
        );
        worst = worst.max(error.abs());
    }
    assert!(worst < 0.03, "worst {:.2} %", 100.0 * worst);
}
