//! The confusion matrix of the diagnosis over the proving ground: every machine of
//! [`proving_machines`], a control (the nominal model is right), every class at magnitudes
//! 0.5x, 1x and 2x, and effects outside the candidate list (cutting coefficients x3 in a speed
//! band; runout, half the teeth cutting). The truth is the semi-discretization at 4x resolution
//! (the diagnosis uses the full discretization); held-out cuts drawn from the truth measure how
//! much of the nominal model's misclassification the diagnosed model closes.
//!
//! `cargo run --release -p chatter-gap --example confusion [-- --machines 0,1 --seeds 2 --first-seed 0 --magnitudes 1
//! --classes drift --cases control,effects,outside --cuts 40 --samples 120 --steps 1 --sampler-offset 0
//! --fit parameter_error,extra_mode --verbose]`; `--fit` limits the classes the diagnosis tries
//! (all by default).
//!
//! `-- --public ../shared/data/gap_public [--only 05,11]` diagnoses instead the campaigns of an
//! outside generator (`public_NN/` with `model.json`, `observations.json`, `heldout.json`,
//! `answer.json`; read from there, never copied) with the diagnosis defaults and validation off,
//! scores the verdict as that set's README does (`consistent` for `none`; for an effect outside
//! the list `unexplained`, or `consistent` where the nominal model misclassifies at most 1 of
//! the 40 held-out cuts) and computes the held-out closure (accuracy of the diagnosed model minus
//! that of the nominal model over the nominal model's error, where it misses at least 2) with
//! the diagnosed machine that `chatter diagnose` writes to `diagnosed_model.json` (with the
//! speed softening and drift of `diagnosed_effects.json`), labelled stable where |mu| < 1 by the
//! inference's solver.

#[path = "../common/mod.rs"]
mod common;
mod public;

use chatter_gap::generator::{proving_machines, true_variant};
use chatter_gap::predict::inference_solver;
use chatter_gap::{
    DiagnoseOptions, EffectClass, HiddenEffect, Recalibration, Scenario, Validation, Variant,
    diagnose, synthesize,
};
use chatter_progress::Observer;
use common::{arg, list};
use std::collections::BTreeMap;
use std::time::Instant;

/// Whether `variant` predicts chatter at a cut (the inference's solver), None on failure.
fn chatters(variant: &Variant, speed_rpm: f64, depth_m: f64, u: f64) -> Option<bool> {
    let model = variant.at(None, speed_rpm, u).ok()?;
    let mu = inference_solver(&model)
        .dominant_multiplier(&model, speed_rpm, depth_m)
        .ok()?;
    Some(mu.modulus() > 1.0)
}

/// Balanced misclassification of `variant` on labelled cuts.
fn balanced_misclassification(variant: &Variant, cuts: &[(f64, f64, f64, bool)]) -> f64 {
    let (mut miss_u, mut n_u, mut miss_s, mut n_s) = (0, 0, 0, 0);
    for &(s, b, u, stable) in cuts {
        let predicted_chatter = chatters(variant, s, b, u).unwrap_or(false);
        if stable {
            n_s += 1;
            miss_s += usize::from(predicted_chatter);
        } else {
            n_u += 1;
            miss_u += usize::from(!predicted_chatter);
        }
    }
    let rate = |m: usize, n: usize| if n == 0 { 0.0 } else { m as f64 / n as f64 };
    0.5 * (rate(miss_u, n_u) + rate(miss_s, n_s))
}

/// Prints each class's evidence and the time since the diagnosis started (stderr).
struct Log(Instant);
impl Observer for Log {
    fn class_done(&self, class: &str, log_evidence: f64) {
        eprintln!(
            "  {class}: ln Z {log_evidence:.1} at {:.1} s",
            self.0.elapsed().as_secs_f64()
        );
    }
}

