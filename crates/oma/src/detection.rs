//! Chatter detection: is there a self-excited vibration in a record, beside the response forced
//! at the harmonics of a known fundamental (the spindle frequency), and at what frequency.
//!
//! Knows nothing of machining beyond the fundamental: every multiple k f_0 (spindle and
//! tooth-passing harmonics alike, since the tooth-passing frequency is a multiple of the
//! spindle's) is "synchronous".
//!
//! # Spectrum
//! Each channel (mean removed, divided by its standard deviation so that channels of different
//! units weigh alike) gives a Welch power spectral density (Hann segments of 2^m samples with a
//! bin width df at most the requested resolution, 50 % overlap); the densities are summed.
//!
//! # Fundamental
//! Without a once-per-revolution channel the nominal f_0 is refined within
//! +-[`DetectionOptions::speed_tolerance`] to the value that maximizes sum_k ln S(k f_0) over the
//! harmonics in the band (a logarithmic comb, so a single strong chatter line cannot pull the
//! comb onto itself); with one, f_0 is the pulse rate. When the speed is unknown
//! ([`Fundamental::Search`], e.g. a sound clip whose cutting conditions were not recorded), f_0
//! is the fundamental of the record's harmonic comb in the given range
//! ([`crate::interference::harmonic_fundamental`]: the most lines at its first 12 multiples, the
//! lowest of equally good submultiples); a record without such a comb is an error.
//!
//! # Criterion
//! A bin is synchronous when it lies within 2.5 df + k f_0 [`HARMONIC_TOLERANCE`] of a multiple
//! k f_0 (or is a line of an interference comb, see [`DetectionOptions::interference`]). In the band
//! [`DetectionOptions::min_frequency_hz`] .. [`DetectionOptions::max_frequency_hz`] the
//! strongest non-synchronous local maximum of the density is the candidate line. What tells a
//! self-excited vibration from a structural resonance driven by the random part of the cutting
//! force is not its level, which depends on the unknown excitation, but its amplitude: a limit
//! cycle has a constant one, a resonance driven by broadband forces is a narrowband Gaussian
//! process whose power in a short window is exponentially distributed (coefficient of variation
//! 1). So the power of the line (three bins around it, segments of half the spectrum's length
//! hopped by a quarter over the record's second half, where a growing vibration has settled) has
//! its coefficient of variation V computed, and the record chatters when
//! - V <= [`DetectionOptions::max_line_variation`] (default [`MAX_LINE_VARIATION`]): a limit
//!   cycle, or V >= [`DetectionOptions::min_burst_variation`] (default
//!   [`MIN_BURST_VARIATION`]): a line that grows or comes and goes far beyond the scatter of a
//!   stationary resonance (intermittent chatter, as in real cuts), and
//! - the line stands [`MIN_LINE_TO_FLOOR_DB`] above the floor, the median density of the
//!   non-synchronous bins (so that a record of noise is never chatter).
//!
//! The margin reported is the larger of the two threshold distances (positive: chatter). On
//! simulated lobe diagrams (see `tests/oma_detection.rs`) V was at most 0.19 in chatter and
//! between 0.37 and 0.94 in stable cuts; on the real chatter record `test255_accelY.csv`
//! (intermittent chatter) it is 2.0.
//! Also reported: the line's power against the synchronous (forced) power, E_line / E_sync, and
//! against everything else in the band, both less the floor, in dB.
//!
//! A stationary deterministic line that is not a multiple of f_0 (mains hum, a neighbouring
//! machine) has a constant amplitude too. By default ([`Interference::Search`]) a comb of such
//! lines with a fundamental in 45-65 Hz is searched for (see [`crate::interference`]) and its
//! member lines are synchronous as well; the comb found is reported in
//! [`DetectionEvidence::interference`]. Known fundamentals ([`Interference::Known`]) make every
//! one of their multiples synchronous instead.
//!
//! # Flip chatter
//! Period-doubling (flip) chatter of a cutter with an even number z of teeth vibrates at the odd
//! multiples of half the tooth-passing frequency, (2k + 1) z f_0 / 2: spindle harmonics, which
//! the criterion above takes for forced response. With the tooth count given
//! ([`DetectionOptions::teeth`], even), those flip lines are judged apart. A stable cut has
//! lines there too: the spindle-periodic forcing (runout, here the simulator's harmonics at 1-4
//! f_0) reaches every spindle harmonic through the tooth-periodic cut, and is constant, so V
//! cannot tell them from a limit cycle. Their level can: forced lines at the flip harmonics are
//! of the order of those at the "runout-only" harmonics (multiples of f_0 that are neither tooth
//! harmonics nor flip lines, e.g. the odd ones for 4 teeth), while a flip limit cycle stands far
//! above them. So the strongest flip line in the band is flip chatter when its V (second half,
//! as above) is at most the limit-cycle threshold, it stands [`MIN_LINE_TO_FLOOR_DB`] above the
//! floor and [`MIN_FLIP_TO_RUNOUT_DB`] = 16 dB above the strongest runout-only line
//! ([`FlipEvidence`]). The threshold is from the proving ground's xy machine (the example
//! `milling_study` of the workspace's tests package: 4 teeth, 30 %, 72 simulated records):
//! stable records reach +10.0 dB, its
//! three flip-chatter records +22.6 to +25.0 dB; it is checked on another machine (seed 001's,
//! `tests/oma_detection.rs`). With two teeth there is no runout-only harmonic and flip chatter is
//! not judged; a record that is chatter by the main criterion keeps its line. Judged on the whole
//! record only, not window by window.
//!
//! The chatter frequency is the line's, refined by a parabola through the logarithms of the
//! three densities around it.
//!
//! # Windows
//! Chatter that lasts only part of a record (a sound clip of several passes, a cut that chatters
//! on entry and then settles) is missed by a criterion that judges the record's second half. So
//! the record is also judged window by window: windows of [`WINDOW_SEGMENTS`] = 4 spectrum
//! segments (2 to 6 s at the default resolutions) start every half window; each window is judged
//! like the whole record (its own Welch density from the same segments, floor, strongest
//! non-synchronous line, the same synchronous bins, and the line's variation V over all of the
//! window's short segments, not only its second half). The record chatters when the whole-record
//! criterion says so **or** at least [`MIN_SUSTAINED_WINDOWS`] = 2 consecutive windows chatter at
//! the same line (within [`LINE_MATCH_BINS`] bins): the chatter must last at least 1.5 windows
//! (6 spectrum segments). One window alone never decides: the start of a cut (the simulator's
//! records start from rest with the whole static force applied at once, a step that rings the
//! structure for a few of its time constants, far below a window) or one burst of a random
//! resonance make one window's V large, not two windows' at the same line. Records shorter than
//! 1.5 windows are judged whole only (the simulator sweeps' 4 s records at 10 kHz, for one).
//! Reported in [`DetectionEvidence::windows`]: every window's line, V and margin, the record's
//! windowed margin (the best pair of neighbouring windows at the same line, the smaller of their
//! two margins) and the chattering time span.
//!
//! # Reference stretch
//! A record of a shop cut (a sound clip above all) often holds the machine before and after the
//! cut: the spindle idling, fans, drives, the room. Their tones are stationary and non-harmonic,
//! so V calls them limit cycles. Such a stretch is recognised by its level: when the loudest
//! window's band power exceeds the quietest's by [`REFERENCE_CONTRAST_DB`] = 6 dB or more, the
//! windows within [`REFERENCE_LEVEL_DB`] = 3 dB of the quietest form the record's reference
//! stretch; they are not judged (whatever stands out there is present without the cut), and the
//! others are the cutting windows. Chatter in a real cut is seldom a constant-amplitude limit
//! cycle (feed, engagement and a drifting frequency modulate it: V between the thresholds), but
//! it dominates the vibration it adds. So in a record with a reference stretch, a cutting window
//! also chatters when its line carries at least [`DOMINANT_LINE_DB`] = 0 dB over everything else
//! in the band (synchronous lines, other lines and the floor: half the window's power or more)
//! and stands [`MIN_LINE_TO_FLOOR_DB`] above the floor; two neighbouring windows at the same
//! line are needed, as for V. A tone of the background cannot pass: at a constant level it holds
//! at most half of a cutting window's power (3 dB or more above the quietest window's), i.e.
//! less than 0 dB over the rest. A stationary record (a simulated cut, a cut recorded whole)
//! has no reference stretch and is judged by V alone.
//!
//! On the chatter clip `combined_chatter6567.mp3` (63 s; `tests/oma_detection.rs`) the cut lasts
//! from about 5 to 18 s: its windows are 5-10 dB louder than the rest, whose stationary lines
//! (2329.9, 1770.7, 869.4 Hz: the same before and after the cut) V took for chatter; the
//! chatter line 1067-1077 Hz carries +2.0, +3.9 and +1.0 dB over the rest of the band in three
//! windows from 8.9 s (V 0.67, 0.62, 1.92 there). The thresholds were set with this clip in view
//! (the only real record with a reference stretch in the project). The no-chatter clip
//! (contrast 0.6 dB) and the built records of `tests/oma_detection.rs` (contrast at most 0.1
//! dB, also with a limit cycle in part of the record) have none; the simulator sweeps' 4 s records are
//! judged whole.

