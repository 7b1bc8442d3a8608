//! The detection job of a signal record (`chatter detect`, and the first step of
//! [`crate::recordings`]): stable or chatter, the chatter frequency and the evidence behind the
//! verdict, as a labelled cut of the observations format.
//!
//! The record is read (CSV at the entry's `sample_rate_hz`, WAV or MP3 at its own rate,
//! [`crate::oma::read_record`]); its `once_per_rev_channel`, if any, gives the spindle frequency
//! and is left out of the spectrum, otherwise the spindle frequency is `speed_rpm / 60` refined
//! within 0.5 % ([`DetectRequest::estimate_speed`]: the fundamental of the record's harmonic
//! comb instead). Every multiple of the spindle frequency is forced response; the strongest
//! other line is chatter when its share of the power is constant (a limit cycle) or grows and
//! bursts far beyond a random resonance (criterion and thresholds in
//! [`chatter_oma::detection`]). With a milling model of an even tooth count, flip
//! (period-doubling) lines are judged too.

use crate::error::Result;
use crate::oma::{channels_match, interference_note, read_record};
use chatter_dynamics::{Cut, CutEvidence, ModalModel, Operation, SignalRecord};
use chatter_oma::detection::{Detection, DetectionOptions, Verdict, detect_with_observer};
use chatter_oma::interference::Interference;
use chatter_oma::signals::Signals;
use chatter_progress::Observer;

/// What detection was asked; the default is what `chatter detect` does without options.
#[derive(Debug, Clone, Default)]
pub struct DetectRequest {
    /// Interference combs left out of the spectrum (default: a search over the mains range).
    pub interference: Interference,
    /// The spindle speed is unknown: estimate it from each record's harmonic comb (600 to
    /// 30 000 rpm) instead of reading `speed_rpm`.
    pub estimate_speed: bool,
}

/// One record judged.
#[derive(Debug, Clone)]
pub struct RecordDetection {
    /// The channels as read (tachometer included; detection leaves it out itself).
    pub signals: Signals,
    /// Verdict, chatter frequency, evidence and spectrum.
    pub detection: Detection,
    /// The labelled cut: `speed_rpm` (the estimate with [`DetectRequest::estimate_speed`]),
    /// `depth_mm`, `stable`, `chatter_hz`, `sequence` and `radial_immersion` copied, a `note`
    /// naming the file and the [`CutEvidence`].
    pub cut: Cut,
}

/// Judge record `i` of an observations file. `model` gives a milling machine's tooth count (flip
/// chatter judged with an even count) and checks the record's channels against its operation;
/// `observer` may cancel.
pub fn detect_record(
    i: usize,
    record: &SignalRecord,
    model: Option<&ModalModel>,
    request: &DetectRequest,
    observer: &dyn Observer,
) -> Result<RecordDetection> {
    let signals = read_record(i, record)?;
    if let Some(m) = model {
        channels_match(m, &signals.names, &format!("signals[{i}]"))?;
    }
    let options = options(
        record.speed_rpm,
        record.once_per_rev_channel.clone(),
        model,
        request,
    );
    let detection = detect_with_observer(&signals, &options, observer)?;
    let cut = cut_of(
        record,
        &detection,
        &request.interference,
        request.estimate_speed,
    );
    Ok(RecordDetection {
        signals,
        detection,
        cut,
    })
}

/// The detection options of a record at `speed_rpm` (ignored with
/// [`DetectRequest::estimate_speed`]) with its tachometer channel, if any: the request's
/// interference, and a milling `model`'s tooth count for flip chatter.
fn options(
    speed_rpm: f64,
    once_per_rev_channel: Option<String>,
    model: Option<&ModalModel>,
    request: &DetectRequest,
) -> DetectionOptions {
    let mut options = if request.estimate_speed {
        DetectionOptions::unknown_speed()
    } else {
        DetectionOptions::new(speed_rpm / 60.0)
    };
    options.once_per_rev_channel = once_per_rev_channel;
    options.interference = request.interference.clone();
    options.teeth = model.and_then(|m| match m.operation() {
        Operation::Milling(milling) => Some(milling.teeth()),
        _ => None,
    });
    options
}

/// Judge signals already in memory (`chatter.detect`): the record's channels at `speed_rpm`
/// with its tachometer channel, if any, and a milling `model`'s tooth count, as
/// [`detect_record`] judges a record of a file.
pub fn detect_signals(
    signals: &Signals,
    speed_rpm: f64,
    once_per_rev_channel: Option<String>,
    model: Option<&ModalModel>,
    request: &DetectRequest,
    observer: &dyn Observer,
) -> Result<Detection> {
    let options = options(speed_rpm, once_per_rev_channel, model, request);
    Ok(detect_with_observer(signals, &options, observer)?)
}

