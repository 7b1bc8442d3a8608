//! One call from signals to the dominant pole: correlations, stabilization diagram, automatic
//! pick and repeated identification on random segments (000 Section 6.1 and Table 2; 002
//! Section 2.1 and Table 2).
//!
//! 1. Turning (time-invariant): the channels, each with its mean removed, are correlated with
//!    the reference channel (000 Eq. 21) and fitted by (modified) LSCE (Eq. 19-25, harmonics as
//!    in [`crate::harmonics`]) at model orders P = H + `min_order` ..= H + `max_order` pole
//!    pairs, H the number of imposed harmonics. Milling ([`Lifting`]): every channel is lifted
//!    at the tooth period (002 Eq. 6-7), `virtual_sensors` evenly spaced lifted channels per
//!    physical channel are kept with their means removed (which removes the periodic forced
//!    response; per residue class of periods modulo `periods_per_revolution` to remove runout
//!    too), correlated with the virtual sensors of the reference channel (Eq. 8) and fitted by
//!    time-domain polyreference (Eq. 9) at AR orders n_a = `min_order`..=`max_order`.
//! 2. The first `skip_lags` lags are dropped: lag 0 carries the power of uncorrelated measurement
//!    noise and, for accelerations, the direct feed-through of the force, neither of which is a
//!    sum of damped exponentials.
//! 3. Band (turning): a first plain pass over the whole record locates the dominant pole f_p
//!    (the harmonics imposed as below). With [`Decimation::Auto`] a record sampled faster than
//!    [`DECIMATE_ABOVE`] f_p is low-passed and decimated by
//!    D = floor(f_s / ([`RATE_PER_POLE`] f_p)) ([`crate::decimation`]; the lags the filter
//!    touches are skipped too), so that the pole no longer crowds next to mu = 1. The analysed
//!    band is then 0 to the Nyquist frequency, or to the filter's passband edge after decimation.
//!    With [`Harmonics::Spindle`] every multiple in that band that is a spectral line of the
//!    record is imposed.
//! 4. Pick ([`crate::picking`] and the rejections here): the stable clusters of the whole-record
//!    diagram, less
//!    - poles at the band edges: below [`LOWER_EDGE_FRACTION`] or above 1 - [`UPPER_EDGE_FRACTION`]
//!      of the band's upper end (the noise and feed-through are white up to the Nyquist
//!      frequency or cut off by the filter there, and LSCE models the edge of a flat spectrum
//!      with lightly damped poles; in issue 16 such a pole at 4823.6 Hz = 0.94 Nyquist won), and
//!    - poles that are spectral lines of the record ([`crate::harmonics::LineSpectrum`]): a
//!      structural resonance of half-power bandwidth zeta f much wider than 1 / T is never a
//!      line, a forced sinusoid (mains hum at 150 Hz in the real chatter record, a harmonic of
//!      an unknown fundamental) or a limit cycle always is,
//!
//!    - (LSCE) poles in the noise floor: whose spectral support ([`crate::support`]: the
//!      channels' normalized Welch density at the pole against its highest peak that is not a
//!      spindle harmonic or spectral line) is more than [`NOISE_FLOOR_DB`] below that peak,
//!
//!    are ranked by the rule of [`crate::picking`] (persistent over three quarters of the longest
//!    run of stable orders; smallest decay rate -Re(lambda) first), and then (LSCE) by their
//!    spectral support, highest first (see "Dominant by spectral support" below).
//! 5. N_s = `segments` windows of `segment_fraction` of the record start at seeded uniform random
//!    positions; each is identified at every order of the diagram and contributes the admitted
//!    pole nearest the cluster's mean lambda (and within 5 times the frequency tolerance of its
//!    frequency). Mean and sample standard deviation over the windows at each order are the
//!    curves of 000 Fig. 3b/c ([`Identification::order_statistics`]); the identification order
//!    is where they settle (from the first order of the cluster's run of stable orders on, the
//!    lowest order whose mean agrees with those of the next orders, [`MIN_SETTLED_ORDERS`] in
//!    all, within the relative stabilization tolerances), else the run's first order, unless
//!    `order` fixes one. The
//!    mean and standard deviation at that order are the reported pole, as in the tables of 000
//!    and 002. A cluster found in fewer than [`MIN_SEGMENT_SHARE`] of the segments there is not
//!    stable across segments: the next cluster of the ranking is tried.
//!
//! # Dominant by spectral support
//! On the closed-loop records of a turning cut (the gap proving ground's lathe: a chain of
//! closed-loop roots about 26 Hz apart near 720 Hz, damping 0.002-0.013, 10 % measurement
//! noise, 16 s at 5 kHz) the LSCE estimates of the root the response is made of move between
//! 0.004 and 0.03 in damping from order to order, so it rarely counts as stable, while poles of
//! the flat noise floor above 1 kHz, 20-38 dB below the resonance peak, stay stable and have the
//! smallest decay rates: the decay-rate rule alone picked them (1743 Hz and 1794.8 Hz against
//! the truth's 722-730 Hz), or the envelope of the feed mode near 640 Hz, 5-9 dB below the
//! peak. So a structural cluster must have spectral support (the density at its frequency
//! within [`NOISE_FLOOR_DB`] of the highest non-line peak: there, the 8 records' clusters of the
//! resonance chain lay 0-16 dB below it, the noise-floor clusters 17-38 dB below), and the
//! persistent clusters are ranked by that support: the dominant pole is the one the response
//! is made of. The decay rate of noisy damping estimates does not decide. The spectral peak
//! under the picked pole is reported too ([`Identification::spectral_peak`], half-power
//! damping), as an independent cross-check of the LSCE estimate.
//!
//! # Automatic correlation window
//! Unless `max_lag` is given, the correlations span [`LAG_TIME_CONSTANTS`] decay times
//! 1 / (zeta omega) = -1 / Re(lambda) of the dominant pole (at least [`LAG_MIN_CYCLES`] of its
//! periods and [`LAG_BEAT_PERIODS`] periods of the beat with the nearest other stable pole),
//! clamped below by twice the fewest lags that determine the least squares at the
//! order fitted and above by half the segment. The first diagram uses a quarter of the segment
//! (at most [`LAG_FIRST_PASS`]); the diagram is redone with the adapted window when it differs.
//! The segments use the same rule at their own order, so they are not forced to the longer
//! window that the highest order of the diagram needs.