use crate::error::{OmaError, Result};
use crate::interference::{
    Interference, InterferenceComb, LOW_HARMONICS, MIN_LOW_MEMBERS, find_comb,
    harmonic_fundamental, spectral_lines,
};
use crate::signals::Signals;
use crate::spectrum::{Spectrum, refine_peak_hz, segment_densities};
use chatter_progress::{Observer, Silent};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Default largest coefficient of variation of the line's power, over the segments of the
/// record's second half, for chatter.
pub const MAX_LINE_VARIATION: f64 = 0.3;
/// Default smallest coefficient of variation of the line's share for intermittent or growing
/// chatter: far beyond the scatter of a stationary random resonance (about 1 +- 0.25 over the
/// segments of a few seconds).
pub const MIN_BURST_VARIATION: f64 = 1.6;
/// A chatter line stands at least this far above the broadband floor (dB, peak density over
/// floor density).
pub const MIN_LINE_TO_FLOOR_DB: f64 = 20.0;
/// Relative width of the synchronous band around each harmonic, beyond the window's 2.5 bins:
/// the spindle speed drifts by this fraction during a record.
pub const HARMONIC_TOLERANCE: f64 = 5e-4;
/// Default relative search range of the fundamental around its nominal value.
pub const SPEED_TOLERANCE: f64 = 0.005;

/// A flip line is flip chatter only when it stands this far above the strongest runout-only
/// spindle harmonic (dB; see the [module documentation](self#flip-chatter)).
pub const MIN_FLIP_TO_RUNOUT_DB: f64 = 16.0;
/// Window length, in spectrum segments, of the window-by-window judgement (so a window's
/// density averages 2 x 4 - 1 = 7 half-overlapping segments and its line variation 15
/// short segments, about as many as the whole-record criterion uses on a 4 s record).
pub const WINDOW_SEGMENTS: usize = 4;
/// Consecutive windows (each shifted by half a window) that must chatter at the same line: a
/// sustained chatter lasts at least 1.5 windows (6 spectrum segments).
pub const MIN_SUSTAINED_WINDOWS: usize = 2;
/// A window's short segments (half a spectrum segment) start every 1 / this of their length:
/// half-overlapping Hann segments, nearly all of the information at half the cost of the whole
/// record's quarter hop (the window judgement costs about as much as the rest of the detection).
pub const WINDOW_HOPS_PER_SEGMENT: usize = 2;
/// Two windows' lines are the same line when they lie within this many bins.
pub const LINE_MATCH_BINS: f64 = 2.0;

/// A record whose loudest window's band power exceeds its quietest's by at least this (dB) holds
/// a reference stretch (see the [module documentation](self#reference-stretch)).
pub const REFERENCE_CONTRAST_DB: f64 = 6.0;
/// The reference stretch: the windows within this of the quietest window's band power (dB).
pub const REFERENCE_LEVEL_DB: f64 = 3.0;
/// In a record with a reference stretch, a cutting window whose line carries at least this much
/// over everything else in the band (dB, [`WindowJudgement::line_to_rest_db`]) chatters.
pub const DOMINANT_LINE_DB: f64 = 0.0;

/// Default range of the spindle frequency searched when it is unknown (Hz): 600 to 30 000 rpm.
pub const SPINDLE_RANGE_HZ: (f64, f64) = (10.0, 500.0);

/// Where the fundamental f_0 comes from (a once-per-revolution channel overrides both).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fundamental {
    /// The spindle rotation frequency rpm / 60 (Hz), refined within
    /// [`DetectionOptions::speed_tolerance`].
    Nominal(f64),
    /// Unknown speed: the fundamental of the record's harmonic comb in `min_hz` to `max_hz`
    /// (default [`SPINDLE_RANGE_HZ`]).
    Search {
        /// Lowest fundamental (Hz).
        min_hz: f64,
        /// Highest fundamental (Hz).
        max_hz: f64,
    },
}

impl Fundamental {
    /// The lowest fundamental it can be (Hz): the scale of the default resolution and band.
    fn lowest_hz(self) -> f64 {
        match self {
            Self::Nominal(f) => f,
            Self::Search { min_hz, .. } => min_hz,
        }
    }
}

/// Options of [`detect`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DetectionOptions {
    /// The fundamental: nominal (the spindle rotation frequency) or searched.
    pub fundamental: Fundamental,
    /// Finest bin width wanted (Hz); default `None`: f_0 / 10 (the lowest f_0 searched), at
    /// most 2 Hz, with at least 8 segments in the record.
    pub resolution_hz: Option<f64>,
    /// Lowest frequency searched (Hz); default `None`: f_0 / 2 (the lowest f_0 searched).
    pub min_frequency_hz: Option<f64>,
    /// Highest frequency searched (Hz); default `None`: 0.45 times the sample rate.
    pub max_frequency_hz: Option<f64>,
    /// Relative search range of the fundamental (default [`SPEED_TOLERANCE`]; 0 keeps the
    /// nominal value).
    pub speed_tolerance: f64,
    /// Largest coefficient of variation of the line's power for chatter, default
    /// [`MAX_LINE_VARIATION`].
    pub max_line_variation: f64,
    /// Smallest coefficient of variation of the line's share for intermittent or growing
    /// chatter, default [`MIN_BURST_VARIATION`].
    pub min_burst_variation: f64,
    /// Name of a once-per-revolution channel: excluded from the spectrum, its pulse rate is f_0.
    pub once_per_rev_channel: Option<String>,
    /// Interference combs (mains hum) whose lines are synchronous too: searched for in
    /// 45-65 Hz by default, given, or none.
    pub interference: Interference,
    /// The cutter's number of teeth (milling), if known: with an even number, period-doubling
    /// (flip) chatter lies on spindle harmonics, at the odd multiples of half the tooth-passing
    /// frequency, and is looked for there (see the [module documentation](self#flip-chatter)).
    pub teeth: Option<usize>,
}

