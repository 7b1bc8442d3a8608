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