fn main() -> chatter_gap::Result<()> {
    if let Some(dir) = arg("--public") {
        return public::run(std::path::Path::new(&dir), &Log(Instant::now()));
    }
    let machines = proving_machines()?;
    let pick: Vec<usize> = list("--machines", (0..machines.len()).collect());
    let seeds: u64 = arg("--seeds").and_then(|s| s.parse().ok()).unwrap_or(1);
    let first_seed: u64 = arg("--first-seed")
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let magnitudes: Vec<f64> = list("--magnitudes", vec![0.5, 1.0, 2.0]);
    let classes: Vec<EffectClass> = list("--classes", EffectClass::ALL.to_vec());
    let verbose = std::env::args().any(|a| a == "--verbose");
    // the samplers' seed apart from the campaign's: repeats one campaign to see the evidence's
    // Monte Carlo scatter
    let sampler_offset: u64 = arg("--sampler-offset")
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let kinds: Vec<String> = list(
        "--cases",
        vec!["control".into(), "effects".into(), "outside".into()],
    );
    let kind_of = |magnitude: &str| match magnitude {
        "control" | "outside" => magnitude.to_string(),
        _ => "effects".to_string(),
    };
    let defaults = DiagnoseOptions::default();
    let options = DiagnoseOptions {
        validation: Validation::Off,
        samples: arg("--samples")
            .and_then(|s| s.parse().ok())
            .unwrap_or(defaults.samples),
        steps: arg("--steps")
            .and_then(|s| s.parse().ok())
            .unwrap_or(defaults.steps),
        classes: list("--fit", defaults.classes.clone()),
        ..defaults
    };
    // (machine, magnitude label) -> (right, total)
    let mut table: BTreeMap<(String, String), (usize, usize)> = BTreeMap::new();
    let mut closures = Vec::new();
    let mut times = Vec::new();
    println!("machine | case | magnitude | expected | verdict | seconds | held-out closure");
    for &mi in &pick {
        let machine = &machines[mi];
        let (lo, hi) = machine.speed_range_rpm;
        let mut cases = machine.cases(&classes, &magnitudes)?;
        cases.push((
            "cutting x3 in a band".into(),
            "outside".into(),
            HiddenEffect::CuttingBand {
                from_rpm: lo + 0.4 * (hi - lo),
                to_rpm: lo + 0.7 * (hi - lo),
                factor: 3.0,
            },
            Recalibration::default(),
        ));
        if let chatter_dynamics::Operation::Milling(op) = machine.model.operation()
            && op.teeth() % 2 == 0
        {
            cases.push((
                "runout".into(),
                "outside".into(),
                HiddenEffect::Runout {
                    cutting_teeth: op.teeth() / 2,
                },
                Recalibration::default(),
            ));
        }
        cases.retain(|(_, magnitude, _, _)| kinds.contains(&kind_of(magnitude)));
        for (name, magnitude, effect, error) in cases {
            for seed in first_seed..first_seed + seeds {
                let mut scenario = Scenario::new(effect, 1000 + seed).with_speed_range(lo, hi, 4);
                scenario.error = error;
                if let Some(cuts) = arg("--cuts").and_then(|s| s.parse().ok()) {
                    scenario.cuts = cuts;
                }
                let start = Instant::now();
                // a campaign whose truth cannot be computed is reported, not counted
                let data = match synthesize(&machine.model, &scenario) {
                    Ok(data) => data,
                    Err(e) => {
                        println!(
                            "{} | {name} | {magnitude} | truth failed: {e}",
                            machine.name
                        );
                        continue;
                    }
                };
                eprintln!("synthesized in {:.1} s", start.elapsed().as_secs_f64());
                let start = Instant::now();
                let options = DiagnoseOptions {
                    seed: seed + sampler_offset,
                    ..options.clone()
                };
                let d = diagnose(&machine.model, &data, &options, &Log(Instant::now()))?;
                let seconds = start.elapsed().as_secs_f64();
                times.push(seconds);
                if verbose {
                    eprintln!(
                        "  nominal ln L {:.1}, nominal check {:?}\n  best check {:?}",
                        d.nominal_log_evidence, d.nominal_check, d.predictive_check
                    );
                    for c in &d.classes {
                        eprintln!("  {}: {:?}", c.name, c.parameters);
                    }
                }
                let expected = effect.expected_verdict(&error);
                let right = d.verdict.name() == expected;
                // held-out cuts from the truth, labelled without noise
                let mut held = Scenario::new(effect, 5000 + seed).with_speed_range(lo, hi, 0);
                held.error = error;
                held.pole_depth_fractions.clear();
                held.label_width_log_depth = 1e-6;
                let Ok(held_out) = synthesize(&machine.model, &held) else {
                    println!(
                        "{} | {name} | {magnitude} | held-out truth failed",
                        machine.name
                    );
                    continue;
                };
                let n = held_out.cuts.len().max(2) as f64 - 1.0;
                let cuts: Vec<(f64, f64, f64, bool)> = held_out
                    .cuts
                    .iter()
                    .enumerate()
                    .map(|(k, c)| (c.speed_rpm, c.depth_mm * 1e-3, k as f64 / n, c.stable))
                    .collect();
                let truth = true_variant(&machine.model, &held)?;
                let nominal = Variant::new(machine.model.clone());
                let before = balanced_misclassification(&nominal, &cuts);
                let after = balanced_misclassification(d.diagnosed_variant(), &cuts);
                let best = balanced_misclassification(&truth, &cuts);
                let closure = if before - best > 0.02 {
                    let c = (before - after) / (before - best);
                    closures.push(c);
                    format!("{c:.2} ({before:.2} -> {after:.2}, truth {best:.2})")
                } else {
                    format!("- ({before:.2} -> {after:.2}, truth {best:.2})")
                };
                println!(
                    "{} | {name} | {magnitude} | {expected} | {} | {seconds:.1} | {closure}",
                    machine.name,
                    d.verdict.name(),
                );
                let e = table
                    .entry((machine.name.to_string(), magnitude.clone()))
                    .or_default();
                e.0 += usize::from(right);
                e.1 += 1;
            }
        }
    }
    println!("\nright verdicts by machine and magnitude:");
    for ((machine, magnitude), (right, total)) in &table {
        println!("{machine} | {magnitude} | {right}/{total}");
    }
    let mut by_magnitude: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
    for ((_, magnitude), (right, total)) in &table {
        let e = by_magnitude.entry(magnitude.as_str()).or_default();
        e.0 += right;
        e.1 += total;
    }
    for (magnitude, (right, total)) in by_magnitude {
        println!(
            "all machines | {magnitude} | {right}/{total} ({:.0} %)",
            100.0 * right as f64 / total.max(1) as f64
        );
    }
    print_summary(&mut closures, &mut times);
    Ok(())
}

/// The median held-out closure and the median and largest diagnosis time (both modes).
fn print_summary(closures: &mut [f64], times: &mut [f64]) {
    closures.sort_by(f64::total_cmp);
    if !closures.is_empty() {
        println!(
            "median held-out closure {:.2} over {} campaigns with a gap",
            closures[closures.len() / 2],
            closures.len()
        );
    }
    times.sort_by(f64::total_cmp);
    if let Some(max) = times.last() {
        println!(
            "diagnosis time: median {:.1} s, max {max:.1} s",
            times[times.len() / 2]
        );
    }
}