impl DetectionOptions {
    /// Options with the documented defaults for the nominal fundamental `fundamental_hz`.
    pub fn new(fundamental_hz: f64) -> Self {
        Self::with_fundamental(Fundamental::Nominal(fundamental_hz))
    }

    /// Options with the documented defaults for an unknown speed: the fundamental is searched
    /// over [`SPINDLE_RANGE_HZ`].
    pub fn unknown_speed() -> Self {
        Self::with_fundamental(Fundamental::Search {
            min_hz: SPINDLE_RANGE_HZ.0,
            max_hz: SPINDLE_RANGE_HZ.1,
        })
    }

    fn with_fundamental(fundamental: Fundamental) -> Self {
        Self {
            fundamental,
            resolution_hz: None,
            min_frequency_hz: None,
            max_frequency_hz: None,
            speed_tolerance: SPEED_TOLERANCE,
            max_line_variation: MAX_LINE_VARIATION,
            min_burst_variation: MIN_BURST_VARIATION,
            once_per_rev_channel: None,
            interference: Interference::default(),
            teeth: None,
        }
    }
}

/// The verdict on one record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// No self-excited line dominates the forced response.
    Stable,
    /// A self-excited line dominates.
    Chatter,
}

/// The numbers behind a verdict (see the [module documentation](self#criterion)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DetectionEvidence {
    /// Fundamental used (Hz), after refinement.
    pub fundamental_hz: f64,
    /// Frequency of the strongest non-synchronous peak (Hz).
    pub peak_hz: f64,
    /// R = 10 log10(E_line / E_sync) (dB).
    pub line_to_forced_db: f64,
    /// Peak density over the floor density (dB).
    pub line_to_floor_db: f64,
    /// 10 log10 of E_line over the power of everything else in the band, synchronous or not
    /// (dB).
    pub line_to_rest_db: f64,
    /// The limit-cycle threshold of the line variation.
    pub max_line_variation: f64,
    /// The burst threshold of the line variation.
    pub min_burst_variation: f64,
    /// The larger of (limit-cycle threshold - V) and (V - burst threshold): positive for
    /// chatter (unless the line does not stand [`MIN_LINE_TO_FLOOR_DB`] above the floor).
    pub margin: f64,
    /// Bin width (Hz).
    pub resolution_hz: f64,
    /// Coefficient of variation of the line's power over the segments of the record's second
    /// half: about 1 for a stable resonance driven by random forces (a narrowband Gaussian
    /// process), near 0 for a limit cycle.
    pub line_variation: f64,
    /// The interference comb found and left out ([`Interference::Search`]), if any.
    pub interference: Option<InterferenceComb>,
    /// The record judged window by window ([`WINDOW_SEGMENTS`]); `None` when the record is
    /// shorter than two windows.
    pub windows: Option<WindowedEvidence>,
    /// The flip lines, when the tooth count is known and even.
    pub flip: Option<FlipEvidence>,
}

/// The period-doubling (flip) lines of an even-toothed cutter (see the
/// [module documentation](self#flip-chatter)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlipEvidence {
    /// Frequency of the strongest line at an odd multiple of half the tooth-passing frequency
    /// (Hz).
    pub line_hz: f64,
    /// Its peak density over the floor (dB).
    pub line_to_floor_db: f64,
    /// Its peak density over that of the strongest other spindle harmonic in the band (dB).
    pub line_to_forced_db: f64,
    /// Its peak density over that of the strongest spindle harmonic that is neither a tooth
    /// harmonic nor a flip line (runout only; `None` with two teeth, where there is none) (dB).
    pub line_to_runout_db: Option<f64>,
    /// Coefficient of variation of its share of the power over the record's second half.
    pub line_variation: f64,
    /// Limit-cycle threshold - V (positive: a limit cycle).
    pub variation_margin: f64,
    /// line_to_runout_db - [`MIN_FLIP_TO_RUNOUT_DB`] (dB; positive: not runout); `None` with two
    /// teeth.
    pub runout_margin_db: Option<f64>,
    /// Flip chatter: a limit cycle (V at most the limit-cycle threshold) at least
    /// [`MIN_FLIP_TO_RUNOUT_DB`] above the runout lines and [`MIN_LINE_TO_FLOOR_DB`] above the
    /// floor.
    pub chatter: bool,
}

/// One window of the record judged on its own (see the [module documentation](self#windows)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WindowJudgement {
    /// Start of the window (s from the record's start).
    pub start_s: f64,
    /// Frequency of the window's strongest non-synchronous line (Hz).
    pub line_hz: f64,
    /// Its peak density over the window's floor (dB).
    pub line_to_floor_db: f64,
    /// Coefficient of variation of its share of the power over the window's short segments;
    /// `None` (not computed: it cannot make a sustained chatter) unless the line stands
    /// [`MIN_LINE_TO_FLOOR_DB`] above the floor in this window and in a neighbouring one whose
    /// line lies within [`LINE_MATCH_BINS`].
    pub line_variation: Option<f64>,
    /// Distance of that variation to the nearer threshold (positive: the window chatters).
    pub margin: Option<f64>,
    /// Part of the record's reference stretch (see [`WindowedEvidence::reference_stretch`]): not
    /// judged.
    pub reference: bool,
    /// 10 log10 of the line's power over everything else in the band (dB).
    pub line_to_rest_db: f64,
    /// A cutting window of a record with a reference stretch whose line carries at least
    /// [`DOMINANT_LINE_DB`] over the rest of the band and stands [`MIN_LINE_TO_FLOOR_DB`] above
    /// the floor: it chatters whatever its V.
    pub dominant: bool,
}

/// A run of consecutive chattering windows at the same line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChatterSpan {
    /// Start of the run's first window (s).
    pub start_s: f64,
    /// End of its last window (s).
    pub end_s: f64,
    /// The line of the run's window with the largest margin (Hz).
    pub line_hz: f64,
    /// Its coefficient of variation.
    pub line_variation: f64,
    /// Some window of the run chatters by dominance only (its V between the thresholds).
    pub by_dominance: bool,
}

