//! Where a chattering cut's frequency lies (issue 15, proving ground part b): turning cuts past
//! the boundary simulated in the time domain with loss of contact (`tests/shop/mod.rs`),
//! detected as a shop would, against three linear predictions: the dominant root at the cut's
//! own depth, the point where that root's branch crosses the imaginary axis as the depth is
//! lowered (the describing-function limit cycle), and the boundary's chatter frequency.
//!
//! `cargo run --release -p chatter-gap --example chatter_frequency [-- --ratios 1.1,1.5,2
//! --speeds 6 --pd 0]` (`--pd C`: process damping C in N/m).

#![allow(clippy::unwrap_used)]

#[path = "../tests/shop/mod.rs"]
#[allow(dead_code)]
mod shop;

mod common;

use chatter_gap::generator::proving_machines;
use chatter_oma::detection::{DetectionOptions, Verdict, detect};
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::frequency_domain::{
    FrequencyDomain, axis_crossings, dominant_and_unstable_poles,
};
use common::{arg, list};

fn main() {
    let machines = proving_machines().unwrap();
    let mut model = machines[3].model.clone();
    let pd: f64 = arg("--pd").and_then(|s| s.parse().ok()).unwrap_or(0.0);
    if pd > 0.0 {
        model = model.with_process_damping(Some(pd)).unwrap();
    }
    let (lo, hi) = machines[3].speed_range_rpm;
    if let Some(t) = arg("--trace") {
        let v: Vec<f64> = t.split(',').map(|x| x.parse().unwrap()).collect();
        let b_lim = limiting_depth(&FrequencyDomain, &model, v[0], &BoundaryOptions::default())
            .unwrap()
            .depth_m;
        let mut st =
            chatter_dynamics::simulate::SimulationSettings::new(v[0], v[1] * b_lim, 8.0, 5000.0, 3);
        st.quantity = chatter_dynamics::simulate::Quantity::Displacement;
        let sim = chatter_dynamics::simulate::simulate(&model, &st).unwrap();
        println!("lost contact {:.3}", sim.lost_contact_fraction);
        for c in &sim.channels {
            let rms: Vec<String> = c
                .data
                .chunks(2500)
                .map(|w| {
                    let m = w.iter().sum::<f64>() / w.len() as f64;
                    format!(
                        "{:.2e}",
                        (w.iter().map(|x| (x - m).powi(2)).sum::<f64>() / w.len() as f64).sqrt()
                    )
                })
                .collect();
            println!("{}: {}", c.name, rms.join(" "));
            if c.name == "feed" {
                let text: Vec<String> = c.data.iter().map(|x| format!("{x:e}")).collect();
                std::fs::write("/tmp/feed.txt", text.join("\n")).unwrap();
            }
        }
        return;
    }
    let ratios: Vec<f64> = list("--ratios", vec![1.1, 1.3, 1.6, 2.0, 2.5]);
    let n: usize = arg("--speeds").and_then(|s| s.parse().ok()).unwrap_or(6);
    println!(
        "speed rpm | b_lim mm | ratio | detected Hz | root at depth Hz | crossing Hz (depth mm) \
         | other roots: at depth / crossing Hz"
    );
    let mut seed = 7u64;
    for k in 0..n {
        // speeds off a regular grid so that they fall on different lobe positions
        let speed = lo + (hi - lo) * (k as f64 + 0.37) / n as f64;
        let b_lim = limiting_depth(&FrequencyDomain, &model, speed, &BoundaryOptions::default())
            .unwrap()
            .depth_m;
        for &r in &ratios {
            let depth = r * b_lim;
            seed += 1;
            let signals = shop::record(&model, speed, depth, shop::CUT_S, seed);
            let options = DetectionOptions {
                resolution_hz: Some(speed / 60.0 / 40.0),
                ..DetectionOptions::new(speed / 60.0)
            };
            let d = detect(&signals, &options).unwrap();
            let (dominant, others) = dominant_and_unstable_poles(&model, speed, depth).unwrap();
            let mut all = vec![dominant];
            all.extend(others.iter().copied());
            let crossings = axis_crossings(&model, speed, depth, &all).unwrap();
            let f = |p: &chatter_stability::frequency_domain::ClosedLoopPole| {
                p.lambda.im / (2.0 * std::f64::consts::PI)
            };
            let cross = |i: usize| {
                crossings[i].map_or("-".to_string(), |(a, p)| {
                    format!("{:.1} ({:.3})", f(&p), a * 1e3)
                })
            };
            let rest: Vec<String> = (1..all.len())
                .map(|i| format!("{:.1}/{}", f(&all[i]), cross(i)))
                .collect();
            println!(
                "{speed:.0} | {:.3} | {r} | {} | {:.1} | {} | {}",
                b_lim * 1e3,
                match (d.verdict, d.chatter_hz) {
                    (Verdict::Stable, _) => format!(
                        "stable (V {:.2}, R {:.1} dB, peak {:.1} Hz, f0 {:.3}, |mu| {:.2})",
                        d.evidence.line_variation,
                        d.evidence.line_to_forced_db,
                        d.evidence.peak_hz,
                        d.evidence.fundamental_hz,
                        (dominant.lambda.re * 60.0 / speed).exp()
                    ),
                    (_, Some(h)) => format!("{h:.1}"),
                    (_, None) => "chatter ?".to_string(),
                },
                f(&dominant),
                cross(0),
                rest.join(", ")
            );
        }
    }
}
