//! Sensitivity of the dominant pole to the modal parameters (Ahmadi 2022, seed 000, Section 6.2,
//! Table 3).
//!
//! Table 3 lists |d mu / d theta_k| (Eq. 15) at the five tested points P1-P5. Its numbers are
//! those of the *one-step* map of the full discretization (000 Eq. 9-12: y_{i+1} = G y_i over
//! one time step h = tau / m, with m = 200 steps per revolution), not of the transition matrix
//! over one revolution (the monodromy Phi = G^m that the stability lobes use): for the turning
//! model of 000, whose coefficients do not vary in time, G is the same at every step, so the
//! dominant eigenvalues satisfy mu_Phi = lambda^m and
//!
//! ```text
//! d lambda / d theta = (d mu_Phi / d theta) / (m lambda^(m-1)),   |d lambda| = |d mu_Phi| / (m |mu_Phi|^((m-1)/m)),
//! ```
//!
//! about m = 200 times smaller than the period map's derivative near the boundary. The root
//! lambda of mu_Phi is picked on the chatter frequency f_c (from the eigenvector): lambda =
//! |mu_Phi|^(1/m) exp(i 2 pi f_c h), the eigenvalue whose phase is that of the pole's frequency
//! over one step. Its modulus does not depend on the choice.
//!
//! A milling model's one-step maps differ from step to step (H(t) is periodic), so there is no
//! single one-step eigenvalue; only the period map is offered there.

use crate::error::{Result, UncertaintyError};
use chatter_dynamics::{ModalModel, Operation, Parameter, ParameterKind};
use chatter_stability::StabilitySolver;
use chatter_stability::monodromy::{Discretization, steps};
use num_complex::Complex64;
use std::f64::consts::PI;
use std::num::NonZeroUsize;

/// Steps per revolution of the sensitivities of 000 Table 3.
pub const TABLE3_STEPS_PER_REVOLUTION: NonZeroUsize = steps::<200>();

/// The parameters of 000 Table 3's mode-2 columns, in [`TABLE3_MODE2`]'s order:
/// theta_omega_2, theta_zeta_2, theta_phi_2.
pub const TABLE3_MODE2_PARAMETERS: [Parameter; 3] = [
    Parameter {
        kind: ParameterKind::Omega,
        mode: 1,
    },
    Parameter {
        kind: ParameterKind::Zeta,
        mode: 1,
    },
    Parameter {
        kind: ParameterKind::Phi,
        mode: 1,
    },
];

/// 000 Table 3's mode-2 rows as printed (2-4 significant digits): the point, its speed (rpm)
/// and depth (mm), and |d mu / d theta| for [`TABLE3_MODE2_PARAMETERS`].
pub const TABLE3_MODE2: [(&str, f64, f64, [f64; 3]); 5] = [
    ("P1", 7150.0, 2.286, [0.3105, 0.0028, 0.0078]),
    ("P2", 7150.0, 2.54, [0.3025, 0.0028, 0.0080]),
    ("P3", 6950.0, 2.54, [0.2753, 0.0025, 0.0122]),
    ("P4", 7500.0, 2.032, [0.3126, 0.0028, 0.0071]),
    ("P5", 7500.0, 2.54, [0.2955, 0.0027, 0.0075]),
];

/// Which map's dominant eigenvalue is differentiated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum TransitionMap {
    /// One time step of the full discretization (000 Eq. 9-12): what Table 3 lists.
    OneStep,
    /// One delay period (the monodromy whose |mu| = 1 is the stability boundary).
    Period,
}

/// d mu / d theta for one parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParameterSensitivity {
    /// The parameter.
    pub parameter: Parameter,
    /// d mu / d theta (complex).
    pub derivative: Complex64,
}

impl ParameterSensitivity {
    /// |d mu / d theta|, the entry of 000 Table 3.
    pub fn modulus(&self) -> f64 {
        self.derivative.norm()
    }
}

/// The dominant eigenvalue of the chosen map and its gradient.
#[derive(Debug, Clone, PartialEq)]
pub struct PoleSensitivity {
    /// The differentiated map.
    pub map: TransitionMap,
    /// Full-discretization steps per delay (one revolution in turning).
    pub steps_per_delay: usize,
    /// Dominant eigenvalue of the map.
    pub eigenvalue: Complex64,
    /// Dominant multiplier over one delay (equal to `eigenvalue` for the period map, to
    /// `eigenvalue^m` for the one-step map: the member of the conjugate pair that matches).
    pub period_multiplier: Complex64,
    /// Chatter frequency of the dominant pole (Hz).
    pub chatter_hz: f64,
    /// One entry per parameter, in the order asked.
    pub entries: Vec<ParameterSensitivity>,
}

