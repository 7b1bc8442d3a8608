//! Multi-mode modal models (000 Eq. 1-2, 002 Section 2).
//!
//! The structure obeys, in modal coordinates q, q'' + 2 Omega Z q' + Omega^2 q = Phi^T f
//! (000 Eq. 1) with Phi the 2 x N matrix of mass-normalized mode shapes over the operation's
//! two coordinates. A mode given by a stiffness k in one direction is the mass-normalized shape
//! omega_n / sqrt(k) in that direction (modal mass k / omega_n^2).
//!
//! # Non-proportional (complex) modes
//! A mode may carry a residue phase alpha (`residue_phase_deg` in model files; 0 for a real,
//! proportionally damped mode). Its receptance is the complex-mode pair of Ewins (2000,
//! Section 2.7; the pole-residue form of `chatter_frf::fit`)
//!
//! G_ij(i w) = A_ij / (i w - lambda) + conj(A_ij) / (i w - conj(lambda)),
//! A_ij = e^{i alpha} phi_i phi_j / (2 i w_d),
//!
//! with lambda = -zeta w_n + i w_d, w_d = w_n sqrt(1 - zeta^2). At alpha = 0 this is exactly
//! phi_i phi_j / (w_n^2 - w^2 + 2 i zeta w_n w); in general it is
//! phi_i phi_j (n_0 + n_1 i w) / (w_n^2 - w^2 + 2 i zeta w_n w) with the numerator of
//! [`complex_mode_numerator`]. The stiffness form k = w_n^2 / phi^2 keeps its meaning as the
//! size of the residue, |A| = w_n^2 / (2 w_d k); the phase rotates it. Methods built on real
//! modal coordinates (FDM, SDM, the frequency-domain poles, time-domain simulation) refuse such
//! modes ([`ModalModel::require_proportional`]); the zero-order method uses them.
//!
//! # Residual terms
//! A fit over a band stands for the modes outside it by residual terms ([`ResidualTerms`],
//! `residuals` in model files): each coordinate's direct receptance gains U - L / w^2 (upper
//! residual U in m/N, the modes above the band; lower residual L in 1/kg, the modes below it),
//! G_ii(i w) += U_i - L_i / w^2. They have no modal coordinate, so only the zero-order method,
//! which works on the receptance itself, uses them; the others refuse them by name
//! ([`ModalModel::require_proportional`]).

use crate::error::{DynamicsError, Result, finite, non_negative, positive};
use crate::operation::Operation;
use chatter_modal::ModalPole;
use num_complex::Complex64;
use std::f64::consts::PI;

/// The numerator (n_0, n_1 in s) of a complex mode's receptance over its real-mode denominator:
/// A / (i w - lambda) + conj(A) / (i w - conj(lambda)) = phi^2 (n_0 + n_1 i w) /
/// (w_n^2 - w^2 + 2 i zeta w_n w) for A = e^{i alpha} phi^2 / (2 i w_d) (module docs), i.e.
/// n_0 = cos(alpha) + zeta / sqrt(1 - zeta^2) sin(alpha), n_1 = sin(alpha) / w_d. (1, 0) for a
/// real mode.
pub fn complex_mode_numerator(
    omega_rad_s: f64,
    damping_ratio: f64,
    residue_phase_rad: f64,
) -> (f64, f64) {
    if residue_phase_rad == 0.0 {
        return (1.0, 0.0);
    }
    let root = (1.0 - damping_ratio * damping_ratio).sqrt();
    let (sin, cos) = residue_phase_rad.sin_cos();
    (cos + damping_ratio / root * sin, sin / (omega_rad_s * root))
}

/// How a mode's shape (and so its modal mass or stiffness) is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModeShape {
    /// A mode that moves in one coordinate only, with stiffness `k` (N/m).
    Directional {
        /// Index of the coordinate (0 or 1) in [`Operation::coordinates`].
        coordinate: usize,
        /// Modal stiffness in N/m.
        stiffness_n_per_m: f64,
    },
    /// Mass-normalized components over the two coordinates, in 1/sqrt(kg).
    MassNormalized([f64; 2]),
}

