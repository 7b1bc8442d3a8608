//! 004 Fig. 2: 4000 zero-order boundaries over 200 speeds from the RCSA prior of the example
//! assembly (the prior itself is built once, outside the timing).
use chatter_rcsa::Assembly;
use chatter_rcsa::prior::{PriorSettings, prior_boundaries, rcsa_prior, three_flute_milling};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/schmitz2022_rcsa_assembly.json");
    let (Ok(assembly), Ok(operation)) = (Assembly::from_path(&path), three_flute_milling(0.75))
    else {
        return;
    };
    let Ok(prior) = rcsa_prior(&assembly, &PriorSettings::default()) else {
        return;
    };
    let speeds: Vec<f64> = (0..200)
        .map(|i| 5000.0 + 20000.0 * f64::from(i) / 199.0)
        .collect();
    let mut group = c.benchmark_group("rcsa_prior");
    group.sample_size(10);
    group.bench_function("map_4000_boundaries_200_speeds", |b| {
        b.iter(|| prior_boundaries(&prior, &operation, &speeds, 4000, 7))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
