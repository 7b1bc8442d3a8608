//! The OMA job of an observations file (`chatter oma --observations FILE`,
//! `chatter.oma_observations`): every signal record listed in the file identified, one pole
//! observation per record.
//!
//! Each record is read (CSV at the entry's `sample_rate_hz`, WAV or MP3 at its own rate), its
//! `once_per_rev_channel` (if any) gives the spindle frequency and is taken out of the analysed
//! channels. A record that chatter detection (`chatter_oma::detection`, with the spindle
//! frequency and the request's interference) calls chatter is refused: its dominant line is a
//! limit cycle, not a structural pole; [`OmaRequest::allow_chatter`] identifies it anyway and
//! says so in the pole's `note`. Then the dominant pole is identified with repeated segments
//! (`chatter_oma::identify`):
//! - turning, or no model: modified LSCE with every spindle harmonic (rpm / 60) in the analysed
//!   band imposed (000 Eq. 19-25); the pole's `frequency_hz` is the physical frequency;
//! - milling model: lifting at the tooth period (from the tachometer pulses when there is a
//!   once-per-revolution channel, else from `speed_rpm`) and polyreference (002 Eq. 6-9); the
//!   pole's `frequency_hz` is the principal frequency of the Floquet multiplier.

use crate::error::{JobError, Result};
use chatter_dynamics::{ModalModel, Observations, Operation, PoleObservation, SignalRecord};
use chatter_oma::OmaError;
use chatter_oma::detection::{Detection, DetectionOptions, Verdict, detect_with_observer};
use chatter_oma::interference::{Interference, LOW_HARMONICS};
use chatter_oma::signals::Signals;
use chatter_oma::{
    Decimation, Harmonics, Identification, IdentifyOptions, Lifting, identify_with_observer,
};
use chatter_progress::Observer;

/// Overrides of the identification and the chatter check; the default is the automatic choice
/// of every setting (what `chatter oma` does without options).
#[derive(Debug, Clone, Default)]
pub struct OmaRequest {
    /// Lowest model order beyond the imposed harmonics (default 1).
    pub min_order: Option<usize>,
    /// Highest model order beyond the imposed harmonics (default 30; 6 with lifting).
    pub max_order: Option<usize>,
    /// Number of random segments (default 10).
    pub segments: Option<usize>,
    /// Harmonics to impose instead of the spindle lines found in the record.
    pub harmonics: Option<Harmonics>,
    /// Decimation factor before LSCE (1: none; default automatic).
    pub decimation: Option<usize>,
    /// Interference combs of the chatter check (default: a search over the mains range).
    pub interference: Interference,
    /// Identify records that chatter detection calls chatter (flagged in the pole's note).
    pub allow_chatter: bool,
}

/// Most random segments, model orders of an identification.
pub const MAX_SEGMENTS_OR_ORDER: usize = 200;
/// Largest decimation factor.
pub const MAX_DECIMATION: usize = 1000;

impl OmaRequest {
    /// Check the overrides once: segments and model orders from 1 to
    /// [`MAX_SEGMENTS_OR_ORDER`], a decimation factor from 1 to [`MAX_DECIMATION`]
    /// ([`identify_observations`] runs it before any record is read).
    pub fn check(&self) -> Result<()> {
        for (field, value, max, what) in [
            (
                "segments",
                self.segments,
                MAX_SEGMENTS_OR_ORDER,
                "random segments",
            ),
            (
                "min_order",
                self.min_order,
                MAX_SEGMENTS_OR_ORDER,
                "model orders",
            ),
            (
                "max_order",
                self.max_order,
                MAX_SEGMENTS_OR_ORDER,
                "model orders",
            ),
            (
                "decimation",
                self.decimation,
                MAX_DECIMATION,
                "a decimation factor",
            ),
        ] {
            if let Some(n) = value {
                crate::error::count(field, n, 1, max, what)?;
            }
        }
        Ok(())
    }
}

/// One identified record.
#[derive(Debug, Clone)]
pub struct RecordAnalysis {
    /// The identification: pole, stabilization diagram, order statistics.
    pub identification: Identification,
    /// The analysed channels (tachometer removed).
    pub signals: Signals,
    /// The lifting of a milling record.
    pub lifting: Option<Lifting>,
    /// The method in words.
    pub method: String,
    /// The chatter frequency (Hz) of a record let through by [`OmaRequest::allow_chatter`].
    pub chatter_hz: Option<f64>,
    /// The interference the chatter check left out, as a clause of the pole's note.
    pub interference: String,
}

