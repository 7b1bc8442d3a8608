//! The FRF job (`chatter frf`): the receptance G_ij(f) of a modal model between a response and a
//! force coordinate on an evenly spaced frequency grid (the modal sum of
//! `chatter_dynamics::ModalModel::receptance`).

use crate::checks;
use crate::error::{JobError, Result};
use chatter_dynamics::ModalModel;
use chatter_dynamics::grid::evenly_spaced;
use chatter_dynamics::limits::{Plausible, closed, written};
use num_complex::Complex64;

/// Frequencies of the FRF job (zero allowed).
pub const FRF_HZ: Plausible = closed(0.0, 1e6, "a frequency", "Hz");
/// Most frequencies of the FRF job.
pub const MAX_POINTS: usize = 1_000_000;
/// Default number of frequencies.
pub const DEFAULT_POINTS: usize = 1000;

/// What the FRF job was asked, in user units.
#[derive(Debug, Clone, PartialEq)]
pub struct FrfRequest {
    /// Lowest frequency (Hz); default 0 (needs `fmax_hz`).
    pub fmin_hz: Option<f64>,
    /// Highest frequency (Hz); default twice the highest natural frequency.
    pub fmax_hz: Option<f64>,
    /// Number of frequencies, 2 to [`MAX_POINTS`]; default [`DEFAULT_POINTS`].
    pub points: usize,
    /// Response coordinate by name (default the operation's first).
    pub response: Option<String>,
    /// Force coordinate by name (default the operation's first).
    pub force: Option<String>,
}

impl Default for FrfRequest {
    fn default() -> Self {
        Self {
            fmin_hz: None,
            fmax_hz: None,
            points: DEFAULT_POINTS,
            response: None,
            force: None,
        }
    }
}

/// The receptance on the grid.
#[derive(Debug, Clone, PartialEq)]
pub struct FrfOutcome {
    /// Response coordinate name.
    pub response: String,
    /// Force coordinate name.
    pub force: String,
    /// Frequencies (Hz).
    pub frequencies_hz: Vec<f64>,
    /// G_ij at each frequency (m/N).
    pub receptance_m_per_n: Vec<Complex64>,
}

/// The receptance of `model` as `request` asks, after checking the range, the number of points
/// and the coordinate names.
pub fn frf(model: &ModalModel, request: &FrfRequest) -> Result<FrfOutcome> {
    let range = match (request.fmin_hz, request.fmax_hz) {
        (None, None) => None,
        (a, Some(b)) => Some((
            checks::in_range("fmin_hz", a.unwrap_or(0.0), &FRF_HZ)?,
            checks::in_range("fmax_hz", b, &FRF_HZ)?,
        )),
        (Some(a), None) => {
            return Err(JobError::Refused(format!(
                "`fmin_hz` {} needs `fmax_hz`",
                written(a)
            )));
        }
    };
    crate::error::count("points", request.points, 2, MAX_POINTS, "frequencies")?;
    let op = model.operation();
    let index = |name: &Option<String>| -> Result<usize> {
        match name {
            None => Ok(0),
            Some(n) => op.coordinate_index(n).ok_or_else(|| {
                let names: Vec<_> = op.coordinates().iter().map(|c| c.name()).collect();
                JobError::NotOneOf {
                    what: "coordinate",
                    value: n.clone(),
                    known: names.iter().map(|s| s.to_string()).collect(),
                }
            }),
        }
    };
    let (i, j) = (index(&request.response)?, index(&request.force)?);
    let f_max = model
        .modes()
        .iter()
        .map(|m| m.frequency_hz())
        .fold(0.0, f64::max);
    let (f0, f1) = range.unwrap_or((0.0, 2.0 * f_max));
    if f1 <= f0 {
        return Err(JobError::Invalid {
            field: "fmax_hz",
            value: written(f1),
            expected: format!("above `fmin_hz` {}", written(f0)),
        });
    }
    let frequencies_hz = evenly_spaced(f0, f1, request.points);
    let receptance_m_per_n = frequencies_hz
        .iter()
        .map(|&f| model.receptance(f, i, j))
        .collect();
    let names = op.coordinates();
    Ok(FrfOutcome {
        response: names[i].name().to_string(),
        force: names[j].name().to_string(),
        frequencies_hz,
        receptance_m_per_n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    /// At the grid's frequencies the job's receptance is the model's modal sum, and the default
    /// range ends at twice the highest natural frequency; bad coordinates and ranges are named.
    #[test]
    fn default_range_and_checks() {
        let model = examples::schmitz_2023_milling();
        let out = frf(&model, &FrfRequest::default()).unwrap();
        let top = model
            .modes()
            .iter()
            .map(|m| m.frequency_hz())
            .fold(0.0, f64::max);
        assert_eq!(out.frequencies_hz.len(), DEFAULT_POINTS);
        assert_eq!(*out.frequencies_hz.last().unwrap(), 2.0 * top);
        let e = frf(
            &model,
            &FrfRequest {
                response: Some("z".into()),
                ..FrfRequest::default()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("`z`"), "{e}");
        let e = frf(
            &model,
            &FrfRequest {
                fmin_hz: Some(10.0),
                ..FrfRequest::default()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("`fmin_hz` 10 needs"), "{e}");
    }
}
