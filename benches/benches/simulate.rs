//! Simulator throughput: 1 s of signal at 50 kHz for the seed-000 turning tool and the seed-001
//! milling example.
use chatter_dynamics::examples;
use chatter_dynamics::simulate::{SimulationSettings, simulate};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("simulate_1s_50khz");
    group.sample_size(10);
    let turning = examples::ahmadi_2022_turning();
    let milling = examples::schmitz_2023_milling();
    group.bench_function("turning_7150rpm_2mm", |b| {
        b.iter(|| {
            simulate(
                &turning,
                &SimulationSettings::new(7150.0, 2e-3, 1.0, 50_000.0, 1),
            )
        })
    });
    group.bench_function("milling_7000rpm_0.5mm", |b| {
        b.iter(|| {
            simulate(
                &milling,
                &SimulationSettings::new(7000.0, 0.5e-3, 1.0, 50_000.0, 1),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
