//! The diagnosis on campaigns observed the way a shop observes them (issue 15, proving ground
//! part b): every test cut of the [`campaign_plan`] is simulated in the time domain
//! (`chatter_dynamics::simulate`: regenerative force with loss of contact, broadband and
//! spindle-harmonic forcing) on the true machine, 10 % measurement noise is added, the record is
//! labelled stable or chatter with its chatter frequency by `chatter_oma::detection`, and the
//! dominant pole of each pole test is identified by modified LSCE (`chatter_oma::identify`)
//! from a long stable record. Nothing of the diagnosis's own prediction path (the
//! characteristic roots or the full discretization) makes the data.
//!
//! Turning machine of the proving ground, model right (a control), 24 cut tests at 8 speeds.
//! Asserted: the observation chain itself (detection labels agree with the sign of ln|mu| of
//! the true model wherever |ln|mu|| > 0.1, i.e. away from the boundary, on >= 85 % of the cuts;
//! chatter frequencies within 1 % of the true dominant root on >= 85 % of the chattering cuts:
//! the limit cycle with loss of contact sits a little below the linear root, and can settle on
//! another root) and the nominal model passing the predictive check on data it did not make.
//! And the verdict `consistent`: the classes' mean evidence beats the nominal model by ln BF 1.3
//! (a Bayes factor of 3.5, from chatter frequencies 0.1-0.25 % below the linear root), under the
//! Bayes factor of 10 needed to reject the nominal model. Pole tests are left out: on this two-mode lathe at 1200-3600 rpm the
//! identified poles include spurious ones (1743 Hz) and ones between roots (see the issue note).
#![allow(clippy::unwrap_used)]

use chatter_dynamics::observations::{Cut, Observations, PoleObservation};
use chatter_dynamics::simulate::{SimulationSettings, simulate};
use chatter_gap::generator::{PlannedKind, campaign_plan, proving_machines, true_variant};
use chatter_gap::predict::inference_solver;
use chatter_gap::{DiagnoseOptions, HiddenEffect, Quiet, Scenario, Validation, diagnose};
use chatter_oma::detection::{DetectionOptions, Verdict, detect};
use chatter_oma::signals::Signals;
use chatter_oma::{Harmonics, IdentifyOptions, identify};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};

/// Output rate of the simulated records (Hz): above twice the highest chatter frequency.
const SAMPLE_RATE_HZ: f64 = 5000.0;
/// Length of a test cut's record (s).
const CUT_S: f64 = 8.0;
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
                let truth_mu = inference_solver(&model)
                    .chatter_frequency_hz(&model, test.speed_rpm, test.depth_m)
                    .map(|(mu, f)| (mu.modulus(), f))
                    .unwrap_or((f64::NAN, f64::NAN));
                let options = DetectionOptions {
                    // finer than the default f0 / 10: the harmonics mask 5 bins each
                    resolution_hz: Some(f0 / 40.0),
                    ..DetectionOptions::new(f0)
                };
                let d = detect(&signals, &options).unwrap();
                obs.cuts.push(Cut {
                    speed_rpm: test.speed_rpm,
                    depth_mm: test.depth_m * 1e3,
                    stable: d.verdict == Verdict::Stable,
                    chatter_hz: d.chatter_hz,
                    sequence: test.sequence,
                    radial_immersion: None,
                    evidence: None,
                    note: Some(format!(
                        "V {:.2}, line {:.1} Hz; true model: |mu| {:.3} at {:.1} Hz",
                        d.evidence.line_variation, d.evidence.peak_hz, truth_mu.0, truth_mu.1
                    )),
                });
            }
            PlannedKind::Pole { .. } => {
                let signals = record(&model, test.speed_rpm, test.depth_m, POLE_S, seed);
                let options = IdentifyOptions {
                    harmonics: Harmonics::Spindle { fundamental_hz: f0 },
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
                let roots = chatter_stability::frequency_domain::mode_poles(
                    &model,
                    test.speed_rpm,
                    test.depth_m,
                )
                .unwrap_or_default();
                eprintln!(
                    "pole {:.0} rpm: identified {:.1} Hz / {:.4}; roots {:?}",
                    test.speed_rpm,
                    e.frequency_hz,
                    e.damping_ratio,
                    roots
                        .iter()
                        .flatten()
                        .map(|r| (r.frequency_hz, r.damping_ratio))
                        .collect::<Vec<_>>()
                );
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

#[test]
fn simulated_turning_control() {
    let machine = proving_machines().unwrap().remove(3);
    let (lo, hi) = machine.speed_range_rpm;
    let effect = HiddenEffect::ParameterError;
    // cut tests only: the poles the OMA identifies on this two-mode lathe at low speed are not
    // yet reliable (see the issue note)
    let mut scenario = Scenario::new(effect, 11).with_speed_range(lo, hi, 0);
    scenario.cuts = 24;
    scenario.speeds = 8;
    let data = observe(&machine.model, &scenario);
    let (mut labels, mut labels_right, mut chatters, mut chatters_right) = (0, 0, 0, 0);
    for c in &data.cuts {
        let model = &machine.model;
        let (mu, f) = inference_solver(model)
            .chatter_frequency_hz(model, c.speed_rpm, c.depth_mm * 1e-3)
            .unwrap();
        let ln_mu = mu.modulus().ln();
        if ln_mu.abs() > 0.1 {
            labels += 1;
            labels_right += usize::from(c.stable == (ln_mu < 0.0));
        }
        if let (Some(detected), false) = (c.chatter_hz, ln_mu < 0.0) {
            chatters += 1;
            chatters_right += usize::from((detected / f - 1.0).abs() < 0.01);
        }
    }
    eprintln!(
        "labels right {labels_right}/{labels} away from the boundary; chatter frequencies \
         within 1 %: {chatters_right}/{chatters}"
    );
    assert!(labels_right as f64 >= 0.85 * labels as f64);
    assert!(chatters > 0 && chatters_right as f64 >= 0.85 * chatters as f64);
    let options = DiagnoseOptions {
        validation: Validation::Off,
        ..DiagnoseOptions::default()
    };
    let d = diagnose(&machine.model, &data, &options, &Quiet).unwrap();
    eprintln!(
        "verdict {} (expected consistent); nominal ln L {:.1}, practical shift {:.2} sd, check {:?}",
        d.verdict.name(),
        d.nominal_log_evidence,
        d.practical_shift,
        d.nominal_check
    );
    for c in &d.classes {
        eprintln!("  {}: ln Z {:.1}", c.name, c.log_evidence);
    }
    assert!(d.nominal_check.passed, "{:?}", d.nominal_check);
    assert_eq!(d.verdict.name(), "consistent");
}
