//! Free-free Timoshenko beams built from cylindrical segments, and their end receptances.
//!
//! Each segment (solid or hollow cylinder) obeys Timoshenko's beam equations at frequency
//! omega, written as a first-order system for the state z = [w, psi, M, V] (lateral displacement,
//! cross-section rotation, bending moment, shear force):
//!
//! w' = psi + V / (kappa G A), psi' = M / (E I), M' = -V - rho I omega^2 psi,
//! V' = -rho A omega^2 w,
//!
//! with Cowper's shear coefficient of a (hollow) circular section,
//! kappa = 6 (1 + nu) (1 + m^2)^2 / ((7 + 6 nu) (1 + m^2)^2 + (20 + 12 nu) m^2), m = d_i / d_o,
//! and structural damping through a complex modulus E (1 + i eta), G (1 + i eta). The field
//! (transfer) matrix of a segment of length L is the matrix exponential exp(A L) of the system,
//! evaluated on a dimensionless state so that its entries are of order one; the segments'
//! matrices are chained, and the free-end conditions give the end receptances exactly, with no
//! mode truncation. This is the method this crate uses (not a finite element model); the tests
//! check it against closed-form cantilever frequencies and an independent Euler-Bernoulli finite
//! element model.
//!
//! Receptances are 2 x 2 matrices in the order of Schmitz et al. (2022, Eq. 2):
//! R_ij = [[h_ij, l_ij], [n_ij, p_ij]] = [[x_i/f_j, x_i/m_j], [theta_i/f_j, theta_i/m_j]], end 1 the
//! free end of the first segment, end 2 the far end of the last one, all in one global sign
//! convention (rotation = dw/dx, a moment positive in the sense of the rotation).

use crate::error::{RcsaError, Result};
use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64;
use std::f64::consts::PI;

/// A 2 x 2 complex receptance matrix [[h, l], [n, p]] (m/N, 1/N, 1/N, 1/(N m)).
pub type Receptance = Matrix2<Complex64>;

/// One cylindrical segment, in the units of the assembly file.
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Segment {
    /// Length (mm).
    pub length_mm: f64,
    /// Outer diameter (mm).
    pub outer_diameter_mm: f64,
    /// Inner diameter (mm); 0 (the default) for a solid section.
    #[serde(default)]
    pub inner_diameter_mm: f64,
    /// Young's modulus (GPa).
    pub youngs_modulus_gpa: f64,
    /// Density (kg/m^3).
    pub density_kg_per_m3: f64,
    /// Poisson's ratio.
    pub poisson_ratio: f64,
    /// Structural loss factor eta (complex modulus E (1 + i eta)); 0 by default.
    #[serde(default)]
    pub loss_factor: f64,
}

impl Segment {
    /// A steel segment (E 200 GPa, 7800 kg/m^3, nu 0.29, no loss) of the given size.
    ///
    /// ```
    /// let s = chatter_rcsa::Segment::steel(100.0, 10.0, 0.0);
    /// assert_eq!(s.youngs_modulus_gpa, 200.0);
    /// assert!(s.validate("tool[0]").is_ok());
    /// ```
    pub fn steel(length_mm: f64, outer_diameter_mm: f64, inner_diameter_mm: f64) -> Self {
        Self {
            length_mm,
            outer_diameter_mm,
            inner_diameter_mm,
            youngs_modulus_gpa: 200.0,
            density_kg_per_m3: 7800.0,
            poisson_ratio: 0.29,
            loss_factor: 0.0,
        }
    }