/// The record judged window by window: it chatters when at least [`MIN_SUSTAINED_WINDOWS`]
/// consecutive windows chatter at the same line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WindowedEvidence {
    /// Band power of the loudest window over the quietest's (dB).
    pub contrast_db: f64,
    /// The record holds a reference stretch (contrast at least [`REFERENCE_CONTRAST_DB`]): its
    /// windows within [`REFERENCE_LEVEL_DB`] of the quietest are not judged, and the others may
    /// chatter by dominance (see the [module documentation](self#reference-stretch)).
    pub reference_stretch: bool,
    /// Window length (s): [`WINDOW_SEGMENTS`] spectrum segments.
    pub window_s: f64,
    /// Shift between windows (s): half a window.
    pub hop_s: f64,
    /// Shortest chatter that counts (s): [`MIN_SUSTAINED_WINDOWS`] windows, overlapping.
    pub min_duration_s: f64,
    /// The largest, over pairs of neighbouring windows whose lines agree within
    /// [`LINE_MATCH_BINS`] and stand [`MIN_LINE_TO_FLOOR_DB`] above their floors, of the smaller of
    /// the two margins (positive: the record chatters); `None` when no pair qualifies.
    pub margin: Option<f64>,
    /// The longest-lasting sustained chatter (the one with the largest margin among equals), if any.
    pub chatter: Option<ChatterSpan>,
    /// Every window.
    pub windows: Vec<WindowJudgement>,
}

/// Result of [`detect`].
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// Stable or chatter.
    pub verdict: Verdict,
    /// The chatter frequency (Hz) when the verdict is chatter.
    pub chatter_hz: Option<f64>,
    /// The numbers behind the verdict.
    pub evidence: DetectionEvidence,
    /// Summed normalized density (1 / Hz) from 0 to the Nyquist frequency.
    pub spectrum: Spectrum,
    /// The harmonics k f_0 in the band (Hz).
    pub harmonics_hz: Vec<f64>,
    /// The band searched (Hz).
    pub band_hz: (f64, f64),
}

fn invalid(field: &'static str, message: String) -> OmaError {
    OmaError::InvalidInput { field, message }
}

/// Decide whether `signals` chatter (see the [module documentation](self)).
pub fn detect(signals: &Signals, options: &DetectionOptions) -> Result<Detection> {
    detect_with_observer(signals, options, &Silent)
}

