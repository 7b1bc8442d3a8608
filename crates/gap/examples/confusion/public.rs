//! The outside proving ground of `confusion -- --public DIR` (module docs of the example).

use crate::chatters;
use crate::common::list;
use chatter_dynamics::{ModalModel, Observations};
use chatter_gap::{DiagnoseOptions, Validation, Variant, diagnose};
use chatter_progress::Observer;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// A held-out cut: speed (rpm), depth (m), campaign position, stable.
type HeldOut = (f64, f64, f64, bool);

fn json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn held_out(path: &Path) -> Vec<HeldOut> {
    json(path)["cuts"]
        .as_array()
        .map(|cuts| {
            cuts.iter()
                .filter_map(|c| {
                    Some((
                        c["speed_rpm"].as_f64()?,
                        c["depth_mm"].as_f64()? * 1e-3,
                        c["campaign_position"].as_f64().unwrap_or(0.0),
                        c["stable"].as_bool()?,
                    ))
                })
                .collect()
        })
        .unwrap_or_default()
}

/// Held-out cuts `variant` labels wrongly (a failed solver counts as wrong).
fn misses(variant: &Variant, cuts: &[HeldOut]) -> usize {
    cuts.iter()
        .filter(|&&(s, b, u, stable)| chatters(variant, s, b, u) != Some(!stable))
        .count()
}

/// Diagnose every `public_NN` campaign under `dir` (or those of `--only`), print one row each and
/// the confusion table by machine and magnitude.
pub fn run(dir: &Path, observer: &dyn Observer) -> chatter_gap::Result<()> {
    let only: Vec<String> = list("--only", Vec::new());
    let mut campaigns: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("answer.json").exists())
        .filter(|p| {
            only.is_empty()
                || only.iter().any(|n| {
                    p.file_name()
                        .is_some_and(|f| f.to_string_lossy().ends_with(n.as_str()))
                })
        })
        .collect();
    campaigns.sort();
    let options = DiagnoseOptions {
        validation: Validation::Off,
        seed: 1,
        ..DiagnoseOptions::default()
    };
    let mut table: BTreeMap<(String, String), (usize, usize)> = BTreeMap::new();
    let (mut closures, mut times) = (Vec::new(), Vec::new());
    println!(
        "campaign | machine | effect | magnitude | expected | verdict | right | seconds | \
         nominal misses /40 | diagnosed misses | closure"
    );
    for path in campaigns {
        let model = ModalModel::from_path(path.join("model.json")).expect("model.json");
        let observations =
            Observations::from_path(path.join("observations.json")).expect("observations.json");
        let answer = json(&path.join("answer.json"));
        let held = held_out(&path.join("heldout.json"));
        let start = Instant::now();
        let d = diagnose(&model, &observations, &options, observer)?;
        let seconds = start.elapsed().as_secs_f64();
        times.push(seconds);
        let nominal_misses = misses(&Variant::new(model.clone()), &held);
        let diagnosed_misses = misses(d.diagnosed_variant(), &held);
        let effect = answer["effect"].as_str().unwrap_or("?");
        // the set's README: read `none` as `consistent` (its `expected_verdict` field names
        // the class a recalibration would take there)
        let expected = match effect {
            "none" => "consistent",
            "out_of_list" => "unexplained",
            _ => answer["expected_verdict"].as_str().unwrap_or("?"),
        };
        let verdict = d.verdict.name();
        let right = verdict == expected
            || (effect == "out_of_list" && verdict == "consistent" && nominal_misses <= 1);
        let closure = if nominal_misses >= 2 {
            let c = (nominal_misses as f64 - diagnosed_misses as f64) / nominal_misses as f64;
            if effect != "none" {
                closures.push(c);
            }
            format!("{c:.2}")
        } else {
            "-".into()
        };
        let machine = answer["machine"].as_str().unwrap_or("?").to_string();
        let magnitude = match effect {
            "none" => "control".to_string(),
            "out_of_list" => "outside".to_string(),
            _ => format!("{}x", answer["magnitude"]),
        };
        println!(
            "{} | {machine} | {effect} | {magnitude} | {expected} | {verdict} | {} | {seconds:.1} \
             | {nominal_misses} | {diagnosed_misses} | {closure}",
            path.file_name().unwrap_or_default().to_string_lossy(),
            if right { "yes" } else { "NO" },
        );
        if std::env::args().any(|a| a == "--verbose") {
            let evidences: Vec<String> = d
                .classes
                .iter()
                .map(|c| format!("{} {:.1}", c.name, c.log_evidence))
                .collect();
            println!(
                "    nominal ln L {:.1}, alternative {:.1}, shift {:.2}; {}\n    nominal check \
                 {:?}\n    best check {:?}",
                d.nominal_log_evidence,
                d.alternative_log_evidence,
                d.practical_shift,
                evidences.join(", "),
                d.nominal_check,
                d.predictive_check
            );
            for c in d.classes.iter().filter(|c| !c.name.is_listed()) {
                let p: Vec<String> = c
                    .parameters
                    .iter()
                    .map(|(k, v)| format!("{k} {:.3} +- {:.3}", v.mean, v.sd))
                    .collect();
                println!("    {}: {}", c.name, p.join(", "));
            }
            for note in &d.notes {
                println!("    note: {note}");
            }
        }
        let e = table.entry((machine, magnitude)).or_default();
        e.0 += usize::from(right);
        e.1 += 1;
    }
    println!("\nright verdicts by machine and magnitude:");
    let (mut right, mut total) = (0, 0);
    for ((machine, magnitude), (r, t)) in &table {
        println!("{machine} | {magnitude} | {r}/{t}");
        right += r;
        total += t;
    }
    println!("all | {right}/{total}");
    crate::print_summary(&mut closures, &mut times);
    Ok(())
}
