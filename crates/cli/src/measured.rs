//! `chatter fit-frf`: modal fit of a measured FRF, model file, overlay plot.

use crate::output::write_atomic;
use crate::plot::{Series, line_chart};
use anyhow::{Context, Result, bail};
use chatter_dynamics::ModelFile;
use chatter_dynamics::model_file::{ModeFile, ResidualFile};
use chatter_frf::{FitOptions, ModalFit, fit_modes, read_frf, read_model_file};
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

/// The fitted modes as model-file entries along `direction`, complex or real; real modes with a
/// negative modal mass are left out.
fn mode_entries(fit: &ModalFit, complex: bool, direction: &str) -> Result<Vec<ModeFile>> {
    let mut entries = Vec::new();
    for m in &fit.modes {
        let mode = if complex {
            m.complex_mode(0)?
        } else {
            match m.real_mode(0) {
                Some(mode) => mode,
                None => continue,
            }
        };
        entries.push(ModeFile {
            frequency_hz: mode.frequency_hz(),
            damping_ratio: mode.damping_ratio(),
            // the mode moves coordinate 0 only: its stiffness there is the directional one
            stiffness_n_per_m: Some(mode.stiffness_at(0)),
            direction: Some(direction.to_string()),
            shape: None,
            residue_phase_deg: (!mode.is_proportional())
                .then(|| mode.residue_phase_rad().to_degrees()),
        });
    }
    Ok(entries)
}

/// `chatter fit-frf`: prints the fit report (complex modes, residual terms, misfits) as JSON.
pub fn fit_frf(args: &FitFrfArgs) -> Result<()> {
    let fmin = crate::validate::option("--fmin-hz", args.fmin_hz, &chatter_jobs::frf::FRF_HZ)?;
    let fmax = crate::validate::option("--fmax-hz", args.fmax_hz, &chatter_jobs::frf::FRF_HZ)?;
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
    let complex = match args.mode_form {
        ModeForm::Auto => fit.needs_complex_modes(),
        ModeForm::Real => false,
        ModeForm::Complex => true,
    };
    if args.with_residuals && !complex {
        bail!(
            "--with-residuals: the residual terms were fitted with the complex modes, and real \
             modes are written (--mode-form {}); use --mode-form complex",
            if args.mode_form == ModeForm::Real {
                "real"
            } else {
                "auto chose real"
            }
        );
    }
    let residual = args.with_residuals.then(|| ResidualFile {
        direction: args.direction.clone(),
        upper_m_per_n: fit.upper_residual_m_per_n,
        lower_per_kg: fit.lower_residual_per_kg,
    });
    let modes = mode_entries(&fit, complex, &args.direction)?;
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
            let direction = Some(args.direction.clone());
            // modes along this direction (directional, or a shape that moves it) are replaced
            file.modes.retain(|m| {
                m.direction != direction
                    && m.shape
                        .as_ref()
                        .is_none_or(|s| s.get(&args.direction).is_none_or(|v| *v == 0.0))
            });
            file.modes.extend(modes);
            // the residual terms of this direction belonged to the replaced modes
            let mut residuals: Vec<ResidualFile> = file
                .residuals
                .take()
                .unwrap_or_default()
                .into_iter()
                .filter(|r| r.direction != args.direction)
                .chain(residual)
                .collect();
            residuals.sort_by(|a, b| a.direction.cmp(&b.direction));
            file.residuals = (!residuals.is_empty()).then_some(residuals);
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
            let mut json = serde_json::json!({ "modes": modes });
            if let Some(r) = residual {
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
