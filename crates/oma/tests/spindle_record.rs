//! The record of issue 16, rebuilt from its description: one mode at 800 Hz with zeta 0.02, a
//! unit white-noise force, the acceleration recorded (so the force feeds through to the output),
//! a 78 Hz spindle whose 9th, 10th and 11th harmonics (702, 780 and 858 Hz: the 780 Hz one
//! inside the mode's half-power band, 800 +- 16 Hz) are forced lines, 10 % measurement noise,
//! 10 240 Hz sampling, 10 s.
//!
//! No inverse crime: the record comes from the closed-form transition of the SDOF written here
//! (zero-order hold of the force, exact for the sampled state), not from
//! [`chatter_oma::synthetic`] (matrix exponential) or the crate under test.
#![allow(clippy::unwrap_used)]

use chatter_oma::identify::Rejection;
use chatter_oma::signals::Signals;
use chatter_oma::{Harmonics, IdentifyOptions, identify};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::f64::consts::PI;

const F_HZ: f64 = 800.0;
const ZETA: f64 = 0.02;
const FS_HZ: f64 = 10_240.0;
const DURATION_S: f64 = 10.0;
const SPINDLE_HZ: f64 = 78.0;
const LINES_HZ: [f64; 3] = [702.0, 780.0, 858.0];
const NOISE: f64 = 0.1;

/// The acceleration record of seed `seed`: each harmonic with an amplitude equal to the RMS of
/// the modal acceleration, phases 0, 1 and 2 rad.
fn record(seed: u64) -> Signals {
    let w = 2.0 * PI * F_HZ;
    let sigma = ZETA * w;
    let wd = w * (1.0 - ZETA * ZETA).sqrt();
    let ts = 1.0 / FS_HZ;
    // q'' + 2 sigma q' + w^2 q = f, f held over each step: x(k+1) = Phi x(k) + Gamma f(k)
    let (e, c, s) = ((-sigma * ts).exp(), (wd * ts).cos(), (wd * ts).sin());
    let phi = [
        e * (c + sigma / wd * s),
        e * s / wd,
        -e * w * w / wd * s,
        e * (c - sigma / wd * s),
    ];
    let gamma = [(1.0 - phi[3] - 2.0 * sigma * phi[1]) / (w * w), phi[1]];
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let n = (DURATION_S * FS_HZ) as usize;
    // ten decay times to reach the stationary state
    let warmup = (10.0 / sigma / ts) as usize;
    let (mut q, mut qd) = (0.0, 0.0);
    let mut a = Vec::with_capacity(n);
    for k in 0..warmup + n {
        let f: f64 = StandardNormal.sample(&mut rng);
        if k >= warmup {
            a.push(f - 2.0 * sigma * qd - w * w * q);
        }
        (q, qd) = (
            phi[0] * q + phi[1] * qd + gamma[0] * f,
            phi[2] * q + phi[3] * qd + gamma[1] * f,
        );
    }
    let rms = (a.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
    for (k, v) in a.iter_mut().enumerate() {
        let t = k as f64 * ts;
        let lines: f64 = LINES_HZ
            .iter()
            .enumerate()
            .map(|(i, f)| (2.0 * PI * f * t + i as f64).cos())
            .sum();
        let noise: f64 = StandardNormal.sample(&mut rng);
        *v += rms * (lines + NOISE * noise);
    }
    Signals::new(vec!["a".into()], FS_HZ, vec![a]).unwrap()
}

fn options(seed: u64) -> IdentifyOptions {
    IdentifyOptions {
        harmonics: Harmonics::Spindle {
            fundamental_hz: SPINDLE_HZ,
        },
        seed,
        ..IdentifyOptions::default()
    }
}

/// Seeds 0-9 with the CLI's options (spindle harmonics found as lines and imposed, 10 segments
/// of half the record): every harmonic imposed, the 780 Hz one next to the mode included; the
/// noise clusters at the upper band edge (4.7-5.1 kHz, zeta about 0.01, the kind of pole the
/// issue got) rejected at the band edge, the clusters of the noise floor below it (0.5-4.6 kHz)
/// by their spectral support; the pole within 0.5 % in frequency (the issue's tolerance) in every
/// seed, the median absolute damping error at most 8 % (the issue's), and at least 7 of the 10
/// seeds within 15 % in damping (the issue's tolerance for its one record; the scatter of a
/// 10 s record at this damping is about 1.4 / sqrt(zeta omega T) = 4.4 % for a clean single
/// mode, and the notch of the 780 Hz harmonic inside the mode's band and the force feed-through
/// widen it: seeds 0 and 1 give +16 %, seed 1 between +18 and +31 % at orders 15-20).
#[test]
fn issue_record_pole_over_ten_seeds() {
    let mut errors = Vec::new();
    for seed in 0..10 {
        let id = identify(&record(seed), &options(seed)).unwrap();
        let e = id.estimate;
        let (ef, ez) = (e.frequency_hz / F_HZ - 1.0, e.damping_ratio / ZETA - 1.0);
        eprintln!(
            "seed {seed}: {:.2} Hz ({:+.2} %), zeta {:.5} ({:+.1} %), order {}, lags {}, \
             harmonics {:?}, rejected {:?}",
            e.frequency_hz,
            100.0 * ef,
            e.damping_ratio,
            100.0 * ez,
            id.order,
            id.segment_lags,
            id.harmonics_hz,
            id.rejected
                .iter()
                .map(|r| (r.frequency_hz.round(), r.reason))
                .collect::<Vec<_>>()
        );
        assert_eq!(id.harmonics_hz, LINES_HZ.to_vec());
        assert!(ef.abs() < 0.005, "seed {seed}: {e:?}");
        // passed over: band-edge clusters and clusters of the noise floor, never the mode
        assert!(
            id.rejected.iter().all(|r| {
                matches!(r.reason, Rejection::BandEdge | Rejection::NoiseFloor)
                    && (r.frequency_hz / F_HZ - 1.0).abs() > 0.1
            }),
            "seed {seed}: {:?}",
            id.rejected
        );
        errors.push(ez.abs());
    }
    errors.sort_by(f64::total_cmp);
    let median = 0.5 * (errors[4] + errors[5]);
    eprintln!("median absolute damping error {:.2} %", 100.0 * median);
    assert!(median <= 0.08, "{errors:?}");
    assert!(
        errors.iter().filter(|e| **e < 0.15).count() >= 7,
        "{errors:?}"
    );
}

/// Control, seed 0: the 780 Hz line inside the mode's band is what matters. Imposing 702, 780
/// and 858 Hz gives the damping within 20 % (+16 %); imposing 702 and 858 Hz alone (the
/// issue's imposed set) leaves the 780 Hz line to be fitted as a free pole next to the mode,
/// and the damping comes out wrong by more than 50 % (-88 %), or no pole at all.
#[test]
fn every_harmonic_in_the_band_is_needed() {
    let signals = record(0);
    let run = |harmonics: Harmonics| {
        let o = IdentifyOptions {
            harmonics,
            ..options(0)
        };
        identify(&signals, &o).map(|id| id.estimate.damping_ratio / ZETA - 1.0)
    };
    let all = run(Harmonics::Known(LINES_HZ.to_vec())).unwrap();
    let outer = run(Harmonics::Known(vec![702.0, 858.0]));
    eprintln!(
        "all three: {:+.1} %, 702 and 858 only: {outer:?}",
        100.0 * all
    );
    assert!(all.abs() < 0.2);
    assert!(outer.is_err() || outer.unwrap().abs() > 0.5);
}
