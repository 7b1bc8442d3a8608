//! The confusion matrix and the shrink figures of the diagnosis over synthetic campaigns: every
//! class at three magnitudes, two pure parameter errors and two strengths of runout (outside the
//! candidate list).
//!
//! `cargo run --release -p chatter-gap --example confusion [-- --quick]` (`--quick` skips the
//! held-out validation).

use chatter_gap::{
    DiagnoseOptions, HiddenEffect, Quiet, Recalibration, Scenario, Validation, diagnose,
    nominal_milling, synthesize,
};
use std::collections::BTreeMap;

fn main() -> chatter_gap::Result<()> {
    let quick = std::env::args().any(|a| a == "--quick");
    let nominal = nominal_milling()?;
    let none = Recalibration::default();
    let mut cases: Vec<(String, HiddenEffect, Recalibration)> = vec![
        (
            "parameter error A".into(),
            HiddenEffect::ParameterError,
            Recalibration {
                frequency_factor: 0.97,
                damping_factor: 1.5,
                cutting_over_stiffness_factor: 0.8,
            },
        ),
        (
            "parameter error B".into(),
            HiddenEffect::ParameterError,
            Recalibration {
                frequency_factor: 1.03,
                damping_factor: 0.7,
                cutting_over_stiffness_factor: 1.25,
            },
        ),
    ];
    for c in [2e4, 4e4, 6e4] {
        cases.push((
            format!("process damping C {c:.0} N/m"),
            HiddenEffect::ProcessDamping { c_n_per_m: c },
            none,
        ));
    }
    for drop in [0.02, 0.04, 0.06] {
        cases.push((
            format!("speed-dependent, drop {:.0} %", drop * 100.0),
            HiddenEffect::SpeedDependentDynamics {
                frequency_drop_at_max_speed: drop,
            },
            none,
        ));
    }
    for k in [1.6e7, 8e6, 4e6] {
        cases.push((
            format!("extra mode 1150 Hz, k {k:.1e} N/m"),
            HiddenEffect::ExtraMode {
                frequency_hz: 1150.0,
                damping_ratio: 0.02,
                stiffness_n_per_m: k,
                direction_deg: 30.0,
            },
            none,
        ));
    }
    for r in [0.2, 0.4, 0.6] {
        cases.push((
            format!("drift {:+.0} %", r * 100.0),
            HiddenEffect::Drift {
                cutting_change_over_campaign: r,
            },
            none,
        ));
    }
    for teeth in [2, 1] {
        cases.push((
            format!("runout, {teeth} of 4 teeth cut"),
            HiddenEffect::Runout {
                cutting_teeth: teeth,
            },
            none,
        ));
    }
    let names = [
        "parameter_error",
        "process_damping",
        "speed_dependent_dynamics",
        "extra_mode",
        "drift",
        "unexplained",
    ];
    let mut matrix: BTreeMap<(&str, &str), usize> = BTreeMap::new();
    println!(
        "{:<36} {:<26} {:>6}  {:>17}  {:>17}  {:>15}  {:>15}",
        "case", "verdict", "p", "misclass. b->a", "lpd/obs b->a", "chatter Hz", "pole Hz"
    );
    for (k, (name, effect, error)) in cases.iter().enumerate() {
        let mut scenario = Scenario::new(*effect, 1000 + k as u64);
        scenario.error = *error;
        let data = synthesize(&nominal, &scenario)?;
        let options = DiagnoseOptions {
            seed: k as u64,
            validation: if quick {
                Validation::Off
            } else {
                Validation::KFold { folds: 5 }
            },
            ..DiagnoseOptions::default()
        };
        let d = diagnose(&nominal, &data, &options, &Quiet)?;
        let p = d
            .classes
            .iter()
            .find(|c| c.name == d.best_class)
            .map_or(0.0, |c| c.probability);
        let pair = |m: Option<chatter_gap::shrink::Metric>| {
            m.map_or("-".to_string(), |m| {
                format!("{:.3} -> {:.3}", m.before, m.after)
            })
        };
        let (bmr, lpd, fc, pf) = match &d.shrink {
            Some(s) => (
                pair(s.balanced_misclassification),
                pair(Some(s.log_predictive_density_per_observation)),
                pair(s.rms_chatter_residual_hz),
                pair(s.rms_pole_frequency_residual_hz),
            ),
            None => Default::default(),
        };
        println!(
            "{name:<36} {:<26} {p:>6.3}  {bmr:>17}  {lpd:>17}  {fc:>15}  {pf:>15}",
            d.verdict.name()
        );
        let truth = names
            .iter()
            .find(|n| **n == effect.expected_verdict())
            .copied()
            .unwrap_or("unexplained");
        let verdict = names
            .iter()
            .find(|n| **n == d.verdict.name())
            .copied()
            .unwrap_or("unexplained");
        *matrix.entry((truth, verdict)).or_default() += 1;
    }
    println!("\nconfusion matrix (rows: hidden effect, columns: verdict)");
    let short = ["param", "pd", "speed", "extra", "drift", "unexpl"];
    print!("{:<26}", "");
    for s in short {
        print!("{s:>8}");
    }
    println!();
    for truth in names {
        print!("{truth:<26}");
        for verdict in names {
            print!("{:>8}", matrix.get(&(truth, verdict)).copied().unwrap_or(0));
        }
        println!();
    }
    Ok(())
}
