//! OMA on the real chatter record `test255_accelY.csv` (shared data folder, see its README:
//! slot milling at 5000 rpm with a four-flute cutter, 10 kHz, 8 s, labelled chatter by its
//! authors). A chattering cut is not an OMA record: the CLI refuses it when detection calls it
//! chatter (with the mains given; see the CLI test). Without that check the identification
//! must still not return a forced line: before issue 16 it returned 150.01 Hz with zeta 0.00048,
//! the third harmonic of the 50 Hz mains. Skipped with a message when the data are absent.
#![allow(clippy::unwrap_used)]

use chatter_oma::signals::Signals;
use chatter_oma::{Harmonics, IdentifyOptions, identify};
use std::path::Path;

const RECORD: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/real/milling_chatter_record/test255_accelY.csv"
);

/// Distance (Hz) from `f` to the nearest multiple of `base`.
fn off_comb(f: f64, base: f64) -> f64 {
    (f - (f / base).round().max(1.0) * base).abs()
}

/// The identified pole, if any, is neither a mains harmonic nor a spindle harmonic: at least
/// 1 Hz (8 record bins 1 / T) from every multiple of 50 Hz and of 5000 / 60 Hz, the lines of
/// this record. The mains comb is not given to the identification: the check that keeps it out
/// is the crate's spectral-line test, this one is independent of it.
#[test]
fn chatter_record_never_yields_a_forced_line() {
    if !Path::new(RECORD).exists() {
        eprintln!("skipped: {RECORD} is absent");
        return;
    }
    let signals = Signals::from_csv(Path::new(RECORD), 10_000.0).unwrap();
    let options = IdentifyOptions {
        harmonics: Harmonics::Spindle {
            fundamental_hz: 5000.0 / 60.0,
        },
        ..IdentifyOptions::default()
    };
    match identify(&signals, &options) {
        Err(e) => eprintln!("no pole: {e}"),
        Ok(id) => {
            let e = id.estimate;
            eprintln!(
                "test255: {:.2} Hz, zeta {:.5}, order {}, {} harmonics imposed, rejected {:?}",
                e.frequency_hz,
                e.damping_ratio,
                id.order,
                id.harmonics_hz.len(),
                id.rejected
                    .iter()
                    .map(|r| (r.frequency_hz, r.damping_ratio, r.reason))
                    .collect::<Vec<_>>()
            );
            assert!(off_comb(e.frequency_hz, 50.0) > 1.0, "{e:?}");
            assert!(off_comb(e.frequency_hz, 5000.0 / 60.0) > 1.0, "{e:?}");
        }
    }
}
