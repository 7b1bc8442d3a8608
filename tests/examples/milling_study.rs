//! Chatter detection and lifted OMA on simulated milling records of the proving ground's xy
//! machine (issue 15, part b: x 650 Hz / 0.025 / 8e6 N/m, y 720 Hz / 0.03 / 1.1e7 N/m, 4 teeth,
//! 30 % down milling, kt 700 MPa, kn 210 MPa; `chatter_gap::generator::proving_machines()[0]`,
//! rebuilt here because this crate does not depend on chatter-gap), observed as the gap shop
//! chain observes it (`crates/gap/tests/shop`: 5 kHz, 10 % noise, 5 N spindle harmonics).
//! Truth: the dominant multiplier of the first-order full discretization at 4x its automatic
//! resolution (`chatter_stability`), independent of the simulator and of the OMA.
//!
//! `cargo run --release -p chatter-integration --example milling_study -- [--speeds 12] [--seconds 8]
//! [--poles]`: one line per record (speed, depth ratio, truth kind, |mu|, chatter frequency,
//! detection verdict, flip evidence); with `--poles`, lifted OMA on 16 s stable records against
//! the truth's multiplier.

#![allow(clippy::unwrap_used)]

use chatter_dynamics::simulate::{SimulationSettings, simulate};
use chatter_dynamics::{
    CuttingCoefficients, Milling, MillingDirection, ModalModel, Mode, ModeShape, Operation,
};
use chatter_oma::detection::{DetectionOptions, Verdict, detect};
use chatter_oma::signals::Signals;
use chatter_oma::{IdentifyOptions, identify};
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::monodromy::{Discretization, steps, steps_at_least};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use std::f64::consts::PI;

const FS_HZ: f64 = 5000.0;
const NOISE: f64 = 0.1;

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

fn machine() -> ModalModel {
    let mode = |f, z, k, coordinate| {
        Mode::new(
            f,
            z,
            ModeShape::Directional {
                coordinate,
                stiffness_n_per_m: k,
            },
        )
        .unwrap()
    };
    ModalModel::new(
        None,
        Operation::Milling(
            Milling::new(4, 0.3, MillingDirection::Down, Some(0.0127), None).unwrap(),
        ),
        CuttingCoefficients::new(700e6, 210e6).unwrap(),
        vec![mode(650.0, 0.025, 8e6, 0), mode(720.0, 0.03, 1.1e7, 1)],
        None,
    )
    .unwrap()
}

/// The truth's solver: the full discretization at 4x its automatic resolution (at least 200).
fn truth(model: &ModalModel, speed_rpm: f64) -> Discretization {
    let m = Discretization::full().steps_at(model, speed_rpm);
    Discretization::full().with_steps(steps_at_least(4 * m.get(), steps::<200>()))
}

fn record(model: &ModalModel, speed_rpm: f64, depth_m: f64, seconds: f64, seed: u64) -> Signals {
    let mut settings = SimulationSettings::new(speed_rpm, depth_m, seconds, FS_HZ, seed);
    settings.harmonic_force_n = 5.0;
    let sim = simulate(model, &settings).unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed ^ 0x5eed);
    let (names, data): (Vec<String>, Vec<Vec<f64>>) = sim
        .channels
        .into_iter()
        .filter(|c| c.name != "once_per_rev")
        .map(|c| {
            let rms = (c.data.iter().map(|v| v * v).sum::<f64>() / c.data.len() as f64).sqrt();
            let noisy = c
                .data
                .iter()
                .map(|v| {
                    let e: f64 = StandardNormal.sample(&mut rng);
                    v + NOISE * rms * e
                })
                .collect();
            (c.name, noisy)
        })
        .unzip();
    Signals::new(names, FS_HZ, data).unwrap()
}

