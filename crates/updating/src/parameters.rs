//! What the samplers vary: named model parameters and the map theta -> machine model.
//!
//! Modal parameters are the relative perturbations of `chatter-dynamics`
//! (`theta_omega_N`, `theta_zeta_N`, `theta_phi_N`, `theta_k_N`: the quantity times (1 + theta),
//! 000 Eq. 2, 002 Eq. 16). The process parameters of 003 and 004 are sampled as absolute values
//! with units in their names: `kt_n_per_mm2` and `kn_n_per_mm2` (cutting-force coefficients) and
//! `c_n_per_m` (the process-damping coefficient C of F_d = -C b ydot / V, 003 Eq. 1).

use crate::error::{Result, UpdatingError};
use chatter_dynamics::{CuttingCoefficients, ModalModel, Parameter};
use std::fmt;
use std::str::FromStr;

/// One sampled model quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ModelParameter {
    /// A relative modal perturbation (`theta_omega_N`, ...).
    Modal(Parameter),
    /// Tangential cutting coefficient kt (N/mm^2), absolute.
    KtNPerMm2,
    /// Normal (milling) or feed (turning) cutting coefficient kn (N/mm^2), absolute.
    KnNPerMm2,
    /// Process-damping coefficient C (N/m), absolute.
    ProcessDampingNPerM,
}

impl fmt::Display for ModelParameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelParameter::Modal(p) => write!(f, "{p}"),
            ModelParameter::KtNPerMm2 => f.write_str("kt_n_per_mm2"),
            ModelParameter::KnNPerMm2 => f.write_str("kn_n_per_mm2"),
            ModelParameter::ProcessDampingNPerM => f.write_str("c_n_per_m"),
        }
    }
}

impl FromStr for ModelParameter {
    type Err = UpdatingError;

    fn from_str(s: &str) -> Result<Self> {
        match s {
            "kt_n_per_mm2" => Ok(ModelParameter::KtNPerMm2),
            "kn_n_per_mm2" => Ok(ModelParameter::KnNPerMm2),
            "c_n_per_m" => Ok(ModelParameter::ProcessDampingNPerM),
            _ => s
                .parse::<Parameter>()
                .map(ModelParameter::Modal)
                .map_err(|e| UpdatingError::InvalidInput {
                    field: "parameters",
                    message: format!("{e}; or kt_n_per_mm2, kn_n_per_mm2, c_n_per_m"),
                }),
        }
    }
}

impl ModelParameter {
    /// The value of this parameter in `model` (0 for a modal perturbation: theta = 0 is nominal).
    pub fn nominal_value(&self, model: &ModalModel) -> f64 {
        match self {
            ModelParameter::Modal(_) => 0.0,
            ModelParameter::KtNPerMm2 => model.cutting().kt_n_per_m2() * 1e-6,
            ModelParameter::KnNPerMm2 => model.cutting().kn_n_per_m2() * 1e-6,
            ModelParameter::ProcessDampingNPerM => model.process_damping_n_per_m().unwrap_or(0.0),
        }
    }
}

/// Parse a comma-separated list of parameter names (empty entries are skipped).
pub fn parse_model_parameters(list: &str) -> Result<Vec<ModelParameter>> {
    list.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(str::parse)
        .collect()
}

/// A nominal model and the parameters that vary: theta -> model.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameterization {
    nominal: ModalModel,
    parameters: Vec<ModelParameter>,
    modal: Vec<Parameter>,
}

impl Parameterization {
    /// Validated: no parameter twice, modal parameters refer to existing modes.
    pub fn new(nominal: ModalModel, parameters: Vec<ModelParameter>) -> Result<Self> {
        for (i, p) in parameters.iter().enumerate() {
            if parameters[..i].contains(p) {
                return Err(UpdatingError::InvalidInput {
                    field: "parameters",
                    message: format!("`{p}` is listed twice"),
                });
            }
            if let ModelParameter::Modal(m) = p
                && m.mode >= nominal.mode_count()
            {
                return Err(UpdatingError::InvalidInput {
                    field: "parameters",
                    message: format!("`{p}`: the model has {} modes", nominal.mode_count()),
                });
            }
        }
        let modal = parameters
            .iter()
            .filter_map(|p| match p {
                ModelParameter::Modal(m) => Some(*m),
                _ => None,
            })
            .collect();
        Ok(Self {
            nominal,
            parameters,
            modal,
        })
    }

    /// The nominal model.
    pub fn nominal(&self) -> &ModalModel {
        &self.nominal
    }

