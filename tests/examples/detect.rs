//! Chatter detection on simulated cuts over a lobe diagram and on a real record when present:
//! prints the verdict, the chatter frequency and the evidence, and the time of one detection
//! of a 10 s, 50 kHz, 3-channel record.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples;
use chatter_dynamics::simulate::{SimulationSettings, simulate};
use chatter_oma::detection::{DetectionOptions, detect};
use chatter_oma::signals::Signals;
use std::time::Instant;

fn main() {
    let real = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/real/milling_chatter_record/test255_accelY.csv"
    );
    if let Ok(s) = Signals::from_csv(std::path::Path::new(real), 10_000.0) {
        let mut o = DetectionOptions::new(5000.0 / 60.0);
        let d0 = detect(&s, &o).unwrap();
        println!(
            "test255, mains comb searched: {:?} {:?} {:?}",
            d0.verdict, d0.chatter_hz, d0.evidence
        );
        o.interference = chatter_oma::interference::Interference::Known(vec![50.0]);
        let d = detect(&s, &o).unwrap();
        println!(
            "test255: {:?} {:?} {:?}",
            d.verdict, d.chatter_hz, d.evidence
        );
        let v = &d.spectrum.values;
        let mut peaks: Vec<(f64, f64)> = (1..v.len() - 1)
            .filter(|&i| v[i] > v[i - 1] && v[i] >= v[i + 1])
            .map(|i| (d.spectrum.frequencies_hz[i], v[i]))
            .collect();
        peaks.sort_by(|a, b| b.1.total_cmp(&a.1));
        for p in peaks.iter().take(25) {
            println!(
                "  {:.1} Hz ({:.2} f0): {:.3e}",
                p.0,
                p.0 / d.evidence.fundamental_hz,
                p.1
            );
        }
    }
    let model = examples::schmitz_2023_milling();
    for (rpm, b) in [
        (7000.0, 0.5e-3),
        (7000.0, 1.0e-3),
        (7000.0, 2.0e-3),
        (9000.0, 1.0e-3),
        (9000.0, 3e-3),
    ] {
        let s = SimulationSettings::new(rpm, b, 2.0, 20_000.0, 1);
        let sim = simulate(&model, &s).unwrap();
        let sig = Signals::new(
            vec!["x".into(), "y".into()],
            20_000.0,
            sim.channels[..2].iter().map(|c| c.data.clone()).collect(),
        )
        .unwrap();
        let d = detect(&sig, &DetectionOptions::new(rpm / 60.0)).unwrap();
        println!(
            "{rpm} {b}: lost {:.3} {:?} {:?} {:?}",
            sim.lost_contact_fraction, d.verdict, d.chatter_hz, d.evidence
        );
    }
    // speed: 10 s, 50 kHz, 3 channels
    let n = 500_000;
    let data: Vec<Vec<f64>> = (0..3)
        .map(|c| {
            (0..n)
                .map(|k: usize| {
                    let t = k as f64 / 50_000.0;
                    (2.0 * std::f64::consts::PI * 100.0 * t).sin()
                        + 0.3 * (2.0 * std::f64::consts::PI * 1234.5 * t + c as f64).sin()
                        + 0.01 * ((k.wrapping_mul(7919) + c) % 1000) as f64 / 1000.0
                })
                .collect()
        })
        .collect();
    let sig = Signals::new(vec!["a".into(), "b".into(), "c".into()], 50_000.0, data).unwrap();
    let start = Instant::now();
    let d = detect(&sig, &DetectionOptions::new(100.0)).unwrap();
    println!(
        "10 s, 50 kHz, 3 channels: {:.3} s ({:?} at {:?} Hz)",
        start.elapsed().as_secs_f64(),
        d.verdict,
        d.chatter_hz
    );
}
