//! The papers' defaults: priors, model classes and which parameters to update.
//!
//! - Turning (000 Section 6.3): theta_omega ~ N(0, 0.001) truncated to +-0.03 (one lobe either
//!   way); theta_zeta, theta_phi (and theta_k) ~ N(0, 0.05) truncated to +-0.8; the residual
//!   variance sigma_R^2 ~ U[1e-10, 0.1]; 16 classes alpha = 2^-5.5, 2^-5, ..., 2^2.
//! - Milling (002 Section 3.2): theta_omega, theta_k (and theta_phi) ~ U[-0.1, 0.1],
//!   theta_zeta ~ U[-0.5, 0.5]; sigma_w^2 ~ U[1e-10, 1] Hz^2; classes alpha = sigma_zeta/sigma_w
//!   from 0.001 to 1 (ten per three decades: 10^(-3 + k/3)).
//! - Process parameters: kt and kn ~ N(nominal, (5 % nominal)^2) truncated to +-50 % (003 measured
//!   about 4 %); C ~ U[0.5e5, 10e5] N/m (003).
//! - Parameters: the omega, zeta and shape (turning, mass-normalized shapes) or stiffness
//!   (directional modes, 002) perturbations of the mode to which the identified poles are most
//!   sensitive (000 Section 6.2 chooses mode 2); for cut results only, kt and kn, plus C when the
//!   model has process damping.

use crate::error::{Result, UpdatingError};
use crate::milling::MillingPoleLikelihood;
use crate::parameters::{ModelParameter, Parameterization};
use crate::turning::{ResidualForm, TurningPoleLikelihood, expand_repetitions};
use chatter_bayes::prior::Marginal;
use chatter_dynamics::{
    ModalModel, ModeShape, Operation, Parameter, ParameterKind, PoleObservation,
};
use chatter_stability::monodromy::Discretization;

/// Name of the turning error variance (normalized real residual, 000 Eq. 31).
pub const TURNING_ERROR_VARIANCE: &str = "sigma_r2";
/// Name of the milling error variance (frequency, Hz^2, 002 Eq. 15).
pub const MILLING_ERROR_VARIANCE: &str = "sigma_w2_hz2";

/// The 16 model classes of 000: alpha = 2^(-5.5 + k/2), k = 0..15.
pub fn turning_alphas() -> Vec<f64> {
    (0..16).map(|k| 2f64.powf(-5.5 + 0.5 * k as f64)).collect()
}

/// Model classes over the range of 002 (0.001 to 1): alpha = 10^(-3 + k/3), k = 0..9.
pub fn milling_alphas() -> Vec<f64> {
    (0..10).map(|k| 10f64.powf(-3.0 + k as f64 / 3.0)).collect()
}

/// The default prior of one model parameter for `operation`, at the nominal `model`.
pub fn parameter_prior(parameter: ModelParameter, model: &ModalModel) -> Marginal {
    let turning = matches!(model.operation(), Operation::Turning(_));
    let tn = |var: f64, bound: f64| Marginal::TruncatedNormal {
        mean: 0.0,
        sd: var.sqrt(),
        low: -bound,
        high: bound,
    };
    let uniform = |bound: f64| Marginal::Uniform {
        low: -bound,
        high: bound,
    };
    let coefficient = |nominal: f64| Marginal::TruncatedNormal {
        mean: nominal,
        sd: 0.05 * nominal.abs().max(1e-9),
        low: nominal - 0.5 * nominal.abs(),
        high: nominal + 0.5 * nominal.abs().max(1e-9),
    };
    match parameter {
        ModelParameter::Modal(p) => match (turning, p.kind) {
            (true, ParameterKind::Omega) => tn(0.001, 0.03),
            (true, _) => tn(0.05, 0.8),
            (false, ParameterKind::Zeta) => uniform(0.5),
            (false, _) => uniform(0.1),
        },
        ModelParameter::KtNPerMm2
        | ModelParameter::KnNPerMm2
        | ModelParameter::KsNPerMm2
        | ModelParameter::BetaDeg
        | ModelParameter::ModeFrequencyHz(_)
        | ModelParameter::ModeStiffnessNPerM(_)
        | ModelParameter::ModeDampingRatio(_) => coefficient(parameter.nominal_value(model)),
        ModelParameter::ProcessDampingNPerM => Marginal::Uniform {
            low: 0.5e5,
            high: 10e5,
        },
    }
}

