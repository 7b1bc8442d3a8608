//! The diagnosis on a campaign observed the way a shop observes it (issue 15, proving ground
//! part b; the observation chain is in `shop/mod.rs`; `examples/simulated.rs` runs effects).
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

mod shop;

use chatter_gap::generator::proving_machines;
use chatter_gap::predict::inference_solver;
use chatter_gap::{DiagnoseOptions, HiddenEffect, Scenario, Validation, diagnose};
use chatter_progress::Silent;

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
    let data = shop::observe(&machine.model, &scenario, false);
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
