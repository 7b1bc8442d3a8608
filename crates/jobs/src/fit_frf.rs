//! The modal-fit job (`chatter fit-frf`): modes fitted to a measured FRF in a band (complex
//! modes with residual terms, `chatter_frf::fit_modes`), the form the model keeps (real or
//! complex), and the merge of the fitted modes into a model file along one direction: that
//! direction's modes and residual terms replaced, the others kept, so x and y are fitted one
//! after the other.

use crate::checks;
use crate::error::{JobError, Result};
use chatter_dynamics::ModelFile;
use chatter_dynamics::model_file::{ModeFile, ResidualFile};
use chatter_frf::{FitOptions, Frf, ModalFit, fit_modes};

/// Most modes of a fit.
pub const MAX_MODES: usize = 50;

/// Which modes the model keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeForm {
    /// Complex when the data need them ([`ModalFit::needs_complex_modes`]).
    Auto,
    /// Real (proportionally damped) modes.
    Real,
    /// Non-proportional (complex) modes.
    Complex,
}

/// What the fit was asked, in user units.
#[derive(Debug, Clone, PartialEq)]
pub struct FitFrfRequest {
    /// Lowest frequency fitted (Hz).
    pub fmin_hz: f64,
    /// Highest frequency fitted (Hz).
    pub fmax_hz: f64,
    /// Number of modes, 1 to [`MAX_MODES`]; default from the stabilization diagram.
    pub modes: Option<usize>,
    /// Coordinate of the measured direct FRF (x, y, feed, cutting).
    pub direction: String,
    /// The modes the model keeps.
    pub mode_form: ModeForm,
    /// Keep the fit's residual terms (complex modes only: they were fitted together).
    pub with_residuals: bool,
}

impl FitFrfRequest {
    /// A fit over `fmin_hz`..`fmax_hz` with the defaults: modes from the stabilization diagram,
    /// direction x, [`ModeForm::Auto`], no residual terms.
    pub fn new(fmin_hz: f64, fmax_hz: f64) -> Self {
        Self {
            fmin_hz,
            fmax_hz,
            modes: None,
            direction: "x".into(),
            mode_form: ModeForm::Auto,
            with_residuals: false,
        }
    }
}

/// What the fit gave.
#[derive(Debug, Clone)]
pub struct FitFrfOutcome {
    /// The fit (complex modes, residual terms, misfits).
    pub fit: ModalFit,
    /// Whether the model keeps complex modes.
    pub complex: bool,
    /// The kept modes as model-file entries along the request's direction.
    pub modes: Vec<ModeFile>,
    /// The residual terms, when kept.
    pub residual: Option<ResidualFile>,
    /// Fitted modes left out (real modes with a negative modal mass).
    pub dropped: usize,
}

impl FitFrfRequest {
    /// The checked request (linfa's `ParamGuard::check`): the band plausible and ordered, the
    /// number of modes within range; checked before any FRF is read.
    pub fn check(self) -> Result<FitFrf> {
        let fmin = checks::in_range("fmin_hz", self.fmin_hz, &crate::frf::FRF_HZ)?;
        let fmax = checks::in_range("fmax_hz", self.fmax_hz, &crate::frf::FRF_HZ)?;
        if fmax <= fmin {
            return Err(JobError::Invalid {
                field: "fmax_hz",
                value: chatter_dynamics::limits::written(fmax),
                expected: format!(
                    "above `fmin_hz` {}",
                    chatter_dynamics::limits::written(fmin)
                ),
            });
        }
        if let Some(n) = self.modes {
            crate::error::count("modes", n, 1, MAX_MODES, "modes")?;
        }
        Ok(FitFrf { request: self })
    }
}

/// A checked fit request.
#[derive(Debug, Clone, PartialEq)]
pub struct FitFrf {
    request: FitFrfRequest,
}

impl FitFrf {
    /// Fit `frf`; residual terms are refused with real modes.
    pub fn run(&self, frf: &Frf) -> Result<FitFrfOutcome> {
        fit_frf(frf, &self.request)
    }
}

/// Fit `frf` as the checked `request` asks.
fn fit_frf(frf: &Frf, request: &FitFrfRequest) -> Result<FitFrfOutcome> {
    let (fmin, fmax) = (request.fmin_hz, request.fmax_hz);
    let options = FitOptions {
        modes: request.modes,
        ..FitOptions::default()
    };
    let fit = fit_modes(frf, fmin, fmax, &options)?;
    let complex = match request.mode_form {
        ModeForm::Auto => fit.needs_complex_modes(),
        ModeForm::Real => false,
        ModeForm::Complex => true,
    };
    if request.with_residuals && !complex {
        return Err(JobError::Refused(format!(
            "`with_residuals`: the residual terms were fitted with the complex modes, and real \
             modes are written (`mode_form` {}); use `mode_form` complex",
            if request.mode_form == ModeForm::Real {
                "real"
            } else {
                "auto chose real"
            }
        )));
    }
    let residual = request.with_residuals.then(|| ResidualFile {
        direction: request.direction.clone(),
        upper_m_per_n: fit.upper_residual_m_per_n,
        lower_per_kg: fit.lower_residual_per_kg,
    });
    let modes = mode_entries(&fit, complex, &request.direction)?;
    if modes.is_empty() {
        return Err(JobError::Refused(
            "no fitted mode is a real mode with positive modal mass; nothing to write".into(),
        ));
    }
    let dropped = fit.modes.len() - modes.len();
    Ok(FitFrfOutcome {
        fit,
        complex,
        modes,
        residual,
        dropped,
    })
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

impl FitFrfOutcome {
    /// `base` with its modes along `direction` (directional, or a shape that moves it) and that
    /// direction's residual terms replaced by the fitted ones, the others kept, the measured
    /// FRFs dropped; validated as a model.
    pub fn merged_into(&self, mut file: ModelFile, direction: &str) -> Result<ModelFile> {
        let along = Some(direction.to_string());
        file.modes.retain(|m| {
            m.direction != along
                && m.shape
                    .as_ref()
                    .is_none_or(|s| s.get(direction).is_none_or(|v| *v == 0.0))
        });
        file.modes.extend(self.modes.iter().cloned());
        // the residual terms of this direction belonged to the replaced modes
        let mut residuals: Vec<ResidualFile> = file
            .residuals
            .take()
            .unwrap_or_default()
            .into_iter()
            .filter(|r| r.direction != direction)
            .chain(self.residual.clone())
            .collect();
        residuals.sort_by(|a, b| a.direction.cmp(&b.direction));
        file.residuals = (!residuals.is_empty()).then_some(residuals);
        file.measured_frf = None;
        file.validate()?;
        Ok(file)
    }
}
