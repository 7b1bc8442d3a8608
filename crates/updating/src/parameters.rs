//! What the samplers vary: named model parameters and the map theta -> machine model.
//!
//! Modal parameters are the relative perturbations of `chatter-dynamics`
//! (`theta_omega_N`, `theta_zeta_N`, `theta_phi_N`, `theta_k_N`: the quantity times (1 + theta),
//! 000 Eq. 2, 002 Eq. 16). The process parameters of 003 and 004 are sampled as absolute values
//! with units in their names: `kt_n_per_mm2` and `kn_n_per_mm2` (cutting-force coefficients) and
//! `c_n_per_m` (the process-damping coefficient C of F_d = -C b ydot / V, 003 Eq. 1).
//!
//! Seed 004 samples u = [K_s, beta, f_n1, k_1, zeta_1, f_n2, k_2, zeta_2] (Schmitz et al. 2022,
//! Sec. 2), all absolute: `ks_n_per_mm2` and `beta_deg` (K_t = K_s sin beta, K_n = K_s cos beta,
//! as in 001) and, per mode number N, `fnN_hz`, `kN_n_per_m`, `zetaN`. 004's tool is symmetric:
//! mode N is the N-th mode of EACH direction (the model's directional modes counted per
//! coordinate in file order), so `fn1_hz` sets the first x mode and the first y mode alike. On a
//! mode whose nominal value differs, the value replaces it the same way; internally each is the
//! relative perturbation theta = value / nominal - 1 of every such mode (exact, so the complex
//! residue phase of a mode is kept).

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
    /// Resultant cutting coefficient K_s (N/mm^2), absolute (004).
    KsNPerMm2,
    /// Force angle beta (deg), absolute (004).
    BetaDeg,
    /// Natural frequency (Hz) of the N-th mode of every direction (0-based here, `fnN_hz`).
    ModeFrequencyHz(usize),
    /// Modal stiffness (N/m) of the N-th mode of every direction (`kN_n_per_m`).
    ModeStiffnessNPerM(usize),
    /// Damping ratio of the N-th mode of every direction (`zetaN`).
    ModeDampingRatio(usize),
}

/// The 1-based mode number N of an absolute modal name `{prefix}N{suffix}` (N >= 1).
fn mode_number(s: &str, prefix: &str, suffix: &str) -> Option<usize> {
    let n: usize = s.strip_prefix(prefix)?.strip_suffix(suffix)?.parse().ok()?;
    (n >= 1 && !s[prefix.len()..].starts_with('0')).then(|| n - 1)
}

