//! Identify the dominant pole of a synthetic four-channel record (three modes, two spindle
//! harmonics of a 7150 rpm spindle, 10 % noise) with the modified LSCE, and print the
//! stabilization diagram's stable clusters and the mean and spread over ten random segments.
//!
//! `cargo run --release -p chatter-oma --example identify`

use chatter_oma::picking::stable_clusters;
use chatter_oma::synthetic::SyntheticRecord;
use chatter_oma::{Harmonics, IdentifyOptions, identify};

fn main() -> Result<(), chatter_oma::OmaError> {
    let record = SyntheticRecord::four_channel_reference(20_000.0, 10.0, 7);
    let signals = record.generate()?;
    let options = IdentifyOptions {
        harmonics: Harmonics::Spindle {
            fundamental_hz: 7150.0 / 60.0,
        },
        ..IdentifyOptions::default()
    };
    let id = identify(&signals, &options)?;
    println!("true modes (Hz, damping ratio):");
    for m in &record.modes {
        println!("  {:8.2}  {:.4}", m.pole.frequency_hz, m.pole.damping_ratio);
    }
    println!("imposed harmonics (Hz): {:.1?}", id.harmonics_hz);
    println!("stable clusters of the whole-record diagram (orders, Hz, damping ratio):");
    for c in stable_clusters(&id.diagram, &id.harmonics_hz, &options.picking) {
        let first = c.members.first().map_or(0, |m| m.order);
        let last = c.members.last().map_or(0, |m| m.order);
        println!(
            "  P {first:2}..{last:2}  {:8.2}  {:.4}",
            c.frequency_hz, c.damping_ratio
        );
    }
    let e = id.estimate;
    println!(
        "dominant pole at order {} over {} segments: {:.2} +- {:.2} Hz, damping {:.5} +- {:.5}",
        id.order,
        e.repetitions,
        e.frequency_hz,
        e.frequency_std_hz.unwrap_or(0.0),
        e.damping_ratio,
        e.damping_std.unwrap_or(0.0)
    );
    Ok(())
}