use crate::correlation::{correlate, correlation_matrices};
use crate::decimation::{PASSBAND_FRACTION, correlation_support_lags, decimate};
use crate::error::{OmaError, Result};
use crate::harmonics::{Harmonics, LineSpectrum, multiples_below};
use crate::lifting::lift_at_period;
use crate::lsce::{Pole, lsce};
use crate::picking::{PickingOptions, PoleCluster, ranked, stable_clusters};
use crate::polyreference::polyreference;
use crate::signals::Signals;
use crate::stabilization::{StabilityCriteria, StabilizationDiagram};
use crate::support::{SpectralPeak, SpectralSupport};
use chatter_progress::{Observer, Silent};
use nalgebra::DMatrix;
use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Decay times of the dominant pole spanned by the automatic correlation window: the envelope
/// falls to e^-1 = 37 %. Correlation estimates carry noise of relative size
/// sqrt(decay time / record length) at every lag, so longer windows add mostly noise: on the
/// single-mode test (800 Hz, 2 %, 10 s) the relative damping scatter over seeds is 4.1 % with
/// one decay time, near the asymptotic 1.4 / sqrt(zeta omega T) = 4.4 %, but 8 % with 2.4 and
/// 12 % with 4 decay times.
pub const LAG_TIME_CONSTANTS: f64 = 1.0;
/// Fewest periods of the beat between the dominant pole and the nearest other stable pole in the
/// automatic correlation window, so that the two are resolved: on the turning test (poles at
/// 2497.5 and 2427.7 Hz, one decay time = 17 ms) one decay time alone overestimates the damping
/// by 40 %, two beat periods (29 ms) by 2-17 %.
pub const LAG_BEAT_PERIODS: f64 = 2.0;
/// Highest AR order the CLI uses with lifting (see [`IdentifyOptions::max_order`]): on the
/// 002 milling test (one channel, two virtual sensors) the dominant multiplier is stable from
/// order 2, while orders beyond 10 split it.
pub const LIFTED_MAX_ORDER: usize = 6;
/// Stabilization criteria the CLI uses with lifting: frequency 1 %, damping max(10 %, 5e-4).
/// A lifted record has one sample per period (thousands, not hundreds of thousands), so the
/// damping moves by more than the 5 % of the default between consecutive orders: on the 002
/// milling test the default leaves a quarter of the seeds without any stable pole.
pub const LIFTED_CRITERIA: StabilityCriteria = StabilityCriteria {
    frequency_rel: 0.01,
    damping_rel: 0.1,
    damping_abs: 5e-4,
};
/// Most lags of the first diagram, before the window is adapted to the pole.
pub const LAG_FIRST_PASS: usize = 1000;
/// Fewest periods of the dominant pole in the automatic correlation window (for heavily damped
/// poles).
pub const LAG_MIN_CYCLES: f64 = 3.0;
/// [`Decimation::Auto`] decimates a record sampled faster than this many times the dominant
/// pole's frequency. The issue-16 record (800 Hz at 10 240 Hz, 1/12.8 of the rate) is
/// identified better without decimation (median damping error over 10 seeds 7.9 %, against
/// 13.9 % decimated by 3); seed 000's P3 pole at 100 kHz (1/40 of the rate) needs it.
pub const DECIMATE_ABOVE: f64 = 16.0;
/// [`Decimation::Auto`] decimates to a rate of at least this many times the dominant pole's
/// frequency (the pole at 1/4 of the rate or above, as seed 000's P3 pole in a 10 kHz record).
pub const RATE_PER_POLE: f64 = 4.0;
/// Poles below this fraction of the band's upper end are at the lower band edge (drift, the
/// removed mean).
pub const LOWER_EDGE_FRACTION: f64 = 0.01;
/// Poles within this fraction of the band's upper end from it are at the upper band edge (the
/// edge of a white or filtered noise spectrum, which LSCE models with lightly damped poles).
/// Widening it to end the band at f_s / 2.56 (the usable band behind an anti-aliasing filter)
/// lost seed 000's P3 pole at 100 kHz (decimated by 10): kept at 0.1.
pub const UPPER_EDGE_FRACTION: f64 = 0.1;
/// Consecutive orders over which the segments' mean pole must agree to count as settled.
pub const MIN_SETTLED_ORDERS: usize = 5;
/// Smallest share of the segments in which a cluster must be found to count as stable across
/// segments.
pub const MIN_SEGMENT_SHARE: f64 = 0.5;
/// Structural clusters whose spectral support lies more than this many dB below the highest
/// resonance peak are in the noise floor (module documentation, "Dominant by spectral
/// support"): the clusters of the gap proving ground's lathe records lay 0-16 dB (resonance
/// chain) and 17-38 dB (noise floor) below the peak; 20 dB is also a factor of 10 in amplitude,
/// the line factor of [`crate::harmonics::LINE_FACTOR`].
pub const NOISE_FLOOR_DB: f64 = 20.0;
/// Structural clusters whose spectral prominence (height over the median density,
/// [`crate::support`]) is below this many dB are in the noise floor too: the highest bin of a
/// density of white noise stands about 2 dB over its median with 32 Welch segments; 6 dB is
/// four times the floor's power. It is the test that refuses lifted (milling) records whose
/// measurement noise buries the response.
pub const MIN_PROMINENCE_DB: f64 = 6.0;

