//! Measured FRFs in the CLI: `chatter lobes --method zoa` on a model whose `measured_frf` gives
//! its dynamics, and `chatter fit-frf` (modal fit, model file, overlay plot).

use crate::commands::Method;
use crate::output::write_atomic;
use crate::plot::{Series, line_chart};
use anyhow::{Context, Result, bail};
use chatter_dynamics::ModelFile;
use chatter_dynamics::model_file::ModeFile;
use chatter_frf::{FitOptions, MeasuredModel, fit_modes, read_frf, read_model_file};
use chatter_stability::boundary::LobePoint;
use chatter_stability::zero_order::{ZeroOrderOptions, measured_limiting_depths};
use plotters::style::{BLUE, GREEN, RED};
use std::path::{Path, PathBuf};

/// Zero-order lobes from the model's measured FRFs when it has them: None for a modal model;
/// an error for other methods on a model without modes.
pub fn lobes(
    model_path: &Path,
    method: Method,
    speeds: Option<&str>,
) -> Result<Option<Vec<LobePoint>>> {
    let file = read_model_file(model_path).context("reading the model file")?;
    if file.measured_frf.is_none() {
        return Ok(None);
    }
    if method != Method::Zoa {
        if file.modes.is_empty() {
            bail!(
                "{}: --method {} needs modal parameters, and this model gives its dynamics as \
                 measured_frf only; use --method zoa (zero-order lobes straight from the FRF), or \
                 fit modes with `chatter fit-frf` and add them as `modes`",
                model_path.display(),
                format!("{method:?}").to_lowercase()
            );
        }
        // a model with both: the modes serve the time-domain methods
        return Ok(None);
    }
    let model = MeasuredModel::from_path(model_path).context("reading the measured FRFs")?;
    let speeds = match speeds {
        Some(s) => crate::validate::speeds(s)?,
        None => {
            let f = model.receptance.peak_frequency_hz();
            let n = model.operation.delays_per_revolution() as f64;
            let max = (60.0 * f / n * 1.2).min(60_000.0);
            (0..200)
                .map(|i| max / 10.0 + (max - max / 10.0) * i as f64 / 199.0)
                .collect()
        }
    };
    Ok(Some(measured_limiting_depths(
        &model.operation,
        model.cutting,
        &model.receptance,
        &speeds,
        // the depth ceiling of every `lobes` method (see `commands::warn_unbounded`)
        &ZeroOrderOptions::default(),
    )?))
}