    /// The parameters, in theta order.
    pub fn parameters(&self) -> &[ModelParameter] {
        &self.parameters
    }

    /// Number of parameters.
    pub fn dimension(&self) -> usize {
        self.parameters.len()
    }

    /// Parameter names in theta order.
    pub fn names(&self) -> Vec<String> {
        self.parameters.iter().map(ToString::to_string).collect()
    }

    /// theta at the nominal model.
    pub fn nominal_theta(&self) -> Vec<f64> {
        self.parameters
            .iter()
            .map(|p| p.nominal_value(&self.nominal))
            .collect()
    }

    /// Index of `parameter` in theta.
    pub fn index_of(&self, parameter: ModelParameter) -> Option<usize> {
        self.parameters.iter().position(|p| *p == parameter)
    }

    /// The model at `theta` (same length as the parameters). Errors where theta is not physical
    /// (1 + theta <= 0, damping >= 1, kt <= 0, C < 0).
    pub fn model(&self, theta: &[f64]) -> Result<ModalModel> {
        if theta.len() != self.parameters.len() {
            return Err(UpdatingError::InvalidInput {
                field: "theta",
                message: format!(
                    "{} values for {} parameters",
                    theta.len(),
                    self.parameters.len()
                ),
            });
        }
        let modal_theta: Vec<f64> = self
            .parameters
            .iter()
            .zip(theta)
            .filter(|(p, _)| matches!(p, ModelParameter::Modal(_)))
            .map(|(_, &t)| t)
            .collect();
        let mut model = if self.modal.is_empty() {
            self.nominal.clone()
        } else {
            self.nominal.perturbed(&self.modal, &modal_theta)?
        };
        let (mut kt, mut kn) = (model.cutting().kt_n_per_m2(), model.cutting().kn_n_per_m2());
        let mut cutting_changed = false;
        for (p, &t) in self.parameters.iter().zip(theta) {
            match p {
                ModelParameter::Modal(_) => {}
                ModelParameter::KtNPerMm2 => {
                    kt = t * 1e6;
                    cutting_changed = true;
                }
                ModelParameter::KnNPerMm2 => {
                    kn = t * 1e6;
                    cutting_changed = true;
                }
                ModelParameter::ProcessDampingNPerM => {
                    if !(t.is_finite() && t >= 0.0) {
                        return Err(UpdatingError::InvalidInput {
                            field: "c_n_per_m",
                            message: format!("{t}; expected >= 0"),
                        });
                    }
                    model = model.with_process_damping(Some(t))?;
                }
            }
        }
        if cutting_changed {
            model = model.with_cutting(CuttingCoefficients::new(kt, kn)?);
        }
        Ok(model)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    #[test]
    fn names_round_trip_and_models_follow_theta() {
        let names = "theta_omega_1, kt_n_per_mm2,kn_n_per_mm2,c_n_per_m";
        let params = parse_model_parameters(names).unwrap();
        let joined: Vec<String> = params.iter().map(ToString::to_string).collect();
        assert_eq!(
            joined.join(","),
            "theta_omega_1,kt_n_per_mm2,kn_n_per_mm2,c_n_per_m"
        );
        let p = Parameterization::new(examples::ebrahimi_2025_milling(), params).unwrap();
        assert_eq!(p.nominal_theta(), vec![0.0, 650.0, 110.0, 0.0]);
        let m = p.model(&[0.01, 700.0, 120.0, 2.5e5]).unwrap();
        assert!((m.modes()[0].frequency_hz() - 195.3 * 1.01).abs() < 1e-9);
        assert_eq!(m.cutting().kt_n_per_m2(), 700e6);
        assert_eq!(m.cutting().kn_n_per_m2(), 120e6);
        assert_eq!(m.process_damping_n_per_m(), Some(2.5e5));
        assert!(p.model(&[0.0, -1.0, 120.0, 0.0]).is_err());
        assert!(p.model(&[0.0, 700.0, 120.0, -1.0]).is_err());
        assert!(p.model(&[0.0]).is_err());
    }

    #[test]
    fn bad_lists_are_errors() {
        assert!(parse_model_parameters("theta_omega_1,bogus").is_err());
        let model = examples::ebrahimi_2025_milling();
        let twice = parse_model_parameters("c_n_per_m,c_n_per_m").unwrap();
        assert!(Parameterization::new(model.clone(), twice).is_err());
        let missing = parse_model_parameters("theta_zeta_3").unwrap();
        assert!(Parameterization::new(model, missing).is_err());
    }
}
