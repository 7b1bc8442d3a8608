//! The simulator's physics does not depend on the output rate: seed 000's P3 cut (6950 rpm,
//! 2.54 mm, Table 1 model) simulated at 10 kHz and at 100 kHz and identified by the CLI's
//! default OMA (which decimates the 100 kHz record itself, by 5: the 2.5 kHz pole at 2.5 % of
//! the rate is identified 200 % too damped by LSCE on the raw record) gives the model's dominant closed-loop pole (characteristic equation,
//! `chatter_stability::frequency_domain::dominant_pole`, 000 Eq. 5-6: 2497.5 Hz, zeta 0.0038)
//! within 0.2 % in frequency and 10 % in damping at both rates. The identification's own
//! scatter is about 1.4 / sqrt(zeta omega T) (see `white_noise.rs`) and its order choice
//! adds more (one 64 s record gave +5.3 % at 10 kHz and -13.9 % at 100 kHz although the two
//! records agree within 1 %), so the check is on the mean over four 32 s records (seeds 3-6);
//! the same seeds at both rates give the same internal trajectories.
//!
//! Before the internal step was decoupled from the output rate (and the regenerative force held
//! over each step), the same check gave the damping 31 % low at 10 kHz and 5 % low at 100 kHz.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples::ahmadi_2022_turning;
use chatter_dynamics::simulate::{SimulationSettings, simulate};
use chatter_oma::signals::Signals;
use chatter_oma::{Harmonics, IdentifyOptions, identify};
use chatter_stability::frequency_domain::dominant_pole;
use std::f64::consts::PI;

/// Low-pass (Hamming-windowed sinc, cutoff 0.4 of the new rate, 20 taps per output period
/// each side) and keep every `factor`-th sample; `factor` 1 returns the record.
fn decimate(x: &[f64], factor: usize) -> Vec<f64> {
    if factor == 1 {
        return x.to_vec();
    }
    let half = 20 * factor;
    let fc = 0.4 / factor as f64; // cycles per input sample
    let taps: Vec<f64> = (0..=2 * half)
        .map(|i| {
            let k = i as f64 - half as f64;
            let sinc = if k == 0.0 {
                2.0 * fc
            } else {
                (2.0 * PI * fc * k).sin() / (PI * k)
            };
            sinc * (0.54 + 0.46 * (PI * k / half as f64).cos())
        })
        .collect();
    let gain: f64 = taps.iter().sum();
    (half..x.len() - half)
        .step_by(factor)
        .map(|n| {
            taps.iter()
                .enumerate()
                .map(|(i, t)| t * x[n + i - half])
                .sum::<f64>()
                / gain
        })
        .collect()
}

fn identified(sample_rate_hz: f64, duration_s: f64, seed: u64) -> (f64, f64) {
    let (speed_rpm, depth_mm) = (6950.0, 2.54);
    let model = ahmadi_2022_turning();
    let mut settings =
        SimulationSettings::new(speed_rpm, depth_mm * 1e-3, duration_s, sample_rate_hz, seed);
    settings.harmonic_force_n = 5.0;
    let sim = simulate(&model, &settings).unwrap();
    assert_eq!(sim.lost_contact_fraction, 0.0);
    let coordinates = &sim.channels[..2];
    let signals = Signals::new(
        coordinates.iter().map(|c| c.name.clone()).collect(),
        sample_rate_hz,
        coordinates.iter().map(|c| c.data.clone()).collect(),
    )
    .unwrap();
    let options = IdentifyOptions {
        harmonics: Harmonics::Spindle {
            fundamental_hz: speed_rpm / 60.0,
        },
        seed,
        ..IdentifyOptions::default()
    };
    let id = identify(&signals, &options).unwrap();
    eprintln!(
        "{sample_rate_hz} Hz seed {seed}: decimated by {}, order {}, harmonics {:?}",
        id.decimation_factor, id.order, id.harmonics_hz
    );
    (id.estimate.frequency_hz, id.estimate.damping_ratio)
}

/// Mean over `seeds` of the identified frequency and damping against the model's pole.
fn check(sample_rate_hz: f64, duration_s: f64, seeds: &[u64]) {
    let model = ahmadi_2022_turning();
    let pole = dominant_pole(&model, 6950.0, 2.54e-3).unwrap();
    let (mut f_sum, mut z_sum) = (0.0, 0.0);
    for &seed in seeds {
        let (f, zeta) = identified(sample_rate_hz, duration_s, seed);
        eprintln!(
            "{sample_rate_hz} Hz, seed {seed}: identified {f:.2} Hz, zeta {zeta:.5}; errors \
             {:+.3} % and {:+.1} %",
            100.0 * (f / pole.frequency_hz - 1.0),
            100.0 * (zeta / pole.damping_ratio - 1.0)
        );
        f_sum += f;
        z_sum += zeta;
    }
    let (f, zeta) = (f_sum / seeds.len() as f64, z_sum / seeds.len() as f64);
    let (ef, ez) = (f / pole.frequency_hz - 1.0, zeta / pole.damping_ratio - 1.0);
    eprintln!(
        "{sample_rate_hz} Hz mean: {f:.2} Hz, zeta {zeta:.5}; model {:.2} Hz, zeta {:.5}; \
         errors {:+.3} % and {:+.1} %",
        pole.frequency_hz,
        pole.damping_ratio,
        100.0 * ef,
        100.0 * ez
    );
    assert!(ef.abs() < 0.002, "frequency error {ef}");
    assert!(ez.abs() < 0.10, "damping error {ez}");
}

#[test]
fn p3_identified_at_10_khz() {
    check(10_000.0, 32.0, &[3, 4, 5, 6]);
}

#[test]
fn p3_identified_at_100_khz() {
    check(100_000.0, 32.0, &[3, 4, 5, 6]);
}

/// Same seed, same internal trajectory: the 10 kHz record equals the 100 kHz one low-passed
/// and decimated by 10 in the test, within 1 % of the RMS (the two anti-aliasing filters
/// differ in the transition band only).
#[test]
fn ten_khz_record_is_the_decimated_100_khz_record() {
    let model = ahmadi_2022_turning();
    let run = |fs: f64| {
        let mut s = SimulationSettings::new(6950.0, 2.54e-3, 0.5, fs, 9);
        s.harmonic_force_n = 5.0;
        simulate(&model, &s).unwrap().channels[0].data.clone()
    };
    let slow = run(10_000.0);
    let fast = decimate(&run(100_000.0), 10);
    // decimate drops 20 output periods at the start
    let (a, b) = (&slow[20..20 + fast.len() - 40], &fast[..fast.len() - 40]);
    let rms = (a.iter().map(|v| v * v).sum::<f64>() / a.len() as f64).sqrt();
    let err = (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt();
    assert!(err < 0.01 * rms, "{err} vs {rms}");
}