/// Lifting of time-periodic (milling) signals before identification.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Lifting {
    /// The period of the system (s): the tooth-passing period in milling.
    pub period_s: f64,
    /// Lifted channels kept per physical channel, evenly spaced over the period (default 2).
    pub virtual_sensors: usize,
    /// Periods per revolution (the number of teeth, default 1). With more than one, each lifted
    /// channel has its mean removed separately over every residue class of periods modulo this
    /// number, which removes responses periodic in the revolution (runout, spindle harmonics)
    /// as well as in the period; otherwise those alias to undamped lifted poles at multiples of
    /// 1 / (periods_per_revolution x period_s).
    pub periods_per_revolution: usize,
}

impl Lifting {
    /// Lifting at `period_s` with 2 virtual sensors per channel and one period per revolution.
    pub fn new(period_s: f64) -> Self {
        Self {
            period_s,
            virtual_sensors: 2,
            periods_per_revolution: 1,
        }
    }
}

/// Low-pass and decimation before LSCE (step 3 of the module documentation; ignored with
/// lifting).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Decimation {
    /// By floor(f_s / ([`RATE_PER_POLE`] f_p)) when f_s > [`DECIMATE_ABOVE`] f_p, f_p the pole
    /// located by the first pass.
    #[default]
    Auto,
    /// Never.
    Off,
    /// By this factor (1: never).
    Factor(usize),
}

/// Options of [`identify`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IdentifyOptions {
    /// Index of the reference channel (default 0).
    pub reference: usize,
    /// Lowest model order of the diagram beyond the imposed harmonics (default 1; LSCE starts
    /// at 2 pole pairs at least).
    pub min_order: usize,
    /// Highest model order of the diagram beyond the imposed harmonics (default 30): free pole
    /// pairs P - H for LSCE with H harmonics imposed, AR order n_a for polyreference. Lifted
    /// records are short (one sample per period) and polyreference fits n_a times the number of
    /// lifted channels poles, so lifted identification wants a low order (the CLI uses
    /// [`LIFTED_MAX_ORDER`]): at high orders the dominant multiplier splits into nearby noise
    /// poles and the correlation window must grow with the order.
    pub max_order: usize,
    /// Harmonics imposed by the modified LSCE and excluded from picking (default none; ignored
    /// with lifting, where periodic responses are constants).
    pub harmonics: Harmonics,
    /// Correlation lags used, after the skipped ones (samples, or periods with lifting); default
    /// `None`: automatic, see the [module documentation](self#automatic-correlation-window).
    pub max_lag: Option<usize>,
    /// Leading lags dropped (default 1, see step 2 of the module documentation; after
    /// decimation at least [`correlation_support_lags`]).
    pub skip_lags: usize,
    /// Model order of the segment identifications (P for LSCE, harmonics included); default
    /// `None`: where the segments' pole settles (step 5 of the module documentation).
    pub order: Option<usize>,
    /// Number N_s of random segments (default 10, >= 1).
    pub segments: usize,
    /// Segment length as a fraction of the record, in (0, 1] (default 0.5).
    pub segment_fraction: f64,
    /// Seed of the segment positions.
    pub seed: u64,
    /// Stabilization tolerances.
    pub criteria: StabilityCriteria,
    /// Which poles may be picked.
    pub picking: PickingOptions,
    /// Lift at a period and use polyreference (milling); `None` for LSCE (turning).
    pub lifting: Option<Lifting>,
    /// Low-pass and decimation before LSCE (default [`Decimation::Auto`]).
    pub decimation: Decimation,
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        Self {
            reference: 0,
            min_order: 1,
            max_order: 30,
            harmonics: Harmonics::None,
            max_lag: None,
            skip_lags: 1,
            order: None,
            segments: 10,
            segment_fraction: 0.5,
            seed: 0,
            criteria: StabilityCriteria::default(),
            picking: PickingOptions::default(),
            lifting: None,
            decimation: Decimation::Auto,
        }
    }
}

impl IdentifyOptions {
    /// A turning (time-invariant) record: modified LSCE with the spindle harmonics of
    /// `fundamental_hz` that are spectral lines imposed (000 Sec. 3), the other defaults.
    pub fn spindle(fundamental_hz: f64) -> Self {
        Self {
            harmonics: Harmonics::Spindle { fundamental_hz },
            ..Self::default()
        }
    }

    /// A milling (time-periodic) record: lifted at the tooth period `tooth_period_s` of a
    /// cutter with `teeth` teeth (2 virtual sensors per channel, the revolution's periodic
    /// response removed) and polyreference (002 Eq. 6-9), model orders up to
    /// [`LIFTED_MAX_ORDER`] with [`LIFTED_CRITERIA`].
    pub fn lifted(tooth_period_s: f64, teeth: usize) -> Self {
        Self {
            max_order: LIFTED_MAX_ORDER,
            criteria: LIFTED_CRITERIA,
            lifting: Some(Lifting {
                periods_per_revolution: teeth,
                ..Lifting::new(tooth_period_s)
            }),
            ..Self::default()
        }
    }
}