impl RecordAnalysis {
    /// The first singular value of the Welch PSD matrix of the analysed data (the channels
    /// lifted at the tooth period, two virtual sensors each, for a milling record; Welch
    /// segments of an eighth of the record, 4 to 4096 samples): the background of the
    /// stabilization diagram (000 Fig. 3a).
    pub fn psd_first_singular_value(&self) -> Result<chatter_oma::spectrum::Spectrum> {
        let (data, rate_hz) = match self.lifting {
            Some(l) => {
                let mut lifted = Vec::new();
                for ch in &self.signals.data {
                    let all = chatter_oma::lifting::lift_at_period(
                        ch,
                        self.signals.sample_rate_hz,
                        l.period_s,
                    )?;
                    let r = all.len();
                    lifted.extend(
                        (0..l.virtual_sensors).map(|k| all[k * r / l.virtual_sensors].clone()),
                    );
                }
                (lifted, 1.0 / l.period_s)
            }
            None => (self.signals.data.clone(), self.signals.sample_rate_hz),
        };
        let len = data.first().map_or(0, Vec::len);
        let segment = (len / 8).clamp(4, 4096);
        Ok(chatter_oma::spectrum::first_singular_value(
            &data, rate_hz, segment,
        )?)
    }
}

/// The channels of record `i`: CSV at the entry's rate, WAV or MP3 at their own.
pub fn read_record(i: usize, record: &SignalRecord) -> Result<Signals> {
    let extension = record
        .file
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    Ok(match extension.as_deref() {
        Some("wav") => Signals::from_wav(&record.file, None)?,
        Some("mp3") => Signals::from_mp3(&record.file)?,
        _ => {
            let fs = record.sample_rate_hz.ok_or_else(|| JobError::Invalid {
                field: "signals.sample_rate_hz",
                value: format!("missing in signals[{i}]"),
                expected: "the sample rate of a CSV record (Hz)".into(),
            })?;
            Signals::from_csv(&record.file, fs)?
        }
    })
}

/// A record's channels belong to the model's operation: a milling model has channels `x`/`y`,
/// a turning model `feed`/`cutting`; a channel of the other operation is an error (a record of
/// another machine). `record` names the record in the message.
pub fn channels_match(model: &ModalModel, names: &[String], record: &str) -> Result<()> {
    let (kind, own, other) = match model.operation() {
        Operation::Milling(_) => ("milling", ["x", "y"], ["feed", "cutting"]),
        Operation::Turning(_) => ("turning", ["feed", "cutting"], ["x", "y"]),
    };
    match names.iter().find(|n| other.contains(&n.as_str())) {
        Some(name) => Err(JobError::Record {
            record: record.into(),
            message: format!(
                "channel `{name}` is a coordinate of the other operation, but the model is \
                 {kind} (coordinates {own:?}); is this record from another machine?"
            ),
        }),
        None => Ok(()),
    }
}

/// What interference the chatter check left out, as a clause of a note: the comb found, the
/// fundamentals given, or nothing.
pub fn interference_note(interference: &Interference, d: &Detection) -> String {
    match (interference, &d.evidence.interference) {
        (_, Some(c)) => format!(
            "; interference comb found and left out: {:.3} Hz, {} lines ({} of the first {} \
             multiples) up to {:.0} Hz",
            c.fundamental_hz,
            c.lines_hz.len(),
            c.low_members,
            LOW_HARMONICS,
            c.lines_hz.last().copied().unwrap_or(0.0)
        ),
        (Interference::Search { min_hz, max_hz }, None) => {
            format!("; no interference comb found in {min_hz}-{max_hz} Hz")
        }
        (Interference::Known(bases), None) => {
            format!("; interference given: multiples of {bases:?} Hz left out")
        }
        (Interference::Off, None) => String::new(),
    }
}

/// Identify record `i` (see the module documentation); `model` chooses lifting for milling and
/// checks the channels; `observer` may cancel the detection and the identification.
pub fn analyse_record(
    i: usize,
    record: &SignalRecord,
    model: Option<&ModalModel>,
    request: &OmaRequest,
    observer: &dyn Observer,
) -> Result<RecordAnalysis> {
    let name = format!("signals[{i}]");
    let mut signals = read_record(i, record)?;
    if let Some(m) = model {
        channels_match(m, &signals.names, &name)?;
    }
    let mut revolution_s = 60.0 / record.speed_rpm;
    if let Some(channel) = &record.once_per_rev_channel {
        let c = signals.channel(channel).ok_or_else(|| JobError::Record {
            record: name.clone(),
            message: format!(
                "`once_per_rev_channel` `{channel}` is not a channel of the record (channels: \
                 {})",
                signals.names.join(", ")
            ),
        })?;
        revolution_s = signals.pulse_period_s(c)?;
        signals = signals.without_channel(c)?;
    }
    let mut detection_options = DetectionOptions::new(1.0 / revolution_s);
    detection_options.interference = request.interference.clone();
    let detection = detect_with_observer(&signals, &detection_options, observer)?;
    let interference = interference_note(&detection_options.interference, &detection);
    let chatter_hz = match (detection.verdict, request.allow_chatter) {
        (Verdict::Stable, _) => None,
        (Verdict::Chatter, false) => {
            return Err(JobError::Record {
                record: name,
                message: format!(
                    "chatter detection calls this record chatter at {:.2} Hz (line variation V \
                     {:.3}, margin {:+.3}{interference}): a chattering cut is not an OMA \
                     record, its dominant line is a limit cycle, not a structural pole; pass \
                     --allow-chatter to identify it anyway",
                    detection.evidence.peak_hz,
                    detection.evidence.line_variation,
                    detection.evidence.margin
                ),
            });
        }
        (Verdict::Chatter, true) => Some(detection.evidence.peak_hz),
    };
    let teeth = match model.map(ModalModel::operation) {
        Some(Operation::Milling(m)) => Some(m.teeth()),
        _ => None,
    };
    let mut options = match teeth {
        Some(teeth) => IdentifyOptions::lifted(revolution_s / teeth as f64, teeth),
        None => IdentifyOptions::spindle(1.0 / revolution_s),
    };
    let lifting = options.lifting;
    let method = match lifting {
        Some(l) => format!(
            "lifted at the tooth period {:.6} s, polyreference",
            l.period_s
        ),
        None => "modified LSCE".to_string(),
    };
    if let Some(n) = request.min_order {
        options.min_order = n;
    }
    if let Some(n) = request.max_order {
        options.max_order = n;
    }
    if let Some(n) = request.segments {
        options.segments = n;
    }
    if let Some(h) = &request.harmonics {
        options.harmonics = h.clone();
    }
    if let Some(n) = request.decimation {
        options.decimation = Decimation::Factor(n);
    }
    let identification = identify_with_observer(&signals, &options, observer)?;
    Ok(RecordAnalysis {
        identification,
        signals,
        lifting,
        method,
        chatter_hz,
        interference,
    })
}

