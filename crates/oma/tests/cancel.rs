//! Detection and identification handed an observer cancelled from the start return
//! `OmaError::Cancelled` without a result.
#![allow(clippy::unwrap_used)]

use chatter_oma::detection::{DetectionOptions, detect_with_observer};
use chatter_oma::signals::Signals;
use chatter_oma::synthetic::SyntheticRecord;
use chatter_oma::{IdentifyOptions, OmaError, identify_with_observer};
use chatter_progress::AlreadyCancelled;

#[test]
fn detection_and_identification_stop_when_cancelled() {
    let four = SyntheticRecord::four_channel_reference(10_000.0, 10.0, 1)
        .generate()
        .unwrap();
    let signals = Signals::new(
        four.names[..3].to_vec(),
        four.sample_rate_hz,
        four.data[..3].to_vec(),
    )
    .unwrap();
    let detection = detect_with_observer(
        &signals,
        &DetectionOptions::new(7150.0 / 60.0),
        &AlreadyCancelled,
    );
    assert!(
        matches!(detection, Err(OmaError::Cancelled(_))),
        "{detection:?}"
    );
    let identification = identify_with_observer(
        &signals,
        &IdentifyOptions::spindle(7150.0 / 60.0),
        &AlreadyCancelled,
    );
    assert!(
        matches!(identification, Err(OmaError::Cancelled(_))),
        "{identification:?}"
    );
}