/// One structural mode: its modal pole (natural frequency and damping ratio, the
/// [`ModalPole`] every mode type of the workspace holds), its shape and its residue phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    pole: ModalPole,
    shape: ModeShape,
    residue_phase_rad: f64,
}

impl Mode {
    /// Validated mode: `frequency_hz > 0`, `0 <= damping_ratio < 1`, positive stiffness or a
    /// finite, non-zero shape.
    pub fn new(frequency_hz: f64, damping_ratio: f64, shape: ModeShape) -> Result<Self> {
        positive("frequency_hz", frequency_hz)?;
        non_negative("damping_ratio", damping_ratio)?;
        if damping_ratio >= 1.0 {
            return Err(DynamicsError::value(
                "damping_ratio",
                damping_ratio,
                "an underdamped ratio in [0, 1)",
            ));
        }
        match shape {
            ModeShape::Directional {
                coordinate,
                stiffness_n_per_m,
            } => {
                positive("stiffness_n_per_m", stiffness_n_per_m)?;
                if coordinate > 1 {
                    return Err(DynamicsError::value(
                        "direction",
                        coordinate as f64,
                        "coordinate index 0 or 1",
                    ));
                }
            }
            ModeShape::MassNormalized(phi) => {
                finite("shape", phi[0])?;
                finite("shape", phi[1])?;
                if phi[0] == 0.0 && phi[1] == 0.0 {
                    return Err(DynamicsError::invalid(
                        "shape",
                        "at least one non-zero component expected",
                    ));
                }
            }
        }
        Ok(Self {
            pole: ModalPole::new(frequency_hz, damping_ratio),
            shape,
            residue_phase_rad: 0.0,
        })
    }

    /// The same mode made non-proportional with residue phase alpha (rad, module docs),
    /// -pi < alpha <= pi, of a damped mode (an undamped complex mode is not physical).
    pub fn with_residue_phase(self, residue_phase_rad: f64) -> Result<Self> {
        finite("residue_phase_deg", residue_phase_rad)?;
        if !(residue_phase_rad > -PI && residue_phase_rad <= PI) {
            return Err(DynamicsError::value(
                "residue_phase_deg",
                residue_phase_rad.to_degrees(),
                "a phase in (-180, 180] degrees",
            ));
        }
        if residue_phase_rad != 0.0 && self.pole.damping_ratio == 0.0 {
            return Err(DynamicsError::invalid(
                "residue_phase_deg",
                "a non-proportional (complex) mode needs a damping ratio > 0",
            ));
        }
        Ok(Self {
            residue_phase_rad,
            ..self
        })
    }

    /// The directional mode at `coordinate` whose complex residue is `residue_m_per_n_s` (A of
    /// the module docs, m/(N s)): k = w_n^2 / (2 w_d |A|), alpha = arg(i A). This is how a
    /// measured FRF's pole-residue fit becomes a model mode.
    pub fn from_residue(
        frequency_hz: f64,
        damping_ratio: f64,
        coordinate: usize,
        residue_m_per_n_s: Complex64,
    ) -> Result<Self> {
        let magnitude = residue_m_per_n_s.norm();
        positive("residue_m_per_n_s", magnitude)?;
        let pole = ModalPole::new(frequency_hz, damping_ratio);
        let (wn, wd) = (pole.omega_rad_s(), pole.pole().im);
        let alpha = (Complex64::i() * residue_m_per_n_s).arg();
        let shape = ModeShape::Directional {
            coordinate,
            stiffness_n_per_m: wn * wn / (2.0 * wd * magnitude),
        };
        Self::new(frequency_hz, damping_ratio, shape)?.with_residue_phase(alpha)
    }