/// Mean and spread of a pole over repeated identifications.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoleEstimate {
    /// Mean frequency |lambda| / 2 pi (Hz; 000 Eq. 6).
    pub frequency_hz: f64,
    /// Sample standard deviation of the frequency (Hz); `None` for one repetition.
    pub frequency_std_hz: Option<f64>,
    /// Mean damping ratio -Re(lambda) / |lambda|.
    pub damping_ratio: f64,
    /// Sample standard deviation of the damping ratio; `None` for one repetition.
    pub damping_std: Option<f64>,
    /// Mean principal frequency Im(lambda) / 2 pi (Hz): for lifted data, in [0, 1 / (2 tau)].
    pub principal_frequency_hz: f64,
    /// Mean discrete pole (Floquet multiplier for lifted data).
    pub multiplier: Complex64,
    /// Number of repetitions averaged.
    pub repetitions: usize,
}

impl PoleEstimate {
    /// Mean and sample standard deviation over `poles` (at least one).
    pub fn from_poles(poles: &[Pole]) -> Result<Self> {
        if poles.is_empty() {
            return Err(OmaError::NoPole("no repetition identified the pole".into()));
        }
        let n = poles.len() as f64;
        let mean = |f: &dyn Fn(&Pole) -> f64| poles.iter().map(f).sum::<f64>() / n;
        let std = |f: &dyn Fn(&Pole) -> f64, m: f64| {
            (poles.len() > 1)
                .then(|| (poles.iter().map(|p| (f(p) - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt())
        };
        let frequency_hz = mean(&|p| p.frequency_hz);
        let damping_ratio = mean(&|p| p.damping_ratio);
        Ok(Self {
            frequency_hz,
            frequency_std_hz: std(&|p| p.frequency_hz, frequency_hz),
            damping_ratio,
            damping_std: std(&|p| p.damping_ratio, damping_ratio),
            principal_frequency_hz: mean(&|p| p.principal_frequency_hz()),
            multiplier: poles.iter().map(|p| p.multiplier).sum::<Complex64>() / n,
            repetitions: poles.len(),
        })
    }
}

/// Why a stable cluster of the whole-record diagram was not taken for the structural pole
/// (step 4-5 of the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Rejection {
    /// At an edge of the analysed band.
    BandEdge,
    /// A spectral line of the record (forced response or limit cycle).
    SpectralLine,
    /// In the noise floor: spectral support more than [`NOISE_FLOOR_DB`] below the highest
    /// resonance peak, or prominence below [`MIN_PROMINENCE_DB`].
    NoiseFloor,
    /// Found in too few segments.
    Segments {
        /// Segments in which it was found.
        found: usize,
        /// Segments identified.
        of: usize,
    },
}

/// A stable cluster that was not picked, and why.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RejectedCluster {
    /// Mean frequency of the cluster (Hz).
    pub frequency_hz: f64,
    /// Mean damping ratio of the cluster.
    pub damping_ratio: f64,
    /// Why.
    pub reason: Rejection,
}

/// The segments' pole at one model order (000 Fig. 3b/c).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OrderStatistics {
    /// Model order.
    pub order: usize,
    /// Mean and spread over the segments that have the pole at this order; `None` if none has.
    pub estimate: Option<PoleEstimate>,
}

/// Result of [`identify`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Identification {
    /// The dominant pole: mean and standard deviation over the segments.
    pub estimate: PoleEstimate,
    /// The pole found in each segment that identified it.
    pub segment_poles: Vec<Pole>,
    /// The dominant cluster of the whole-record diagram.
    pub cluster: PoleCluster,
    /// Model order used on the segments.
    pub order: usize,
    /// Sample interval of the identified sequence (s): 1 / sample rate (after decimation), or
    /// the lifting period.
    pub sample_interval_s: f64,
    /// Decimation factor applied before LSCE (1: none).
    pub decimation_factor: usize,
    /// The band in which poles may be picked (Hz; step 4 of the module documentation).
    pub band_hz: (f64, f64),
    /// Correlation lags of the whole-record diagram.
    pub lags: usize,
    /// Correlation lags of the segment identifications.
    pub segment_lags: usize,
    /// Harmonics imposed (Hz; empty for plain LSCE and lifting).
    pub harmonics_hz: Vec<f64>,
    /// Stabilization diagram of the whole record.
    pub diagram: StabilizationDiagram,
    /// Stable clusters passed over, in the order they were examined.
    pub rejected: Vec<RejectedCluster>,
    /// The segments' pole at every order of the diagram (000 Fig. 3b/c).
    pub order_statistics: Vec<OrderStatistics>,
    /// The resonance peak of the record's density under the pole (LSCE only; `None` with
    /// lifting or where the density has no peak there): frequency and half-power damping, an
    /// estimate independent of the LSCE fit ([`crate::support`]).
    pub spectral_peak: Option<SpectralPeak>,
}

/// One whole-record pass: the diagram and its structural clusters, most dominant first.
struct Pass {
    diagram: StabilizationDiagram,
    lags: usize,
    /// Persistent structural clusters by rank (never empty).
    candidates: Vec<PoleCluster>,
    rejected: Vec<RejectedCluster>,
}

impl Pass {
    /// Frequency gap (Hz) from candidate `i` to the nearest other candidate.
    fn gap_hz(&self, i: usize) -> Option<f64> {
        let f = self.candidates[i].frequency_hz;
        self.candidates
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, c)| (c.frequency_hz - f).abs())
            .filter(|g| *g > 0.0)
            .min_by(f64::total_cmp)
    }
}

/// Correlations of one window, in the form its method fits.
enum Correlations {
    Scalar(Vec<Vec<f64>>),
    Matrix(Vec<DMatrix<f64>>),
}

