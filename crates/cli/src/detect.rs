//! `chatter detect`: stable or chatter, and the chatter frequency, for every signal record of an
//! observations file (`chatter_oma::detection`, called through `chatter_jobs::detect`, which
//! `chatter diagnose` shares for recordings).
//!
//! Each record is read (CSV at the entry's `sample_rate_hz`, WAV or MP3 at its own rate); its
//! `once_per_rev_channel`, if any, gives the spindle frequency and is left out of the spectrum,
//! otherwise the spindle frequency is `speed_rpm / 60` refined within 0.5 %. Every multiple of
//! the spindle frequency (spindle and tooth-passing harmonics alike) is forced response; the
//! strongest other line is chatter when its share of the power is constant (a limit cycle) or
//! grows and bursts far beyond a random resonance (see the `chatter_oma::detection` docs). The
//! output is an observations JSON with the input's `cuts`, then one `cuts` entry per record
//! (`speed_rpm`, `depth_mm`, `stable`, `chatter_hz` when it chattered, `sequence` and
//! `radial_immersion` copied, `note` naming the file) whose `evidence` holds the numbers behind
//! the verdict (`chatter_dynamics::CutEvidence`: line frequency, V, margin, level ratios,
//! spindle frequency, bin width). `--plot DIR` writes `DIR/detect-N.svg`, the
//! spectrum of record N with the harmonics and the line marked.
//!
//! Unknown speed (`--estimate-speed`, e.g. a sound clip whose cutting conditions were not
//! recorded): the records' `speed_rpm` is ignored and the spindle frequency is the fundamental
//! of the record's harmonic comb in 10-500 Hz (600-30 000 rpm; `chatter_oma::interference::
//! harmonic_fundamental`); the cut's `speed_rpm` is the estimate, and its note says so.
//!
//! With `--model` of a milling machine, its tooth count is used: with an even count, lines at
//! the odd multiples of half the tooth-passing frequency are judged for period-doubling (flip)
//! chatter (`chatter_oma::detection`, "Flip chatter"). Records long enough for two windows are
//! also judged window by window (chatter in part of a record; "Windows"), leaving out a
//! reference stretch without the cut when the record holds one ("Reference stretch"); the note
//! gives the chattering span or the windows' margin.
//!
//! Interference (mains hum): by default a comb of lines at the multiples of a 45-65 Hz
//! fundamental is searched for (`chatter_oma::interference`) and its lines are left out; the
//! `note` reports the comb found. `--interference-hz 50` (or a list) gives the fundamentals
//! instead (every multiple left out), `--interference-hz none` turns it off.

use crate::output::emit;
use anyhow::{Context, Result, bail};
use chatter_dynamics::{ModalModel, Observations, Operation, SignalRecord};
use chatter_jobs::detect::{DetectRequest, detect_record};
use chatter_oma::detection::Detection;
use chatter_oma::interference::Interference;
use plotters::prelude::*;
use std::path::PathBuf;