    /// Residue phase alpha (rad) of a non-proportional mode; 0 for a real mode.
    pub fn residue_phase_rad(&self) -> f64 {
        self.residue_phase_rad
    }
    /// Whether the mode is real (proportionally damped): residue phase 0.
    pub fn is_proportional(&self) -> bool {
        self.residue_phase_rad == 0.0
    }
    /// The numerator (n_0, n_1 in s) of [`complex_mode_numerator`] for this mode.
    pub fn receptance_numerator(&self) -> (f64, f64) {
        complex_mode_numerator(
            self.omega_rad_s(),
            self.pole.damping_ratio,
            self.residue_phase_rad,
        )
    }

    /// Natural frequency in Hz.
    pub fn frequency_hz(&self) -> f64 {
        self.pole.frequency_hz
    }
    /// Natural frequency omega_n in rad/s.
    pub fn omega_rad_s(&self) -> f64 {
        self.pole.omega_rad_s()
    }
    /// Damping ratio zeta_n.
    pub fn damping_ratio(&self) -> f64 {
        self.pole.damping_ratio
    }
    /// The natural frequency and damping ratio as a [`ModalPole`].
    pub fn modal_pole(&self) -> ModalPole {
        self.pole
    }
    /// How the shape was given.
    pub fn shape(&self) -> ModeShape {
        self.shape
    }

    /// Mass-normalized shape phi_n over the two coordinates (1/sqrt(kg)).
    pub fn mass_normalized_shape(&self) -> [f64; 2] {
        match self.shape {
            ModeShape::MassNormalized(phi) => phi,
            ModeShape::Directional {
                coordinate,
                stiffness_n_per_m,
            } => {
                let mut phi = [0.0; 2];
                phi[coordinate] = self.omega_rad_s() / stiffness_n_per_m.sqrt();
                phi
            }
        }
    }

    /// Modal stiffness seen at a coordinate, omega_n^2 / phi^2 (N/m); infinite when the mode does
    /// not move there.
    pub fn stiffness_at(&self, coordinate: usize) -> f64 {
        let phi = self.mass_normalized_shape()[coordinate];
        self.omega_rad_s().powi(2) / (phi * phi)
    }

    pub(crate) fn with_values(
        self,
        frequency_hz: f64,
        damping_ratio: f64,
        shape: ModeShape,
    ) -> Self {
        Self {
            pole: ModalPole::new(frequency_hz, damping_ratio),
            shape,
            ..self
        }
    }
}

/// Linear specific cutting-force coefficients in SI (N/m^2).
///
/// Milling: tangential `kt` and normal `kn`. Turning: `kt` is the cutting (tangential) coefficient
/// k_tc and `kn` the feed coefficient k_fc of 000 Eq. 3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CuttingCoefficients {
    kt_n_per_m2: f64,
    kn_n_per_m2: f64,
}

impl CuttingCoefficients {
    /// From kt and kn in N/m^2 (kt > 0, kn finite).
    pub fn new(kt_n_per_m2: f64, kn_n_per_m2: f64) -> Result<Self> {
        positive("cutting.kt_n_per_mm2", kt_n_per_m2)?;
        finite("cutting.kn_n_per_mm2", kn_n_per_m2)?;
        Ok(Self {
            kt_n_per_m2,
            kn_n_per_m2,
        })
    }

    /// From the resultant ks (N/m^2) and its angle beta: kt = ks sin(beta), kn = ks cos(beta).
    pub fn from_ks_beta(ks_n_per_m2: f64, beta_rad: f64) -> Result<Self> {
        positive("cutting.ks_n_per_mm2", ks_n_per_m2)?;
        finite("cutting.beta_deg", beta_rad)?;
        Self::new(ks_n_per_m2 * beta_rad.sin(), ks_n_per_m2 * beta_rad.cos())
    }

    /// Tangential (cutting) coefficient in N/m^2.
    pub fn kt_n_per_m2(&self) -> f64 {
        self.kt_n_per_m2
    }
    /// Normal (milling) or feed (turning) coefficient in N/m^2.
    pub fn kn_n_per_m2(&self) -> f64 {
        self.kn_n_per_m2
    }
}

