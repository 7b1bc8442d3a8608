//! Receptance coupling and decoupling of two substructures at one end pair (Schmitz et al. 2022,
//! Eq. 1, 3 and 4).
//!
//! A substructure with end receptances R11, R12, R21, R22 (module [`crate::beam`]) is joined at
//! its end 2 to a base whose receptance at the joint is B, through a connection of dynamic
//! stiffness K (Eq. 4). Compatibility and equilibrium at the joint give the assembly receptance
//! at end 1 (Eq. 3):
//!
//! G11 = R11 - R12 (R22 + K^-1 + B)^-1 R21,
//!
//! with K^-1 = 0 for a rigid joint. Solving Eq. 3 for B with a rigid joint is the inverse RCSA of
//! Eq. 1, which recovers the spindle-machine receptance from a tap test G11 on an artifact:
//!
//! B = R21 (R11 - G11)^-1 R12 - R22.

use crate::beam::{EndReceptances, Receptance};
use crate::error::{RcsaError, Result};
use num_complex::Complex64;

/// The holder-tool connection of Eq. 4: K = diag(k_x + i omega c_x, k + i omega c), a
/// translational and a rotational spring-damper; the translational one is rigid unless given.
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct FlexibleConnection {
    /// Rotational stiffness k (N m/rad; Schmitz et al. 2022 write N/rad).
    pub k_n_per_rad: f64,
    /// Rotational viscous damping c (N m s/rad; the paper's N-s/rad).
    pub c_n_s_per_rad: f64,
    /// Translational stiffness k_x (N/m); rigid when absent.
    #[serde(default)]
    pub k_n_per_m: Option<f64>,
    /// Translational viscous damping c_x (N s/m); 0 when absent.
    #[serde(default)]
    pub c_n_s_per_m: Option<f64>,
}

/// How the tool is joined to the holder (or to the spindle when there is no holder).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Connection {
    /// Equal displacement and rotation across the joint.
    Rigid,
    /// The spring-damper connection of Eq. 4.
    Flexible(FlexibleConnection),
}

impl Connection {
    /// Check the values; `at` names the connection in errors.
    pub fn validate(&self, at: &str) -> Result<()> {
        let Connection::Flexible(c) = self else {
            return Ok(());
        };
        let checks = [
            ("k_n_per_rad", Some(c.k_n_per_rad), true),
            ("c_n_s_per_rad", Some(c.c_n_s_per_rad), false),
            ("k_n_per_m", c.k_n_per_m, true),
            ("c_n_s_per_m", c.c_n_s_per_m, false),
        ];
        for (name, v, strictly) in checks {
            let Some(v) = v else { continue };
            if !(v.is_finite() && (v > 0.0 || (!strictly && v == 0.0))) {
                let expected = if strictly {
                    "a finite value > 0"
                } else {
                    "a finite value >= 0"
                };
                return Err(RcsaError::value(format!("{at}.{name}"), v, expected));
            }
        }
        if c.c_n_s_per_m.is_some() && c.k_n_per_m.is_none() {
            return Err(RcsaError::value(
                format!("{at}.c_n_s_per_m"),
                c.c_n_s_per_m.unwrap_or(0.0),
                "given together with k_n_per_m (a translational damper alone is not a joint)",
            ));
        }
        Ok(())
    }

    /// The joint compliance K^-1 (Eq. 4) at `omega_rad_per_s`: zero for the rigid directions.
    ///
    /// ```
    /// use chatter_rcsa::{Connection, FlexibleConnection};
    /// let c = Connection::Flexible(FlexibleConnection {
    ///     k_n_per_rad: 1e6, c_n_s_per_rad: 0.0, k_n_per_m: None, c_n_s_per_m: None,
    /// });
    /// let k_inv = c.compliance(1000.0);
    /// assert_eq!(k_inv[(0, 0)].norm(), 0.0);
    /// assert!((k_inv[(1, 1)].re - 1e-6).abs() < 1e-18);
    /// ```
    pub fn compliance(&self, omega_rad_per_s: f64) -> Receptance {
        let zero = Complex64::new(0.0, 0.0);
        match self {
            Connection::Rigid => Receptance::zeros(),
            Connection::Flexible(c) => {
                let inv = |k: f64, c: f64| 1.0 / Complex64::new(k, omega_rad_per_s * c);
                let x = c
                    .k_n_per_m
                    .map_or(zero, |k| inv(k, c.c_n_s_per_m.unwrap_or(0.0)));
                Receptance::new(x, zero, zero, inv(c.k_n_per_rad, c.c_n_s_per_rad))
            }
        }
    }
}

/// Eq. 3: the receptance at end 1 of `sub` joined at its end 2 to a base of receptance `base`
/// through a joint of compliance `joint` (K^-1, zero when rigid).
///
/// ```
/// use chatter_rcsa::{Receptance, Segment, couple, free_free_receptances};
/// // a beam clamped at end 2 (rigid base): the static-like tip receptance is positive
/// let r = free_free_receptances(&[Segment::steel(100.0, 10.0, 0.0)], 10.0)?;
/// let g = couple(&r, &Receptance::zeros(), &Receptance::zeros(), 10.0)?;
/// assert!(g[(0, 0)].re > 0.0);
/// # Ok::<(), chatter_rcsa::RcsaError>(())
/// ```
pub fn couple(
    sub: &EndReceptances,
    base: &Receptance,
    joint: &Receptance,
    frequency_hz: f64,
) -> Result<Receptance> {
    let inner = (sub.r22 + joint + base)
        .try_inverse()
        .ok_or(RcsaError::Singular {
            what: "R22 + K^-1 + B (Eq. 3)",
            frequency_hz,
        })?;
    Ok(sub.r11 - sub.r12 * inner * sub.r21)
}

/// Eq. 1: the base receptance B that, joined rigidly to end 2 of `sub`, gives the measured
/// receptance `assembly` at end 1 (inverse RCSA of an artifact tap test).
///
/// ```
/// use chatter_rcsa::{Receptance, Segment, couple, decouple, free_free_receptances};
/// use num_complex::Complex64;
/// let r = free_free_receptances(&[Segment::steel(50.0, 20.0, 0.0)], 800.0)?;
/// let b = Receptance::new(
///     Complex64::new(2e-8, -1e-8), Complex64::new(1e-7, 0.0),
///     Complex64::new(1e-7, 0.0), Complex64::new(3e-6, -1e-7),
/// );
/// let g = couple(&r, &b, &Receptance::zeros(), 800.0)?;
/// let back = decouple(&r, &g, 800.0)?;
/// assert!((back - b).norm() < 1e-8 * b.norm());
/// # Ok::<(), chatter_rcsa::RcsaError>(())
/// ```
pub fn decouple(
    sub: &EndReceptances,
    assembly: &Receptance,
    frequency_hz: f64,
) -> Result<Receptance> {
    let inner = (sub.r11 - assembly)
        .try_inverse()
        .ok_or(RcsaError::Singular {
            what: "R11 - G11 (Eq. 1)",
            frequency_hz,
        })?;
    Ok(sub.r21 * inner * sub.r12 - sub.r22)
}
