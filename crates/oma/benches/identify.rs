//! Identification throughput (issue 4): 10 s of 4-channel 50 kHz data
//! ([`SyntheticRecord::four_channel_reference`]: three modes, two spindle harmonics, 10 % noise)
//! identified with model orders up to 40 (whole-record diagrams, spindle-harmonic search and ten
//! half-record segments).
use chatter_oma::synthetic::SyntheticRecord;
use chatter_oma::{Harmonics, IdentifyOptions, identify};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let signals = SyntheticRecord::four_channel_reference(50_000.0, 10.0, 1)
        .generate()
        .unwrap_or_else(|e| panic!("reference record: {e}"));
    let options = IdentifyOptions {
        max_order: 40,
        harmonics: Harmonics::Spindle {
            fundamental_hz: 7150.0 / 60.0,
        },
        ..IdentifyOptions::default()
    };
    let mut group = c.benchmark_group("identify");
    group.sample_size(10);
    group.bench_function("4ch_50khz_10s_order40", |b| {
        b.iter(|| identify(&signals, &options))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
