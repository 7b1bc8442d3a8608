//! `chatter oma`: operational modal analysis of every signal listed in an observations file.
//!
//! Each record is read (CSV at the entry's `sample_rate_hz`, or WAV at its own rate), its
//! `once_per_rev_channel` (if any) is taken out of the analysed channels, and the dominant pole
//! is identified with repeated segments:
//! - turning, or no model: modified LSCE with the spindle harmonics (rpm / 60) near the pole
//!   that are present as spectral lines imposed (000 Eq. 19-25); the pole's `frequency_hz` is
//!   the physical frequency;
//! - milling model: lifting at the tooth period (from the tachometer pulses when there is a
//!   once-per-revolution channel, else from `speed_rpm`) and polyreference (002 Eq. 6-9); the
//!   pole's `frequency_hz` is the principal frequency of the Floquet multiplier.
//!
//! The result is an observations JSON with the input's `cuts` and one `poles` entry per
//! signal, ready for the updating commands.

use crate::output::emit;
use crate::plot::{Series, line_chart};
use anyhow::{Context, Result, bail};
use chatter_dynamics::{ModalModel, Observations, Operation, PoleObservation, SignalRecord};
use chatter_oma::identify::{LIFTED_CRITERIA, LIFTED_MAX_ORDER};
use chatter_oma::lifting::lift_at_period;
use chatter_oma::signals::Signals;
use chatter_oma::spectrum::first_singular_value;
use chatter_oma::{Harmonics, Identification, IdentifyOptions, Lifting, identify};
use plotters::style::{BLUE, RGBColor};
use std::path::{Path, PathBuf};

/// Spindle harmonics the modified LSCE may impose around the pole (000 Fig. 3 shows three).
const SPINDLE_HARMONICS: usize = 3;
/// Lifted channels kept per physical channel.
const VIRTUAL_SENSORS: usize = 2;

/// `chatter oma`.
pub fn oma(
    observations_path: &Path,
    model_path: Option<&Path>,
    out: Option<&Path>,
    plot: Option<&Path>,
) -> Result<()> {
    let observations = crate::inputs::observations(observations_path)?;
    let model = model_path.map(crate::inputs::model).transpose()?;
    if observations.signals.is_empty() {
        bail!(
            "{}: no `signals` to identify; expected at least one entry with a `file`",
            observations_path.display()
        );
    }
    let mut poles = Vec::with_capacity(observations.signals.len());
    for (i, record) in observations.signals.iter().enumerate() {
        let context = || {
            format!(
                "{}: signals[{i}] ({})",
                observations_path.display(),
                record.file.display()
            )
        };
        let analysis = analyse(i, record, model.as_ref()).with_context(context)?;
        if let Some(plot) = plot {
            let path = plot_path(plot, i, observations.signals.len());
            draw(&path, record, &analysis).with_context(context)?;
            eprintln!("wrote {}", path.display());
        }
        poles.push(pole_observation(record, &analysis));
    }
    let result = Observations {
        cuts: observations.cuts,
        poles,
        signals: Vec::new(),
    };
    emit(out, &result.to_json_string())
}

/// One identified record.
struct Analysis {
    id: Identification,
    /// Analysed channels (tachometer removed).
    signals: Signals,
    lifting: Option<Lifting>,
    method: String,
}

fn analyse(i: usize, record: &SignalRecord, model: Option<&ModalModel>) -> Result<Analysis> {
    let is_wav = record
        .file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("wav"));
    let mut signals = if is_wav {
        Signals::from_wav(&record.file, None)?
    } else {
        let fs = record.sample_rate_hz.with_context(|| {
            format!("`signals[{i}].sample_rate_hz` is missing: a CSV record needs its sample rate")
        })?;
        Signals::from_csv(&record.file, fs)?
    };
    let mut revolution_s = 60.0 / record.speed_rpm;
    if let Some(name) = &record.once_per_rev_channel {
        let c = signals.channel(name).with_context(|| {
            format!(
                "`signals[{i}].once_per_rev_channel` `{name}` is not a channel of the record \
                 (channels: {})",
                signals.names.join(", ")
            )
        })?;
        revolution_s = signals.pulse_period_s(c)?;
        signals = signals.without_channel(c)?;
    }
    let teeth = match model.map(ModalModel::operation) {
        Some(Operation::Milling(m)) => Some(m.teeth()),
        _ => None,
    };
    let (options, lifting, method) = match teeth {
        Some(teeth) => {
            let lifting = Lifting {
                period_s: revolution_s / teeth as f64,
                virtual_sensors: VIRTUAL_SENSORS,
                periods_per_revolution: teeth,
            };
            let options = IdentifyOptions {
                max_order: LIFTED_MAX_ORDER,
                criteria: LIFTED_CRITERIA,
                lifting: Some(lifting),
                ..IdentifyOptions::default()
            };
            let method = format!(
                "lifted at the tooth period {:.6} s, polyreference",
                lifting.period_s
            );
            (options, Some(lifting), method)
        }
        None => {
            let options = IdentifyOptions {
                harmonics: Harmonics::Spindle {
                    fundamental_hz: 1.0 / revolution_s,
                    count: SPINDLE_HARMONICS,
                },
                ..IdentifyOptions::default()
            };
            (options, None, "modified LSCE".to_string())
        }
    };
    let id = identify(&signals, &options)?;
    Ok(Analysis {
        id,
        signals,
        lifting,
        method,
    })
}

