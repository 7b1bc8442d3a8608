//! One call from signals to the dominant pole: correlations, stabilization diagram, automatic
//! pick and repeated identification on random segments (000 Section 6.1 and Table 2; 002
//! Section 2.1 and Table 2).
//!
//! 1. Turning (time-invariant): the channels, each with its mean removed, are correlated with
//!    the reference channel (000 Eq. 21) and fitted by (modified) LSCE (Eq. 19-25, harmonics as
//!    in [`crate::harmonics`]) at model orders P = 2..=`max_order` (pole pairs; more than the
//!    number of imposed harmonics). Milling
//!    ([`Lifting`]): every channel is lifted at the tooth period (002 Eq. 6-7),
//!    `virtual_sensors` evenly spaced lifted channels per physical channel are kept with their
//!    means removed (which removes the periodic forced response; per residue class of periods
//!    modulo `periods_per_revolution` to remove runout too), correlated with the virtual sensors
//!    of the reference channel (Eq. 8) and fitted by time-domain polyreference (Eq. 9) at AR
//!    orders n_a = 1..=`max_order`.
//! 2. The first `skip_lags` lags are dropped: lag 0 carries the power of uncorrelated measurement
//!    noise and, for accelerations, the direct feed-through of the force, neither of which is a
//!    sum of damped exponentials.
//! 3. The diagram of the whole record ([`crate::stabilization`]) gives the dominant cluster
//!    ([`crate::picking`]); the first order of its run of consecutive stable orders (where the
//!    pole settles) is the identification order unless `order` fixes one. With
//!    [`Harmonics::Spindle`] a first plain pass locates the pole, and the multiples nearest it
//!    that are present as spectral lines are imposed from then on.
//! 4. N_s = `segments` windows of `segment_fraction` of the record start at seeded uniform random
//!    positions; each is identified at that order and contributes the admitted pole nearest the
//!    cluster's mean lambda (and within 5 times the frequency tolerance of its frequency). Mean
//!    and sample standard deviation over the windows are the reported pole, as in the tables of
//!    000 and 002.
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
use crate::error::{OmaError, Result};
use crate::harmonics::{
    Harmonics, SPINDLE_CLEARANCE, multiples_below, multiples_by_distance, present_lines,
};
use crate::lifting::lift_at_period;
use crate::lsce::{Pole, lsce};
use crate::picking::{PickingOptions, PoleCluster, persistent, pick_dominant, stable_clusters};
use crate::polyreference::polyreference;
use crate::signals::Signals;
use crate::stabilization::{StabilityCriteria, StabilizationDiagram, lsce_min_order};
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

/// Options of [`identify`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IdentifyOptions {
    /// Index of the reference channel (default 0).
    pub reference: usize,
    /// Highest model order of the diagram (default 30): pole pairs P for LSCE, AR order n_a
    /// for polyreference. Lifted records are short (one sample per period) and polyreference
    /// fits n_a times the number of lifted channels poles, so lifted identification wants a
    /// low order (the CLI uses [`LIFTED_MAX_ORDER`]): at high orders the dominant multiplier splits
    /// into nearby noise poles and the correlation window must grow with the order.
    pub max_order: usize,
    /// Harmonics imposed by the modified LSCE and excluded from picking (default none; ignored with lifting, where periodic responses are constants).
    pub harmonics: Harmonics,
    /// Correlation lags used, after the skipped ones (samples, or periods with lifting); default
    /// `None`: automatic, see the [module documentation](self#automatic-correlation-window).
    pub max_lag: Option<usize>,
    /// Leading lags dropped (default 1, see step 2 of the module documentation).
    pub skip_lags: usize,
    /// Model order of the segment identifications; default `None`: the first order of the
    /// dominant cluster's run of consecutive stable orders (higher orders fit noise poles that
    /// scatter the damping).
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
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        Self {
            reference: 0,
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
    /// Sample interval of the identified sequence (s): 1 / sample rate, or the lifting period.
    pub sample_interval_s: f64,
    /// Correlation lags of the whole-record diagram.
    pub lags: usize,
    /// Correlation lags of the segment identifications.
    pub segment_lags: usize,
    /// Harmonics imposed (Hz; empty for plain LSCE and lifting).
    pub harmonics_hz: Vec<f64>,
    /// Stabilization diagram of the whole record.
    pub diagram: StabilizationDiagram,
}

