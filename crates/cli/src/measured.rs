//! `chatter fit-frf`: modal fit of a measured FRF, model file, overlay plot.

use crate::output::write_atomic;
use crate::plot::{Series, line_chart};
use anyhow::{Context, Result};
use chatter_dynamics::ModelFile;
use chatter_frf::{read_frf, read_model_file};
use chatter_jobs::JobError;
use chatter_jobs::fit_frf::{self, FitFrfRequest};
use plotters::style::{BLUE, GREEN, RED};
use std::path::PathBuf;

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
    /// Model file whose operation and cutting coefficients the written model takes: its modes
    /// along --direction and its measured_frf are replaced, its modes along other directions
    /// kept (so x and y are fitted one after the other); without it --out holds the fitted
    /// modes only.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Coordinate of the measured direct FRF (x, y, feed, cutting).
    #[arg(long, default_value = "x")]
    direction: String,
    /// Which modes the model file keeps: `complex` (non-proportional, with residue_phase_deg),
    /// `real` (proportional refit), or `auto`: complex when the data need them (the complex
    /// modes fit at least 5 % better than the real ones).
    #[arg(long, value_enum, default_value = "auto")]
    mode_form: ModeForm,
    /// Also write the fit's residual terms for --direction (upper U m/N and lower L 1/kg, the
    /// modes outside the band) as the model's `residuals`; with complex modes only (they were
    /// fitted together). Only the zero-order method takes them; FDM and SDM refuse them.
    #[arg(long)]
    with_residuals: bool,
    /// Output model file (JSON).
    #[arg(long)]
    out: PathBuf,
    /// SVG overlay of measured and fitted |H| with the misfit.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// The modes `chatter fit-frf` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ModeForm {
    /// Complex when the data need them ([`chatter_frf::ModalFit::needs_complex_modes`]).
    Auto,
    /// Real (proportionally damped) modes.
    Real,
    /// Non-proportional (complex) modes.
    Complex,
}

/// `chatter fit-frf`: prints the fit report (complex modes, residual terms, misfits) as JSON.
pub fn fit_frf(args: &FitFrfArgs) -> Result<()> {
    let request = FitFrfRequest {
        fmin_hz: args.fmin_hz,
        fmax_hz: args.fmax_hz,
        modes: args.modes,
        direction: args.direction.clone(),
        mode_form: match args.mode_form {
            ModeForm::Auto => fit_frf::ModeForm::Auto,
            ModeForm::Real => fit_frf::ModeForm::Real,
            ModeForm::Complex => fit_frf::ModeForm::Complex,
        },
        with_residuals: args.with_residuals,
    };
    let job = request.check().map_err(crate::job_error)?;
    crate::output::check_file("--out", &args.out)?;
    crate::output::check_optional_file("--plot", args.plot.as_deref())?;
    let frf = read_frf(&args.frf, args.dataset).context("reading the FRF")?;
    let outcome = match job.run(&frf) {
        Ok(o) => o,
        Err(e @ (JobError::Invalid { .. } | JobError::Refused(_))) => {
            return Err(crate::job_error(e)).with_context(|| args.frf.display().to_string());
        }
        Err(e) => {
            return Err(crate::job_error(e))
                .with_context(|| format!("fitting {}", args.frf.display()));
        }
    };
    let (fit, complex) = (&outcome.fit, outcome.complex);
    let json = match &args.model {
        Some(base) => {
            let file: ModelFile = read_model_file(base).context("reading --model")?;
            let merged = outcome
                .merged_into(file, &args.direction)
                .map_err(crate::job_error)
                .with_context(|| format!("the fitted modes in the model of {}", base.display()))?;
            serde_json::to_string_pretty(&merged)?
        }
        None => {
            eprintln!(
                "note: no --model given, so {} holds the fitted modes only; add operation and \
                 cutting (or pass --model) to use it as a model file",
                args.out.display()
            );
            let mut json = serde_json::json!({ "modes": outcome.modes });
            if let Some(r) = &outcome.residual {
                json["residuals"] = serde_json::json!([r]);
            }
            serde_json::to_string_pretty(&json)?
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
        "nrmse_real_modes": fit.real_mode_relative_misfit,
        "nrmse_complex_modes": fit.complex_mode_relative_misfit,
        "modes_in_model": if complex { "complex" } else { "real" },
        "residuals_in_model": args.with_residuals,
        "modes_dropped_from_model": outcome.dropped,
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
                    "{} modes of the model (NRMSE {:.1} %)",
                    if complex { "complex" } else { "real" },
                    100.0
                        * if complex {
                            fit.complex_mode_relative_misfit
                        } else {
                            fit.real_mode_relative_misfit
                        }
                ),
                points: f
                    .iter()
                    .map(|&f| {
                        let g = if complex {
                            fit.complex_mode_receptance(f)
                        } else {
                            fit.real_mode_receptance(f)
                        };
                        (f, g.norm() * um)
                    })
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
