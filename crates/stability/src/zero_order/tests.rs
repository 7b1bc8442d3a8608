//! The fast solver against brute force: every lobe crossing of the zero-order equation on a dense
//! frequency scan, and for process damping the smallest fixed point of b = M(b) by bisection on
//! dense scans.

use super::system::{AddedDamping, EigenPair};
use super::*;
use crate::process_damping::{damping_ratio_slopes_per_m, process_damping_limiting_depth};
use chatter_dynamics::{
    CuttingCoefficients, Milling, MillingDirection, Mode, ModeShape, Operation, examples,
};
use std::f64::consts::PI;

/// Lobe points (eps, b) of both eigenvalues on a dense geometric grid over the solver's range
/// [f_min / 2, 2 f_max], branches followed by continuity.
struct DenseScan {
    omega: Vec<f64>,
    points: Vec<[Option<(f64, f64)>; 2]>,
}

impl DenseScan {
    /// None where a damping ratio reaches 1.
    fn new(system: &OrientedSystem, added: AddedDamping, n: usize) -> Option<Self> {
        let (f_min, f_max) = system.frequency_span_hz();
        let (lo, hi) = (0.5 * f_min, 2.0 * f_max);
        let mut omega = Vec::with_capacity(n);
        let mut points = Vec::with_capacity(n);
        let mut previous: Option<EigenPair> = None;
        for i in 0..n {
            let w = 2.0 * PI * lo * (hi / lo).powf(i as f64 / (n - 1) as f64);
            let mut pair = system.eigenvalues(w, added)?;
            if let Some(p) = previous {
                pair = pair.matched(&p);
            }
            previous = Some(pair);
            omega.push(w);
            points.push([0, 1].map(|b| pair.lobe(b).map(|l| (l.eps, l.depth_m))));
        }
        Some(Self { omega, points })
    }

    /// Every crossing (depth m, Hz) at delay `tau`, ascending in depth: where p = (w tau - eps) /
    /// 2 pi passes an integer between neighbouring points (at most one there on this grid),
    /// linearly interpolated.
    fn crossings(&self, tau: f64) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        for branch in 0..2 {
            for (j, pair) in self.points.windows(2).enumerate() {
                let (Some((e0, b0)), Some((e1, b1))) = (pair[0][branch], pair[1][branch]) else {
                    continue;
                };
                if (e1 - e0).abs() > PI {
                    continue;
                }
                let (w0, w1) = (self.omega[j], self.omega[j + 1]);
                let p0 = (w0 * tau - e0) / (2.0 * PI);
                let p1 = (w1 * tau - e1) / (2.0 * PI);
                let m = p0.max(p1).floor();
                if m < 0.0 || m < p0.min(p1) || m == p1 {
                    continue;
                }
                let t = (m - p0) / (p1 - p0);
                out.push((b0 + t * (b1 - b0), (w0 + t * (w1 - w0)) / (2.0 * PI)));
            }
        }
        out.sort_by(|a, b| a.0.total_cmp(&b.0));
        out
    }
}

/// Two distinct modes in x and y under a seed-001 cutter (four teeth, 20 % down milling).
pub(super) fn two_mode_milling(diameter_m: Option<f64>, c_n_per_m: Option<f64>) -> ModalModel {
    let mode = |f, zeta, k, coordinate| {
        Mode::new(
            f,
            zeta,
            ModeShape::Directional {
                coordinate,
                stiffness_n_per_m: k,
            },
        )
        .unwrap()
    };
    ModalModel::new(
        None,
        Operation::Milling(Milling::new(4, 0.2, MillingDirection::Down, diameter_m, None).unwrap()),
        CuttingCoefficients::from_ks_beta(750e6, 68f64.to_radians()).unwrap(),
        vec![mode(750.0, 0.03, 3.0e6, 0), mode(810.0, 0.035, 3.6e6, 1)],
        c_n_per_m,
    )
    .unwrap()
}