/// One whole-record pass: the diagram, its dominant cluster and the gap (Hz) to the nearest
/// other stable cluster.
struct Pass {
    diagram: StabilizationDiagram,
    cluster: PoleCluster,
    gap_hz: Option<f64>,
}

/// Correlations of one window, in the form its method fits.
enum Correlations {
    Scalar(Vec<Vec<f64>>),
    Matrix(Vec<DMatrix<f64>>),
}

/// The sequences poles are fitted to and how.
struct Prepared {
    data: Vec<Vec<f64>>,
    interval_s: f64,
    /// Reference channels of `data` (one for LSCE).
    references: Vec<usize>,
    /// Imposed by the modified LSCE and removed from the windows (Hz).
    imposed_hz: Vec<f64>,
    /// Excluded from picking (Hz): the imposed ones, or every spindle multiple.
    excluded_hz: Vec<f64>,
    lifted: bool,
    /// Samples are grouped by index modulo this for mean removal (periods per revolution).
    classes: usize,
}

impl Prepared {
    fn new(signals: &Signals, options: &IdentifyOptions) -> Result<Self> {
        let fs = signals.sample_rate_hz;
        match options.lifting {
            None => {
                let (imposed_hz, excluded_hz) = match &options.harmonics {
                    Harmonics::None => (Vec::new(), Vec::new()),
                    Harmonics::Known(list) => (list.clone(), list.clone()),
                    Harmonics::Spindle { fundamental_hz, .. } => {
                        (Vec::new(), multiples_below(*fundamental_hz, 0.5 * fs))
                    }
                };
                Ok(Self {
                    data: signals.data.clone(),
                    interval_s: 1.0 / fs,
                    references: vec![options.reference],
                    imposed_hz,
                    excluded_hz,
                    lifted: false,
                    classes: 1,
                })
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
                Ok(Self {
                    data,
                    interval_s: l.period_s,
                    references: (options.reference * nv..(options.reference + 1) * nv).collect(),
                    imposed_hz: Vec::new(),
                    excluded_hz: Vec::new(),
                    lifted: true,
                    classes: l.periods_per_revolution,
                })
            }
        }
    }

