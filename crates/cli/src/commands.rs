//! The simple subcommands (`check`, `frf`, `lobes`, `multiplier`, `simulate`): the options as a
//! `chatter_jobs` request, the outcome as CSV, JSON or SVG.

use crate::output::{self, emit, write_atomic};
use crate::plot::{Panel, Series, line_chart, stacked_line_charts_svg};
use crate::progress::{Bar, Working};
use crate::{inputs, tables, validate};
use anyhow::{Context, Result, bail};
use chatter_jobs::frf::FrfRequest;
use chatter_jobs::lobes::{Dynamics, Lobes, LobesRequest};
use chatter_jobs::multiplier::{Multiplier, MultiplierRequest};
use chatter_stability::prepared::Method;
use plotters::style::BLUE;
use std::fmt::Write as _;
use std::path::Path;

/// `chatter check`.
pub fn check(model: &Path, observations: Option<&Path>) -> Result<()> {
    let m = inputs::model(model)?;
    let mut line = format!(
        "{}: {} model with {} modes",
        model.display(),
        match m.operation() {
            chatter_dynamics::Operation::Milling(_) => "milling",
            chatter_dynamics::Operation::Turning(_) => "turning",
        },
        m.mode_count()
    );
    if let Some(o) = observations {
        let obs = inputs::observations(o)?;
        validate::observations_match(&m, &obs, o, model)?;
        let _ = write!(
            line,
            "; {}: {} cuts, {} poles, {} signals",
            o.display(),
            obs.cuts.len(),
            obs.poles.len(),
            obs.signals.len()
        );
    }
    println!("{line}");
    Ok(())
}

/// `chatter frf`.
pub fn frf(
    model_path: &Path,
    request: &FrfRequest,
    out: Option<&Path>,
    plot: Option<&Path>,
) -> Result<()> {
    let model = inputs::model(model_path)?;
    let g = chatter_jobs::frf::frf(&model, request).map_err(crate::job_error)?;
    emit(out, &tables::frf_csv(&g))?;
    if let Some(p) = plot {
        let series = [Series {
            label: format!("|G_{}{}|", g.response, g.force),
            points: g
                .frequencies_hz
                .iter()
                .zip(&g.receptance_m_per_n)
                .map(|(f, r)| (*f, r.norm() * 1e6))
                .collect(),
            color: BLUE,
            dashed: false,
        }];
        line_chart(
            p,
            "Receptance",
            "frequency (Hz)",
            "|G| (um/N)",
            &series,
            None,
        )?;
    }
    Ok(())
}

/// Options of `chatter lobes` beyond the lobe CSV and plot ([`crate::lobe_map`]).
pub struct LobeExtras<'a> {
    /// Fixed fdm/sdm cutting steps per delay.
    pub cutting_steps: Option<std::num::NonZeroUsize>,
    /// |mu| map CSV.
    pub map_out: Option<&'a Path>,
    /// |mu| heat map SVG.
    pub map_plot: Option<&'a Path>,
    /// Map depths MIN:MAX:N (mm).
    pub depths: Option<&'a str>,
    /// The SLE panel under the lobe plot (`--sle`), at this depth (`--sle-depth-mm`; default
    /// [`sle_panel_depth_mm`]).
    pub sle: Option<Option<f64>>,
}

/// Default depth (mm) of the SLE panel of `lobes --plot --sle`: half the shallowest finite
/// limiting depth over the plotted speeds, so that the cut is stable at every speed by the
/// lobes (the SLE of a chattering cut is not what the cut leaves) with a factor 2 of margin.
pub fn sle_panel_depth_mm(lobes: &[chatter_stability::boundary::LobePoint]) -> Option<f64> {
    lobes
        .iter()
        .map(|p| p.depth_mm())
        .filter(|d| d.is_finite())
        .min_by(f64::total_cmp)
        .map(|d| 0.5 * d)
}

