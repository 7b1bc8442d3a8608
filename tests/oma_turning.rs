//! Turning (seed 000): stable cuts at conditions of Table 2 simulated with the Table 1 model
//! (`chatter_dynamics::examples::ahmadi_2022_turning`, kt 635 and kn 159 N/mm^2); the
//! identified dominant pole matches the closed-loop pole of the characteristic equation
//! (`chatter_stability::frequency_domain::dominant_pole`, 000 Eq. 5-6): frequency within 0.5 %,
//! damping within 25 %.
//!
//! Conditions. The damping scatter of an identification from T seconds is about
//! 1.4 / sqrt(zeta omega T) (see `white_noise.rs`), so the very lightly damped poles of Table 2
//! (7150 rpm / 2.286 mm: zeta omega = 12 1/s; 7150 / 2.54: 5 1/s; 7500 / 2.54: 4 1/s) would need
//! minutes of signal for a 25 % check. 6950 rpm / 2.54 mm (2497.5 Hz, zeta 0.0038, 59 1/s; a
//! second pole at 2427.7 Hz, 72 1/s, makes it a resolution test) and 7500 rpm / 2.032 mm
//! (2465.3 Hz, zeta 0.0012, 19 1/s) are checked with 32 s and 24 s: over seeds 3-8 the
//! identified damping then lies within -14..+7 % and -10..+12 % of the model's.
//!
//! Simulation. The cuts are simulated at 100 kHz and averaged over blocks of ten samples (an
//! anti-aliasing FIR filter that leaves the poles alone): the 10 kHz record the identification
//! sees. Since the simulator's internal step no longer depends on the output rate (see
//! `output_rate.rs`), a 10 kHz simulation would do as well; the block average is kept so that
//! these figures stay comparable with the earlier ones. The spindle harmonics forced by the
//! simulator (1-4 times the spindle frequency) are lines of the record and are imposed.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples::ahmadi_2022_turning;
use chatter_dynamics::simulate::{SimulationSettings, simulate};
use chatter_oma::signals::Signals;
use chatter_oma::{Harmonics, IdentifyOptions, identify};
use chatter_stability::frequency_domain::dominant_pole;

const FS_HZ: f64 = 10_000.0;
const OVERSAMPLING: usize = 10;

/// Simulate the cut, identify its dominant pole with the spindle harmonics as the CLI does, and
/// compare with the characteristic equation.
fn check(speed_rpm: f64, depth_mm: f64, duration_s: f64, seed: u64) {
    let model = ahmadi_2022_turning();
    let mut settings = SimulationSettings::new(
        speed_rpm,
        depth_mm * 1e-3,
        duration_s,
        FS_HZ * OVERSAMPLING as f64,
        seed,
    );
    settings.harmonic_force_n = 5.0;
    let sim = simulate(&model, &settings).unwrap();
    assert_eq!(sim.lost_contact_fraction, 0.0);
    let coordinates = &sim.channels[..2];
    let signals = Signals::new(
        coordinates.iter().map(|c| c.name.clone()).collect(),
        FS_HZ,
        coordinates
            .iter()
            .map(|c| {
                c.data
                    .chunks_exact(OVERSAMPLING)
                    .map(|block| block.iter().sum::<f64>() / OVERSAMPLING as f64)
                    .collect()
            })
            .collect(),
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
    // the lines imposed are the harmonics the simulator forces (1-4 times the spindle frequency)
    let f0 = speed_rpm / 60.0;
    assert!(
        id.harmonics_hz
            .iter()
            .all(|h| (1..=4).any(|k| (h - k as f64 * f0).abs() < 1e-9)),
        "{:?}",
        id.harmonics_hz
    );
    let model_pole = dominant_pole(&model, speed_rpm, depth_mm * 1e-3).unwrap();
    let e = id.estimate;
    eprintln!(
        "{speed_rpm} rpm / {depth_mm} mm: identified {:.2} Hz (std {:.2}), zeta {:.5} (std {:.5}) \
         at order {} with {} lags, harmonics {:?}; model {:.2} Hz, zeta {:.5}",
        e.frequency_hz,
        e.frequency_std_hz.unwrap_or(0.0),
        e.damping_ratio,
        e.damping_std.unwrap_or(0.0),
        id.order,
        id.segment_lags,
        id.harmonics_hz,
        model_pole.frequency_hz,
        model_pole.damping_ratio
    );
    assert!(
        (e.frequency_hz - model_pole.frequency_hz).abs() < 0.005 * model_pole.frequency_hz,
        "{e:?} vs {model_pole:?}"
    );
    assert!(
        (e.damping_ratio - model_pole.damping_ratio).abs() < 0.25 * model_pole.damping_ratio,
        "{e:?} vs {model_pole:?}"
    );
}

#[test]
fn p3_6950_rpm_2_54_mm() {
    check(6950.0, 2.54, 32.0, 3);
}

#[test]
fn p4_7500_rpm_2_032_mm() {
    check(7500.0, 2.032, 24.0, 4);
}
