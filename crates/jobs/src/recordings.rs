//! From a shop's recordings to the observations a diagnosis reads: every signal record of an
//! observations file judged by chatter detection ([`crate::detect`], what `chatter detect`
//! does) and, when stable, identified by operational modal analysis ([`crate::oma`], what
//! `chatter oma` does), with one row per record saying what came of it.
//!
//! A record becomes
//! - a labelled cut (`stable`, or chatter with its `chatter_hz`) with the detection's
//!   [`CutEvidence`], when detection can judge it;
//! - and, when it is stable, a pole observation (000 Eq. 19-25 for turning: the physical
//!   frequency; 002 Eq. 6-9 for milling: the principal frequency of the lifted multiplier),
//!   when OMA identifies one.
//!
//! Nothing is dropped silently: a record that cannot be read or judged (a missing or malformed
//! file, too short for a spectrum, channels of the other operation) is
//! [`RecordVerdict::NotJudged`] with the error as its reason; a chattering record gets no pole
//! (its dominant line is a limit cycle, not a structural pole; `chatter oma` refuses it) and a
//! stable record that OMA refuses (its own chatter check, no persistent stable pole) or whose
//! pole is out of the observations' ranges keeps its cut and gets the reason instead of a pole.
//! The cuts and poles already in the file are kept, before the new ones.
//!
//! [`write_simulated_records`] writes a signal-level campaign made with the time-domain
//! simulator ([`chatter_dynamics::simulate`]): the reference problem of the tests.

use crate::detect::{DetectRequest, detect_record};
use crate::error::{JobError, Result};
use crate::oma::{OmaRequest, analyse_record, pole_observation};
use chatter_dynamics::simulate::{Quantity, SimulationSettings, simulate};
use chatter_dynamics::{CutEvidence, ModalModel, Observations, PoleObservation, SignalRecord};
use chatter_oma::OmaError;
use chatter_progress::Observer;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// What detection made of a record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RecordVerdict {
    /// No self-excited line: a stable cut.
    Stable,
    /// A self-excited line: chatter at `chatter_hz`.
    Chatter,
    /// The record could not be read or judged; the row's `reason` says why.
    NotJudged,
}

impl RecordVerdict {
    /// The verdict in the words of the report (`stable`, `chatter`, `not judged`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Stable => "stable",
            Self::Chatter => "chatter",
            Self::NotJudged => "not judged",
        }
    }
}

/// What came of one signal record: the `records` table of a diagnosis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordRow {
    /// Index of the record in the file's `signals`.
    pub record: usize,
    /// The record's file as listed (resolved against the observations file's folder).
    pub file: PathBuf,
    /// Spindle speed of the record (rpm).
    pub speed_rpm: f64,
    /// Depth (milling) or width (turning) of cut of the record (mm).
    pub depth_mm: f64,
    /// Detection's verdict.
    pub verdict: RecordVerdict,
    /// The chatter frequency (Hz) of a chattering record.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub chatter_hz: Option<f64>,
    /// The numbers behind the verdict (line, V, margin, levels), absent when not judged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub evidence: Option<CutEvidence>,
    /// The detection's note: file, interference, windows, flip lines.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detection_note: Option<String>,
    /// The pole OMA identified (stable records only), as it enters the diagnosis.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pole: Option<PoleObservation>,
    /// Why the record has no cut (not judged) or no pole (chatter, OMA refused, pole out of
    /// range); absent when it gave both.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// Settings of the detection and the identification of the records; the default is what
/// `chatter detect` and `chatter oma` do without options.
#[derive(Debug, Clone, Default)]
pub struct RecordsRequest {
    /// The detection (interference, speed estimated or read).
    pub detection: DetectRequest,
    /// The identification's overrides. `allow_chatter` is ignored: a chattering record never
    /// gives a pole here.
    pub oma: OmaRequest,
}

/// The observations made from the recordings and the table of records.
#[derive(Debug, Clone)]
pub struct Recordings {
    /// The file's cuts and poles, then one cut per judged record and one pole per identified
    /// stable record; no `signals`.
    pub observations: Observations,
    /// One row per signal record, in the file's order.
    pub records: Vec<RecordRow>,
}

/// A cancel of the caller's observer, from any step.
fn cancelled(e: &JobError) -> bool {
    matches!(
        e,
        JobError::Cancelled(_)
            | JobError::Oma(OmaError::Cancelled(_))
            | JobError::Dynamics(chatter_dynamics::DynamicsError::Cancelled(_))
    )
}

/// An error's message without the `signals[i]: ` the job functions put before it.
fn message(e: JobError) -> String {
    match e {
        JobError::Record { message, .. } => message,
        e => e.to_string(),
    }
}