/// [`detect`], polling `observer` between its stages (the spectrum, the fundamental, the
/// windows) and before every short segment of the line variation: a cancelled call returns
/// [`OmaError::Cancelled`].
pub fn detect_with_observer(
    signals: &Signals,
    options: &DetectionOptions,
    observer: &dyn Observer,
) -> Result<Detection> {
    chatter_progress::check(observer)?;
    let fs = signals.sample_rate_hz;
    let nyquist = fs / 2.0;
    let f0_lowest = options.fundamental.lowest_hz();
    let f0_highest = match options.fundamental {
        Fundamental::Nominal(f) => f,
        Fundamental::Search { max_hz, .. } => max_hz,
    };
    if !(f0_lowest.is_finite()
        && f0_highest.is_finite()
        && f0_lowest > 0.0
        && f0_highest >= f0_lowest
        && f0_highest < nyquist)
    {
        return Err(invalid(
            "fundamental_hz",
            format!(
                "{f0_lowest} to {f0_highest} Hz; expected a frequency (or range) in (0, \
                 {nyquist}) Hz"
            ),
        ));
    }
    if !(options.speed_tolerance.is_finite() && (0.0..0.2).contains(&options.speed_tolerance)) {
        return Err(invalid(
            "speed_tolerance",
            format!(
                "{}; expected a fraction in [0, 0.2)",
                options.speed_tolerance
            ),
        ));
    }
    if !(options.max_line_variation.is_finite()
        && options.max_line_variation > 0.0
        && options.min_burst_variation > options.max_line_variation)
    {
        return Err(invalid(
            "max_line_variation",
            format!(
                "{} (burst threshold {}); expected 0 < max_line_variation < min_burst_variation",
                options.max_line_variation, options.min_burst_variation
            ),
        ));
    }
    // channels and fundamental
    let (signals, f0_pulse) = match &options.once_per_rev_channel {
        Some(name) => {
            let c = signals.channel(name).ok_or_else(|| {
                invalid(
                    "once_per_rev_channel",
                    format!("`{name}` is not among the channels {:?}", signals.names),
                )
            })?;
            let period = signals.pulse_period_s(c)?;
            (signals.without_channel(c)?, Some(1.0 / period))
        }
        None => (signals.clone(), None),
    };
    let n = signals.data[0].len();
    let resolution = match options.resolution_hz {
        Some(r) if !(r.is_finite() && r > 0.0) => {
            return Err(invalid(
                "resolution_hz",
                format!("{r} Hz; expected a bin width > 0"),
            ));
        }
        Some(r) => r,
        None => (f0_lowest / 10.0).min(2.0),
    };
    // segment: a power of two with df <= resolution, at most an eighth of the record (at
    // least 64 samples)
    let mut segment = 64usize;
    while (fs / segment as f64) > resolution && segment * 2 <= (n / 4).max(64) {
        segment *= 2;
    }
    if segment > n {
        return Err(invalid(
            "samples",
            format!("{n} samples; need at least {segment} for the spectrum"),
        ));
    }
    let df = fs / segment as f64;
    // each channel's mean and 1 / standard deviation (0 for a constant channel, which carries
    // nothing)
    let stats: Vec<(f64, f64)> = signals.data.iter().map(|ch| standardization(ch)).collect();
    // the Welch segments' densities of the standardized channels, channels in parallel, summed
    // in channel order (independent of the thread count)
    let per_channel: Vec<Option<Vec<Vec<f64>>>> = signals
        .data
        .par_iter()
        .zip(&stats)
        .map(|(ch, &(mean, scale))| {
            if scale == 0.0 {
                return Ok(None);
            }
            let normalized: Vec<f64> = ch.iter().map(|v| (v - mean) * scale).collect();
            segment_densities(&normalized, fs, segment).map(Some)
        })
        .collect::<Result<_>>()?;
    let count = (n - segment) / (segment / 2) + 1;
    let mut segment_psd = vec![vec![0.0; segment / 2 + 1]; count];
    for channel in per_channel.into_iter().flatten() {
        for (acc, d) in segment_psd.iter_mut().zip(channel) {
            acc.iter_mut().zip(d).for_each(|(a, b)| *a += b);
        }
    }
    let psd = mean_density(&segment_psd);
    chatter_progress::check(observer)?;
    let lo = options.min_frequency_hz.unwrap_or(f0_lowest / 2.0);
    let hi = options.max_frequency_hz.unwrap_or(0.45 * fs).min(nyquist);
    if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi > lo + 8.0 * df) {
        return Err(invalid(
            "band",
            format!("{lo} to {hi} Hz; expected 0 <= min < max <= Nyquist, at least 8 bins wide"),
        ));
    }
    let first = ((lo / df).ceil() as usize).max(1);
    let last = ((hi / df).floor() as usize).min(psd.len() - 1);

    let near_multiple = |f: f64, base: f64| {
        let k = (f / base).round().max(1.0);
        (f - k * base).abs() <= 2.5 * df + k * base * HARMONIC_TOLERANCE
    };
    let known: &[f64] = match &options.interference {
        Interference::Known(bases) => {
            if let Some(f) = bases.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
                return Err(invalid(
                    "interference",
                    format!("{f} Hz; expected fundamentals > 0 Hz"),
                ));
            }
            bases
        }
        Interference::Search { min_hz, max_hz } => {
            if !(min_hz.is_finite() && max_hz.is_finite() && *min_hz > 0.0 && max_hz >= min_hz) {
                return Err(invalid(
                    "interference",
                    format!("search range {min_hz} to {max_hz} Hz; expected 0 < min <= max"),
                ));
            }
            &[]
        }
        Interference::Off => &[],
    };
    let interference_search = |spindle_hz: Option<f64>| match options.interference {
        Interference::Search { min_hz, max_hz } => {
            let lines = spectral_lines(&psd, df, first, last, |f| {
                spindle_hz.is_some_and(|f0| near_multiple(f, f0))
            });
            find_comb(&lines, df, (min_hz, max_hz), spindle_hz)
        }
        _ => None,
    };
    let f0 = match (f0_pulse, options.fundamental) {
        (Some(f), _) => f,
        (None, Fundamental::Nominal(f)) => refine_fundamental(&psd, df, f, hi, options),
        (None, Fundamental::Search { min_hz, max_hz }) => {
            // interference first, so that a mains comb is not taken for the spindle's
            let hum = interference_search(None);
            let hum_lines: &[f64] = hum.as_ref().map_or(&[], |c| &c.lines_hz);
            let lines = spectral_lines(&psd, df, first, last, |f| {
                known.iter().any(|b| near_multiple(f, *b))
                    || hum_lines.iter().any(|l| (f - l).abs() <= 2.5 * df)
            });
            harmonic_fundamental(&lines, df, (min_hz, max_hz))
                .ok_or_else(|| {
                    OmaError::NoPole(format!(
                        "no harmonic comb with a fundamental in {min_hz}-{max_hz} Hz (lines at \
                         {MIN_LOW_MEMBERS} of its first {LOW_HARMONICS} multiples): the \
                         spindle frequency cannot be estimated; give the speed"
                    ))
                })?
                .fundamental_hz
        }
    };
    chatter_progress::check(observer)?;
    let comb = interference_search(Some(f0));
    let comb_lines: &[f64] = comb.as_ref().map_or(&[], |c| &c.lines_hz);
    let synchronous_bins: Vec<bool> = (0..psd.len())
        .map(|i| {
            let f = i as f64 * df;
            near_multiple(f, f0)
                || known.iter().any(|b| near_multiple(f, *b))
                || comb_lines.iter().any(|l| (f - l).abs() <= 2.5 * df)
        })
        .collect();
    let synchronous = |i: usize| synchronous_bins[i];
    if !(first..=last).any(|i| !synchronous(i)) {
        return Err(invalid(
            "resolution_hz",
            format!("{df} Hz bins leave no bin between the harmonics of {f0} Hz"),
        ));
    }
    let Some((floor, peak)) = floor_and_peak(&psd, &synchronous_bins, first, last) else {
        return Err(OmaError::NoPole(
            "no non-synchronous peak in the band".into(),
        ));
    };
    let shares = LineShares::new(&psd, &synchronous_bins, floor, peak, (first, last), df);
    let tiny = f64::MIN_POSITIVE;
    let (line_to_rest_db, line_to_forced_db) = (shares.to_rest_db(), shares.to_forced_db());
    let line_to_floor_db = 10.0 * (psd[peak] / floor.max(tiny)).log10();
    let peak_hz = refine_peak_hz(&psd, peak, df);
    let second_half =
        |bin: usize| line_variation(&signals.data, &stats, segment, bin, (n / 2, n), 4, observer);
    let variation = second_half(peak)?;
    let margin = variation_margin(variation, options);
    chatter_progress::check(observer)?;
    let whole = margin >= 0.0 && line_to_floor_db >= MIN_LINE_TO_FLOOR_DB;
    let windowed = judge_windows(
        (&signals.data, &stats),
        &segment_psd,
        &synchronous_bins,
        (first, last),
        fs,
        options,
        observer,
    );
    let flip = match options.teeth {
        Some(teeth) if teeth >= 2 && teeth % 2 == 0 => {
            // a cancelled variation is NaN here; the observer is checked below
            let variation = |bin: usize| second_half(bin).unwrap_or(f64::NAN);
            flip_lines(&psd, floor, f0, teeth, (first, last), df, variation).map(|mut f| {
                f.variation_margin = options.max_line_variation - f.line_variation;
                f.runout_margin_db = f.line_to_runout_db.map(|r| r - MIN_FLIP_TO_RUNOUT_DB);
                f.chatter = f.variation_margin >= 0.0
                    && f.runout_margin_db.is_some_and(|m| m >= 0.0)
                    && f.line_to_floor_db >= MIN_LINE_TO_FLOOR_DB;
                f
            })
        }
        _ => None,
    };
    chatter_progress::check(observer)?;
    let chatter_hz = if whole {
        Some(peak_hz)
    } else {
        windowed
            .as_ref()
            .and_then(|w| w.chatter.as_ref())
            .map(|c| c.line_hz)
            .or_else(|| flip.as_ref().filter(|f| f.chatter).map(|f| f.line_hz))
    };
    let chatter = chatter_hz.is_some();
    let harmonics_hz = (1..)
        .map(|k| k as f64 * f0)
        .skip_while(|f| *f < lo)
        .take_while(|f| *f <= hi)
        .collect();
    Ok(Detection {
        verdict: if chatter {
            Verdict::Chatter
        } else {
            Verdict::Stable
        },
        chatter_hz,
        evidence: DetectionEvidence {
            fundamental_hz: f0,
            peak_hz,
            line_to_forced_db,
            line_to_floor_db,
            line_to_rest_db,
            max_line_variation: options.max_line_variation,
            min_burst_variation: options.min_burst_variation,
            margin,
            resolution_hz: df,
            line_variation: variation,
            interference: comb,
            windows: windowed,
            flip,
        },
        spectrum: Spectrum {
            frequencies_hz: (0..psd.len()).map(|i| i as f64 * df).collect(),
            values: psd,
        },
        harmonics_hz,
        band_hz: (lo, hi),
    })
}

/// The fundamental within the search range that maximizes the logarithmic harmonic comb, in
/// two stages: over the whole range with the first [`COARSE_HARMONICS`] harmonics, then with
/// every harmonic in the band within the first stage's uncertainty (half a bin at its highest
/// harmonic). A chatter line far above the forced harmonics cannot pull the comb onto itself:
/// with every harmonic from the start, a fundamental 0.5 % off would put harmonic 48 of a
/// 15 Hz spindle on a 730 Hz limit cycle and the line would be read as synchronous (a lathe at
/// 918 rpm chattering with 46 um RMS was called stable).
fn refine_fundamental(psd: &[f64], df: f64, f0: f64, hi: f64, options: &DetectionOptions) -> f64 {
    let delta = options.speed_tolerance;
    if delta == 0.0 {
        return f0;
    }
    // ln of the largest density within a bin of each frequency, tabulated once
    let near_ln: Vec<f64> = (0..psd.len())
        .map(|i| {
            (i.saturating_sub(1)..=(i + 1).min(psd.len() - 1))
                .map(|j| psd[j])
                .fold(f64::MIN_POSITIVE, f64::max)
                .ln()
        })
        .collect();
    let k_max = ((hi / f0).floor() as usize).clamp(1, 200);
    let k_coarse = k_max.min(COARSE_HARMONICS);
    let coarse = comb_maximum(
        &near_ln,
        df,
        f0 * (1.0 - delta),
        f0 * (1.0 + delta),
        k_coarse,
    );
    if k_coarse == k_max {
        return coarse;
    }
    let half_width = 0.5 * df / k_coarse as f64;
    comb_maximum(
        &near_ln,
        df,
        (coarse - half_width).max(f0 * (1.0 - delta)),
        (coarse + half_width).min(f0 * (1.0 + delta)),
        k_max,
    )
}

