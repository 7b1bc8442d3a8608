//! `chatter oma`: operational modal analysis of every signal listed in an observations file.
//!
//! Each record is read (CSV at the entry's `sample_rate_hz`, WAV or MP3 at its own rate), its
//! `once_per_rev_channel` (if any) gives the spindle frequency and is taken out of the analysed
//! channels. A record that chatter detection (`chatter_oma::detection`, with the spindle
//! frequency and a mains comb found in the record, or the fundamentals of `--interference-hz`)
//! calls chatter is refused: its dominant line is a
//! limit cycle, not a structural pole; `--allow-chatter` identifies it anyway and says so in the
//! pole's `note`. Then the dominant pole is identified with repeated segments
//! (`chatter_oma::identify`):
//! - turning, or no model: modified LSCE with every spindle harmonic (rpm / 60) in the analysed
//!   band that is a spectral line imposed (000 Eq. 19-25), after decimation when the pole lies
//!   below 1/16 of the sample rate; poles at the band edges, poles that are spectral lines and
//!   poles found in fewer than half the segments are rejected; the pole's `frequency_hz` is the
//!   physical frequency;
//! - milling model: lifting at the tooth period (from the tachometer pulses when there is a
//!   once-per-revolution channel, else from `speed_rpm`) and polyreference (002 Eq. 6-9); the
//!   pole's `frequency_hz` is the principal frequency of the Floquet multiplier.
//!
//! Overrides: `--min-order`/`--max-order` (model orders beyond the imposed harmonics),
//! `--segments`, `--harmonics-hz` (impose exactly these instead of the spindle lines; `none`
//! for plain LSCE), `--decimation` (a factor; 1 for none).
//!
//! The result is an observations JSON with the input's `cuts` and one `poles` entry per
//! signal, ready for the updating commands. `--plot FILE.svg` writes the stabilization diagram
//! and `FILE-orders.svg`, the segments' mean and standard deviation of the pole's frequency and
//! damping by model order (000 Fig. 3b/c).

use crate::output::emit;
use crate::plot::{ErrorBarPanel, Series, error_bar_panels, line_chart};
use anyhow::{Context, Result};
use chatter_dynamics::SignalRecord;
use chatter_jobs::oma::{OmaRequest, RecordAnalysis, identify_observations};
use chatter_oma::Harmonics;
use plotters::style::{BLUE, RGBColor};
use std::path::{Path, PathBuf};

/// Arguments of `chatter oma`.
#[derive(Debug, clap::Args)]
pub struct OmaArgs {
    /// Observations file listing the `signals` (CSV, WAV or MP3).
    #[arg(long)]
    pub observations: PathBuf,
    /// Machine model; a milling model makes the identification lifted at the tooth period.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Write the JSON here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// SVG stabilization diagram over the first singular value of the PSD, and FILE-orders.svg,
    /// the pole by model order (with several signals, one pair per signal: NAME-1.svg, ...).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Lowest model order beyond the imposed harmonics (default 1).
    #[arg(long)]
    pub min_order: Option<usize>,
    /// Highest model order beyond the imposed harmonics (default 30; 6 with lifting).
    #[arg(long)]
    pub max_order: Option<usize>,
    /// Number of random segments (default 10).
    #[arg(long)]
    pub segments: Option<usize>,
    /// Harmonics to impose (Hz, comma-separated) instead of the spindle lines found in the
    /// record; `none` for plain LSCE.
    #[arg(long, value_delimiter = ',')]
    pub harmonics_hz: Option<Vec<String>>,
    /// Decimation factor before LSCE (1: none; default automatic).
    #[arg(long)]
    pub decimation: Option<usize>,
    /// Fundamentals of interference combs for the chatter check (Hz, comma-separated), e.g.
    /// the mains 50 or 60; `none` for no interference; default: search a comb in 45-65 Hz.
    #[arg(long, value_delimiter = ',')]
    pub interference_hz: Vec<String>,
    /// Identify records that chatter detection calls chatter (flagged in the pole's `note`).
    #[arg(long)]
    pub allow_chatter: bool,
}