/// Judge and identify every signal record of `observations` (see the module documentation).
/// Only a cancel by `observer` ([`JobError::Cancelled`]) stops the job: every other failure is
/// a row's reason.
pub fn label_records(
    observations: &Observations,
    model: &ModalModel,
    request: &RecordsRequest,
    observer: &dyn Observer,
) -> Result<Recordings> {
    let mut labelled = Observations {
        cuts: observations.cuts.clone(),
        poles: observations.poles.clone(),
        signals: Vec::new(),
    };
    let oma = OmaRequest {
        allow_chatter: false,
        ..request.oma.clone()
    };
    let mut records = Vec::with_capacity(observations.signals.len());
    for (i, record) in observations.signals.iter().enumerate() {
        let mut row = RecordRow {
            record: i,
            file: record.file.clone(),
            speed_rpm: record.speed_rpm,
            depth_mm: record.depth_mm,
            verdict: RecordVerdict::NotJudged,
            chatter_hz: None,
            evidence: None,
            detection_note: None,
            pole: None,
            reason: None,
        };
        let judged = match detect_record(i, record, Some(model), &request.detection, observer) {
            Ok(j) => j,
            Err(e) if cancelled(&e) => return Err(chatter_progress::Cancelled.into()),
            Err(e) => {
                row.reason = Some(format!("not judged: {}", message(e)));
                records.push(row);
                continue;
            }
        };
        let cut = judged.cut;
        row.speed_rpm = cut.speed_rpm;
        row.evidence = cut.evidence.clone();
        row.detection_note = cut.note.clone();
        if let Err(e) = single(Observations {
            cuts: vec![cut.clone()],
            ..Observations::default()
        }) {
            row.reason = Some(format!("not judged: the labelled cut is out of range: {e}"));
            records.push(row);
            continue;
        }
        if !cut.stable {
            row.verdict = RecordVerdict::Chatter;
            row.chatter_hz = cut.chatter_hz;
            let e = &judged.detection.evidence;
            row.reason = Some(format!(
                "no pole: chatter detection calls the record chatter at {} (line variation V \
                 {:.3}, margin {:+.3}); a chattering cut's dominant line is a limit cycle, not \
                 a structural pole, so OMA refuses it",
                cut.chatter_hz
                    .map_or_else(|| "an unknown frequency".into(), |f| format!("{f:.2} Hz")),
                e.line_variation,
                e.margin
            ));
            labelled.cuts.push(cut);
            records.push(row);
            continue;
        }
        row.verdict = RecordVerdict::Stable;
        // the speed the detection used (the estimate when the speed was unknown)
        let identified = SignalRecord {
            speed_rpm: cut.speed_rpm,
            ..record.clone()
        };
        labelled.cuts.push(cut);
        match analyse_record(i, &identified, Some(model), &oma, observer) {
            Ok(analysis) => {
                let pole = pole_observation(&identified, &analysis);
                match single(Observations {
                    poles: vec![pole.clone()],
                    ..Observations::default()
                }) {
                    Ok(()) => {
                        labelled.poles.push(pole.clone());
                        row.pole = Some(pole);
                    }
                    Err(e) => {
                        row.reason = Some(format!(
                            "no pole: the identified pole ({:.2} Hz, damping ratio {:.5}) is \
                             out of range: {e}",
                            pole.frequency_hz, pole.damping_ratio
                        ));
                    }
                }
            }
            Err(e) if cancelled(&e) => return Err(chatter_progress::Cancelled.into()),
            Err(e) => row.reason = Some(format!("no pole: OMA refuses the record: {}", message(e))),
        }
        records.push(row);
    }
    Ok(Recordings {
        observations: labelled,
        records,
    })
}

/// Validate one entry on its own (the observations' ranges), so that one bad record cannot
/// make the whole set invalid.
fn single(entry: Observations) -> Result<()> {
    entry.validate()?;
    Ok(())
}

/// Simulate every cut `(speed_rpm, depth_mm)` of `cuts` with `settings` (their speed, depth
/// and seed replaced: cut k gets seed `settings.seed + k`) on `model`
/// ([`chatter_dynamics::simulate`], 000 Eq. 1-4 / 002 Eq. 1-2) and write each as
/// `record-K.csv` (K from 1; the coordinates and the `once_per_rev` pulse channel) in `dir`,
/// with `observations.json` listing them as `signals` (`sample_rate_hz` and
/// `once_per_rev_channel` given). Returns the path of `observations.json`.
pub fn write_simulated_records(
    model: &ModalModel,
    cuts: &[(f64, f64)],
    settings: &SimulationSettings,
    dir: &Path,
) -> Result<PathBuf> {
    let io = |path: &Path, e: std::io::Error| JobError::File {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let mut signals = Vec::with_capacity(cuts.len());
    for (k, &(speed_rpm, depth_mm)) in cuts.iter().enumerate() {
        let s = SimulationSettings {
            speed_rpm,
            depth_m: depth_mm * 1e-3,
            seed: settings.seed.wrapping_add(k as u64),
            ..settings.clone()
        };
        let sim = simulate(model, &s)?;
        let names: Vec<&str> = sim.channels.iter().map(|c| c.name.as_str()).collect();
        let mut text = names.join(",");
        text.push('\n');
        for j in 0..sim.channels.first().map_or(0, |c| c.data.len()) {
            let row: Vec<String> = sim
                .channels
                .iter()
                .map(|c| format!("{:e}", c.data[j]))
                .collect();
            text.push_str(&row.join(","));
            text.push('\n');
        }
        let name = format!("record-{}.csv", k + 1);
        let path = dir.join(&name);
        std::fs::write(&path, text).map_err(|e| io(&path, e))?;
        signals.push(SignalRecord {
            file: name.into(),
            speed_rpm,
            depth_mm,
            sample_rate_hz: Some(sim.sample_rate_hz),
            once_per_rev_channel: names
                .iter()
                .find(|n| **n == "once_per_rev")
                .map(|n| n.to_string()),
            quantity: Some(
                match s.quantity {
                    Quantity::Acceleration => "acceleration",
                    Quantity::Velocity => "velocity",
                    Quantity::Displacement => "displacement",
                }
                .into(),
            ),
            sequence: Some(k as i64 + 1),
            radial_immersion: None,
            note: Some(format!("simulated, seed {}", s.seed)),
        });
    }
    let observations = Observations {
        signals,
        ..Observations::default()
    };
    let path = dir.join("observations.json");
    std::fs::write(&path, observations.to_json_string()).map_err(|e| io(&path, e))?;
    Ok(path)
}

/// The file name of a row, for tables.
pub fn row_file_name(row: &RecordRow) -> String {
    row.file.file_name().map_or_else(
        || row.file.display().to_string(),
        |n| n.to_string_lossy().into(),
    )
}