/// The sequences poles are fitted to and how.
struct Prepared<'a> {
    /// Polled before every correlation and fit.
    observer: &'a dyn Observer,
    data: Vec<Vec<f64>>,
    interval_s: f64,
    /// Reference channels of `data` (one for LSCE).
    references: Vec<usize>,
    /// Imposed by the modified LSCE (Hz).
    imposed_hz: Vec<f64>,
    /// Excluded from picking (Hz): the imposed ones, or every spindle multiple.
    excluded_hz: Vec<f64>,
    lifted: bool,
    /// Samples are grouped by index modulo this for mean removal (periods per revolution).
    classes: usize,
    skip_lags: usize,
    factor: usize,
    /// Poles outside are at the band edges.
    band_hz: (f64, f64),
    /// For the line test (LSCE only).
    lines: Option<LineSpectrum>,
    /// For the noise-floor test and the ranking (LSCE only).
    support: Option<SpectralSupport>,
    segment_len: usize,
}

impl<'a> Prepared<'a> {
    /// The sequences of `signals`, decimated by `factor` for LSCE.
    fn new(
        signals: &Signals,
        options: &IdentifyOptions,
        factor: usize,
        observer: &'a dyn Observer,
    ) -> Result<Self> {
        chatter_progress::check(observer)?;
        let fs = signals.sample_rate_hz;
        let with_segments = |mut p: Self| {
            let total = p.len();
            p.segment_len = ((options.segment_fraction * total as f64).round() as usize).min(total);
            p
        };
        match options.lifting {
            None => {
                let data: Vec<Vec<f64>> = signals
                    .data
                    .par_iter()
                    .map(|c| decimate(c, factor))
                    .collect();
                let rate = fs / factor as f64;
                let top = if factor > 1 {
                    PASSBAND_FRACTION * rate
                } else {
                    0.5 * rate
                };
                let lines = LineSpectrum::new(&data, rate);
                let (imposed_hz, excluded_hz) = match &options.harmonics {
                    Harmonics::None => (Vec::new(), Vec::new()),
                    Harmonics::Known(list) => (
                        list.iter().copied().filter(|f| *f < 0.5 * rate).collect(),
                        list.clone(),
                    ),
                    Harmonics::Spindle { fundamental_hz } => (
                        multiples_below(*fundamental_hz, top)
                            .into_iter()
                            .filter(|f| lines.is_line(*f))
                            .collect(),
                        multiples_below(*fundamental_hz, 0.5 * rate),
                    ),
                };
                let band_hz = (LOWER_EDGE_FRACTION * top, (1.0 - UPPER_EDGE_FRACTION) * top);
                // a record without power off its lines has no resonance to support a pole:
                // the noise-floor test and the ranking are then left out
                let support =
                    SpectralSupport::new(&data, rate, band_hz, &excluded_hz, Some(&lines)).ok();
                let skip_lags = if factor > 1 {
                    options.skip_lags.max(correlation_support_lags(factor))
                } else {
                    options.skip_lags
                };
                Ok(with_segments(Self {
                    observer,
                    data,
                    interval_s: 1.0 / rate,
                    references: vec![options.reference],
                    imposed_hz,
                    excluded_hz,
                    lifted: false,
                    classes: 1,
                    skip_lags,
                    factor,
                    band_hz,
                    lines: Some(lines),
                    support,
                    segment_len: 0,
                }))
            }
            Some(l) => {
                let mut data = Vec::new();
                for ch in &signals.data {
                    let lifted = lift_at_period(ch, fs, l.period_s)?;
                    let r = lifted.len();
                    if l.virtual_sensors == 0 || l.virtual_sensors > r {
                        return Err(OmaError::InvalidInput {
                            field: "virtual_sensors",
                            message: format!(
                                "{}; expected 1 to the {r} samples per period",
                                l.virtual_sensors
                            ),
                        });
                    }
                    let nv = l.virtual_sensors;
                    data.extend((0..nv).map(|k| lifted[k * r / nv].clone()));
                }
                let nv = l.virtual_sensors;
                // the support of the lifted record with its periodic response removed (as in
                // the correlations): the noise-floor test, not the ranking
                let rate = 1.0 / l.period_s;
                let fluctuations: Vec<Vec<f64>> = data
                    .iter()
                    .map(|ch| remove_class_means(ch, l.periods_per_revolution))
                    .collect();
                let support =
                    SpectralSupport::new(&fluctuations, rate, (0.0, 0.5 * rate), &[], None).ok();
                Ok(with_segments(Self {
                    observer,
                    data,
                    interval_s: l.period_s,
                    references: (options.reference * nv..(options.reference + 1) * nv).collect(),
                    imposed_hz: Vec::new(),
                    excluded_hz: Vec::new(),
                    lifted: true,
                    classes: l.periods_per_revolution,
                    skip_lags: options.skip_lags,
                    factor: 1,
                    band_hz: (0.0, f64::INFINITY),
                    lines: None,
                    support,
                    segment_len: 0,
                }))
            }
        }
    }