/// The verdict rule: a record is a stable cut when detection judged it so.
pub fn is_stable(d: &Detection) -> bool {
    d.verdict == Verdict::Stable
}

/// The labelled cut of a judged record: the line that decided (the whole record's, the
/// windows' or the flip line's when only they chatter) in the evidence, and a note naming the
/// file, the speed estimate, the interference, the windows and the flip lines.
pub fn cut_of(
    record: &SignalRecord,
    d: &Detection,
    interference: &Interference,
    estimated: bool,
) -> Cut {
    let e = &d.evidence;
    let windowed = e
        .windows
        .as_ref()
        .and_then(|w| w.chatter.as_ref().zip(w.margin));
    let flip = e.flip.as_ref().filter(|f| f.chatter);
    let (line_hz, line_variation, margin) = match (windowed, flip) {
        (Some((span, m)), _) if d.chatter_hz == Some(span.line_hz) => {
            (span.line_hz, span.line_variation, m)
        }
        (_, Some(f)) if d.chatter_hz == Some(f.line_hz) => {
            (f.line_hz, f.line_variation, f.variation_margin)
        }
        _ => (e.peak_hz, e.line_variation, e.margin),
    };
    let (speed_rpm, speed_note) = if estimated {
        let rpm = 60.0 * e.fundamental_hz;
        (
            rpm,
            format!(
                "; speed estimated from the harmonic comb: {:.3} Hz ({rpm:.0} rpm)",
                e.fundamental_hz
            ),
        )
    } else {
        (record.speed_rpm, String::new())
    };
    Cut {
        speed_rpm,
        depth_mm: record.depth_mm,
        stable: is_stable(d),
        chatter_hz: d.chatter_hz,
        sequence: record.sequence,
        radial_immersion: record.radial_immersion,
        note: Some(format!(
            "detect {}{speed_note}{}{}{}",
            file_name(record),
            interference_note(interference, d),
            windows_note(d),
            flip_note(d)
        )),
        evidence: Some(CutEvidence {
            fundamental_hz: e.fundamental_hz,
            line_hz,
            line_variation,
            margin,
            line_to_forced_db: e.line_to_forced_db,
            line_to_floor_db: e.line_to_floor_db,
            line_to_rest_db: e.line_to_rest_db,
            resolution_hz: e.resolution_hz,
        }),
    }
}

/// The record's file name without its folder (the whole path when it has no name).
pub fn file_name(record: &SignalRecord) -> String {
    record.file.file_name().map_or_else(
        || record.file.display().to_string(),
        |n| n.to_string_lossy().into(),
    )
}

/// The window-by-window judgement, for a note: the chattering span, or the best margin.
fn windows_note(d: &Detection) -> String {
    let Some(w) = &d.evidence.windows else {
        return "; record shorter than 1.5 windows: judged whole".into();
    };
    let reference = if w.reference_stretch {
        let quiet = w.windows.iter().filter(|j| j.reference).count();
        format!(
            ", {quiet} of them a reference stretch without the cut ({:.1} dB quieter), not judged",
            w.contrast_db
        )
    } else {
        String::new()
    };
    let frame = format!(
        "{} windows of {:.2} s (chatter counts from {:.2} s){reference}",
        w.windows.len(),
        w.window_s,
        w.min_duration_s
    );
    match (&w.chatter, w.margin) {
        (Some(c), _) if c.by_dominance => format!(
            "; {frame}: chatter at {:.1} Hz from {:.1} to {:.1} s, a line carrying over half \
             of the cut's power (V {:.2})",
            c.line_hz, c.start_s, c.end_s, c.line_variation
        ),
        (Some(c), Some(m)) => format!(
            "; {frame}: chatter at {:.1} Hz from {:.1} to {:.1} s (V {:.2}, margin {m:+.3})",
            c.line_hz, c.start_s, c.end_s, c.line_variation
        ),
        (_, Some(m)) => format!("; {frame}: no sustained chatter (margin {m:+.3})"),
        _ => format!("; {frame}: no line standing out in two neighbouring windows"),
    }
}

/// The flip lines (tooth count known from the model), for a note.
fn flip_note(d: &Detection) -> String {
    d.evidence.flip.as_ref().map_or(String::new(), |f| {
        format!(
            "; flip line {:.1} Hz: V {:.2}, {:.1} dB over the runout lines{}",
            f.line_hz,
            f.line_variation,
            f.line_to_runout_db.unwrap_or(f64::NAN),
            if f.chatter { ", flip chatter" } else { "" }
        )
    })
}
