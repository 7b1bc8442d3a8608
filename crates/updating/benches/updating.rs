//! Sampler benches on the seeds' cases: 5000 iTMCMC samples of the 000 turning case (one model
//! class, the exact characteristic-equation likelihood; target < 5 s on 2 cores) and TMCMC on the
//! 002 milling case with the exact monodromy likelihood (fewer samples; the time scales linearly).
//! Also the limiting depth at one speed that the ensembles call thousands of times, zero-order
//! (before issue 14) and full discretization (the default since), without and with process
//! damping (seed-001 milling with a 19.05 mm cutter, C = 1e5 N/m), and one evaluation of the
//! 003 cut likelihood on the process-damping flexure (cuts at 300, 700 and 1100 rpm) with each.

use chatter_dynamics::Cut;
use chatter_dynamics::{Milling, MillingDirection, ModalModel, Operation, examples};
use chatter_progress::Silent;
use chatter_stability::monodromy::Discretization;
use chatter_stability::prepared::Method;
use chatter_stability::prepared::SolverOptions;
use chatter_updating::classes::{Sampler, SamplerOptions, sample_posterior};
use chatter_updating::cuts::{CutKernel, CutsLikelihood};
use chatter_updating::milling::MillingPoleLikelihood;
use chatter_updating::parameters::{Parameterization, parse_model_parameters};
use chatter_updating::turning::{ResidualForm, TurningPoleLikelihood, expand_repetitions};
use chatter_updating::update::{UpdateJob, UpdateSettings};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

fn model_parameters(job: &UpdateJob) -> String {
    let n = job.parameter_names().len() - 1;
    job.parameter_names()[..n].join(",")
}

fn ahmadi_2022(c: &mut Criterion) {
    let model = examples::ahmadi_2022_turning();
    let obs = examples::ahmadi_2022_turning_observations();
    let job =
        UpdateJob::new(&model, &obs, &UpdateSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    let p = Parameterization::new(
        model,
        parse_model_parameters(&model_parameters(&job)).unwrap_or_default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let like = TurningPoleLikelihood::new(
        p,
        expand_repetitions(&obs.poles),
        1.0,
        ResidualForm::PoleError,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let options = SamplerOptions {
        sampler: Sampler::Itmcmc,
        samples: 5000,
        seed: 1,
    };
    let mut group = c.benchmark_group("ahmadi2022");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    group.bench_function("itmcmc_5000_samples_one_class", |b| {
        b.iter(|| black_box(sample_posterior(job.prior(), &like, &options, &Silent)))
    });
    group.finish();
}

fn ebrahimi_2025(c: &mut Criterion) {
    let model = examples::ebrahimi_2025_milling();
    let obs = examples::ebrahimi_2025_milling_observations();
    let job =
        UpdateJob::new(&model, &obs, &UpdateSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    let p = Parameterization::new(
        model,
        parse_model_parameters(&model_parameters(&job)).unwrap_or_default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let like = MillingPoleLikelihood::new(p, &obs.poles, 0.01, Discretization::full())
        .unwrap_or_else(|e| panic!("{e}"));
    let options = SamplerOptions {
        sampler: Sampler::Tmcmc,
        samples: 500,
        seed: 1,
    };
    let mut group = c.benchmark_group("ebrahimi2025");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(60));
    group.bench_function("tmcmc_500_samples_one_class_exact_monodromy", |b| {
        b.iter(|| black_box(sample_posterior(job.prior(), &like, &options, &Silent)))
    });
    group.finish();
}

fn boundary(c: &mut Criterion) {
    let bare = examples::schmitz_2023_milling();
    let cutter = Milling::new(4, 0.2, MillingDirection::Down, Some(0.01905), None)
        .and_then(|op| bare.with_operation(Operation::Milling(op)))
        .and_then(|m| m.with_process_damping(Some(1e5)))
        .unwrap_or_else(|e| panic!("{e}"));
    let zoa = SolverOptions::new(Method::Zoa);
    let fdm = SolverOptions::default();
    // prepared and queried per iteration, as a sampler does per sampled model
    let limiting_depth = |model: &ModalModel, speed_rpm: f64, options: &SolverOptions| {
        options
            .prepare_on_grid_of(model, model)
            .and_then(|solver| solver.limiting_depth(speed_rpm))
    };
    let mut group = c.benchmark_group("boundary");
    group.sample_size(20);
    group.bench_function("limiting_depth_milling_2_modes", |b| {
        b.iter(|| limiting_depth(&bare, black_box(6960.0), &zoa))
    });
    group.bench_function("limiting_depth_process_damping", |b| {
        b.iter(|| limiting_depth(&cutter, black_box(3000.0), &zoa))
    });
    group.bench_function("limiting_depth_milling_2_modes_fdm", |b| {
        b.iter(|| limiting_depth(&bare, black_box(6960.0), &fdm))
    });
    group.bench_function("limiting_depth_process_damping_fdm", |b| {
        b.iter(|| limiting_depth(&cutter, black_box(3000.0), &fdm))
    });
    group.finish();
}

/// One evaluation of the 003 cut likelihood (kt, kn, C) on the flexure, per method.
fn cut_likelihood(c: &mut Criterion) {
    let flexure = examples::process_damping_flexure(Some(2.5e5));
    let p = Parameterization::new(
        flexure,
        parse_model_parameters("kt_n_per_mm2,kn_n_per_mm2,c_n_per_m").unwrap_or_default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let cuts: Vec<Cut> = [(300.0, 2.5, true), (700.0, 1.5, false), (1100.0, 1.2, true)]
        .into_iter()
        .map(|(speed_rpm, depth_mm, stable)| Cut::labelled(speed_rpm, depth_mm, stable))
        .collect();
    let theta = [2150.0, 1040.0, 2.8e5];
    let mut group = c.benchmark_group("cut_likelihood_003");
    group.sample_size(20);
    for method in [Method::Zoa, Method::Fdm] {
        let options = SolverOptions::new(method).with_max_depth_m(7.5e-3);
        let like = CutsLikelihood::new(p.clone(), cuts.clone(), CutKernel::karandikar(), options)
            .unwrap_or_else(|e| panic!("{e}"));
        group.bench_function(method.name(), |b| {
            b.iter(|| like.ln_likelihood(black_box(&theta)))
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    ahmadi_2022,
    ebrahimi_2025,
    boundary,
    cut_likelihood
);
criterion_main!(benches);