/// Residual terms of one coordinate's direct receptance (module docs): G_ii += U - L / w^2.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ResidualTerms {
    /// Upper residual U (m/N): flexibility of the modes above the fitted band.
    pub upper_m_per_n: f64,
    /// Lower residual L (1/kg): inertance of the modes below the fitted band, the term -L / w^2.
    pub lower_per_kg: f64,
}

impl ResidualTerms {
    /// No residual terms.
    pub fn is_zero(&self) -> bool {
        self.upper_m_per_n == 0.0 && self.lower_per_kg == 0.0
    }

    /// U - L / w^2 at `frequency_hz` (m/N; the lower term is left out where L = 0, so a model
    /// without it has a finite static receptance).
    pub fn receptance(&self, frequency_hz: f64) -> f64 {
        let mut g = self.upper_m_per_n;
        if self.lower_per_kg != 0.0 {
            let w = 2.0 * PI * frequency_hz;
            g -= self.lower_per_kg / (w * w);
        }
        g
    }
}

/// A complete machine model: operation, cutting coefficients, modes, optional residual terms
/// and optional process damping.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalModel {
    name: Option<String>,
    operation: Operation,
    cutting: CuttingCoefficients,
    modes: Vec<Mode>,
    residuals: [ResidualTerms; 2],
    process_damping_n_per_m: Option<f64>,
}

impl ModalModel {
    /// A validated model with at least one mode.
    pub fn new(
        name: Option<String>,
        operation: Operation,
        cutting: CuttingCoefficients,
        modes: Vec<Mode>,
        process_damping_n_per_m: Option<f64>,
    ) -> Result<Self> {
        if modes.is_empty() {
            return Err(DynamicsError::invalid(
                "modes",
                "at least one mode expected",
            ));
        }
        if let Some(c) = process_damping_n_per_m {
            non_negative("process_damping.c_n_per_m", c)?;
            if let Some(n) = modes.iter().position(|m| !m.is_proportional()) {
                return Err(DynamicsError::invalid(
                    format!("modes[{n}].residue_phase_deg"),
                    "process damping adds to the damping of real modes; it is not defined for \
                     non-proportional (complex) modes: drop residue_phase_deg or process_damping",
                ));
            }
            if operation.cutting_diameter_m().is_none() {
                return Err(DynamicsError::invalid(
                    "process_damping",
                    "needs the cutting speed: give operation.tool_diameter_mm (milling) or \
                     operation.workpiece_diameter_mm (turning)",
                ));
            }
        }
        Ok(Self {
            name,
            operation,
            cutting,
            modes,
            residuals: [ResidualTerms::default(); 2],
            process_damping_n_per_m,
        })
    }

    /// The same model with residual terms per coordinate (module docs); finite values.
    pub fn with_residuals(&self, residuals: [ResidualTerms; 2]) -> Result<Self> {
        for (i, r) in residuals.iter().enumerate() {
            for (term, v) in [
                ("upper_m_per_n", r.upper_m_per_n),
                ("lower_per_kg", r.lower_per_kg),
            ] {
                // the field's name is written only for the error (samplers rebuild models often)
                if !v.is_finite() {
                    finite(&format!("residuals[{i}].{term}"), v)?;
                }
            }
        }
        Ok(Self {
            residuals,
            ..self.clone()
        })
    }

    /// Residual terms per coordinate (zero where none).
    pub fn residuals(&self) -> [ResidualTerms; 2] {
        self.residuals
    }

    /// Free-text name (which paper table the model comes from, for the examples).
    pub fn name(&self) -> Option<&str> {
        self.name.as_deref()
    }
    /// The operation.
    pub fn operation(&self) -> &Operation {
        &self.operation
    }
    /// The cutting coefficients.
    pub fn cutting(&self) -> CuttingCoefficients {
        self.cutting
    }
    /// The modes.
    pub fn modes(&self) -> &[Mode] {
        &self.modes
    }
    /// Process-damping coefficient C (N/m) in F_d = -C b ydot / V (003 Eq. 1), if any.
    pub fn process_damping_n_per_m(&self) -> Option<f64> {
        self.process_damping_n_per_m
    }