impl fmt::Display for ModelParameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelParameter::Modal(p) => write!(f, "{p}"),
            ModelParameter::KtNPerMm2 => f.write_str("kt_n_per_mm2"),
            ModelParameter::KnNPerMm2 => f.write_str("kn_n_per_mm2"),
            ModelParameter::ProcessDampingNPerM => f.write_str("c_n_per_m"),
            ModelParameter::KsNPerMm2 => f.write_str("ks_n_per_mm2"),
            ModelParameter::BetaDeg => f.write_str("beta_deg"),
            ModelParameter::ModeFrequencyHz(n) => write!(f, "fn{}_hz", n + 1),
            ModelParameter::ModeStiffnessNPerM(n) => write!(f, "k{}_n_per_m", n + 1),
            ModelParameter::ModeDampingRatio(n) => write!(f, "zeta{}", n + 1),
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
            "ks_n_per_mm2" => Ok(ModelParameter::KsNPerMm2),
            "beta_deg" => Ok(ModelParameter::BetaDeg),
            _ => {
                if let Some(n) = mode_number(s, "fn", "_hz") {
                    return Ok(ModelParameter::ModeFrequencyHz(n));
                }
                if let Some(n) = mode_number(s, "k", "_n_per_m") {
                    return Ok(ModelParameter::ModeStiffnessNPerM(n));
                }
                if let Some(n) = mode_number(s, "zeta", "") {
                    return Ok(ModelParameter::ModeDampingRatio(n));
                }
                s.parse::<Parameter>()
                    .map(ModelParameter::Modal)
                    .map_err(|e| UpdatingError::InvalidInput {
                        field: "parameters",
                        message: format!(
                            "{e}; or kt_n_per_mm2, kn_n_per_mm2, c_n_per_m, ks_n_per_mm2, \
                             beta_deg, fnN_hz, kN_n_per_m, zetaN (N = 1, 2, ...)"
                        ),
                    })
            }
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
            ModelParameter::KsNPerMm2 => {
                let c = model.cutting();
                c.kt_n_per_m2().hypot(c.kn_n_per_m2()) * 1e-6
            }
            ModelParameter::BetaDeg => {
                let c = model.cutting();
                c.kt_n_per_m2().atan2(c.kn_n_per_m2()).to_degrees()
            }
            ModelParameter::ModeFrequencyHz(_)
            | ModelParameter::ModeStiffnessNPerM(_)
            | ModelParameter::ModeDampingRatio(_) => self
                .tied_modes(model)
                .ok()
                .and_then(|modes| modes.first().map(|&(_, v)| v))
                .unwrap_or(f64::NAN),
        }
    }

    /// For an absolute modal parameter (`fnN_hz`, `kN_n_per_m`, `zetaN`): the relative parameter
    /// it acts through and the nominal value of each mode it sets (the N-th directional mode of
    /// every coordinate). Errors where no coordinate has N directional modes, where the model
    /// has a mass-normalized mode (no stiffness, no direction), or where a nominal value is zero
    /// (no relative perturbation reaches another value). Empty for other parameters.
    fn tied_modes(&self, model: &ModalModel) -> Result<Vec<(Parameter, f64)>> {
        use chatter_dynamics::{ModeShape, ParameterKind};
        let (n, kind) = match *self {
            ModelParameter::ModeFrequencyHz(n) => (n, ParameterKind::Omega),
            ModelParameter::ModeStiffnessNPerM(n) => (n, ParameterKind::Stiffness),
            ModelParameter::ModeDampingRatio(n) => (n, ParameterKind::Zeta),
            _ => return Ok(Vec::new()),
        };
        let invalid = |message: String| UpdatingError::InvalidInput {
            field: "parameters",
            message: format!("`{self}`: {message}"),
        };
        let mut count = [0usize; 2];
        let mut tied = Vec::new();
        for (i, mode) in model.modes().iter().enumerate() {
            let ModeShape::Directional {
                coordinate,
                stiffness_n_per_m,
            } = mode.shape()
            else {
                return Err(invalid(format!(
                    "mode {} is mass-normalized; absolute modal parameters need modes with a \
                     direction and a stiffness",
                    i + 1
                )));
            };
            if count[coordinate] == n {
                let value = match kind {
                    ParameterKind::Omega => mode.frequency_hz(),
                    ParameterKind::Stiffness => stiffness_n_per_m,
                    _ => mode.damping_ratio(),
                };
                if value <= 0.0 {
                    return Err(invalid(format!(
                        "mode {} has a nominal value of 0, which cannot be scaled to another",
                        i + 1
                    )));
                }
                tied.push((Parameter::new(kind, i), value));
            }
            count[coordinate] += 1;
        }
        if tied.is_empty() {
            return Err(invalid(format!(
                "no direction of the model has {} modes (x: {}, y: {})",
                n + 1,
                count[0],
                count[1]
            )));
        }
        Ok(tied)
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
    /// Per parameter the relative modal parameters it moves, with each mode's nominal value for
    /// an absolute one (None: theta is the relative perturbation itself).
    modal: Vec<Vec<(Parameter, Option<f64>)>>,
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
        let has = |q: ModelParameter| parameters.contains(&q);
        for (a, b) in [
            (ModelParameter::KsNPerMm2, ModelParameter::KtNPerMm2),
            (ModelParameter::KsNPerMm2, ModelParameter::KnNPerMm2),
            (ModelParameter::BetaDeg, ModelParameter::KtNPerMm2),
            (ModelParameter::BetaDeg, ModelParameter::KnNPerMm2),
        ] {
            if has(a) && has(b) {
                return Err(UpdatingError::InvalidInput {
                    field: "parameters",
                    message: format!(
                        "`{a}` and `{b}` both set the cutting coefficients; sample kt and kn or \
                         ks and beta"
                    ),
                });
            }
        }
        let mut modal: Vec<Vec<(Parameter, Option<f64>)>> = Vec::with_capacity(parameters.len());
        for p in &parameters {
            let moved: Vec<(Parameter, Option<f64>)> = match p {
                ModelParameter::Modal(m) => vec![(*m, None)],
                _ => p
                    .tied_modes(&nominal)?
                    .into_iter()
                    .map(|(m, v)| (m, Some(v)))
                    .collect(),
            };
            if let Some((m, _)) = moved
                .iter()
                .find(|(m, _)| modal.iter().flatten().any(|(o, _)| o == m))
            {
                return Err(UpdatingError::InvalidInput {
                    field: "parameters",
                    message: format!("`{p}` moves {m}, which another listed parameter moves too"),
                });
            }
            modal.push(moved);
        }
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
        let mut modal = Vec::new();
        let mut modal_theta = Vec::new();
        for ((p, moved), &t) in self.parameters.iter().zip(&self.modal).zip(theta) {
            for &(m, nominal) in moved {
                let relative = match nominal {
                    None => t,
                    Some(v) => {
                        if !(t.is_finite() && t > 0.0) {
                            return Err(UpdatingError::InvalidInput {
                                field: "theta",
                                message: format!("`{p}` = {t}; expected > 0"),
                            });
                        }
                        t / v - 1.0
                    }
                };
                modal.push(m);
                modal_theta.push(relative);
            }
        }
        let mut model = if modal.is_empty() {
            self.nominal.clone()
        } else {
            self.nominal.perturbed(&modal, &modal_theta)?
        };
        let (mut kt, mut kn) = (model.cutting().kt_n_per_m2(), model.cutting().kn_n_per_m2());
        let (mut ks, mut beta) = (
            ModelParameter::KsNPerMm2.nominal_value(&model) * 1e6,
            ModelParameter::BetaDeg.nominal_value(&model).to_radians(),
        );
        let mut cutting_changed = false;
        let mut polar_changed = false;
        for (p, &t) in self.parameters.iter().zip(theta) {
            match p {
                ModelParameter::Modal(_)
                | ModelParameter::ModeFrequencyHz(_)
                | ModelParameter::ModeStiffnessNPerM(_)
                | ModelParameter::ModeDampingRatio(_) => {}
                ModelParameter::KsNPerMm2 => {
                    ks = t * 1e6;
                    polar_changed = true;
                }
                ModelParameter::BetaDeg => {
                    beta = t.to_radians();
                    polar_changed = true;
                }
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
        if polar_changed {
            model = model.with_cutting(CuttingCoefficients::from_ks_beta(ks, beta)?);
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