    fn len(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    fn min_order(&self) -> usize {
        if self.lifted {
            1
        } else {
            lsce_min_order(self.imposed_hz.len())
        }
    }

    /// Correlations of the window `[start, start + len)`, means removed (per residue class of
    /// samples modulo `classes`), leading lags skipped.
    fn correlations(
        &self,
        start: usize,
        len: usize,
        lags: usize,
        skip: usize,
    ) -> Result<Correlations> {
        let classes = self.classes;
        let window: Vec<Vec<f64>> = self
            .data
            .iter()
            .map(|ch| {
                let w = &ch[start..start + len];
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
            })
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

    /// Stabilization diagram of the whole record with `lags` lags, its dominant cluster and the
    /// frequency gap to the nearest other cluster that passes the persistence rule of the pick.
    fn diagram(&self, lags: usize, options: &IdentifyOptions) -> Result<Pass> {
        let whole = self.correlations(0, self.len(), lags, options.skip_lags)?;
        let diagram = StabilizationDiagram::compute(
            self.min_order()..=options.max_order,
            options.criteria,
            |n| self.fit(&whole, n),
        )?;
        let cluster = pick_dominant(&diagram, &self.excluded_hz, &options.picking)?;
        // the other physical poles: clusters as persistent as the pick requires
        let others = stable_clusters(&diagram, &self.excluded_hz, &options.picking);
        let most = others.iter().map(|c| c.members.len()).max().unwrap_or(0);
        let gap_hz = others
            .iter()
            .filter(|c| persistent(c, most) && c.members != cluster.members)
            .map(|c| (c.frequency_hz - cluster.frequency_hz).abs())
            .filter(|g| *g > 0.0)
            .min_by(f64::total_cmp);
        Ok(Pass {
            diagram,
            cluster,
            gap_hz,
        })
    }

    fn fit(&self, r: &Correlations, order: usize) -> Result<Vec<Pole>> {
        match r {
            Correlations::Scalar(r) => lsce(r, 1.0 / self.interval_s, 2 * order, &self.imposed_hz),
            Correlations::Matrix(r) => polyreference(r, self.interval_s, order),
        }
    }
}

/// Identify the dominant pole of `signals` (module documentation, steps 1-4).
pub fn identify(signals: &Signals, options: &IdentifyOptions) -> Result<Identification> {
    validate(signals, options)?;
    let mut prepared = Prepared::new(signals, options)?;
    let total = prepared.len();
    let seg_len = ((options.segment_fraction * total as f64).round() as usize).min(total);
    let unit = if prepared.lifted {
        "periods"
    } else {
        "samples"
    };
    let fits = |lags: usize| {
        if lags + options.skip_lags >= seg_len {
            return Err(OmaError::InvalidInput {
                field: "max_lag",
                message: format!(
                    "{lags} lags after {} skipped do not fit segments of {seg_len} {unit}; use \
                     longer records, a larger segment fraction or a lower maximum order",
                    options.skip_lags,
                ),
            });
        }
        Ok(lags)
    };
    // the window rule of the module documentation for the pole of `pass` at `order`
    let window_for = |pass: &Pass, order: usize, prepared: &Prepared| {
        let floor = prepared.min_lags(order);
        options.max_lag.unwrap_or_else(|| {
            adaptive_lags(&pass.cluster, pass.gap_hz, prepared.interval_s)
                .clamp(floor, (seg_len / 2).max(floor))
        })
    };
    let floor = prepared.min_lags(options.max_order);
    let mut lags = fits(
        options
            .max_lag
            .unwrap_or((seg_len / 4).min(LAG_FIRST_PASS).max(floor)),
    )?;
    let mut pass = prepared.diagram(lags, options)?;
    let mut redo = false;
    if let (
        Harmonics::Spindle {
            fundamental_hz,
            count,
        },
        false,
    ) = (&options.harmonics, prepared.lifted)
    {
        let nyquist = 0.5 / prepared.interval_s;
        let clearance =
            SPINDLE_CLEARANCE * -pass.cluster.lambda().re / (2.0 * std::f64::consts::PI);
        let candidates = multiples_by_distance(
            *fundamental_hz,
            pass.cluster.frequency_hz,
            clearance,
            nyquist,
        );
        // the nearest few candidates are enough: 3 per harmonic wanted
        let candidates = &candidates[..candidates.len().min(3 * count)];
        let mut present = present_lines(&signals.data, signals.sample_rate_hz, candidates);
        present.truncate(*count);
        present.sort_by(f64::total_cmp);
        redo = !present.is_empty();
        prepared.imposed_hz = present;
    }
    let adapted = fits(window_for(&pass, options.max_order, &prepared))?;
    if adapted != lags || redo {
        lags = adapted;
        pass = prepared.diagram(lags, options)?;
    }
    let order = options
        .order
        .or_else(|| pass.cluster.members.first().map(|m| m.order))
        .unwrap_or(options.max_order);
    let segment_lags = fits(window_for(&pass, order, &prepared))?;
    let Pass {
        diagram, cluster, ..
    } = pass;
    let mut rng = rand::rngs::StdRng::seed_from_u64(options.seed);
    let starts: Vec<usize> = (0..options.segments)
        .map(|_| rng.random_range(0..=total - seg_len))
        .collect();
    let window = 5.0 * options.criteria.frequency_rel * cluster.frequency_hz;
    let target = cluster.lambda();
    let found = starts
        .par_iter()
        .map(|&s| {
            let r = prepared.correlations(s, seg_len, segment_lags, options.skip_lags)?;
            Ok(prepared
                .fit(&r, order)?
                .into_iter()
                .filter(|p| {
                    options.picking.admits(p, &prepared.excluded_hz)
                        && (p.frequency_hz - cluster.frequency_hz).abs() <= window
                })
                .min_by(|a, b| {
                    (a.lambda - target)
                        .norm()
                        .total_cmp(&(b.lambda - target).norm())
                }))
        })
        .collect::<Result<Vec<Option<Pole>>>>()?;
    let segment_poles: Vec<Pole> = found.into_iter().flatten().collect();
    let estimate = PoleEstimate::from_poles(&segment_poles).map_err(|_| {
        OmaError::NoPole(format!(
            "none of the {} segments has a pole within {window:.3} Hz of {:.3} Hz at order {order}",
            options.segments, cluster.frequency_hz
        ))
    })?;
    Ok(Identification {
        estimate,
        segment_poles,
        cluster,
        order,
        sample_interval_s: prepared.interval_s,
        lags,
        segment_lags,
        harmonics_hz: prepared.imposed_hz,
        diagram,
    })
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