/// The three lowest lobes of the table (fewer where fewer cross) agree with the dense scan of
/// 400 000 points at 60 speeds per model: ordered depths within 1e-4 relative, and each lobe matches a scanned crossing in
/// depth (1e-4 relative) and chatter frequency (1e-5 relative). The scan's own interpolation
/// error is below 1e-6 there.
#[test]
fn lobes_agree_with_a_dense_scan() {
    let cases = [
        (examples::schmitz_2023_milling(), 2000.0f64, 20_000.0f64),
        (two_mode_milling(None, None), 2000.0, 20_000.0),
        (examples::ahmadi_2022_turning(), 1000.0, 12_000.0),
        // (above 25 000 rpm its lowest lobe leaves the frequency range f_n / 2 to 2 f_n)
        (examples::insperger_benchmark(0.05), 4000.0, 25_000.0),
    ];
    for (case, (model, from_rpm, to_rpm)) in cases.into_iter().enumerate() {
        let system = OrientedSystem::from_model(&model).unwrap();
        let scan = DenseScan::new(&system, AddedDamping::NONE, 400_000).unwrap();
        let table = LobeTable::new(system);
        for i in 0..60 {
            let speed = from_rpm * (to_rpm / from_rpm).powf(i as f64 / 59.0);
            let tau = model.operation().delay_s(speed);
            let fast = table.lobes(tau, 3).unwrap();
            let dense = scan.crossings(tau);
            assert_eq!(fast.len(), dense.len().min(3), "case {case}, {speed} rpm");
            for (k, lobe) in fast.iter().enumerate() {
                let (b, _) = dense[k];
                assert!(
                    (lobe.depth_m - b).abs() < 1e-4 * b,
                    "case {case}, {speed} rpm, lobe {k}: {lobe:?} vs {:?}",
                    &dense[..3]
                );
                assert!(
                    dense.iter().take(6).any(|(b, f)| {
                        (lobe.depth_m - b).abs() < 1e-4 * b
                            && (lobe.chatter_hz - f).abs() < 1e-5 * f
                    }),
                    "case {case}, {speed} rpm, lobe {k}: {lobe:?} vs {:?}",
                    &dense[..3]
                );
                let f_lo = lobe.index as f64 / tau;
                assert!(lobe.chatter_hz > f_lo && lobe.chatter_hz < f_lo + 1.0 / tau);
            }
        }
    }
}

