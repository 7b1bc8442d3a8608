//! Stability solver speed: the dominant multiplier of the single-DOF benchmark at m = 40, a
//! 200-speed FDM lobe diagram at m = 40, the seed-000 turning multiplier at the default
//! resolution, and the zero-order limiting depth at one speed (seed-001 two-mode milling, seed-000
//! turning) and over a 200-speed lobe diagram; the same FDM lobe diagram by the prepared solver
//! (boundary search from the zero-order limit, warm-started Arnoldi), and at the automatic
//! resolution (`Method::Fdm`: extrapolated from m and 2m steps); the multiplier of the 003-type
//! flexure at 300 rpm with process damping (clustered multipliers, operator dimension 276); the
//! characteristic roots of turning (the gap diagnosis's turning likelihood) with the seed-000
//! lathe's two modes and with a third mode (the `extra_mode` class: the LU path of Newton's step);
//! the 200-speed SDM lobe diagram of seed 001's mill with four pitch delays (70-110-70-110 deg)
//! and a 30 deg helix in 20 axial slices (issue 33's target: 5 s).
use chatter_dynamics::examples;
use chatter_dynamics::{Mode, ModeShape};
use chatter_progress::Silent;
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, lobe_diagram, speed_range};
use chatter_stability::frequency_domain::dominant_and_unstable_poles;
use chatter_stability::monodromy::{Discretization, steps};
use chatter_stability::prepared::{Method, PreparedDiscretization, PreparedSolver};
use chatter_stability::zero_order::{zoa_limiting_depth, zoa_lobes};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let benchmark = examples::insperger_benchmark(1.0);
    let fdm40 = Discretization::full().with_steps(steps::<40>());
    let sdm40 = Discretization::semi().with_steps(steps::<40>());
    c.bench_function("multiplier_sdof_fdm_m40", |b| {
        b.iter(|| fdm40.dominant_multiplier(&benchmark, 10_000.0, 0.3e-3))
    });
    c.bench_function("multiplier_sdof_sdm_m40", |b| {
        b.iter(|| sdm40.dominant_multiplier(&benchmark, 10_000.0, 0.3e-3))
    });
    let turning = examples::ahmadi_2022_turning();
    c.bench_function("multiplier_turning_fdm_auto", |b| {
        b.iter(|| Discretization::full().dominant_multiplier(&turning, 7150.0, 2.286e-3))
    });
    let flexure = examples::process_damping_flexure(Some(2.5e5));
    c.bench_function("multiplier_flexure_300rpm_fdm_auto", |b| {
        b.iter(|| Discretization::full().dominant_multiplier(&flexure, 300.0, 2.9e-3))
    });
    let speeds = speed_range(5000.0, 25_000.0, 200).unwrap_or_default();
    let mut group = c.benchmark_group("lobes");
    group.sample_size(10);
    group.bench_function("lobes_200_speeds_fdm_m40", |b| {
        b.iter(|| {
            lobe_diagram(
                &fdm40,
                &benchmark,
                &speeds,
                &BoundaryOptions::default(),
                &Silent,
            )
        })
    });
    let prepared = PreparedDiscretization::new(fdm40, &benchmark, &BoundaryOptions::default()).ok();
    group.bench_function("lobes_200_speeds_fdm_m40_prepared", |b| {
        b.iter(|| prepared.as_ref().map(|p| p.lobes(&speeds, &Silent)))
    });
    let auto = Method::Fdm
        .prepare(&benchmark, &BoundaryOptions::default())
        .ok();
    group.bench_function("lobes_200_speeds_fdm_auto_prepared", |b| {
        b.iter(|| auto.as_ref().map(|p| p.lobes(&speeds, &Silent)))
    });
    group.finish();
}

fn zero_order(c: &mut Criterion) {
    let milling = examples::schmitz_2023_milling();
    let turning = examples::ahmadi_2022_turning();
    let mut group = c.benchmark_group("zero_order");
    group.sample_size(10);
    group.bench_function("zoa_limiting_depth_milling_2_modes", |b| {
        b.iter(|| zoa_limiting_depth(&milling, black_box(6960.0)))
    });
    group.bench_function("zoa_limiting_depth_turning", |b| {
        b.iter(|| zoa_limiting_depth(&turning, black_box(7150.0)))
    });
    let speeds = speed_range(4000.0, 16_000.0, 200).unwrap_or_default();
    group.bench_function("zoa_lobes_200_speeds_milling_2_modes", |b| {
        b.iter(|| zoa_lobes(&milling, black_box(&speeds)))
    });
    group.finish();
}

fn characteristic_roots(c: &mut Criterion) {
    let lathe = examples::ahmadi_2022_turning();
    let mut modes = lathe.modes().to_vec();
    let amplitude = 2.0 * std::f64::consts::PI * 1000.0 / 3e7f64.sqrt();
    let shape = ModeShape::MassNormalized([amplitude * 0.6, amplitude * 0.8]);
    modes.extend(Mode::new(1000.0, 0.03, shape));
    let three = lathe.with_modes(modes).unwrap_or_else(|_| lathe.clone());
    let mut group = c.benchmark_group("characteristic");
    group.sample_size(20);
    for (name, model) in [("two_modes", &lathe), ("three_modes", &three)] {
        group.bench_function(format!("dominant_and_unstable_poles_2000rpm_{name}"), |b| {
            b.iter(|| dominant_and_unstable_poles(model, black_box(2000.0), 1.0e-3))
        });
    }
    group.finish();
}

fn variable_pitch_helix(c: &mut Criterion) {
    let mill = examples::schmitz_2023_milling();
    let chatter_dynamics::Operation::Milling(m) = mill.operation() else {
        return;
    };
    let Ok(milling) = chatter_dynamics::Milling::new(4, 0.2, m.direction(), Some(12.7e-3), None)
        .and_then(|h| h.with_helix_deg(Some(&[30.0])))
        .and_then(|h| h.with_axial_slices(Some(20)))
        .and_then(|h| h.with_pitch_deg(Some(&[70.0, 110.0, 70.0, 110.0])))
    else {
        return;
    };
    let Ok(model) = mill.with_operation(chatter_dynamics::Operation::Milling(milling)) else {
        return;
    };
    let speeds = chatter_stability::speed_grid::default_speeds_rpm(&mill);
    let Ok(sdm) = Method::Sdm.prepare(&model, &BoundaryOptions::default()) else {
        return;
    };
    let mut group = c.benchmark_group("lobes");
    group.sample_size(10);
    group.bench_function("lobes_200_speeds_sdm_pitch4_helix20", |b| {
        b.iter(|| sdm.lobes(black_box(&speeds), &Silent))
    });
    group.finish();
}

criterion_group!(
    benches,
    bench,
    zero_order,
    characteristic_roots,
    variable_pitch_helix
);
criterion_main!(benches);