/// Harmonics of the first stage of [`refine_fundamental`].
const COARSE_HARMONICS: usize = 10;

/// The fundamental in `[lo, hi]` whose first `k_max` multiples have the largest summed
/// `near_ln` (ln density near each frequency, `df` apart), in steps that move the highest
/// multiple by a quarter bin.
fn comb_maximum(near_ln: &[f64], df: f64, lo: f64, hi: f64, k_max: usize) -> f64 {
    let step = 0.25 * df / k_max as f64;
    let count = (((hi - lo) / step).ceil() as usize).clamp(1, 20_000);
    let value_near = |f: f64| near_ln[((f / df).round() as usize).min(near_ln.len() - 1)];
    (0..=count)
        .map(|c| lo + c as f64 * (hi - lo) / count as f64)
        .map(|f| {
            let score: f64 = (1..=k_max).map(|k| value_near(k as f64 * f)).sum();
            (f, score)
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(0.5 * (lo + hi), |(f, _)| f)
}

/// The strongest line at an odd multiple of half the tooth-passing frequency, (2k + 1) z f_0 / 2,
/// against the other spindle harmonics; `variation` gives the coefficient of variation of a bin's
/// share of the power.
fn flip_lines(
    psd: &[f64],
    floor: f64,
    f0: f64,
    teeth: usize,
    (first, last): (usize, usize),
    df: f64,
    variation: impl Fn(usize) -> f64,
) -> Option<FlipEvidence> {
    let half = teeth / 2;
    // the largest density within 2 bins of each spindle harmonic in the band
    let mut flip: Option<(usize, usize)> = None; // (harmonic, bin)
    let mut forced = 0.0f64;
    let mut runout: Option<f64> = None;
    let k_first = ((first as f64 * df / f0).ceil() as usize).max(1);
    let k_last = (last as f64 * df / f0).floor() as usize;
    for k in k_first..=k_last {
        let centre = (k as f64 * f0 / df).round() as usize;
        let bin = (centre.saturating_sub(2)..=(centre + 2).min(psd.len() - 1))
            .max_by(|a, b| psd[*a].total_cmp(&psd[*b]))?;
        let level = psd[bin];
        if k % half == 0 && (k / half) % 2 == 1 {
            if flip.is_none_or(|(_, b)| level > psd[b]) {
                flip = Some((k, bin));
            }
        } else {
            forced = forced.max(level);
            if k % half != 0 {
                runout = Some(runout.map_or(level, |r: f64| r.max(level)));
            }
        }
    }
    let (_, bin) = flip?;
    let db = |a: f64, b: f64| 10.0 * (a / b.max(f64::MIN_POSITIVE)).log10();
    Some(FlipEvidence {
        line_hz: refine_peak_hz(psd, bin, df),
        line_to_floor_db: db(psd[bin], floor),
        line_to_forced_db: db(psd[bin], forced),
        line_to_runout_db: runout.map(|r| db(psd[bin], r)),
        line_variation: variation(bin),
        variation_margin: f64::NAN,
        runout_margin_db: None,
        chatter: false,
    })
}

/// A window's strongest non-synchronous line and the window's band power.
#[derive(Debug, Clone, Copy)]
struct WindowLine {
    /// Bin of the peak.
    peak: usize,
    /// Refined frequency (Hz).
    line_hz: f64,
    /// Peak density over the window's floor (dB).
    line_to_floor_db: f64,
    /// The line's power over the rest of the band (dB).
    line_to_rest_db: f64,
    /// Band power of the window (standardized units).
    power: f64,
}

/// Powers (density less the floor, times the bin width) of the line (the non-synchronous bins
/// within 2 of its peak), of the synchronous bins and of the rest of the band.
struct LineShares {
    line: f64,
    synchronous: f64,
    rest: f64,
    floor: f64,
}

impl LineShares {
    fn new(
        psd: &[f64],
        synchronous: &[bool],
        floor: f64,
        peak: usize,
        (first, last): (usize, usize),
        df: f64,
    ) -> Self {
        let above = |i: usize| (psd[i] - floor).max(0.0) * df;
        let near = |i: usize| i.abs_diff(peak) <= 2;
        let (mut line, mut sync, mut rest) = (0.0, 0.0, 0.0);
        let (start, end) = (
            first.min(peak.saturating_sub(2)),
            last.max(peak + 2).min(psd.len() - 1),
        );
        for (i, &sync_bin) in synchronous.iter().enumerate().take(end + 1).skip(start) {
            let inside = (first..=last).contains(&i);
            match (sync_bin, near(i)) {
                (false, true) => line += above(i),
                (true, _) if inside => sync += above(i),
                (false, false) if inside => rest += above(i),
                _ => {}
            }
        }
        Self {
            line,
            synchronous: sync,
            rest,
            floor: floor * df,
        }
    }

    /// 10 log10(E_line / (E_sync + E_rest + floor)) (dB).
    fn to_rest_db(&self) -> f64 {
        10.0 * ((self.line + f64::MIN_POSITIVE) / (self.synchronous + self.rest + self.floor))
            .log10()
    }

    /// 10 log10(E_line / (E_sync + floor)) (dB).
    fn to_forced_db(&self) -> f64 {
        10.0 * ((self.line + f64::MIN_POSITIVE) / (self.synchronous + self.floor)).log10()
    }
}

/// Mean and 1 / standard deviation of a channel (0 for a constant channel).
fn standardization(ch: &[f64]) -> (f64, f64) {
    let n = ch.len() as f64;
    let mean = ch.iter().sum::<f64>() / n;
    let var = ch.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, if var > 0.0 { 1.0 / var.sqrt() } else { 0.0 })
}

/// Mean of densities (Welch's average of segment densities).
fn mean_density(densities: &[Vec<f64>]) -> Vec<f64> {
    let mut mean = vec![0.0; densities.first().map_or(0, Vec::len)];
    for d in densities {
        mean.iter_mut().zip(d).for_each(|(a, b)| *a += b);
    }
    let count = densities.len().max(1) as f64;
    mean.iter_mut().for_each(|v| *v /= count);
    mean
}

/// The floor (median density of the non-synchronous bins `first..=last`) and the strongest
/// non-synchronous local maximum; `None` without one.
fn floor_and_peak(
    psd: &[f64],
    synchronous: &[bool],
    first: usize,
    last: usize,
) -> Option<(f64, usize)> {
    let mut floor_values: Vec<f64> = (first..=last)
        .filter(|i| !synchronous[*i])
        .map(|i| psd[i])
        .collect();
    if floor_values.is_empty() {
        return None;
    }
    let mid = floor_values.len() / 2;
    let floor = *floor_values
        .select_nth_unstable_by(mid, |a, b| a.total_cmp(b))
        .1;
    let peak = (first..=last)
        .filter(|&i| !synchronous[i])
        .filter(|&i| psd[i] >= psd[i - 1] && psd.get(i + 1).is_none_or(|v| psd[i] >= *v))
        .max_by(|a, b| psd[*a].total_cmp(&psd[*b]))?;
    Some((floor, peak))
}

/// The larger of (limit-cycle threshold - V) and (V - burst threshold): positive for chatter.
fn variation_margin(variation: f64, options: &DetectionOptions) -> f64 {
    (options.max_line_variation - variation).max(variation - options.min_burst_variation)
}

/// The record judged window by window (see the [module documentation](self#windows)): windows of
/// [`WINDOW_SEGMENTS`] spectrum segments every half window, each judged like the whole record
/// (its own density, floor and strongest non-synchronous line, the line's variation over all of
/// the window's short segments); `None` when fewer than two windows fit. `data` and `stats` are
/// the channels and their standardization; a cancel (`observer`'s) leaves the variations NaN,
/// and the caller checks the observer.
fn judge_windows(
    (data, stats): (&[Vec<f64>], &[(f64, f64)]),
    segment_psd: &[Vec<f64>],
    synchronous: &[bool],
    (first, last): (usize, usize),
    fs: f64,
    options: &DetectionOptions,
    observer: &dyn Observer,
) -> Option<WindowedEvidence> {
    let bins = segment_psd.first()?.len();
    let segment = 2 * (bins - 1);
    let df = fs / segment as f64;
    // in Welch segments (half a spectrum segment apart)
    let per_window = 2 * WINDOW_SEGMENTS - 1;
    let hop = WINDOW_SEGMENTS;
    if segment_psd.len() < per_window + hop * (MIN_SUSTAINED_WINDOWS - 1) {
        return None;
    }
    let count = (segment_psd.len() - per_window) / hop + 1;
    let half = segment / 2;
    // each window's line first (cheap: the densities are there)
    let lines: Vec<Option<WindowLine>> = (0..count)
        .into_par_iter()
        .map(|w| {
            let psd = mean_density(&segment_psd[w * hop..w * hop + per_window]);
            let (floor, peak) = floor_and_peak(&psd, synchronous, first, last)?;
            let line_to_floor_db = 10.0 * (psd[peak] / floor.max(f64::MIN_POSITIVE)).log10();
            let shares = LineShares::new(&psd, synchronous, floor, peak, (first, last), df);
            let power = psd[first..=last].iter().sum::<f64>() * df;
            Some(WindowLine {
                peak,
                line_hz: refine_peak_hz(&psd, peak, df),
                line_to_floor_db,
                line_to_rest_db: shares.to_rest_db(),
                power,
            })
        })
        .collect();
    // the reference stretch: windows near the quietest when the record holds much louder ones
    let powers = lines.iter().flatten().map(|l| l.power);
    let quietest = powers.clone().fold(f64::INFINITY, f64::min);
    let contrast_db = 10.0 * (powers.fold(0.0, f64::max) / quietest.max(f64::MIN_POSITIVE)).log10();
    let has_reference = contrast_db >= REFERENCE_CONTRAST_DB;
    let reference = |w: usize| {
        has_reference
            && lines[w].is_some_and(|l| l.power <= quietest * 10f64.powf(REFERENCE_LEVEL_DB / 10.0))
    };
    // the line's variation only where it can matter: the line stands out of the floor and a
    // neighbouring window has it too, both cutting
    let stands = |w: usize| {
        lines[w]
            .filter(|l| l.line_to_floor_db >= MIN_LINE_TO_FLOOR_DB)
            .filter(|_| !reference(w))
    };
    let paired = |a: usize, b: usize| {
        stands(a)
            .zip(stands(b))
            .is_some_and(|(x, y)| (x.line_hz - y.line_hz).abs() <= LINE_MATCH_BINS * df)
    };
    let judged: Vec<(WindowJudgement, usize)> = (0..count)
        .into_par_iter()
        .filter_map(|w| {
            let WindowLine {
                peak,
                line_hz,
                line_to_floor_db,
                line_to_rest_db,
                ..
            } = lines[w]?;
            let start = w * hop * half;
            let needed = (w > 0 && paired(w - 1, w)) || (w + 1 < count && paired(w, w + 1));
            let variation = needed.then(|| {
                line_variation(
                    data,
                    stats,
                    segment,
                    peak,
                    (start, start + WINDOW_SEGMENTS * segment),
                    WINDOW_HOPS_PER_SEGMENT,
                    observer,
                )
                // only a cancel fails, and the caller checks the observer
                .unwrap_or(f64::NAN)
            });
            let cutting = has_reference && !reference(w);
            Some((
                WindowJudgement {
                    start_s: start as f64 / fs,
                    line_hz,
                    line_to_floor_db,
                    line_variation: variation,
                    margin: variation.map(|v| variation_margin(v, options)),
                    reference: reference(w),
                    line_to_rest_db,
                    dominant: cutting
                        && line_to_rest_db >= DOMINANT_LINE_DB
                        && line_to_floor_db >= MIN_LINE_TO_FLOOR_DB,
                },
                w,
            ))
        })
        .collect();
    let window_s = (WINDOW_SEGMENTS * segment) as f64 / fs;
    // neighbouring windows at the same line, both standing out of their floor
    let same_line = |a: &(WindowJudgement, usize), b: &(WindowJudgement, usize)| {
        b.1 == a.1 + 1
            && (a.0.line_hz - b.0.line_hz).abs() <= LINE_MATCH_BINS * df
            && a.0.margin.is_some()
            && b.0.margin.is_some()
    };
    let margin = judged
        .windows(2)
        .filter(|p| same_line(&p[0], &p[1]))
        .filter_map(|p| Some(p[0].0.margin?.min(p[1].0.margin?)))
        .max_by(f64::total_cmp);
    // runs of chattering windows at the same line
    let chatters =
        |j: &(WindowJudgement, usize)| j.0.dominant || j.0.margin.is_some_and(|m| m >= 0.0);
    let mut best: Option<(usize, f64, ChatterSpan)> = None;
    let mut i = 0;
    while i < judged.len() {
        let mut end = i;
        while chatters(&judged[i])
            && end + 1 < judged.len()
            && chatters(&judged[end + 1])
            && same_line(&judged[end], &judged[end + 1])
        {
            end += 1;
        }
        let run = &judged[i..=end];
        if chatters(&judged[i]) && run.len() >= MIN_SUSTAINED_WINDOWS {
            let run_margin = run
                .iter()
                .filter_map(|j| j.0.margin)
                .fold(f64::INFINITY, f64::min);
            let strongest = run
                .iter()
                .max_by(|a, b| {
                    a.0.margin
                        .partial_cmp(&b.0.margin)
                        .unwrap_or(std::cmp::Ordering::Equal)
                })
                .map(|j| &j.0)?;
            let span = ChatterSpan {
                start_s: run[0].0.start_s,
                end_s: run[run.len() - 1].0.start_s + window_s,
                line_hz: strongest.line_hz,
                line_variation: strongest.line_variation.unwrap_or(f64::NAN),
                by_dominance: run
                    .iter()
                    .any(|j| j.0.dominant && !j.0.margin.is_some_and(|m| m >= 0.0)),
            };
            let better = best.as_ref().is_none_or(|(len, m, _)| {
                run.len() > *len || (run.len() == *len && run_margin > *m)
            });
            if better {
                best = Some((run.len(), run_margin, span));
            }
        }
        i = end + 1;
    }
    Some(WindowedEvidence {
        contrast_db,
        reference_stretch: has_reference,
        window_s,
        hop_s: window_s / 2.0,
        min_duration_s: window_s * (1.0 + 0.5 * (MIN_SUSTAINED_WINDOWS - 1) as f64),
        margin,
        chatter: best.map(|(_, _, span)| span),
        windows: judged.into_iter().map(|(j, _)| j).collect(),
    })
}

/// Coefficient of variation of the line's share of the power over the samples `range` (the line's
/// power over the segment's power, so that a cut that deepens or leaves the workpiece changes
/// neither): segments of half the spectrum's length (so the line, at bin `peak` of the
/// spectrum, falls at bin peak / 2 of theirs), Hann windowed, starting every
/// 1 / `hops_per_segment` of their length (a quarter for the whole record; a power of two, as
/// the segment is) from the record's start, the ones wholly inside `range`; the power is summed
/// over the three bins around the line and over the channels standardized by `stats` (mean,
/// 1 / standard deviation). `observer` is polled once per block of a hop's samples.
///
/// # Computation
/// The segments overlap, so each is cut into `hops_per_segment` blocks of one hop and every
/// block is transformed once. With the Hann window w_k = 1/2 - 1/4 e^(i theta_k) - 1/4
/// e^(-i theta_k), theta_k = 2 pi k / L, a segment's windowed DFT at bin b is
/// 1/2 X_b - 1/4 X_(b-1) - 1/4 X_(b+1) of its plain DFT X, and its windowed energy
/// sum y^2 w^2 = Re(3/8 E_0 - 1/2 E_1 + 1/8 E_2), E_f the plain DFT of y^2 at bin f. A plain
/// DFT of a segment is the sum of its blocks' DFTs (block j at offset j h), each turned by
/// e^(-2 pi i b j h / L).
fn line_variation(
    data: &[Vec<f64>],
    stats: &[(f64, f64)],
    spectrum_segment: usize,
    peak: usize,
    (from, to): (usize, usize),
    hops_per_segment: usize,
    observer: &dyn Observer,
) -> Result<f64> {
    use num_complex::Complex64;
    use std::f64::consts::PI;
    let n = data[0].len();
    let segment = (spectrum_segment / 2).max(16);
    let step = (segment / hops_per_segment).max(1);
    debug_assert_eq!(segment % step, 0, "the hop divides the segment");
    let hops = segment / step;
    let centre = (peak as f64 / 2.0).round() as usize;
    if n < segment {
        return Ok(f64::NAN);
    }
    let starts: Vec<usize> = (0..=(n - segment) / step)
        .map(|s| s * step)
        .filter(|s| *s >= from && s + segment <= to)
        .collect();
    let (Some(&first), Some(&last)) = (starts.first(), starts.last()) else {
        return Ok(f64::NAN);
    };
    // the windowed bins, and the plain ones they are made of (one more on either side)
    let windowed = (centre.saturating_sub(1) as i64)..=(centre as i64 + 1);
    let plain: Vec<i64> = (windowed.start() - 1..=windowed.end() + 1).collect();
    // e^(-2 pi i b t / L) for a block's offsets t, from one table of the unit circle
    let circle: Vec<Complex64> = (0..segment)
        .map(|k| Complex64::from_polar(1.0, -2.0 * PI * k as f64 / segment as f64))
        .collect();
    let turn = |b: i64, t: usize| {
        let k = (b.rem_euclid(segment as i64) as usize * t) % segment;
        circle[k]
    };
    let kernels: Vec<Vec<Complex64>> = plain
        .iter()
        .chain(&[1, 2])
        .map(|&b| (0..step).map(|t| turn(b, t)).collect())
        .collect();
    let bins = plain.len();
    // per block: each channel's plain DFTs at the plain bins, then the channels' summed E_0,
    // E_1, E_2 of y^2
    let (first_block, last_block) = (first / step, last / step + hops - 1);
    let blocks: Vec<Vec<Complex64>> = (first_block..=last_block)
        .into_par_iter()
        .map(|q| {
            chatter_progress::check(observer)?;
            let mut sums = vec![Complex64::new(0.0, 0.0); bins * data.len() + 3];
            for (c, (ch, &(mean, scale))) in data.iter().zip(stats).enumerate() {
                let mut plain_sums = vec![Complex64::new(0.0, 0.0); bins];
                let (mut e0, mut e1, mut e2) =
                    (0.0, Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
                for (t, v) in ch[q * step..(q + 1) * step].iter().enumerate() {
                    let y = (v - mean) * scale;
                    for (acc, kernel) in plain_sums.iter_mut().zip(&kernels) {
                        *acc += kernel[t] * y;
                    }
                    let y2 = y * y;
                    e0 += y2;
                    e1 += kernels[bins][t] * y2;
                    e2 += kernels[bins + 1][t] * y2;
                }
                sums[c * bins..(c + 1) * bins].copy_from_slice(&plain_sums);
                let energy = &mut sums[bins * data.len()..];
                energy[0] += e0;
                energy[1] += e1;
                energy[2] += e2;
            }
            Ok(sums)
        })
        .collect::<Result<_>>()?;
    let powers: Vec<f64> = starts
        .iter()
        .map(|&s| {
            let m0 = s / step - first_block;
            // a segment's plain DFT at bin b from its blocks
            let segment_dft = |index: usize, b: i64| {
                (0..hops)
                    .map(|j| blocks[m0 + j][index] * turn(b, j * step))
                    .sum::<Complex64>()
            };
            let mut total = 0.0;
            for c in 0..data.len() {
                let x: Vec<Complex64> = (0..bins)
                    .map(|r| segment_dft(c * bins + r, plain[r]))
                    .collect();
                total += (1..bins - 1)
                    .map(|r| (0.5 * x[r] - 0.25 * (x[r - 1] + x[r + 1])).norm_sqr())
                    .sum::<f64>();
            }
            let e = bins * data.len();
            let energy = 0.375 * segment_dft(e, 0).re - 0.5 * segment_dft(e + 1, 1).re
                + 0.125 * segment_dft(e + 2, 2).re;
            if energy > 0.0 {
                total / (energy * segment as f64)
            } else {
                0.0
            }
        })
        .collect();
    if powers.len() < 2 {
        return Ok(f64::NAN);
    }
    let m = powers.len() as f64;
    let mean = powers.iter().sum::<f64>() / m;
    let var = powers.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / (m - 1.0);
    Ok(var.sqrt() / mean)
}