/// The smallest fixed point of b = M(b) (the smallest depth with a lobe at or below it), M the
/// lowest lobe of a dense scan (100 000 points) with the damping ratios zeta_n + b s_n, by
/// bisection.
fn dense_process_damped_depth(model: &ModalModel, speed_rpm: f64) -> f64 {
    let system = OrientedSystem::from_model(model).unwrap();
    let slopes = damping_ratio_slopes_per_m(model, speed_rpm);
    let tau = model.operation().delay_s(speed_rpm);
    let lowest = |b: f64| {
        let added = AddedDamping {
            slopes_per_m: &slopes,
            depth_m: b,
        };
        DenseScan::new(&system, added, 100_000)
            .and_then(|s| s.crossings(tau).first().map(|c| c.0))
            .unwrap_or(f64::INFINITY)
    };
    // M(0) > 0; with several modes the damping can also lower a lobe, so the fixed point may
    // lie below M(0)
    let (mut lo, mut hi) = (0.0, lowest(0.0));
    while lowest(hi) > hi {
        lo = hi;
        hi *= 1.5;
    }
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if lowest(mid) > mid {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// With process damping the limiting depth agrees with the dense fixed point within 2e-4
/// relative, and with the iterative 003 algorithm within 1e-4 (it stops when a step changes b by
/// 1e-6 relative): one mode (the 003-like flexure), and two modes under a 19.05 mm cutter where
/// the added damping raises the limit, lowers it (the damping of one mode lowers the other's
/// lobe, seed-001 cutter with C = 3e4 N/m at 2289 rpm) and makes the lowest lobe where the
/// eigenvalues without it are none (C = 2e5 N/m at 1000 rpm).
#[test]
fn process_damping_agrees_with_a_dense_fixed_point() {
    let options = ZeroOrderOptions {
        relative_tolerance: 1e-7,
        ..ZeroOrderOptions::unbounded()
    };
    let cutter = Milling::new(4, 0.2, MillingDirection::Down, Some(0.01905), None).unwrap();
    let seed_001 = examples::schmitz_2023_milling()
        .with_operation(Operation::Milling(cutter))
        .unwrap();
    let cases = [
        (
            examples::process_damping_flexure(Some(2.5e5)),
            vec![300.0, 600.0, 2000.0],
        ),
        (
            two_mode_milling(Some(0.01905), Some(2.0e5)),
            vec![1200.0, 3100.0],
        ),
        (
            seed_001.with_process_damping(Some(3e4)).unwrap(),
            vec![2289.0],
        ),
        (
            seed_001.with_process_damping(Some(2e5)).unwrap(),
            vec![1000.0],
        ),
    ];
    for (model, speeds) in cases {
        let bare = zoa_lobes(&model, &speeds).unwrap();
        let fast = limiting_depths(&model, &speeds, &options).unwrap();
        for ((f, b), &speed) in fast.iter().zip(&bare).zip(&speeds) {
            let dense = dense_process_damped_depth(&model, speed);
            assert!(
                (f.depth_m - dense).abs() < 2e-4 * dense,
                "{speed} rpm: {} vs {dense}",
                f.depth_m
            );
            // process damping matters at these speeds
            assert!(
                (f.depth_m - b.depth_m).abs() > 0.01 * b.depth_m,
                "{speed} rpm"
            );
            let iterated = process_damping_limiting_depth(&model, speed).unwrap();
            assert!((f.depth_m - iterated.depth_m).abs() < 1e-4 * iterated.depth_m);
        }
    }
}

#[test]
fn single_dof_minimum_is_tlusty_limit() {
    // full-immersion SDOF in x: Lambda = A0_xx G_xx, minimum b = -1 / (2 A0_xx min Re G)
    let model = examples::insperger_benchmark(1.0);
    let speeds: Vec<f64> = (0..4000).map(|i| 5000.0 + 5.0 * i as f64).collect();
    let lobes = zoa_lobes(&model, &speeds).unwrap();
    let b_min = lobes
        .iter()
        .map(|p| p.depth_m)
        .fold(f64::INFINITY, f64::min);
    let a_xx = model.average_directional_matrix()[(0, 0)];
    let re_min = (0..200_000)
        .map(|i| model.receptance(800.0 + i as f64 * 0.001, 0, 0).re)
        .fold(f64::INFINITY, f64::min);
    let exact = -1.0 / (2.0 * a_xx * re_min);
    // speed grid of 5 rpm samples the lobe bottoms to ~0.1 %
    assert!((b_min - exact).abs() < 2e-3 * exact, "{b_min} vs {exact}");
}

#[test]
fn ceilings_and_bad_inputs() {
    let model = examples::process_damping_flexure(Some(1e9));
    // a huge C makes the cut stable up to the ceiling
    let options = ZeroOrderOptions {
        max_depth_m: 0.01,
        ..Default::default()
    };
    assert!(
        PreparedZeroOrder::new(&model, &options)
            .unwrap()
            .limiting_depth(300.0)
            .unwrap()
            .depth_m
            .is_infinite()
    );
    assert!(limiting_depths(&model, &[-1.0], &options).is_err());
    let bad = ZeroOrderOptions {
        relative_tolerance: 0.0,
        ..Default::default()
    };
    assert!(limiting_depths(&model, &[300.0], &bad).is_err());
    let table = LobeTable::new(OrientedSystem::from_model(&model).unwrap());
    assert!(table.lobes(0.0, 1).is_err());
    assert!(table.lobes(0.1, 0).unwrap().is_empty());
    let options = ZeroOrderOptions::default();
    for slopes in [vec![], vec![-1.0], vec![0.0], vec![f64::NAN]] {
        assert!(ProcessDampedTable::new(&table, &slopes, &options).is_err());
    }
    let damped = ProcessDampedTable::new(&table, &[1.0], &options).unwrap();
    assert!(damped.lobes(0.1, -1.0, 1).is_err());
    assert_eq!(
        damped.lobes(0.1, 0.0, 2).unwrap(),
        table.lobes(0.1, 2).unwrap()
    );
}

/// Largest relative difference between the zero-order `table` of `model` at `speeds` and the
/// measured-FRF route on its receptance sampled every 0.05 Hz from 0.25 to 2 times `f_max_hz`.
fn worst_against_sampled(
    model: &ModalModel,
    table: &[LobePoint],
    speeds: &[f64],
    f_max_hz: f64,
) -> f64 {
    let (lo, hi) = (0.25 * f_max_hz, 2.0 * f_max_hz);
    let grid: Vec<f64> = (0..((hi - lo) / 0.05) as usize)
        .map(|k| lo + 0.05 * k as f64)
        .collect();
    let sampled = measured_limiting_depths(
        model.operation(),
        model.cutting(),
        &model.sampled_receptance(grid).unwrap(),
        speeds,
        &ZeroOrderOptions::unbounded(),
    )
    .unwrap();
    table
        .iter()
        .zip(&sampled)
        .map(|(a, b)| (a.depth_m / b.depth_m - 1.0).abs())
        .fold(0.0, f64::max)
}

/// Non-proportional modes: the zero-order table of a model with complex residues against the
/// measured-FRF route on its receptance sampled at 0.05 Hz (a different solver: interpolation
/// and bisection on samples, no modal grid); the methods built on real modal coordinates refuse
/// the model and name themselves.
#[test]
fn complex_modes_in_the_table_agree_with_their_sampled_receptance() {
    use crate::{Method, StabilitySolver, boundary::BoundaryOptions};
    let base = examples::schmitz_2023_milling();
    let modes: Vec<Mode> = base
        .modes()
        .iter()
        .zip([0.45, -0.3, 0.2, 0.1])
        .map(|(m, a)| m.with_residue_phase(a).unwrap())
        .collect();
    let model = base.with_modes(modes).unwrap();
    let speeds: Vec<f64> = (0..40).map(|i| 5000.0 + 250.0 * i as f64).collect();
    let table = zoa_lobes(&model, &speeds).unwrap();
    let f_max = base
        .modes()
        .iter()
        .map(|m| m.frequency_hz())
        .fold(0.0, f64::max);
    let worst = worst_against_sampled(&model, &table, &speeds, f_max);
    assert!(worst < 1e-4, "{worst}");
    // the phases matter: the real-mode lobes differ
    let real = zoa_lobes(&base, &speeds).unwrap();
    let moved = table
        .iter()
        .zip(&real)
        .map(|(a, b)| (a.depth_m / b.depth_m - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!("complex modes: table vs sampled {worst:.2e}, moved from the real modes {moved:.3}");
    assert!(moved > 0.05, "{moved}");
    let options = BoundaryOptions::default();
    for method in [Method::Fdm, Method::Sdm] {
        let e = Method::prepare(method, &model, &options)
            .and_then(|s| s.dominant_multiplier(8000.0, 1e-4))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(method.name()) && e.contains("residue_phase_deg"),
            "{e}"
        );
    }
    let turning = examples::ahmadi_2022_turning();
    let complex_turning = turning
        .with_modes(vec![turning.modes()[0].with_residue_phase(0.2).unwrap()])
        .unwrap();
    let e = crate::frequency_domain::FrequencyDomain
        .dominant_multiplier(&complex_turning, 7000.0, 1e-4)
        .unwrap_err()
        .to_string();
    assert!(e.contains("frequency-domain"), "{e}");
}

/// Residual terms (`residuals` in model files): the zero-order table with U - L / w^2 on the
/// direct receptances against the measured-FRF route on the model's receptance sampled at
/// 0.05 Hz (a different solver); the terms move the lobes, and FDM and SDM refuse them by name.
#[test]
fn residual_terms_in_the_table_agree_with_their_sampled_receptance() {
    use crate::{Method, boundary::BoundaryOptions};
    use chatter_dynamics::ResidualTerms;
    let base = examples::schmitz_2023_milling();
    // x: a fifth of the modal flexibility above the band and an inertance term below it; y:
    // an upper term only
    let model = base
        .with_residuals([
            ResidualTerms {
                upper_m_per_n: 0.2 / 3e6,
                lower_per_kg: 0.5,
            },
            ResidualTerms {
                upper_m_per_n: 0.1 / 3e6,
                lower_per_kg: 0.0,
            },
        ])
        .unwrap();
    let speeds: Vec<f64> = (0..40).map(|i| 5000.0 + 250.0 * i as f64).collect();
    let table = zoa_lobes(&model, &speeds).unwrap();
    let worst = worst_against_sampled(&model, &table, &speeds, 750.0);
    let plain = zoa_lobes(&base, &speeds).unwrap();
    let moved = table
        .iter()
        .zip(&plain)
        .map(|(a, b)| (a.depth_m / b.depth_m - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "residual terms: table vs sampled {worst:.2e}, moved from the modes alone {moved:.3}"
    );
    assert!(worst < 1e-4, "{worst}");
    assert!(moved > 0.05, "{moved}");
    let options = BoundaryOptions::default();
    for method in [Method::Fdm, Method::Sdm] {
        let e = Method::prepare(method, &model, &options)
            .and_then(|s| s.dominant_multiplier(8000.0, 1e-4))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(method.name()) && e.contains("residuals[x]"),
            "{e}"
        );
    }
}