/// The pole observation of an analysed record, with a note that says how it was identified.
pub fn pole_observation(record: &SignalRecord, a: &RecordAnalysis) -> PoleObservation {
    let id = &a.identification;
    let e = &id.estimate;
    let frequency_hz = if a.lifting.is_some() {
        e.principal_frequency_hz
    } else {
        e.frequency_hz
    };
    let harmonics = if id.harmonics_hz.is_empty() {
        String::new()
    } else {
        format!(", harmonics {:.1?} Hz imposed", id.harmonics_hz)
    };
    let decimation = if id.decimation_factor > 1 {
        format!(", decimated by {}", id.decimation_factor)
    } else {
        String::new()
    };
    let rejected = if id.rejected.is_empty() {
        String::new()
    } else {
        let list: Vec<String> = id
            .rejected
            .iter()
            .map(|r| format!("{:.1} Hz ({:?})", r.frequency_hz, r.reason))
            .collect();
        format!(", rejected {}", list.join(", "))
    };
    let flag = a.chatter_hz.map_or_else(String::new, |f| {
        format!("; FLAGGED: chatter detection calls the record chatter at {f:.2} Hz")
    });
    PoleObservation {
        speed_rpm: record.speed_rpm,
        depth_mm: record.depth_mm,
        frequency_hz,
        damping_ratio: e.damping_ratio,
        frequency_std_hz: e.frequency_std_hz,
        damping_std: e.damping_std,
        repetitions: u32::try_from(e.repetitions).ok(),
        sequence: record.sequence,
        radial_immersion: record.radial_immersion,
        note: Some(format!(
            "OMA of {}: {}{decimation}, order {}, {} lags{harmonics}{rejected}{flag}{}",
            record.file.file_name().map_or_else(
                || record.file.display().to_string(),
                |n| n.to_string_lossy().into()
            ),
            a.method,
            id.order,
            id.segment_lags,
            a.interference
        )),
    }
}

/// Every record of `observations` identified: the observations with the input's `cuts` and one
/// `poles` entry per signal (ready for the updating commands), and each record's analysis. The
/// first record that fails is the error, named `signals[i] (file)`; a cancel (`observer`'s) is
/// [`JobError::Cancelled`].
pub fn identify_observations(
    observations: &Observations,
    model: Option<&ModalModel>,
    request: &OmaRequest,
    observer: &dyn Observer,
) -> Result<(Observations, Vec<RecordAnalysis>)> {
    request.check()?;
    if observations.signals.is_empty() {
        return Err(JobError::Invalid {
            field: "observations",
            value: "no `signals`".into(),
            expected: "at least one entry with a `file` to identify".into(),
        });
    }
    let mut poles = Vec::with_capacity(observations.signals.len());
    let mut analyses = Vec::with_capacity(observations.signals.len());
    for (i, record) in observations.signals.iter().enumerate() {
        let analysis =
            analyse_record(i, record, model, request, observer).map_err(|e| match e {
                JobError::Oma(OmaError::Cancelled(c)) => JobError::Cancelled(c),
                e => JobError::Record {
                    record: format!("signals[{i}] ({})", record.file.display()),
                    message: match e {
                        JobError::Record { message, .. } => message,
                        e => e.to_string(),
                    },
                },
            })?;
        poles.push(pole_observation(record, &analysis));
        analyses.push(analysis);
    }
    let result = Observations {
        cuts: observations.cuts.clone(),
        poles,
        signals: Vec::new(),
    };
    Ok((result, analyses))
}