/// Arguments of `chatter detect`.
#[derive(Debug, clap::Args)]
pub struct DetectArgs {
    /// Observations file listing the `signals` (CSV, WAV or MP3).
    #[arg(long)]
    pub observations: PathBuf,
    /// Machine model: a milling model's tooth count is used to judge flip (period-doubling)
    /// chatter with an even count, and is reported in the plot title.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Folder for one SVG spectrum per record (detect-1.svg, detect-2.svg, ...).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Fundamentals of interference combs to leave out (Hz, comma-separated), e.g. the mains
    /// 50 or 60; `none` for no interference; default: search a comb in 45-65 Hz.
    #[arg(long, value_delimiter = ',')]
    pub interference_hz: Vec<String>,
    /// The spindle speed is unknown: estimate it from each record's harmonic comb (600 to
    /// 30 000 rpm) instead of reading `speed_rpm`.
    #[arg(long)]
    pub estimate_speed: bool,
    /// Write the JSON here instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// `chatter detect`.
pub fn run(args: &DetectArgs) -> Result<()> {
    crate::output::check_optional_file("--out", args.out.as_deref())?;
    let (observations, model) =
        crate::inputs::observations_with_model(&args.observations, args.model.as_deref())?;
    if observations.signals.is_empty() {
        bail!(
            "{}: no `signals` to examine; expected at least one entry with a `file`",
            args.observations.display()
        );
    }
    let plot_names: Vec<String> = (1..=observations.signals.len())
        .map(|i| format!("detect-{i}.svg"))
        .collect();
    let mut plots = args
        .plot
        .as_deref()
        .map(|dir| {
            let known: Vec<&str> = plot_names.iter().map(String::as_str).collect();
            crate::output::Folder::new("--plot", dir, &known)
        })
        .transpose()?;
    let request = DetectRequest {
        interference: interference(&args.interference_hz)?,
        estimate_speed: args.estimate_speed,
    };
    let mut cuts = observations.cuts.clone();
    for (i, record) in observations.signals.iter().enumerate() {
        let context = || {
            format!(
                "{}: signals[{i}] ({})",
                args.observations.display(),
                record.file.display()
            )
        };
        let judged = detect_record(
            i,
            record,
            model.as_ref(),
            &request,
            &chatter_progress::Silent,
        )
        .with_context(context)?;
        if let Some(folder) = &mut plots {
            let svg = draw(record, model.as_ref(), &judged.detection).with_context(context)?;
            folder.add(format!("detect-{}.svg", i + 1), svg);
        }
        cuts.push(judged.cut);
    }
    if let Some(folder) = plots {
        for path in folder.commit()? {
            eprintln!("wrote {}", path.display());
        }
    }
    let result = Observations {
        cuts,
        poles: observations.poles,
        signals: Vec::new(),
    };
    emit(args.out.as_deref(), &result.to_json_string())
}

/// The `--interference-hz` values: none given, a search over the mains range; `none`, no
/// interference; else the fundamentals (Hz).
pub(crate) fn interference(values: &[String]) -> Result<Interference> {
    if values.is_empty() {
        return Ok(Interference::default());
    }
    if values.len() == 1 && values[0].trim().eq_ignore_ascii_case("none") {
        return Ok(Interference::Off);
    }
    values
        .iter()
        .map(|v| match v.trim().parse::<f64>() {
            Ok(f) if f.is_finite() && f > 0.0 => Ok(f),
            _ => bail!("--interference-hz `{v}`: expected fundamentals > 0 in Hz, or `none`"),
        })
        .collect::<Result<Vec<f64>>>()
        .map(Interference::Known)
}

/// The spectrum (log scale) over the band, the harmonics as grey ticks, the line as a red
/// marker.
fn draw(record: &SignalRecord, model: Option<&ModalModel>, d: &Detection) -> Result<String> {
    let (lo, hi) = d.band_hz;
    let points: Vec<(f64, f64)> = d
        .spectrum
        .frequencies_hz
        .iter()
        .zip(&d.spectrum.values)
        .filter(|(f, v)| **f >= lo && **f <= hi && **v > 0.0)
        .map(|(f, v)| (*f, v.log10()))
        .collect();
    let (ymin, ymax) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.1), b.max(p.1))
        });
    if !(ymin.is_finite() && ymax > ymin) {
        bail!("nothing to plot in {lo:.1}-{hi:.1} Hz");
    }
    let teeth = match model.map(ModalModel::operation) {
        Some(Operation::Milling(m)) => format!(", {} teeth", m.teeth()),
        _ => String::new(),
    };
    let verdict = match d.chatter_hz {
        Some(f) => format!("chatter at {f:.1} Hz"),
        None => "stable".into(),
    };
    let title = format!(
        "{} rpm, {} mm{teeth}: {verdict} (V {:.2})",
        record.speed_rpm, record.depth_mm, d.evidence.line_variation
    );
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<std::io::Error>| anyhow::anyhow!("{e}");
        root.fill(&WHITE).map_err(e)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(lo..hi, ymin..ymax + 0.5)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("frequency (Hz)")
            .y_desc("log10 normalized PSD (1/Hz)")
            .draw()
            .map_err(e)?;
        chart
            .draw_series(d.harmonics_hz.iter().map(|f| {
                PathElement::new(vec![(*f, ymin), (*f, ymax + 0.5)], RGBColor(200, 200, 200))
            }))
            .map_err(e)?
            .label("spindle harmonics")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RGBColor(200, 200, 200)));
        chart
            .draw_series(LineSeries::new(points, BLUE.stroke_width(1)))
            .map_err(e)?
            .label("spectrum")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
        let peak = d.evidence.peak_hz;
        let color = if d.chatter_hz.is_some() { RED } else { BLACK };
        chart
            .draw_series(std::iter::once(Cross::new(
                (peak, ymax + 0.2),
                6,
                color.stroke_width(2),
            )))
            .map_err(e)?
            .label(format!("strongest non-synchronous line, {peak:.1} Hz"))
            .legend(move |(x, y)| Cross::new((x + 10, y), 6, color.stroke_width(2)));
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(e)?;
        root.present().map_err(e)?;
    }
    Ok(svg)
}
