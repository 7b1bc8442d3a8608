//! The diagnosis on campaigns observed the way a shop observes them (issue 15, proving ground
//! part b): every test cut of the [`campaign_plan`] is simulated in the time domain
//! (`chatter_dynamics::simulate`: regenerative force with loss of contact, broadband and
//! spindle-harmonic forcing) on the true machine, 10 % measurement noise is added, the record is
//! labelled stable or chatter with its chatter frequency by `chatter_oma::detection`, and the
//! dominant pole of each pole test is identified by modified LSCE (`chatter_oma::identify`)
//! from a long stable record. Nothing of the diagnosis's own prediction path (the
//! characteristic roots or the full discretization) makes the data.
//!
//! Turning machine of the proving ground: a control (the nominal model is right) must be
//! `consistent`, and process damping at 2x must be named. Tolerances are the verdicts
//! themselves; the campaign's detection and OMA figures are printed.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::observations::{Cut, Observations, PoleObservation};
use chatter_dynamics::simulate::{SimulationSettings, simulate};
use chatter_gap::generator::{
    PlannedKind, campaign_plan, effect_at, proving_machines, true_variant,
};
use chatter_gap::{
    DiagnoseOptions, EffectClass, HiddenEffect, Quiet, Recalibration, Scenario, Validation,
    diagnose,
};
use chatter_oma::detection::{DetectionOptions, Verdict, detect};
use chatter_oma::signals::Signals;
use chatter_oma::{Harmonics, IdentifyOptions, identify};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};

/// Output rate of the simulated records (Hz): above twice the highest chatter frequency.
const SAMPLE_RATE_HZ: f64 = 5000.0;
/// Length of a test cut's record (s).
const CUT_S: f64 = 4.0;
/// Length of a pole test's record (s).
const POLE_S: f64 = 16.0;
/// Measurement noise as a fraction of each channel's RMS.
const NOISE: f64 = 0.1;

/// The simulated record of a cut with measurement noise, without the once-per-rev channel.
fn record(
    model: &chatter_dynamics::ModalModel,
    speed_rpm: f64,
    depth_m: f64,
    duration_s: f64,
    seed: u64,
) -> Signals {
    let mut settings =
        SimulationSettings::new(speed_rpm, depth_m, duration_s, SAMPLE_RATE_HZ, seed);
    settings.harmonic_force_n = 5.0;
    let sim = simulate(model, &settings).unwrap();
    let mut rng = StdRng::seed_from_u64(seed ^ 0x5eed);
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
    Signals::new(names, SAMPLE_RATE_HZ, data).unwrap()
}

/// The campaign of `scenario` on `nominal`, every test simulated and read as a shop would.
fn observe(nominal: &chatter_dynamics::ModalModel, scenario: &Scenario) -> Observations {
    let truth = true_variant(nominal, scenario).unwrap();
    let mut obs = Observations::default();
    let mut rng = StdRng::seed_from_u64(scenario.seed);
    for test in campaign_plan(nominal, scenario).unwrap() {
        let model = truth.at(None, test.speed_rpm, test.position).unwrap();
        let seed: u64 = rng.random();
        let f0 = test.speed_rpm / 60.0;
        match test.kind {
            PlannedKind::Cut => {
                let signals = record(&model, test.speed_rpm, test.depth_m, CUT_S, seed);
                let d = detect(&signals, &DetectionOptions::new(f0)).unwrap();
                obs.cuts.push(Cut {
                    speed_rpm: test.speed_rpm,
                    depth_mm: test.depth_m * 1e3,
                    stable: d.verdict == Verdict::Stable,
                    chatter_hz: d.chatter_hz,
                    sequence: test.sequence,
                    radial_immersion: None,
                    note: Some(format!(
                        "V {:.2}, line {:.1} Hz",
                        d.evidence.line_variation, d.evidence.peak_hz
                    )),
                });
            }
            PlannedKind::Pole { .. } => {
                let signals = record(&model, test.speed_rpm, test.depth_m, POLE_S, seed);
                let options = IdentifyOptions {
                    harmonics: Harmonics::Spindle {
                        fundamental_hz: f0,
                        count: 3,
                    },
                    seed,
                    ..IdentifyOptions::default()
                };
                let Ok(id) = identify(&signals, &options) else {
                    eprintln!(
                        "pole at {:.0} rpm: identification failed, skipped",
                        test.speed_rpm
                    );
                    continue;
                };
                let e = id.estimate;
                obs.poles.push(PoleObservation {
                    speed_rpm: test.speed_rpm,
                    depth_mm: test.depth_m * 1e3,
                    frequency_hz: e.frequency_hz,
                    damping_ratio: e.damping_ratio,
                    frequency_std_hz: e.frequency_std_hz,
                    damping_std: e.damping_std,
                    repetitions: u32::try_from(e.repetitions).ok(),
                    sequence: test.sequence,
                    radial_immersion: None,
                    note: None,
                });
            }
        }
    }
    obs
}

fn run(effect: HiddenEffect, error: Recalibration, seed: u64) -> &'static str {
    let machine = proving_machines().unwrap().remove(3);
    let (lo, hi) = machine.speed_range_rpm;
    let mut scenario = Scenario::new(effect, seed).with_speed_range(lo, hi, 4);
    scenario.error = error;
    scenario.cuts = 24;
    scenario.speeds = 8;
    let data = observe(&machine.model, &scenario);
    for c in &data.cuts {
        eprintln!(
            "cut {:.0} rpm {:.3} mm: {} {:?} ({})",
            c.speed_rpm,
            c.depth_mm,
            if c.stable { "stable" } else { "chatter" },
            c.chatter_hz,
            c.note.as_deref().unwrap_or("")
        );
    }
    for p in &data.poles {
        eprintln!(
            "pole {:.0} rpm {:.3} mm: {:.1} Hz ({:?}), zeta {:.4} ({:?})",
            p.speed_rpm,
            p.depth_mm,
            p.frequency_hz,
            p.frequency_std_hz,
            p.damping_ratio,
            p.damping_std
        );
    }
    let options = DiagnoseOptions {
        validation: Validation::Off,
        ..DiagnoseOptions::default()
    };
    let d = diagnose(&machine.model, &data, &options, &Quiet).unwrap();
    eprintln!(
        "verdict {} (expected {}); nominal check {:?}",
        d.verdict.name(),
        effect.expected_verdict(&error),
        d.nominal_check
    );
    for c in &d.classes {
        eprintln!("  {}: ln Z {:.1}", c.name, c.log_evidence);
    }
    d.verdict.name()
}

#[test]
fn simulated_turning_control_is_consistent() {
    assert_eq!(
        run(HiddenEffect::ParameterError, Recalibration::default(), 11),
        "consistent"
    );
}

#[test]
fn simulated_turning_process_damping_is_named() {
    let machine = proving_machines().unwrap().remove(3);
    let (effect, error) = effect_at(
        EffectClass::ProcessDamping,
        2.0,
        &machine.model,
        machine.speed_range_rpm,
    )
    .unwrap();
    assert_eq!(run(effect, error, 12), "process_damping");
}