fn pole_observation(record: &SignalRecord, a: &Analysis) -> PoleObservation {
    let e = &a.id.estimate;
    let frequency_hz = if a.lifting.is_some() {
        e.principal_frequency_hz
    } else {
        e.frequency_hz
    };
    let harmonics = if a.id.harmonics_hz.is_empty() {
        String::new()
    } else {
        format!(", harmonics {:.1?} Hz imposed", a.id.harmonics_hz)
    };
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
            "OMA of {}: {}, order {}, {} lags{harmonics}",
            record.file.file_name().map_or_else(
                || record.file.display().to_string(),
                |n| n.to_string_lossy().into()
            ),
            a.method,
            a.id.order,
            a.id.segment_lags
        )),
    }
}

/// `plot` itself for a single signal, else `stem-N.ext` for signal N (from 1).
fn plot_path(plot: &Path, i: usize, count: usize) -> PathBuf {
    if count == 1 {
        return plot.to_path_buf();
    }
    let stem = plot
        .file_stem()
        .map_or_else(|| "oma".into(), |s| s.to_string_lossy().into_owned());
    let ext = plot
        .extension()
        .map_or_else(|| "svg".into(), |s| s.to_string_lossy().into_owned());
    plot.with_file_name(format!("{stem}-{}.{ext}", i + 1))
}

/// The stabilization diagram (poles by model order; stable ones in black) over the first
/// singular value of the PSD matrix of the analysed data (the lifted channels for milling), on a
/// log scale mapped onto the order axis.
fn draw(path: &Path, record: &SignalRecord, a: &Analysis) -> Result<()> {
    let (data, rate_hz) = match a.lifting {
        Some(l) => {
            let mut lifted = Vec::new();
            for ch in &a.signals.data {
                let all = lift_at_period(ch, a.signals.sample_rate_hz, l.period_s)?;
                let r = all.len();
                lifted
                    .extend((0..l.virtual_sensors).map(|k| all[k * r / l.virtual_sensors].clone()));
            }
            (lifted, 1.0 / l.period_s)
        }
        None => (a.signals.data.clone(), a.signals.sample_rate_hz),
    };
    let len = data.first().map_or(0, Vec::len);
    let segment = (len / 8).clamp(4, 4096);
    let psd = first_singular_value(&data, rate_hz, segment)?;
    let orders: Vec<usize> = a.id.diagram.orders.iter().map(|o| o.order).collect();
    let (lo, hi) = (
        orders.iter().copied().min().unwrap_or(1) as f64,
        orders.iter().copied().max().unwrap_or(1) as f64,
    );
    let logs: Vec<f64> = psd
        .values
        .iter()
        .map(|v| v.max(f64::MIN_POSITIVE).log10())
        .collect();
    let (lmin, lmax) = logs
        .iter()
        .skip(1)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let span = (lmax - lmin).max(1e-12);
    let curve: Vec<(f64, f64)> = psd
        .frequencies_hz
        .iter()
        .zip(&logs)
        .skip(1)
        .map(|(f, l)| (*f, lo + (hi - lo).max(1.0) * (l - lmin) / span))
        .collect();
    let frequency = |p: &chatter_oma::lsce::Pole| {
        if a.lifting.is_some() {
            p.principal_frequency_hz()
        } else {
            p.frequency_hz
        }
    };
    let (mut stable, mut other) = (Vec::new(), Vec::new());
    for o in &a.id.diagram.orders {
        for d in &o.poles {
            let point = (frequency(&d.pole), o.order as f64);
            if d.is_stable() {
                stable.push(point);
            } else {
                other.push(point);
            }
        }
    }
    let e = &a.id.estimate;
    let series = [
        Series {
            label: "first singular value of the PSD (log, scaled to the orders)".into(),
            points: curve,
            color: BLUE,
            dashed: false,
        },
        Series {
            label: "pole".into(),
            points: other,
            color: RGBColor(170, 170, 170),
            dashed: true,
        },
        Series {
            label: "stable pole".into(),
            points: stable,
            color: RGBColor(0, 0, 0),
            dashed: true,
        },
    ];
    line_chart(
        path,
        &format!(
            "{} rpm, {} mm: {:.2} Hz, zeta {:.4}",
            record.speed_rpm,
            record.depth_mm,
            if a.lifting.is_some() {
                e.principal_frequency_hz
            } else {
                e.frequency_hz
            },
            e.damping_ratio
        ),
        if a.lifting.is_some() {
            "principal frequency of the lifted poles (Hz)"
        } else {
            "frequency (Hz)"
        },
        "model order",
        &series,
        None,
    )
}
