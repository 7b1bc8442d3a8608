//! Detection throughput (issue 16): 10 s of 3-channel 50 kHz data (the first three channels of
//! [`SyntheticRecord::four_channel_reference`]) judged stable or chatter; the target is 0.2 s.
use chatter_oma::detection::{DetectionOptions, detect};
use chatter_oma::signals::Signals;
use chatter_oma::synthetic::SyntheticRecord;
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let four = SyntheticRecord::four_channel_reference(50_000.0, 10.0, 1)
        .generate()
        .unwrap_or_else(|e| panic!("reference record: {e}"));
    let signals = Signals::new(
        four.names[..3].to_vec(),
        four.sample_rate_hz,
        four.data[..3].to_vec(),
    )
    .unwrap_or_else(|e| panic!("three channels: {e}"));
    let options = DetectionOptions::new(7150.0 / 60.0);
    let mut group = c.benchmark_group("detect");
    group.sample_size(10);
    group.bench_function("3ch_50khz_10s", |b| b.iter(|| detect(&signals, &options)));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
