//! Named parameter perturbations theta, as the samplers use them (000 Eq. 2, 002 Section 4):
//! omega_n (1 + theta_omega_n), zeta_n (1 + theta_zeta_n), phi_n (1 + theta_phi_n) and
//! k_n (1 + theta_k_n). theta = 0 reproduces the nominal model exactly.
//!
//! Conventions: a mass-normalized mode keeps its shape when its frequency changes (000: the modal
//! mass is fixed and the stiffness scales with omega^2); a directional mode keeps its stiffness
//! (002: k and omega are independent). Scaling the shape by (1 + theta_phi) divides the modal
//! stiffness by (1 + theta_phi)^2; scaling the stiffness by (1 + theta_k) divides the shape by
//! sqrt(1 + theta_k).

use crate::error::{DynamicsError, Result};
use crate::model::{ModalModel, ModeShape};
use std::fmt;
use std::str::FromStr;

/// Which modal quantity a theta scales.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ParameterKind {
    /// Natural frequency: omega_n (1 + theta).
    Omega,
    /// Damping ratio: zeta_n (1 + theta).
    Zeta,
    /// Mass-normalized shape: phi_n (1 + theta).
    Phi,
    /// Modal stiffness: k_n (1 + theta).
    Stiffness,
}

impl ParameterKind {
    fn tag(self) -> &'static str {
        match self {
            ParameterKind::Omega => "omega",
            ParameterKind::Zeta => "zeta",
            ParameterKind::Phi => "phi",
            ParameterKind::Stiffness => "k",
        }
    }
}

/// One named perturbation parameter: a kind and a mode (0-based inside, 1-based in its name).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Parameter {
    /// What it scales.
    pub kind: ParameterKind,
    /// 0-based mode index.
    pub mode: usize,
}

impl Parameter {
    /// A parameter of `kind` on the 0-based `mode`.
    pub fn new(kind: ParameterKind, mode: usize) -> Self {
        Self { kind, mode }
    }
}

impl fmt::Display for Parameter {
    /// `theta_omega_N`, `theta_zeta_N`, `theta_phi_N` or `theta_k_N` with N 1-based.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "theta_{}_{}", self.kind.tag(), self.mode + 1)
    }
}

impl FromStr for Parameter {
    type Err = DynamicsError;

    fn from_str(s: &str) -> Result<Self> {
        let bad = || {
            DynamicsError::invalid(
                "parameter",
                format!(
                    "`{s}` is not a parameter name; expected theta_omega_N, theta_zeta_N, \
                     theta_phi_N or theta_k_N with N the 1-based mode index"
                ),
            )
        };
        let rest = s.strip_prefix("theta_").ok_or_else(bad)?;
        let (tag, index) = rest.rsplit_once('_').ok_or_else(bad)?;
        let kind = match tag {
            "omega" => ParameterKind::Omega,
            "zeta" => ParameterKind::Zeta,
            "phi" => ParameterKind::Phi,
            "k" => ParameterKind::Stiffness,
            _ => return Err(bad()),
        };
        let n: usize = index.parse().map_err(|_| bad())?;
        if n == 0 {
            return Err(bad());
        }
        Ok(Self::new(kind, n - 1))
    }
}

impl ModalModel {
    /// The model with each `parameters[i]` scaled by `(1 + theta[i])`.
    ///
    /// Errors when the lengths differ, a mode index is out of range, or a factor 1 + theta is not
    /// positive (or makes damping >= 1).
    pub fn perturbed(&self, parameters: &[Parameter], theta: &[f64]) -> Result<ModalModel> {
        if parameters.len() != theta.len() {
            return Err(DynamicsError::invalid(
                "theta",
                format!(
                    "{} values given for {} parameters",
                    theta.len(),
                    parameters.len()
                ),
            ));
        }
        let mut modes = self.modes().to_vec();
        for (p, &t) in parameters.iter().zip(theta) {
            let factor = 1.0 + t;
            if !(factor.is_finite() && factor > 0.0) {
                return Err(DynamicsError::value(p.to_string(), t, "theta > -1"));
            }
            let mode = modes.get(p.mode).copied().ok_or_else(|| {
                DynamicsError::invalid(
                    p.to_string(),
                    format!("the model has {} modes", self.mode_count()),
                )
            })?;
            let (mut f, mut z, mut shape) =
                (mode.frequency_hz(), mode.damping_ratio(), mode.shape());
            match p.kind {
                ParameterKind::Omega => f *= factor,
                ParameterKind::Zeta => {
                    z *= factor;
                    if z >= 1.0 {
                        return Err(DynamicsError::value(p.to_string(), t, "damping ratio < 1"));
                    }
                }
                ParameterKind::Phi => shape = scale_shape(shape, factor),
                ParameterKind::Stiffness => shape = scale_shape(shape, 1.0 / factor.sqrt()),
            }
            modes[p.mode] = mode.with_values(f, z, shape);
        }
        self.with_modes(modes)
    }
}