/// `chatter lobes`: the options as a `chatter_jobs::lobes::LobesRequest`, the lobes as CSV and
/// plot, the |mu| map as CSV and heat map.
#[allow(clippy::too_many_arguments)]
pub fn lobes(
    model_path: &Path,
    method: Method,
    speeds: Option<&str>,
    observations: Option<&Path>,
    out: Option<&Path>,
    plot: Option<&Path>,
    extras: &LobeExtras,
    quiet: bool,
) -> Result<()> {
    check_outputs(out, plot, observations)?;
    output::check_optional_file("--map-out", extras.map_out)?;
    output::check_optional_file("--map-plot", extras.map_plot)?;
    let map = extras.map_out.is_some() || extras.map_plot.is_some();
    validate::unused(
        !map && extras.depths.is_some(),
        "--depths",
        "without --map-out or --map-plot",
        "the |mu| map",
    )?;
    validate::unused(
        extras.sle.is_some() && plot.is_none(),
        "--sle",
        "without --plot",
        "the SLE panel under the lobe plot",
    )?;
    let obs = observations.map(inputs::observations).transpose()?;
    let request = LobesRequest {
        method,
        speeds_rpm: speeds.map(validate::speeds).transpose()?,
        cutting_steps: extras.cutting_steps,
        map,
        map_depths_mm: extras
            .depths
            .map(|s| validate::grid("--depths", s, &chatter_jobs::checks::DEPTH_GRID_MM))
            .transpose()?,
    };
    let dynamics = inputs::dynamics(model_path, method)?;
    let job = Lobes::new(&dynamics, request).map_err(crate::job_error)?;
    let speeds = job.speeds_rpm().len();
    let measured = matches!(dynamics, Dynamics::Measured(_));
    // zero-order lobes are instant: no bar
    let bar = Bar::new(
        speeds as u64,
        "lobes",
        quiet || measured || (method == Method::Zoa && !map),
    );
    bar.announce(&format!("{speeds} speeds, {}", method.name()));
    let lobes = job.lobes(&bar).map_err(crate::job_error)?;
    bar.finish();
    let bar = Bar::new(speeds as u64, "|mu| map", quiet || !map);
    let map = job.map(&lobes, &bar).map_err(crate::job_error)?;
    bar.finish();
    tables::warn_unbounded(&lobes, "their depth_mm and chatter_hz cells are empty");
    if let Some(m) = &map {
        if let Some(p) = extras.map_out {
            write_atomic(p, tables::map_csv(m).as_bytes())?;
        }
        if let Some(p) = extras.map_plot {
            let title = format!(
                "Dominant multiplier |mu| ({}): blue stable, red chatter, black the limit",
                method.name()
            );
            write_atomic(
                p,
                crate::lobe_map::heat_map_svg(&title, m, &lobes)?.as_bytes(),
            )?;
        }
    }
    emit(out, &tables::lobes_csv(&lobes))?;
    if let Some(p) = plot {
        let series = [Series {
            label: format!("{method:?} limiting depth").to_lowercase(),
            points: chatter_jobs::bands::finite_curve(&lobes),
            color: BLUE,
            dashed: false,
        }];
        let title = format!(
            "Stability lobes ({}): limiting depth against spindle speed",
            method.name()
        );
        let markers = tables::markers(obs.as_ref());
        let lobe_panel = Panel {
            title: &title,
            x_label: "spindle speed (rpm)",
            y_label: "depth (mm)",
            series: &series,
            markers: markers.as_ref(),
        };
        let svg = match (extras.sle, &dynamics) {
            (None, _) => stacked_line_charts_svg(&[lobe_panel])?,
            (Some(depth_mm), Dynamics::Modal(model)) => {
                let depth_mm = match depth_mm {
                    Some(d) => d,
                    None => sle_panel_depth_mm(&lobes).ok_or_else(|| {
                        anyhow::anyhow!(
                            "--sle: no speed has a finite limiting depth to take half of; give \
                             --sle-depth-mm"
                        )
                    })?,
                };
                let sle = crate::shop::sle_outcome(
                    model,
                    job.speeds_rpm().to_vec(),
                    depth_mm,
                    chatter_jobs::sle::FEED_PER_TOOTH_MM,
                )?;
                let sle_title = crate::shop::sle_title(&sle);
                let sle_series = [crate::shop::sle_series(&sle)];
                stacked_line_charts_svg(&[
                    lobe_panel,
                    Panel {
                        title: &sle_title,
                        x_label: "spindle speed (rpm)",
                        y_label: "SLE (um)",
                        series: &sle_series,
                        markers: None,
                    },
                ])?
            }
            (Some(_), Dynamics::Measured(_)) => bail!(
                "--sle: the surface location error needs a modal model; the model has measured \
                 FRFs only"
            ),
        };
        write_atomic(p, svg.as_bytes())?;
    }
    Ok(())
}

/// `--out` and `--plot` writable, and `--observations` only with `--plot` (they are drawn, not
/// used in the numbers).
pub fn check_outputs(
    out: Option<&Path>,
    plot: Option<&Path>,
    observations: Option<&Path>,
) -> Result<()> {
    output::check_optional_file("--out", out)?;
    output::check_optional_file("--plot", plot)?;
    validate::unused(
        observations.is_some() && plot.is_none(),
        "--observations",
        "without --plot",
        "drawing the observed cuts on the plot",
    )
}

