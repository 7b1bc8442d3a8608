//! Solvers against published numbers and classic benchmarks (tolerances stated per test).
#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples;
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::monodromy::{Discretization, steps};
use chatter_stability::zero_order::zoa_lobes;

fn local_extrema(points: &[(f64, f64)]) -> (Vec<f64>, Vec<f64>) {
    let (mut maxima, mut minima) = (Vec::new(), Vec::new());
    for w in points.windows(3) {
        if w[1].1 > w[0].1 && w[1].1 >= w[2].1 {
            maxima.push(w[1].0);
        }
        if w[1].1 < w[0].1 && w[1].1 <= w[2].1 {
            minima.push(w[1].0);
        }
    }
    (maxima, minima)
}

/// Schmitz 2023 (seed 001) Section 4: zero-order lobe maxima near 5660 and 11298 rpm and a
/// minimum near 6960 rpm. Tolerance 1 % (the paper quotes rounded speeds read from its plot).
#[test]
fn schmitz_2023_lobe_extrema() {
    let model = examples::schmitz_2023_milling();
    let speeds: Vec<f64> = (0..=2400).map(|i| 4000.0 + 5.0 * i as f64).collect();
    let lobes = zoa_lobes(&model, &speeds).unwrap();
    let curve: Vec<(f64, f64)> = lobes.iter().map(|p| (p.speed_rpm, p.depth_m)).collect();
    let (maxima, minima) = local_extrema(&curve);
    for target in [5660.0, 11298.0] {
        let nearest = maxima
            .iter()
            .copied()
            .min_by(|a, b| (a - target).abs().total_cmp(&(b - target).abs()))
            .unwrap();
        assert!(
            (nearest - target).abs() < 0.01 * target,
            "maximum {nearest} vs {target}"
        );
    }
    let nearest = minima
        .iter()
        .copied()
        .min_by(|a, b| (a - 6960.0).abs().total_cmp(&(b - 6960.0).abs()))
        .unwrap();
    assert!(
        (nearest - 6960.0).abs() < 0.01 * 6960.0,
        "minimum {nearest}"
    );
}

/// Classic single-DOF benchmark: FDM and SDM converge to the same boundary as m grows
/// (the gap shrinks monotonically and is below 0.5 % at m = 160).
#[test]
fn fdm_and_sdm_converge_together() {
    let opts = BoundaryOptions::default();
    for (ad, rpm) in [
        (1.0, 5000.0),
        (1.0, 20000.0),
        (0.05, 5000.0),
        (0.05, 20000.0),
    ] {
        let model = examples::insperger_benchmark(ad);
        let gaps: Vec<f64> = [steps::<20>(), steps::<40>(), steps::<80>(), steps::<160>()]
            .into_iter()
            .map(|m| {
                let f = limiting_depth(&Discretization::full().with_steps(m), &model, rpm, &opts);
                let s = limiting_depth(&Discretization::semi().with_steps(m), &model, rpm, &opts);
                let (f, s) = (f.unwrap().depth_m, s.unwrap().depth_m);
                (f - s).abs() / s
            })
            .collect();
        assert!(gaps[3] < 5e-3, "a/D {ad} {rpm} rpm: gaps {gaps:?}");
        assert!(gaps[3] <= gaps[0], "a/D {ad} {rpm} rpm: gaps {gaps:?}");
    }
}

/// The default (automatic) resolution is within 2 % of the converged boundary (m = 400) over
/// 5000-25000 rpm for both immersions.
#[test]
fn default_resolution_within_two_percent() {
    let opts = BoundaryOptions::default();
    for ad in [1.0, 0.05] {
        let model = examples::insperger_benchmark(ad);
        for rpm in [5000.0, 9000.0, 13000.0, 17000.0, 21000.0, 25000.0] {
            let auto = limiting_depth(&Discretization::full(), &model, rpm, &opts).unwrap();
            let fine = limiting_depth(
                &Discretization::semi().with_steps(steps::<400>()),
                &model,
                rpm,
                &opts,
            )
            .unwrap();
            let err = (auto.depth_m - fine.depth_m).abs() / fine.depth_m;
            assert!(err < 0.02, "a/D {ad} {rpm} rpm: {err}");
        }
    }
}