/// `chatter oma`.
pub fn run(args: &OmaArgs) -> Result<()> {
    let request = OmaRequest {
        min_order: args.min_order,
        max_order: args.max_order,
        segments: args.segments,
        harmonics: args
            .harmonics_hz
            .as_deref()
            .map(harmonics_override)
            .transpose()?,
        decimation: args.decimation,
        interference: crate::detect::interference(&args.interference_hz)?,
        allow_chatter: args.allow_chatter,
    };
    request.check().map_err(crate::job_error)?;
    crate::output::check_optional_file("--out", args.out.as_deref())?;
    crate::output::check_optional_file("--plot", args.plot.as_deref())?;
    let (observations, model) =
        crate::inputs::observations_with_model(&args.observations, args.model.as_deref())?;
    let (result, analyses) = identify_observations(
        &observations,
        model.as_ref(),
        &request,
        &chatter_progress::Silent,
    )
    .with_context(|| args.observations.display().to_string())?;
    if let Some(plot) = &args.plot {
        let count = observations.signals.len();
        for (i, (record, analysis)) in observations.signals.iter().zip(&analyses).enumerate() {
            let context = || {
                format!(
                    "{}: signals[{i}] ({})",
                    args.observations.display(),
                    record.file.display()
                )
            };
            let path = plot_path(plot, i, count);
            draw(&path, record, analysis).with_context(context)?;
            eprintln!("wrote {}", path.display());
            let orders = path.with_file_name(format!(
                "{}-orders.svg",
                path.file_stem()
                    .map_or_else(|| "oma".into(), |s| s.to_string_lossy())
            ));
            draw_orders(&orders, record, analysis).with_context(context)?;
            eprintln!("wrote {}", orders.display());
        }
    }
    emit(args.out.as_deref(), &result.to_json_string())
}

/// The `--harmonics-hz` override: `none` or frequencies.
fn harmonics_override(values: &[String]) -> Result<Harmonics> {
    if values.len() == 1 && values[0].eq_ignore_ascii_case("none") {
        return Ok(Harmonics::None);
    }
    values
        .iter()
        .map(|v| {
            v.trim().parse::<f64>().with_context(|| {
                format!("--harmonics-hz `{v}`: expected frequencies in Hz or `none`")
            })
        })
        .collect::<Result<Vec<f64>>>()
        .map(Harmonics::Known)
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
fn draw(path: &Path, record: &SignalRecord, a: &RecordAnalysis) -> Result<()> {
    let psd = a.psd_first_singular_value()?;
    let orders: Vec<usize> = a
        .identification
        .diagram
        .orders
        .iter()
        .map(|o| o.order)
        .collect();
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
    for o in &a.identification.diagram.orders {
        for d in &o.poles {
            let point = (frequency(&d.pole), o.order as f64);
            if d.is_stable() {
                stable.push(point);
            } else {
                other.push(point);
            }
        }
    }
    let e = &a.identification.estimate;
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

/// 000 Fig. 3b/c: the mean and standard deviation over the segments of the pole's frequency
/// and damping ratio at every model order of the diagram; the order used is in the title.
fn draw_orders(path: &Path, record: &SignalRecord, a: &RecordAnalysis) -> Result<()> {
    let lifted = a.lifting.is_some();
    let stats: Vec<(f64, chatter_oma::identify::PoleEstimate)> = a
        .identification
        .order_statistics
        .iter()
        .filter_map(|s| s.estimate.map(|e| (s.order as f64, e)))
        .collect();
    let frequency = |e: &chatter_oma::identify::PoleEstimate| {
        if lifted {
            e.principal_frequency_hz
        } else {
            e.frequency_hz
        }
    };
    let panels = [
        ErrorBarPanel {
            y_label: if lifted {
                "principal frequency (Hz)".into()
            } else {
                "frequency (Hz)".into()
            },
            points: stats
                .iter()
                .map(|(o, e)| (*o, frequency(e), e.frequency_std_hz.unwrap_or(0.0)))
                .collect(),
        },
        ErrorBarPanel {
            y_label: "damping ratio".into(),
            points: stats
                .iter()
                .map(|(o, e)| (*o, e.damping_ratio, e.damping_std.unwrap_or(0.0)))
                .collect(),
        },
    ];
    error_bar_panels(
        path,
        &format!(
            "{} rpm, {} mm: pole over {} segments by model order (order used: {})",
            record.speed_rpm,
            record.depth_mm,
            a.identification.segment_poles.len(),
            a.identification.order
        ),
        "model order",
        &panels,
    )
}