    fn len(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    /// Order range of the diagram (step 1 of the module documentation).
    fn orders(&self, options: &IdentifyOptions) -> std::ops::RangeInclusive<usize> {
        if self.lifted {
            options.min_order..=options.max_order
        } else {
            let h = self.imposed_hz.len();
            (h + options.min_order).max(2)..=h + options.max_order
        }
    }

    /// Correlations of the window `[start, start + len)`, means removed (per residue class of
    /// samples modulo `classes`), leading lags skipped.
    fn correlations(&self, start: usize, len: usize, lags: usize) -> Result<Correlations> {
        chatter_progress::check(self.observer)?;
        let classes = self.classes;
        let skip = self.skip_lags;
        let window: Vec<Vec<f64>> = self
            .data
            .iter()
            .map(|ch| remove_class_means(&ch[start..start + len], classes))
            .collect();
        let max_lag = lags + skip;
        Ok(if self.lifted {
            let mut r = correlation_matrices(&window, &self.references, max_lag)?;
            Correlations::Matrix(r.split_off(skip))
        } else {
            let r = correlate(&window, self.references[0], max_lag)?;
            Correlations::Scalar(r.into_iter().map(|mut c| c.split_off(skip)).collect())
        })
    }

    /// Twice the fewest lags that determine the least squares at `order`: LSCE fits 2P
    /// unknowns with one equation per channel and lag, polyreference n_a n_o unknowns per output
    /// with one equation per reference and lag.
    fn min_lags(&self, order: usize) -> usize {
        let (unknowns, per_lag) = if self.lifted {
            (order * self.data.len(), self.references.len())
        } else {
            (2 * order, self.data.len())
        };
        let order_lags = if self.lifted { order } else { 2 * order };
        2 * (order_lags + unknowns.div_ceil(per_lag.max(1)))
    }

    /// `lags` if they fit the segments, else a clear error.
    fn fits(&self, lags: usize) -> Result<usize> {
        if lags + self.skip_lags >= self.segment_len {
            let unit = if self.lifted { "periods" } else { "samples" };
            return Err(OmaError::InvalidInput {
                field: "max_lag",
                message: format!(
                    "{lags} lags after {} skipped do not fit segments of {} {unit}; use \
                     longer records, a larger segment fraction or a lower maximum order",
                    self.skip_lags, self.segment_len,
                ),
            });
        }
        Ok(lags)
    }

    /// The first diagram, with a quarter of the segment as window (at most
    /// [`LAG_FIRST_PASS`]).
    fn first_pass(&self, options: &IdentifyOptions) -> Result<Pass> {
        let floor = self.min_lags(*self.orders(options).end());
        let lags = self.fits(
            options
                .max_lag
                .unwrap_or((self.segment_len / 4).min(LAG_FIRST_PASS).max(floor)),
        )?;
        self.diagram(lags, options)
    }

    /// The window rule of the module documentation for candidate `i` of `pass` at `order`.
    fn window(
        &self,
        pass: &Pass,
        i: usize,
        order: usize,
        options: &IdentifyOptions,
    ) -> Result<usize> {
        let floor = self.min_lags(order);
        self.fits(options.max_lag.unwrap_or_else(|| {
            adaptive_lags(&pass.candidates[i], pass.gap_hz(i), self.interval_s)
                .clamp(floor, (self.segment_len / 2).max(floor))
        }))
    }

    /// Why `cluster` cannot be the structural pole, if it cannot (step 4 of the module
    /// documentation).
    fn rejection(&self, cluster: &PoleCluster) -> Option<Rejection> {
        let f = cluster.frequency_hz;
        if f < self.band_hz.0 || f > self.band_hz.1 {
            return Some(Rejection::BandEdge);
        }
        if self.lines.as_ref().is_some_and(|l| l.is_line(f)) {
            return Some(Rejection::SpectralLine);
        }
        self.support
            .as_ref()
            .is_some_and(|s| {
                s.level_db(f) < -NOISE_FLOOR_DB || s.prominence_db(f) < MIN_PROMINENCE_DB
            })
            .then_some(Rejection::NoiseFloor)
    }

    /// The persistent clusters of `structural` by rank (step 4 of the module documentation).
    fn ranked(&self, structural: Vec<PoleCluster>) -> Vec<PoleCluster> {
        let mut kept = ranked(structural);
        if let (Some(s), false) = (&self.support, self.lifted) {
            // stable sort: equal supports keep the decay-rate order
            kept.sort_by(|a, b| {
                s.level_db(b.frequency_hz)
                    .total_cmp(&s.level_db(a.frequency_hz))
            });
        }
        kept
    }

    /// Stabilization diagram of the whole record with `lags` lags and its structural clusters
    /// by rank.
    fn diagram(&self, lags: usize, options: &IdentifyOptions) -> Result<Pass> {
        let whole = self.correlations(0, self.len(), lags)?;
        let diagram = StabilizationDiagram::compute(self.orders(options), options.criteria, |n| {
            self.fit(&whole, n)
        })?;
        let mut rejected = Vec::new();
        let structural: Vec<PoleCluster> =
            stable_clusters(&diagram, &self.excluded_hz, &options.picking)
                .into_iter()
                .filter(|c| match self.rejection(c) {
                    Some(reason) => {
                        rejected.push(RejectedCluster {
                            frequency_hz: c.frequency_hz,
                            damping_ratio: c.damping_ratio,
                            reason,
                        });
                        false
                    }
                    None => true,
                })
                .collect();
        let candidates = self.ranked(structural);
        if candidates.is_empty() {
            return Err(OmaError::NoPole(format!(
                "no structural pole is stable over consecutive orders among {} orders with \
                 damping in (0, {}) inside {:.1} to {:.1} Hz{}; raise the maximum order or use \
                 more data",
                diagram.orders.len(),
                options.picking.max_damping,
                self.band_hz.0,
                self.band_hz.1,
                describe(&rejected)
            )));
        }
        Ok(Pass {
            diagram,
            lags,
            candidates,
            rejected,
        })
    }

    fn fit(&self, r: &Correlations, order: usize) -> Result<Vec<Pole>> {
        chatter_progress::check(self.observer)?;
        match r {
            Correlations::Scalar(r) => lsce(r, 1.0 / self.interval_s, 2 * order, &self.imposed_hz),
            Correlations::Matrix(r) => polyreference(r, self.interval_s, order),
        }
    }

    /// The admitted pole of `poles` nearest `cluster` (within 5 frequency tolerances).
    fn matching(
        &self,
        poles: Vec<Pole>,
        cluster: &PoleCluster,
        options: &IdentifyOptions,
    ) -> Option<Pole> {
        let window = 5.0 * options.criteria.frequency_rel * cluster.frequency_hz;
        let target = cluster.lambda();
        poles
            .into_iter()
            .filter(|p| {
                options.picking.admits(p, &self.excluded_hz)
                    && (p.frequency_hz - cluster.frequency_hz).abs() <= window
            })
            .min_by(|a, b| {
                (a.lambda - target)
                    .norm()
                    .total_cmp(&(b.lambda - target).norm())
            })
    }
}

/// `w` less the mean of each residue class of its samples modulo `classes`.
fn remove_class_means(w: &[f64], classes: usize) -> Vec<f64> {
    let means: Vec<f64> = (0..classes)
        .map(|k| {
            let class = w.iter().skip(k).step_by(classes);
            class.clone().sum::<f64>() / class.count().max(1) as f64
        })
        .collect();
    w.iter()
        .enumerate()
        .map(|(i, v)| v - means[i % classes])
        .collect()
}

/// ", rejected: 4823.6 Hz (band edge), ..." or nothing.
fn describe(rejected: &[RejectedCluster]) -> String {
    if rejected.is_empty() {
        return String::new();
    }
    let list: Vec<String> = rejected
        .iter()
        .map(|r| {
            let why = match r.reason {
                Rejection::BandEdge => "band edge".to_string(),
                Rejection::SpectralLine => "spectral line".to_string(),
                Rejection::NoiseFloor => "noise floor".to_string(),
                Rejection::Segments { found, of } => format!("in {found} of {of} segments"),
            };
            format!("{:.2} Hz ({why})", r.frequency_hz)
        })
        .collect();
    format!(", rejected: {}", list.join(", "))
}

/// Identify the dominant pole of `signals` (module documentation, steps 1-5).
pub fn identify(signals: &Signals, options: &IdentifyOptions) -> Result<Identification> {
    identify_with_observer(signals, options, &Silent)
}

/// [`identify`], polling `observer` before every correlation and every fit of a model order: a
/// cancelled call returns [`OmaError::Cancelled`] after at most one fit per thread.
pub fn identify_with_observer(
    signals: &Signals,
    options: &IdentifyOptions,
    observer: &dyn Observer,
) -> Result<Identification> {
    validate(signals, options)?;
    let mut prepared = Prepared::new(signals, options, 1, observer)?;
    let mut pass = prepared.first_pass(options);
    if !prepared.lifted {
        let factor = match options.decimation {
            Decimation::Off => 1,
            Decimation::Factor(n) => n,
            Decimation::Auto => pass.as_ref().map_or(1, |p| {
                let f = p.candidates[0].frequency_hz;
                if signals.sample_rate_hz > DECIMATE_ABOVE * f {
                    (signals.sample_rate_hz / (RATE_PER_POLE * f)).floor() as usize
                } else {
                    1
                }
            }),
        };
        if factor > 1 {
            prepared = Prepared::new(signals, options, factor, observer)?;
            pass = prepared.first_pass(options);
        }
    }
    let mut pass = pass?;
    let top = *prepared.orders(options).end();
    let adapted = prepared.window(&pass, 0, top, options)?;
    if adapted != pass.lags {
        pass = prepared.diagram(adapted, options)?;
    }
    let total = prepared.len();
    let seg_len = prepared.segment_len;
    let mut rng = rand::rngs::StdRng::seed_from_u64(options.seed);
    let starts: Vec<usize> = (0..options.segments)
        .map(|_| rng.random_range(0..=total - seg_len))
        .collect();
    let mut rejected = pass.rejected.clone();
    for (i, cluster) in pass.candidates.iter().enumerate() {
        let run_start = cluster.members.first().map_or(top, |m| m.order);
        // segment correlations by window length, shared by the orders that use it
        let mut by_lags: Vec<(usize, Vec<Correlations>)> = Vec::new();
        let mut at_order = |n: usize| -> Result<(usize, Vec<Pole>)> {
            let lags = prepared.window(&pass, i, n, options)?;
            let k = match by_lags.iter().position(|(l, _)| *l == lags) {
                Some(k) => k,
                None => {
                    let r = starts
                        .par_iter()
                        .map(|&s| prepared.correlations(s, seg_len, lags))
                        .collect::<Result<Vec<Correlations>>>()?;
                    by_lags.push((lags, r));
                    by_lags.len() - 1
                }
            };
            let found = by_lags[k]
                .1
                .par_iter()
                .map(|r| Ok(prepared.matching(prepared.fit(r, n)?, cluster, options)))
                .collect::<Result<Vec<Option<Pole>>>>()?;
            Ok((lags, found.into_iter().flatten().collect()))
        };
        // an order whose window does not fit the segments has no statistics (the chosen
        // order's must fit: it is fitted again below)
        let mut per_order = Vec::with_capacity(pass.diagram.orders.len());
        for o in &pass.diagram.orders {
            match at_order(o.order) {
                Ok(found) => per_order.push((o.order, found)),
                Err(OmaError::InvalidInput { .. }) => {}
                Err(e) => return Err(e),
            }
        }
        let order_statistics: Vec<OrderStatistics> = pass
            .diagram
            .orders
            .iter()
            .map(|o| OrderStatistics {
                order: o.order,
                estimate: per_order
                    .iter()
                    .find(|(n, _)| *n == o.order)
                    .and_then(|(_, (_, poles))| PoleEstimate::from_poles(poles).ok()),
            })
            .collect();
        let order = options
            .order
            .or_else(|| settled_order(&order_statistics, run_start, &options.criteria))
            .unwrap_or(run_start);
        let (segment_lags, segment_poles) = match per_order.iter().find(|(o, _)| *o == order) {
            Some((_, found)) => found.clone(),
            None => at_order(order)?,
        };
        let found = segment_poles.len();
        if (found as f64) < MIN_SEGMENT_SHARE * options.segments as f64 {
            rejected.push(RejectedCluster {
                frequency_hz: cluster.frequency_hz,
                damping_ratio: cluster.damping_ratio,
                reason: Rejection::Segments {
                    found,
                    of: options.segments,
                },
            });
            continue;
        }
        let estimate = PoleEstimate::from_poles(&segment_poles)?;
        let spectral_peak = prepared
            .support
            .as_ref()
            .filter(|_| !prepared.lifted)
            .and_then(|s| s.peak(estimate.frequency_hz));
        return Ok(Identification {
            estimate,
            segment_poles,
            cluster: cluster.clone(),
            order,
            sample_interval_s: prepared.interval_s,
            decimation_factor: prepared.factor,
            band_hz: prepared.band_hz,
            lags: pass.lags,
            segment_lags,
            harmonics_hz: prepared.imposed_hz,
            diagram: pass.diagram,
            rejected,
            order_statistics,
            spectral_peak,
        });
    }
    Err(OmaError::NoPole(format!(
        "no stable structural pole is found in {} % of the {} segments{}",
        100.0 * MIN_SEGMENT_SHARE,
        options.segments,
        describe(&rejected)
    )))
}

/// The lowest order n >= `from` at which the segments' mean pole has settled (000 Section 6.1:
/// "at sufficiently high model orders, the identified pole's damping and frequency converge to
/// a constant value", Fig. 3b/c): the means at n and the next orders, [`MIN_SETTLED_ORDERS`]
/// consecutive orders in all, agree with their median within the relative tolerances of
/// `criteria` (not its absolute damping floor, which exceeds the whole damping of lightly
/// damped poles: 5e-4 against 0.0012 on seed 000's P4). `None` if no such order.
fn settled_order(
    stats: &[OrderStatistics],
    from: usize,
    criteria: &StabilityCriteria,
) -> Option<usize> {
    let criteria = StabilityCriteria {
        damping_abs: 0.0,
        ..*criteria
    };
    let means: Vec<(usize, f64, f64)> = stats
        .iter()
        .filter(|s| s.order >= from)
        .filter_map(|s| {
            s.estimate
                .map(|e| (s.order, e.frequency_hz, e.damping_ratio))
        })
        .collect();
    // the middle value (the upper of the two for an even count)
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    means
        .windows(MIN_SETTLED_ORDERS)
        .find(|w| {
            let consecutive = w.windows(2).all(|p| p[1].0 == p[0].0 + 1);
            let f = median(w.iter().map(|m| m.1).collect());
            let z = median(w.iter().map(|m| m.2).collect());
            consecutive
                && w.iter()
                    .all(|m| criteria.same_frequency(m.1, f) && criteria.same_damping(m.2, z))
        })
        .map(|w| w[0].0)
}

/// Correlation lags spanning [`LAG_TIME_CONSTANTS`] decay times -1 / Re(lambda) of the cluster's
/// pole, at least [`LAG_MIN_CYCLES`] of its periods and at least [`LAG_BEAT_PERIODS`] periods of
/// the beat with the nearest other stable pole (`gap_hz` away, if farther than the half-power
/// bandwidth), in samples of `interval_s`.
fn adaptive_lags(cluster: &PoleCluster, gap_hz: Option<f64>, interval_s: f64) -> usize {
    let decay_rate = -cluster.lambda().re;
    let decay_s = LAG_TIME_CONSTANTS / decay_rate;
    let cycles_s = LAG_MIN_CYCLES / cluster.frequency_hz;
    // neighbours within the half-power bandwidth decay_rate / pi are split images of the pole
    // (or unresolvable): they do not widen the window
    let beat_s = gap_hz
        .filter(|g| *g > decay_rate / std::f64::consts::PI)
        .map_or(0.0, |g| LAG_BEAT_PERIODS / g);
    let lags = decay_s.max(cycles_s).max(beat_s) / interval_s;
    // a pole at the admission limit of zero damping has an unbounded decay time
    if lags.is_finite() {
        lags.ceil() as usize
    } else {
        usize::MAX
    }
}

fn validate(signals: &Signals, options: &IdentifyOptions) -> Result<()> {
    let invalid =
        |field: &'static str, message: String| Err(OmaError::InvalidInput { field, message });
    if options.reference >= signals.data.len() {
        return invalid(
            "reference",
            format!("channel {} of {}", options.reference, signals.data.len()),
        );
    }
    if options.segments == 0 {
        return invalid("segments", "0; expected at least one segment".into());
    }
    if !(options.segment_fraction > 0.0 && options.segment_fraction <= 1.0) {
        return invalid(
            "segment_fraction",
            format!("{}; expected a value in (0, 1]", options.segment_fraction),
        );
    }
    if options.min_order == 0 || options.min_order > options.max_order {
        return invalid(
            "min_order",
            format!(
                "{} with max_order {}; expected 1 <= min_order <= max_order",
                options.min_order, options.max_order
            ),
        );
    }
    if let Decimation::Factor(0) = options.decimation {
        return invalid("decimation", "factor 0; expected 1 or more".into());
    }
    options.harmonics.validate(0.5 * signals.sample_rate_hz)?;
    if let Some(l) = options.lifting {
        if !(l.period_s.is_finite() && l.period_s > 0.0) {
            return invalid("period_s", format!("{}; expected a period > 0", l.period_s));
        }
        if l.periods_per_revolution == 0 {
            return invalid(
                "periods_per_revolution",
                "0; expected at least 1 (the number of teeth)".into(),
            );
        }
    }
    options.criteria.validate()?;
    options.picking.validate()
}
