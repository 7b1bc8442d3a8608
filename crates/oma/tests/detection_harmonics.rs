//! A limit cycle that is not sinusoidal: its second harmonic is the strongest non-synchronous
//! line (loss of contact flattens the vibration, an accelerometer weighs the k-th harmonic by
//! k^2). The detection reports the fundamental. Record built here: harmonics of 80 Hz (forced),
//! a self-excited vibration at 617.3 Hz (amplitude 0.2) with its second harmonic (0.5), 10 %
//! white noise; 4 s at 10 kHz. Tolerance: one frequency bin.
#![allow(clippy::unwrap_used)]

use chatter_oma::detection::{DetectionOptions, Verdict, detect};
use chatter_oma::signals::Signals;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::f64::consts::PI;

#[test]
fn a_limit_cycle_is_reported_at_its_fundamental() {
    let (fs, n, fc) = (10_000.0, 40_000, 617.3);
    for seed in 0..3 {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let data: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 / fs;
                let forced: f64 = (1..=12)
                    .map(|h| (2.0 * PI * 80.0 * h as f64 * t + 0.3 * h as f64).cos() / h as f64)
                    .sum();
                let cycle = 0.2 * (2.0 * PI * fc * t).sin() + 0.5 * (4.0 * PI * fc * t + 1.0).sin();
                let e: f64 = StandardNormal.sample(&mut rng);
                forced + cycle + 0.1 * e
            })
            .collect();
        let signals = Signals::new(vec!["a".into()], fs, vec![data]).unwrap();
        let d = detect(&signals, &DetectionOptions::new(80.0)).unwrap();
        assert_eq!(d.verdict, Verdict::Chatter, "{:?}", d.evidence);
        let f = d.chatter_hz.unwrap();
        assert!(
            (f - fc).abs() <= d.evidence.resolution_hz,
            "seed {seed}: {f} Hz"
        );
    }
}