/// The default prior of the error variance (turning sigma_R^2, milling sigma_w^2 in Hz^2).
pub fn error_variance_prior(model: &ModalModel) -> Marginal {
    match model.operation() {
        Operation::Turning(_) => Marginal::Uniform {
            low: 1e-10,
            high: 0.1,
        },
        Operation::Milling(_) => Marginal::Uniform {
            low: 1e-10,
            high: 1.0,
        },
    }
}

/// Relative step of the sensitivity finite differences.
const SENSITIVITY_STEP: f64 = 1e-3;

/// The mode whose natural frequency moves the predicted poles most (sum over the identified
/// conditions of |d pole / d theta_omega_n|, central differences).
pub fn most_sensitive_mode(model: &ModalModel, poles: &[PoleObservation]) -> Result<usize> {
    let mut best = (0, f64::NEG_INFINITY);
    for mode in 0..model.mode_count() {
        let p = Parameterization::new(
            model.clone(),
            vec![ModelParameter::Modal(Parameter::new(
                ParameterKind::Omega,
                mode,
            ))],
        )?;
        let h = SENSITIVITY_STEP;
        let sensitivity: f64 = match model.operation() {
            Operation::Turning(_) => {
                let like = TurningPoleLikelihood::new(
                    p,
                    expand_repetitions(poles),
                    1.0,
                    ResidualForm::PoleError,
                )?;
                let (a, b) = (like.predicted_poles(&[h])?, like.predicted_poles(&[-h])?);
                a.iter().zip(&b).map(|(x, y)| (x.2 - y.2).norm()).sum()
            }
            Operation::Milling(_) => {
                let like = MillingPoleLikelihood::new(p, poles, 1.0, Discretization::full())?;
                let (a, b) = (like.predicted_poles(&[h])?, like.predicted_poles(&[-h])?);
                a.iter().zip(&b).map(|(x, y)| (x.0 - y.0).abs()).sum()
            }
        };
        if sensitivity > best.1 {
            best = (mode, sensitivity);
        }
    }
    Ok(best.0)
}

/// The default parameters: for identified poles the omega, zeta and shape/stiffness perturbations
/// of the most sensitive mode; for cut results only kt, kn (and C with process damping).
pub fn default_parameters(
    model: &ModalModel,
    poles: &[PoleObservation],
) -> Result<Vec<ModelParameter>> {
    if poles.is_empty() {
        let mut out = vec![ModelParameter::KtNPerMm2, ModelParameter::KnNPerMm2];
        if model.process_damping_n_per_m().is_some() {
            out.push(ModelParameter::ProcessDampingNPerM);
        }
        return Ok(out);
    }
    let mode = most_sensitive_mode(model, poles)?;
    let shape_kind = match model.modes().get(mode).map(|m| m.shape()) {
        Some(ModeShape::Directional { .. }) => ParameterKind::Stiffness,
        Some(ModeShape::MassNormalized(_)) => ParameterKind::Phi,
        None => {
            return Err(UpdatingError::InvalidInput {
                field: "model",
                message: "no modes".into(),
            });
        }
    };
    Ok([ParameterKind::Omega, ParameterKind::Zeta, shape_kind]
        .into_iter()
        .map(|k| ModelParameter::Modal(Parameter::new(k, mode)))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    #[test]
    fn the_papers_choices_come_out() {
        let model = examples::ahmadi_2022_turning();
        let poles = examples::ahmadi_2022_turning_observations().poles;
        let names: Vec<String> = default_parameters(&model, &poles)
            .unwrap()
            .iter()
            .map(ToString::to_string)
            .collect();
        assert_eq!(names, ["theta_omega_2", "theta_zeta_2", "theta_phi_2"]);
        let milling = examples::ebrahimi_2025_milling();
        let poles = examples::ebrahimi_2025_milling_observations().poles;
        let names: Vec<String> = default_parameters(&milling, &poles)
            .unwrap()
            .iter()
            .map(ToString::to_string)
            .collect();
        assert_eq!(names, ["theta_omega_1", "theta_zeta_1", "theta_k_1"]);
        assert_eq!(turning_alphas().len(), 16);
        assert!((turning_alphas()[9] - 0.5).abs() < 1e-12);
        assert!((milling_alphas()[0] - 1e-3).abs() < 1e-15);
        assert!((milling_alphas()[9] - 1.0).abs() < 1e-12);
        let cuts_only = default_parameters(&milling, &[]).unwrap();
        assert_eq!(cuts_only.len(), 2);
    }
}