fn main() {
    let model = machine();
    let speeds: usize = arg("--speeds").and_then(|s| s.parse().ok()).unwrap_or(12);
    let seconds: f64 = arg("--seconds").and_then(|s| s.parse().ok()).unwrap_or(8.0);
    let poles = std::env::args().any(|a| a == "--poles");
    let ratios: Vec<f64> = if poles {
        vec![0.5, 0.85]
    } else {
        vec![0.5, 0.7, 0.85, 1.2, 1.35, 1.5]
    };
    let jobs: Vec<(f64, f64, f64, u64)> = (0..speeds)
        .flat_map(|i| {
            let s = 3000.0 + 9000.0 * (i as f64 + 0.5) / speeds as f64;
            let b_lim = limiting_depth(&truth(&model, s), &model, s, &BoundaryOptions::default())
                .unwrap()
                .depth_m;
            ratios
                .iter()
                .enumerate()
                .map(move |(j, &r)| (s, b_lim, r, (100 * i + j) as u64))
                .collect::<Vec<_>>()
        })
        .collect();
    let lines: Vec<String> = jobs
        .par_iter()
        .map(|&(s, b_lim, r, seed)| {
            let depth = r * b_lim;
            let solver = truth(&model, s);
            let (mu, f_chatter) = solver.chatter_frequency_hz(&model, s, depth).unwrap();
            let f0 = s / 60.0;
            if poles {
                let signals = record(&model, s, depth, 16.0, seed);
                let tooth_s = 60.0 / s / 4.0;
                let options = IdentifyOptions {
                    seed,
                    ..IdentifyOptions::lifted(tooth_s, 4)
                };
                let truth_z = -mu.modulus().ln()
                    / (mu.modulus().ln().powi(2)
                        + (2.0 * PI * mu.principal_frequency_hz() * tooth_s).powi(2))
                    .sqrt();
                let truth_phys_z = -mu.modulus().ln() / tooth_s / (2.0 * PI * f_chatter);
                return match identify(&signals, &options) {
                    Ok(id) => {
                        let e = id.estimate;
                        format!(
                            "{s:7.0} rpm {r:.2} b_lim: truth mu {:.4}{:+.4}i |mu| {:.4} f_mu {:.2} Hz \
                             zeta(principal) {:.4} zeta(physical {:.1} Hz) {:.4} | OMA mu {:.4}{:+.4}i \
                             |mu| {:.4} f_mu {:.2} Hz f {:.1} Hz zeta {:.4} reps {}",
                            mu.value.re,
                            mu.value.im,
                            mu.modulus(),
                            mu.principal_frequency_hz(),
                            truth_z,
                            f_chatter,
                            truth_phys_z,
                            e.multiplier.re,
                            e.multiplier.im,
                            e.multiplier.norm(),
                            e.principal_frequency_hz,
                            e.frequency_hz,
                            e.damping_ratio,
                            e.repetitions
                        )
                    }
                    Err(err) => format!("{s:7.0} rpm {r:.2} b_lim: OMA failed: {err}"),
                };
            }
            let signals = record(&model, s, depth, seconds, seed);
            let options = DetectionOptions {
                resolution_hz: Some(f0 / 40.0),
                teeth: Some(4),
                ..DetectionOptions::new(f0)
            };
            let d = detect(&signals, &options).unwrap();
            let e = &d.evidence;
            let expected = if r < 1.0 { Verdict::Stable } else { Verdict::Chatter };
            let flip = e.flip.as_ref().map_or(String::new(), |f| {
                format!(
                    "flip line {:.1} Hz floor {:+.1} dB forced {:+.1} dB runout {:+.1} dB V {:.2}",
                    f.line_hz,
                    f.line_to_floor_db,
                    f.line_to_forced_db,
                    f.line_to_runout_db.unwrap_or(f64::NAN),
                    f.line_variation
                )
            });
            let windows = e.windows.as_ref().map_or(String::new(), |w| {
                format!(
                    "windows margin {:?} span {:?} [{}]",
                    w.margin.map(|m| (m * 100.0).round() / 100.0),
                    w.chatter.as_ref().map(|c| (c.start_s, c.end_s, c.line_hz)),
                    w.windows
                        .iter()
                        .map(|j| format!(
                            "{:.0}:{:.1}",
                            j.line_hz,
                            j.line_variation.unwrap_or(f64::NAN)
                        ))
                        .collect::<Vec<_>>()
                        .join(" ")
                )
            });
            format!(
                "{s:7.0} rpm {r:.2} b_lim: truth {:?} |mu| {:.3} f {:.1} Hz | {:?}{} at {:?} line {:.1} V {:.2} \
                 margin {:+.2} | {flip} | {windows}",
                mu.kind(),
                mu.modulus(),
                f_chatter,
                d.verdict,
                if d.verdict == expected { "" } else { " WRONG" },
                d.chatter_hz.map(|f| (f * 10.0).round() / 10.0),
                e.peak_hz,
                e.line_variation,
                e.margin
            )
        })
        .collect();
    for l in lines {
        println!("{l}");
    }
}