/// 000 Table 3's mode-2 rows recomputed on `model` (seed 000's lathe for the paper's values):
/// [`pole_sensitivity`] of the one-step map at [`TABLE3_STEPS_PER_REVOLUTION`] for
/// [`TABLE3_MODE2_PARAMETERS`] at each condition of [`TABLE3_MODE2`], in its order.
pub fn table3_mode2(model: &ModalModel) -> Result<Vec<PoleSensitivity>> {
    TABLE3_MODE2
        .iter()
        .map(|&(_, rpm, mm, _)| {
            pole_sensitivity(
                model,
                &TABLE3_MODE2_PARAMETERS,
                rpm,
                mm * 1e-3,
                TABLE3_STEPS_PER_REVOLUTION,
                TransitionMap::OneStep,
            )
        })
        .collect()
}

/// Eq. 15 at one cutting condition (depth in m) for `parameters`, on the `map`'s dominant
/// eigenvalue, with the full discretization at `steps_per_delay` steps (Table 3: 200).
pub fn pole_sensitivity(
    model: &ModalModel,
    parameters: &[Parameter],
    speed_rpm: f64,
    depth_m: f64,
    steps_per_delay: NonZeroUsize,
    map: TransitionMap,
) -> Result<PoleSensitivity> {
    if parameters.is_empty() {
        return Err(UncertaintyError::InvalidInput {
            field: "parameters",
            message: "no parameter to differentiate with respect to".into(),
        });
    }
    if map == TransitionMap::OneStep && matches!(model.operation(), Operation::Milling(_)) {
        return Err(UncertaintyError::InvalidInput {
            field: "map",
            message: "a milling model has a different one-step map at every step (periodic \
                      cutting forces); only the period map has one dominant eigenvalue: use the \
                      period map"
                .into(),
        });
    }
    let method = Discretization::full().with_steps(steps_per_delay);
    let m = steps_per_delay.get();
    let s = chatter_stability::sensitivity::eigenvalue_sensitivity(
        method, model, parameters, speed_rpm, depth_m,
    )?;
    let (_, chatter_hz) = method.chatter_frequency_hz(model, speed_rpm, depth_m)?;
    let (mut mu, mut gradient) = (s.mu, s.gradient);
    let (eigenvalue, scale) = match map {
        TransitionMap::Period => (mu, Complex64::new(1.0, 0.0)),
        TransitionMap::OneStep => {
            let h = model.operation().delay_s(speed_rpm) / m as f64;
            let lambda =
                Complex64::from_polar(mu.norm().powf(1.0 / m as f64), 2.0 * PI * chatter_hz * h);
            // lambda^m is mu or its conjugate (the other member of the pair): differentiate that
            let power = lambda.powu(m as u32);
            if (power - mu.conj()).norm() < (power - mu).norm() {
                mu = mu.conj();
                gradient = gradient.map(|d| d.conj());
            }
            (lambda, 1.0 / (m as f64 * lambda.powu(m as u32 - 1)))
        }
    };
    Ok(PoleSensitivity {
        map,
        steps_per_delay: m,
        eigenvalue,
        period_multiplier: mu,
        chatter_hz,
        entries: parameters
            .iter()
            .zip(gradient.iter())
            .map(|(&parameter, &d)| ParameterSensitivity {
                parameter,
                derivative: d * scale,
            })
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    /// 000 Table 3, the mode-2 rows at P1-P5 (printed to 2-4 significant digits; tolerance 3 %,
    /// the issue's): theta_omega_2, theta_zeta_2, theta_phi_2. And lambda^m is the period
    /// multiplier.
    #[test]
    fn table3_mode2_rows() {
        let model = examples::ahmadi_2022_turning();
        let rows = table3_mode2(&model).unwrap();
        for ((_, rpm, mm, paper), one) in TABLE3_MODE2.iter().zip(&rows) {
            for (e, p) in one.entries.iter().zip(paper) {
                let rel = (e.modulus() - p).abs() / p;
                assert!(
                    rel < 0.03,
                    "{rpm} rpm {mm} mm {}: {} vs {p}",
                    e.parameter,
                    e.modulus()
                );
            }
            let back = one.eigenvalue.powu(200);
            assert!(
                (back - one.period_multiplier).norm() < 1e-9,
                "{back} vs {}",
                one.period_multiplier
            );
        }
    }

    #[test]
    fn milling_has_no_one_step_map() {
        let model = examples::schmitz_2023_milling();
        let p: Parameter = "theta_omega_1".parse().unwrap();
        let e = pole_sensitivity(
            &model,
            &[p],
            6000.0,
            1e-3,
            steps::<40>(),
            TransitionMap::OneStep,
        );
        assert!(e.is_err());
    }
}
