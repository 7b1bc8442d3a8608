//! The diagnosis on campaigns observed the way a shop observes them (issue 15, proving ground
//! part b): every cut simulated in the time domain with loss of contact, spindle harmonics and
//! 10 % measurement noise, labelled by chatter detection, and (with `--poles`) pole tests
//! identified by OMA from long stable records (`tests/shop/mod.rs`). A control (the nominal
//! model is right) and hidden effects at the chosen magnitudes, one campaign each.
//!
//! `cargo run --release -p chatter-gap --example simulated [-- --machines 0,3
//! --classes parameter_error,process_damping --magnitudes 1,2 --cuts 24 --poles --seeds 1 --verbose]`

#![allow(clippy::unwrap_used)]

#[path = "../tests/shop/mod.rs"]
mod shop;

mod common;

use chatter_gap::generator::proving_machines;
use chatter_gap::{DiagnoseOptions, EffectClass, Scenario, Validation, diagnose};
use chatter_progress::Silent;
use common::{arg, list};
use std::time::Instant;

fn main() -> chatter_gap::Result<()> {
    let machines = proving_machines()?;
    let pick: Vec<usize> = list("--machines", vec![0, 3]);
    let classes: Vec<EffectClass> = list(
        "--classes",
        vec![EffectClass::ParameterError, EffectClass::ProcessDamping],
    );
    let magnitudes: Vec<f64> = list("--magnitudes", vec![1.0, 2.0]);
    let cuts: usize = arg("--cuts").and_then(|s| s.parse().ok()).unwrap_or(24);
    let seeds: u64 = arg("--seeds").and_then(|s| s.parse().ok()).unwrap_or(1);
    let poles = std::env::args().any(|a| a == "--poles");
    let verbose = std::env::args().any(|a| a == "--verbose");
    let options = DiagnoseOptions {
        validation: Validation::Off,
        ..DiagnoseOptions::default()
    };
    println!(
        "machine | case | magnitude | expected | verdict | cuts (chatter) | poles | ln BF vs nominal \
         | nominal check | practical shift (sd) | seconds"
    );
    let (mut right, mut total) = (0, 0);
    for &mi in &pick {
        let machine = &machines[mi];
        let (lo, hi) = machine.speed_range_rpm;
        let cases = machine.cases(&classes, &magnitudes)?;
        for (name, magnitude, effect, error) in cases {
            for seed in 0..seeds {
                let start = Instant::now();
                let pole_speeds = if poles { 4 } else { 0 };
                let mut scenario =
                    Scenario::new(effect, 2000 + seed).with_speed_range(lo, hi, pole_speeds);
                scenario.error = error;
                scenario.cuts = cuts;
                scenario.speeds = (cuts / 3).max(1);
                let data = shop::observe(&machine.model, &scenario, poles);
                let d = diagnose(
                    &machine.model,
                    &data,
                    &DiagnoseOptions {
                        seed,
                        ..options.clone()
                    },
                    &Silent,
                )?;
                if verbose {
                    for c in &data.cuts {
                        eprintln!(
                            "  cut {:.0} rpm {:.3} mm: {} {:?} ({})",
                            c.speed_rpm,
                            c.depth_mm,
                            if c.stable { "stable" } else { "chatter" },
                            c.chatter_hz,
                            c.note.as_deref().unwrap_or("")
                        );
                    }
                    for (p, r) in data.poles.iter().zip(&d.residuals.nominal.poles) {
                        eprintln!(
                            "  pole {:.0} rpm {:.3} mm: {:.1} Hz / {:.4}, nominal residual {:+.1} Hz / {:+.4}",
                            p.speed_rpm,
                            p.depth_mm,
                            p.frequency_hz,
                            p.damping_ratio,
                            r.frequency_residual_hz,
                            r.damping_residual
                        );
                    }
                    eprintln!("  nominal check {:?}", d.nominal_check);
                    for c in &d.classes {
                        eprintln!(
                            "  {}: ln Z {:.1}, failures {} of {}",
                            c.name, c.log_evidence, c.solver_failures, c.evaluations
                        );
                    }
                    eprintln!("  {} check {:?}", d.best_class, d.predictive_check);
                }
                let expected = effect.expected_verdict(&error);
                total += 1;
                right += usize::from(d.verdict.name() == expected);
                println!(
                    "{} | {name} | {magnitude} | {expected} | {} | {} ({}) | {} | {:.2} | {} | {:.2} | {:.0}",
                    machine.name,
                    d.verdict.name(),
                    data.cuts.len(),
                    data.cuts.iter().filter(|c| !c.stable).count(),
                    data.poles.len(),
                    d.alternative_log_evidence - d.nominal_log_evidence,
                    if d.nominal_check.passed {
                        "passed"
                    } else {
                        "failed"
                    },
                    d.practical_shift,
                    start.elapsed().as_secs_f64()
                );
            }
        }
    }
    println!("right verdicts: {right} of {total}");
    Ok(())
}