    /// The same model with another operation (e.g. a per-cut radial immersion).
    pub fn with_operation(&self, operation: Operation) -> Result<Self> {
        self.rebuilt(operation, self.modes.clone(), self.process_damping_n_per_m)
    }
    /// The same model with other cutting coefficients.
    pub fn with_cutting(&self, cutting: CuttingCoefficients) -> Self {
        Self {
            cutting,
            ..self.clone()
        }
    }
    /// The same model with other modes (at least one).
    pub fn with_modes(&self, modes: Vec<Mode>) -> Result<Self> {
        self.rebuilt(self.operation.clone(), modes, self.process_damping_n_per_m)
    }
    /// The same model with another process-damping coefficient.
    pub fn with_process_damping(&self, c_n_per_m: Option<f64>) -> Result<Self> {
        self.rebuilt(self.operation.clone(), self.modes.clone(), c_n_per_m)
    }
    /// The model [`ModalModel::new`] checks with this one's name, cutting coefficients and
    /// residual terms (checked when they were set).
    fn rebuilt(
        &self,
        operation: Operation,
        modes: Vec<Mode>,
        process_damping_n_per_m: Option<f64>,
    ) -> Result<Self> {
        let model = Self::new(
            self.name.clone(),
            operation,
            self.cutting,
            modes,
            process_damping_n_per_m,
        )?;
        Ok(Self {
            residuals: self.residuals,
            ..model
        })
    }
    /// The same model renamed.
    pub fn with_name(&self, name: Option<String>) -> Self {
        Self {
            name,
            ..self.clone()
        }
    }

    /// Whether every mode is real (proportionally damped).
    pub fn is_proportional(&self) -> bool {
        self.modes.iter().all(Mode::is_proportional)
    }

    /// An error naming `method` when a mode is non-proportional or the model has residual
    /// terms: for the methods built on real modal coordinates q'' + 2 Z Omega q' + Omega^2 q =
    /// Phi^T f, which represent neither a complex residue nor a receptance term without a mode.
    pub fn require_proportional(&self, method: &str) -> Result<()> {
        if let Some(i) = self.residuals.iter().position(|r| !r.is_zero()) {
            let r = self.residuals[i];
            return Err(DynamicsError::invalid(
                format!("residuals[{}]", self.operation.coordinates()[i].name()),
                format!(
                    "{method} needs modal coordinates, and the residual terms (upper {} m/N, \
                     lower {} 1/kg) have none; use the zero-order method (`--method zoa`), \
                     which takes them, or drop `residuals`",
                    crate::limits::written(r.upper_m_per_n),
                    crate::limits::written(r.lower_per_kg)
                ),
            ));
        }
        match self.modes.iter().position(|m| !m.is_proportional()) {
            None => Ok(()),
            Some(n) => Err(DynamicsError::invalid(
                format!("modes[{n}].residue_phase_deg"),
                format!(
                    "{method} models real (proportionally damped) modes only, and mode {n} \
                     ({} Hz) is non-proportional (residue phase {:.4} deg); use the zero-order \
                     method (`--method zoa`), which takes complex modes",
                    crate::limits::written(self.modes[n].frequency_hz()),
                    self.modes[n].residue_phase_rad().to_degrees()
                ),
            )),
        }
    }

    /// Number of modes N.
    pub fn mode_count(&self) -> usize {
        self.modes.len()
    }
    /// Natural frequencies omega_n (rad/s).
    pub fn omegas_rad_s(&self) -> Vec<f64> {
        self.modes.iter().map(Mode::omega_rad_s).collect()
    }
    /// Damping ratios zeta_n.
    pub fn damping_ratios(&self) -> Vec<f64> {
        self.modes.iter().map(Mode::damping_ratio).collect()
    }
    /// Mass-normalized shape matrix Phi (2 x N, 000 Eq. 1) as rows per coordinate.
    pub fn shape_matrix(&self) -> nalgebra::DMatrix<f64> {
        let n = self.modes.len();
        nalgebra::DMatrix::from_fn(2, n, |i, j| self.modes[j].mass_normalized_shape()[i])
    }
}
