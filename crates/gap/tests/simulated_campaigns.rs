//! The diagnosis on a campaign observed the way a shop observes it (issue 15, proving ground
//! part b; the observation chain is in `shop/mod.rs`; `examples/simulated.rs` runs effects).
//!
//! Turning machine of the proving ground, model right (a control), 24 cut tests at 8 speeds and
//! 8 pole tests (4 speeds x 0.3 and 0.6 of the true limiting depth).
//! Asserted: the observation chain itself (detection labels agree with the sign of ln|mu| of
//! the true model wherever |ln|mu|| > 0.1, i.e. away from the boundary, on >= 85 % of the cuts;
//! chatter frequencies within 1 % of the true dominant root on >= 85 % of the chattering cuts:
//! the limit cycle with loss of contact sits a little below the linear root, and can settle on
//! another root) and the nominal model passing the predictive check on data it did not make.
//! And the verdict `consistent`: the classes' mean evidence beats the nominal model by ln BF 1.3
//! (a Bayes factor of 3.5, from chatter frequencies 0.1-0.25 % below the linear root), under the
//! Bayes factor of 10 needed to reject the nominal model. The poles, identified by OMA (the
//! spectral peak under the dominant LSCE pole, see `shop/mod.rs`), are checked against the
//! exact truth (the gap generator's refined semi-discretization, the resonance multiplier at the
//! test's speed and depth; not the inference's solver): all 8 reported, frequencies within 0.5 %
//! (measured 0.0-0.3 %) and damping within a factor 1.5 (measured 0.9-1.4).
#![allow(clippy::unwrap_used)]

mod shop;

use chatter_gap::generator::{proving_machines, truth_solver};
use chatter_gap::predict::inference_solver;
use chatter_gap::{DiagnoseOptions, HiddenEffect, Scenario, Validation, diagnose};
use chatter_progress::Silent;
use std::f64::consts::PI;

#[test]
fn simulated_turning_control() {
    let machine = proving_machines().unwrap().remove(3);
    let (lo, hi) = machine.speed_range_rpm;
    let effect = HiddenEffect::ParameterError;
    let mut scenario = Scenario::new(effect, 11).with_speed_range(lo, hi, 4);
    scenario.cuts = 24;
    scenario.speeds = 8;
    let data = shop::observe(&machine.model, &scenario, true);
    let model = &machine.model;
    let mut poles_right = 0;
    for p in &data.poles {
        let depth_m = p.depth_mm * 1e-3;
        let (mu, f) = truth_solver(model, p.speed_rpm)
            .resonance_frequency_hz(model, p.speed_rpm, depth_m)
            .unwrap();
        let re = mu.modulus().ln() / mu.period_s;
        let zeta = -re / (re * re + (2.0 * PI * f).powi(2)).sqrt();
        eprintln!(
            "pole {:.0} rpm {:.3} mm: identified {:.1} Hz / {:.4}, truth {:.1} Hz / {:.4} ({})",
            p.speed_rpm,
            p.depth_mm,
            p.frequency_hz,
            p.damping_ratio,
            f,
            zeta,
            p.note.as_deref().unwrap_or("")
        );
        let ratio = p.damping_ratio / zeta;
        poles_right += usize::from(
            (p.frequency_hz / f - 1.0).abs() < 0.005 && (1.0 / 1.5..=1.5).contains(&ratio),
        );
    }
    assert_eq!(data.poles.len(), 8);
    assert_eq!(poles_right, 8, "poles right {poles_right}/8");
    let (mut labels, mut labels_right, mut chatters, mut chatters_right) = (0, 0, 0, 0);
    for c in &data.cuts {
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
    let d = diagnose(&machine.model, &data, &options, &Silent).unwrap();
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