    /// Check every value; `at` names the segment in errors (e.g. `tool[1]`).
    pub fn validate(&self, at: &str) -> Result<()> {
        let positive = [
            ("length_mm", self.length_mm),
            ("outer_diameter_mm", self.outer_diameter_mm),
            ("youngs_modulus_gpa", self.youngs_modulus_gpa),
            ("density_kg_per_m3", self.density_kg_per_m3),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(RcsaError::value(
                    format!("{at}.{name}"),
                    v,
                    "a finite value > 0",
                ));
            }
        }
        let d = self.inner_diameter_mm;
        if !(d.is_finite() && d >= 0.0 && d < self.outer_diameter_mm) {
            return Err(RcsaError::value(
                format!("{at}.inner_diameter_mm"),
                d,
                format!(
                    ">= 0 and below the outer diameter {} mm",
                    self.outer_diameter_mm
                ),
            ));
        }
        let nu = self.poisson_ratio;
        if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
            return Err(RcsaError::value(
                format!("{at}.poisson_ratio"),
                nu,
                "between -1 and 0.5",
            ));
        }
        let eta = self.loss_factor;
        if !(eta.is_finite() && eta >= 0.0) {
            return Err(RcsaError::value(
                format!("{at}.loss_factor"),
                eta,
                "a finite value >= 0",
            ));
        }
        Ok(())
    }

    /// Cross-section area (m^2) and second moment of area (m^4).
    pub fn section_m(&self) -> (f64, f64) {
        let (o, i) = (self.outer_diameter_mm * 1e-3, self.inner_diameter_mm * 1e-3);
        (
            PI / 4.0 * (o * o - i * i),
            PI / 64.0 * (o.powi(4) - i.powi(4)),
        )
    }

    /// Cowper's shear coefficient of a hollow circular section (solid: 6 (1 + nu) / (7 + 6 nu)).
    pub fn shear_coefficient(&self) -> f64 {
        let nu = self.poisson_ratio;
        let m2 = (self.inner_diameter_mm / self.outer_diameter_mm).powi(2);
        let a = (1.0 + m2).powi(2);
        6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m2)
    }

    /// Field (transfer) matrix T with z(L) = T z(0), z = [w, psi, M, V] in SI units, at
    /// `omega_rad_per_s`: exp(A L) computed on the dimensionless state
    /// [w / L, psi, M L / (E I), V L^2 / (E I)].
    pub fn transfer_matrix(&self, omega_rad_per_s: f64) -> Matrix4<Complex64> {
        let l = self.length_mm * 1e-3;
        let (area, inertia) = self.section_m();
        let loss = Complex64::new(1.0, self.loss_factor);
        let e = self.youngs_modulus_gpa * 1e9 * loss;
        let g = self.youngs_modulus_gpa * 1e9 / (2.0 * (1.0 + self.poisson_ratio)) * loss;
        let ei = e * inertia;
        let kga = g * self.shear_coefficient() * area;
        let w2 = omega_rad_per_s * omega_rad_per_s;
        let rho = self.density_kg_per_m3;
        let zero = Complex64::new(0.0, 0.0);
        let one = Complex64::new(1.0, 0.0);
        let s = ei / (kga * l * l);
        let r = rho * inertia * w2 * l * l / ei;
        let q = rho * area * w2 * l.powi(4) / ei;
        #[rustfmt::skip]
        let a = Matrix4::new(
            zero, one, zero, s,
            zero, zero, one, zero,
            zero, -r, zero, -one,
            -q, zero, zero, zero,
        );
        let t = a.exp();
        let d = [one / l, one, l / ei, l * l / ei];
        Matrix4::from_fn(|i, j| t[(i, j)] * d[j] / d[i])
    }
}

/// The four 2 x 2 end receptances of a free-free beam at one frequency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EndReceptances {
    /// At end 1 (the free end of the first segment), loads at end 1.
    pub r11: Receptance,
    /// At end 1, loads at end 2.
    pub r12: Receptance,
    /// At end 2, loads at end 1.
    pub r21: Receptance,
    /// At end 2, loads at end 2.
    pub r22: Receptance,
}

/// End receptances of the free-free beam made of `segments` (end 1 = the start of the first) at
/// `frequency_hz` > 0.
///
/// With the chained field matrix T split into 2 x 2 blocks (displacements d = [w, psi], forces
/// s = [M, V]) and the end loads q = [f, m] related to the internal forces by s(0) = -P q_1,
/// s(L) = P q_2 (P swaps the two entries), the free-free conditions give
/// R11 = T_sd^-1 T_ss P, R12 = T_sd^-1 P, R21 = (T_dd T_sd^-1 T_ss - T_ds) P,
/// R22 = T_dd T_sd^-1 P.
///
/// ```
/// use chatter_rcsa::{Segment, free_free_receptances};
/// let r = free_free_receptances(&[Segment::steel(100.0, 10.0, 0.0)], 500.0)?;
/// // reciprocity: R12 = R21^T
/// assert!((r.r12 - r.r21.transpose()).norm() < 1e-9 * r.r12.norm());
/// # Ok::<(), chatter_rcsa::RcsaError>(())
/// ```
pub fn free_free_receptances(segments: &[Segment], frequency_hz: f64) -> Result<EndReceptances> {
    if segments.is_empty() {
        return Err(RcsaError::value("segments", 0.0, "at least one segment"));
    }
    if !(frequency_hz.is_finite() && frequency_hz > 0.0) {
        return Err(RcsaError::value(
            "frequency_hz",
            frequency_hz,
            "> 0 (a free-free beam has rigid-body motion at 0 Hz)",
        ));
    }
    let omega = 2.0 * PI * frequency_hz;
    let t = segments
        .iter()
        .fold(Matrix4::identity(), |acc, s| s.transfer_matrix(omega) * acc);
    let block = |r: usize, c: usize| -> Receptance { t.fixed_view::<2, 2>(r, c).into_owned() };
    let (t_dd, t_ds, t_sd, t_ss) = (block(0, 0), block(0, 2), block(2, 0), block(2, 2));
    let one = Complex64::new(1.0, 0.0);
    let zero = Complex64::new(0.0, 0.0);
    let p = Receptance::new(zero, one, one, zero);
    let t_sd_inv = t_sd.try_inverse().ok_or(RcsaError::Singular {
        what: "the free-free field matrix block",
        frequency_hz,
    })?;
    Ok(EndReceptances {
        r11: t_sd_inv * t_ss * p,
        r12: t_sd_inv * p,
        r21: (t_dd * t_sd_inv * t_ss - t_ds) * p,
        r22: t_dd * t_sd_inv * p,
    })
}