/// `chatter multiplier`: the options as a `chatter_jobs::multiplier::MultiplierRequest`, the
/// outcome as JSON on stdout.
pub fn multiplier(
    model_path: &Path,
    speed_rpm: f64,
    depth_mm: f64,
    method: Method,
    variation: Option<chatter_stability::ssv::SpeedVariation>,
    quiet: bool,
) -> Result<()> {
    let model = inputs::model(model_path)?;
    let request = MultiplierRequest {
        speed_rpm,
        depth_mm,
        method,
        variation,
    };
    let job = Multiplier::new(&model, request).map_err(crate::job_error)?;
    let working = variation.is_none().then(|| {
        Working::start(
            &format!(
                "multiplier: {} at {speed_rpm} rpm, {} steps per delay",
                job.method_name(),
                job.steps_per_delay()
            ),
            quiet,
        )
    });
    let out = job.run().map_err(crate::job_error)?;
    if let Some(w) = working {
        w.finish();
    }
    let mu = &out.multiplier;
    let json = match (variation, out.chatter_hz) {
        (Some(variation), _) => serde_json::json!({
            "speed_rpm": speed_rpm,
            "depth_mm": depth_mm,
            "method": out.method,
            "ssv_amplitude_ratio": variation.amplitude_ratio(),
            "ssv_frequency_ratio": variation.frequency_ratio(),
            "period_s": mu.period_s,
            "modulus": mu.modulus(),
            "real": mu.value.re,
            "imag": mu.value.im,
            "stable": out.stable,
        }),
        (None, chatter_hz) => serde_json::json!({
            "speed_rpm": speed_rpm,
            "depth_mm": depth_mm,
            "method": out.method,
            "modulus": mu.modulus(),
            "real": mu.value.re,
            "imag": mu.value.im,
            "frequency_hz": mu.principal_frequency_hz(),
            "chatter_hz": chatter_hz,
            "kind": mu.kind(),
            "stable": out.stable,
        }),
    };
    println!("{}", serde_json::to_string_pretty(&json)?);
    Ok(())
}

/// `chatter simulate`: a simulated cut as signals CSV (header = channel names, first channel the
/// reference) or 32-bit float WAV (channels in the same order: coordinates, then once_per_rev).
pub fn simulate(
    model_path: &Path,
    settings: &chatter_dynamics::simulate::SimulationSettings,
    out: &Path,
    quiet: bool,
) -> Result<()> {
    let model = inputs::model(model_path)?;
    let bar = Bar::new(1000, "simulate", quiet);
    bar.announce(&format!(
        "{} s of cutting at {} rpm, {} samples",
        settings.duration_s,
        settings.speed_rpm,
        (settings.duration_s * settings.sample_rate_hz).round()
    ));
    let sim = chatter_jobs::simulate::simulate(&model, settings, &bar).map_err(crate::job_error)?;
    bar.finish();
    let is_wav = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("wav"));
    if is_wav {
        let spec = hound::WavSpec {
            channels: sim.channels.len() as u16,
            sample_rate: sim.sample_rate_hz.round() as u32,
            bits_per_sample: 32,
            sample_format: hound::SampleFormat::Float,
        };
        if (spec.sample_rate as f64 - sim.sample_rate_hz).abs() > 1e-9 {
            bail!(
                "--sample-rate-hz {} is not an integer; WAV needs an integer rate",
                sim.sample_rate_hz
            );
        }
        let mut buffer = std::io::Cursor::new(Vec::new());
        {
            let mut writer =
                hound::WavWriter::new(&mut buffer, spec).context("starting the WAV stream")?;
            let n = sim.channels[0].data.len();
            for k in 0..n {
                for c in &sim.channels {
                    writer
                        .write_sample(c.data[k] as f32)
                        .context("writing WAV samples")?;
                }
            }
            writer.finalize().context("finishing the WAV stream")?;
        }
        write_atomic(out, buffer.get_ref())?;
    } else {
        let mut csv = sim
            .channels
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(",");
        csv.push('\n');
        let n = sim.channels[0].data.len();
        for k in 0..n {
            let row: Vec<String> = sim
                .channels
                .iter()
                .map(|c| format!("{:e}", c.data[k]))
                .collect();
            csv.push_str(&row.join(","));
            csv.push('\n');
        }
        write_atomic(out, csv.as_bytes())?;
    }
    eprintln!(
        "wrote {} ({} samples, lost contact {:.1} %)",
        out.display(),
        sim.channels[0].data.len(),
        100.0 * sim.lost_contact_fraction
    );
    Ok(())
}