/// Arguments of `chatter fit-frf`.
#[derive(Debug, clap::Args)]
pub struct FitFrfArgs {
    /// Measured FRF: .csv, .uff/.unv (dataset 58), .frf (CutPro) or .txt columns.
    #[arg(long)]
    frf: PathBuf,
    /// Dataset 58 record of a universal file (0-based).
    #[arg(long)]
    dataset: Option<usize>,
    /// Lowest frequency fitted (Hz).
    #[arg(long)]
    fmin_hz: f64,
    /// Highest frequency fitted (Hz).
    #[arg(long)]
    fmax_hz: f64,
    /// Number of modes; default chosen from the stabilization diagram.
    #[arg(long)]
    modes: Option<usize>,
    /// Model file whose operation and cutting coefficients the written model takes (its modes
    /// and measured_frf are replaced); without it --out holds the fitted modes only.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Coordinate of the measured direct FRF (x, y, feed, cutting).
    #[arg(long, default_value = "x")]
    direction: String,
    /// Output model file (JSON).
    #[arg(long)]
    out: PathBuf,
    /// SVG overlay of measured and fitted |H| with the misfit.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// `chatter fit-frf`: prints the fit report (complex modes, residual terms, misfits) as JSON.
pub fn fit_frf(args: &FitFrfArgs) -> Result<()> {
    let fmin = crate::validate::option("--fmin-hz", args.fmin_hz, &crate::validate::FRF_HZ)?;
    let fmax = crate::validate::option("--fmax-hz", args.fmax_hz, &crate::validate::FRF_HZ)?;
    if fmax <= fmin {
        bail!(
            "--fmax-hz {}: expected above --fmin-hz {}",
            crate::validate::as_typed("--fmax-hz", fmax),
            crate::validate::as_typed("--fmin-hz", fmin)
        );
    }
    if let Some(n) = args.modes {
        crate::validate::count("--modes", n, 1, 50, "modes")?;
    }
    crate::output::check_file("--out", &args.out)?;
    crate::output::check_optional_file("--plot", args.plot.as_deref())?;
    let frf = read_frf(&args.frf, args.dataset).context("reading the FRF")?;
    let options = FitOptions {
        modes: args.modes,
        ..FitOptions::default()
    };
    let fit = fit_modes(&frf, args.fmin_hz, args.fmax_hz, &options)
        .with_context(|| format!("fitting {}", args.frf.display()))?;
    let modes: Vec<ModeFile> = fit
        .modes
        .iter()
        .filter_map(|m| {
            Some(ModeFile {
                frequency_hz: m.frequency_hz,
                damping_ratio: m.damping_ratio,
                stiffness_n_per_m: Some(m.stiffness_n_per_m?),
                direction: Some(args.direction.clone()),
                shape: None,
            })
        })
        .collect();
    if modes.is_empty() {
        bail!(
            "{}: no fitted mode is a real mode with positive modal mass; nothing to write",
            args.frf.display()
        );
    }
    let dropped = fit.modes.len() - modes.len();
    let json = match &args.model {
        Some(base) => {
            let mut file: ModelFile = read_model_file(base).context("reading --model")?;
            file.modes = modes;
            file.measured_frf = None;
            // validate the result before writing it
            file.validate()
                .with_context(|| format!("the fitted modes in the model of {}", base.display()))?;
            serde_json::to_string_pretty(&file)?
        }
        None => {
            eprintln!(
                "note: no --model given, so {} holds the fitted modes only; add operation and \
                 cutting (or pass --model) to use it as a model file",
                args.out.display()
            );
            serde_json::to_string_pretty(&serde_json::json!({ "modes": modes }))?
        }
    };
    write_atomic(&args.out, json.as_bytes())?;
    let report = serde_json::json!({
        "frf": args.frf,
        "band_hz": [args.fmin_hz, args.fmax_hz],
        "modes": fit.modes,
        "upper_residual_m_per_n": fit.upper_residual_m_per_n,
        "lower_residual_per_kg": fit.lower_residual_per_kg,
        "nrmse_complex_modes_with_residuals": fit.relative_misfit,
        "nrmse_real_modes_in_model": fit.real_mode_relative_misfit,
        "modes_dropped_from_model": dropped,
    });
    println!("{}", serde_json::to_string_pretty(&report)?);
    if let Some(p) = &args.plot {
        let band = frf.band(args.fmin_hz, args.fmax_hz)?;
        let f = band.frequencies_hz();
        let um = 1e6;
        let series = [
            Series {
                label: "measured |H|".into(),
                points: f
                    .iter()
                    .zip(band.receptance_m_per_n())
                    .map(|(f, g)| (*f, g.norm() * um))
                    .collect(),
                color: BLUE,
                dashed: false,
            },
            Series {
                label: format!(
                    "complex modes + residuals (NRMSE {:.1} %)",
                    100.0 * fit.relative_misfit
                ),
                points: f
                    .iter()
                    .map(|&f| (f, fit.receptance(f).norm() * um))
                    .collect(),
                color: RED,
                dashed: false,
            },
            Series {
                label: format!(
                    "real modes of the model (NRMSE {:.1} %)",
                    100.0 * fit.real_mode_relative_misfit
                ),
                points: f
                    .iter()
                    .map(|&f| (f, fit.real_mode_receptance(f).norm() * um))
                    .collect(),
                color: GREEN,
                dashed: true,
            },
        ];
        line_chart(
            p,
            &format!("Modal fit of {}", args.frf.display()),
            "frequency (Hz)",
            "|H| (um/N)",
            &series,
            None,
        )?;
    }
    Ok(())
}