/// Turning has constant coefficients, so the zero-order (oriented FRF) solution is exact there:
/// FDM at the default resolution agrees within 1 % in depth and exactly in chatter frequency
/// (000 turning case, 6900-7450 rpm).
#[test]
fn turning_fdm_matches_exact_frequency_domain_solution() {
    let model = examples::ahmadi_2022_turning();
    let speeds: Vec<f64> = (0..12).map(|i| 6900.0 + 50.0 * i as f64).collect();
    let zoa = zoa_lobes(&model, &speeds).unwrap();
    let fdm = chatter_stability::boundary::lobe_diagram(
        &Discretization::full(),
        &model,
        &speeds,
        &BoundaryOptions::default(),
        &chatter_progress::Silent,
    )
    .unwrap();
    for (z, f) in zoa.iter().zip(&fdm) {
        let err = (f.depth_m - z.depth_m).abs() / z.depth_m;
        assert!(err < 0.01, "{} rpm: {err}", z.speed_rpm);
        assert!(
            (f.chatter_hz - z.chatter_hz).abs() < 2.0,
            "{} vs {}",
            f.chatter_hz,
            z.chatter_hz
        );
    }
}

/// Slotting with two teeth (benchmark a/D = 1): on the high-speed lobe the zero-order boundary
/// holds within 4 % at 20500-22500 rpm (the discretized boundary there is a period-doubling one,
/// chatter at 1.5 f_tooth, which the zero-order method cannot label but whose depth it matches). At the low-speed lobe bottoms the
/// strong harmonics of h_xx(t) make the zero-order result 4-12 % conservative (a known limit of
/// the approximation for few teeth); both bounds are asserted.
#[test]
fn full_immersion_zero_order_where_it_holds() {
    let model = examples::insperger_benchmark(1.0);
    let opts = BoundaryOptions::default();
    let speeds = [20500.0, 21000.0, 21500.0, 22000.0, 22500.0];
    let zoa = zoa_lobes(&model, &speeds).unwrap();
    for (z, &rpm) in zoa.iter().zip(&speeds) {
        let f = limiting_depth(&Discretization::full(), &model, rpm, &opts).unwrap();
        let err = (f.depth_m - z.depth_m).abs() / f.depth_m;
        assert!(
            err < 0.04,
            "{rpm} rpm: fdm {} zoa {} ({err})",
            f.depth_m,
            z.depth_m
        );
    }
    for rpm in [6000.0, 7500.0, 10000.0, 16000.0] {
        let z = zoa_lobes(&model, &[rpm]).unwrap()[0];
        let f = limiting_depth(&Discretization::full(), &model, rpm, &opts).unwrap();
        let ratio = z.depth_m / f.depth_m;
        assert!(
            (0.88..0.97).contains(&ratio),
            "{rpm} rpm: zoa/fdm = {ratio}"
        );
    }
}

/// Seed 000 Table 2: closed-loop poles identified at P1-P5. The nominal (hammer) model's
/// frequency-domain pole and the FDM multiplier's pole agree with each other (frequency within
/// 0.1 %, damping within 0.0005 absolute), and the frequency is within 1 % of the table (the
/// model is not yet updated; the damping differs by design and is reported, not asserted).
#[test]
fn ahmadi_2022_table2_poles() {
    use chatter_stability::frequency_domain::dominant_pole;
    let model = examples::ahmadi_2022_turning();
    let table = [
        (7150.0, 2.286, 2473.0, 0.0012),
        (7150.0, 2.54, 2477.0, 0.0006),
        (6950.0, 2.54, 2508.0, 0.0019),
        (7500.0, 2.032, 2476.0, 0.0009),
        (7500.0, 2.54, 2476.0, 0.0002),
    ];
    for (rpm, mm, f_obs, _z_obs) in table {
        let p = dominant_pole(&model, rpm, mm * 1e-3).unwrap();
        assert!(
            (p.frequency_hz - f_obs).abs() < 0.01 * f_obs,
            "{rpm} rpm {mm} mm: {} Hz",
            p.frequency_hz
        );
        let (mu, f_fdm) = Discretization::full()
            .chatter_frequency_hz(&model, rpm, mm * 1e-3)
            .unwrap();
        let lambda_re = mu.modulus().ln() / mu.period_s;
        let z_fdm = -lambda_re / (2.0 * std::f64::consts::PI * f_fdm);
        assert!(
            (f_fdm - p.frequency_hz).abs() < 1e-3 * p.frequency_hz,
            "{f_fdm} vs {}",
            p.frequency_hz
        );
        assert!(
            (z_fdm - p.damping_ratio).abs() < 5e-4,
            "{z_fdm} vs {}",
            p.damping_ratio
        );
    }
}