/// Scale a mass-normalized shape by `s` (directional modes: stiffness divided by s^2).
fn scale_shape(shape: ModeShape, s: f64) -> ModeShape {
    match shape {
        ModeShape::MassNormalized(phi) => ModeShape::MassNormalized([phi[0] * s, phi[1] * s]),
        ModeShape::Directional {
            coordinate,
            stiffness_n_per_m,
        } => ModeShape::Directional {
            coordinate,
            stiffness_n_per_m: stiffness_n_per_m / (s * s),
        },
    }
}

/// Parse a comma-separated list of parameter names.
pub fn parse_parameters(list: &str) -> Result<Vec<Parameter>> {
    list.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(str::parse)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::examples;

    #[test]
    fn names_round_trip() {
        for name in ["theta_omega_1", "theta_zeta_2", "theta_phi_3", "theta_k_10"] {
            let p: Parameter = name.parse().unwrap();
            assert_eq!(p.to_string(), name);
        }
        for bad in [
            "theta_omega_0",
            "omega_1",
            "theta_x_1",
            "theta_k_",
            "theta_k_a",
        ] {
            assert!(bad.parse::<Parameter>().is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn stiffness_and_shape_scalings_agree() {
        // k (1 + theta_k) is phi / sqrt(1 + theta_k): the same model as theta_phi = 1/sqrt(1+t) - 1
        let model = examples::ebrahimi_2025_milling();
        let t = 0.21;
        let by_k = model
            .perturbed(&[Parameter::new(ParameterKind::Stiffness, 0)], &[t])
            .unwrap();
        let by_phi = model
            .perturbed(
                &[Parameter::new(ParameterKind::Phi, 0)],
                &[1.0 / (1.0_f64 + t).sqrt() - 1.0],
            )
            .unwrap();
        let (a, b) = (
            by_k.modes()[0].stiffness_at(0),
            by_phi.modes()[0].stiffness_at(0),
        );
        assert!((a - b).abs() < 1e-9 * a);
        assert!((a - 2.34e6 * (1.0 + t)).abs() < 1e-6 * a);
    }

    #[test]
    fn omega_keeps_shape_for_mass_normalized_and_stiffness_for_directional() {
        let turning = examples::ahmadi_2022_turning();
        let p = [Parameter::new(ParameterKind::Omega, 1)];
        let t = turning.perturbed(&p, &[0.01]).unwrap();
        assert_eq!(
            t.modes()[1].mass_normalized_shape(),
            turning.modes()[1].mass_normalized_shape()
        );
        let milling = examples::ebrahimi_2025_milling();
        let m = milling
            .perturbed(&[Parameter::new(ParameterKind::Omega, 0)], &[0.01])
            .unwrap();
        assert!((m.modes()[0].stiffness_at(0) - 2.34e6).abs() < 1e-6);
    }

    #[test]
    fn invalid_perturbations_are_errors() {
        let model = examples::ahmadi_2022_turning();
        let p = Parameter::new(ParameterKind::Zeta, 5);
        assert!(model.perturbed(&[p], &[0.1]).is_err());
        let p = Parameter::new(ParameterKind::Omega, 0);
        assert!(model.perturbed(&[p], &[-1.5]).is_err());
        assert!(model.perturbed(&[p], &[0.1, 0.2]).is_err());
        let z = Parameter::new(ParameterKind::Zeta, 0);
        assert!(model.perturbed(&[z], &[100.0]).is_err());
    }
}
