//! The machine-model file of `shared/spec/formats.md`: JSON with units in every field name.
//! Unknown fields are rejected so a typo never passes silently; every error names the file, the
//! field and what was expected.

use crate::error::{DynamicsError, Result};
use crate::limits;
use crate::model::{CuttingCoefficients, ModalModel, Mode, ModeShape, ResidualTerms};
use crate::operation::{Milling, MillingDirection, Operation, Turning};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Model file as written by users (formats spec, "Machine model").
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// Free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Operation.
    pub operation: OperationFile,
    /// Cutting coefficients.
    pub cutting: CuttingFile,
    /// Structural modes (may be empty when `measured_frf` gives the dynamics).
    #[serde(default)]
    pub modes: Vec<ModeFile>,
    /// Residual terms of the direct receptances, at most one entry per coordinate
    /// ([`crate::model`] "Residual terms"): what a band-limited fit (`chatter fit-frf`) adds
    /// for the modes outside its band. Only the zero-order method takes them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub residuals: Option<Vec<ResidualFile>>,
    /// Optional process damping.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub process_damping: Option<ProcessDampingFile>,
    /// Measured receptances that give the dynamics instead of (or beside) `modes`; read by
    /// `chatter-frf`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measured_frf: Option<Vec<MeasuredFrfFile>>,
}

/// One entry of `measured_frf`: a measured FRF file and the coordinates it relates.
///
/// `direction: "x"` is the direct receptance G_xx; `directions: ["x", "y"]` the cross receptance
/// G_xy (response x, force y), also used for G_yx unless that is given too.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MeasuredFrfFile {
    /// The FRF file, relative to the model file: `.csv` (`frequency_hz,real_m_per_n,
    /// imag_m_per_n`), `.uff`/`.unv` (dataset 58), `.frf` (CutPro) or `.txt` (three columns).
    pub file: std::path::PathBuf,
    /// Coordinate of a direct FRF (`x`, `y`, `feed`, `cutting`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<String>,
    /// Response and force coordinates of a cross FRF.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub directions: Option<[String; 2]>,
    /// Which dataset 58 of a universal file (0-based, counting dataset-58 records only);
    /// default the first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dataset: Option<usize>,
    /// Lowest frequency used (Hz), e.g. above a tap test's low-frequency artefacts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fmin_hz: Option<f64>,
    /// Highest frequency used (Hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fmax_hz: Option<f64>,
}

impl MeasuredFrfFile {
    /// The (response, force) coordinate indices of entry `index` in `operation`.
    pub fn coordinates(&self, index: usize, operation: &Operation) -> Result<(usize, usize)> {
        let field = |f: &str| format!("measured_frf[{index}].{f}");
        let coordinate = |name: &str, f: &str| {
            operation.coordinate_index(name).ok_or_else(|| {
                let names: Vec<_> = operation.coordinates().iter().map(|c| c.name()).collect();
                DynamicsError::invalid(
                    field(f),
                    format!(
                        "`{name}` is not a coordinate of this operation; expected one of {names:?}"
                    ),
                )
            })
        };
        match (&self.direction, &self.directions) {
            (Some(d), None) => {
                let i = coordinate(d, "direction")?;
                Ok((i, i))
            }
            (None, Some([r, f])) => {
                Ok((coordinate(r, "directions")?, coordinate(f, "directions")?))
            }
            _ => Err(DynamicsError::invalid(
                field("direction"),
                "expected either `direction` (direct FRF) or `directions` [response, force] \
                 (cross FRF)",
            )),
        }
    }
}

/// `operation` object.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OperationFile {
    /// `"milling"` or `"turning"`.
    pub kind: String,
    /// Milling: number of teeth.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub teeth: Option<i64>,
    /// Milling: radial immersion a/D.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial_immersion: Option<f64>,
    /// Milling: `"up"` or `"down"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<String>,
    /// Milling: tool diameter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool_diameter_mm: Option<f64>,
    /// Milling: helix angle (optional), one value or one per tooth (a variable-helix cutter,
    /// [`crate::Milling::with_helix_deg`]); a helix other than zero spreads the cut along the
    /// axis and needs `tool_diameter_mm`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub helix_deg: Option<HelixDeg>,
    /// Milling, helical cutter (optional): the number of axial slices of the depth (>= 1;
    /// default [`crate::DEFAULT_AXIAL_SLICES`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial_slices: Option<i64>,
    /// Milling, variable pitch (optional): the angle (deg) from each tooth to the tooth ahead of
    /// it, one per tooth, each > 0, summing to 360 ([`crate::Milling::with_pitch_deg`]);
    /// absent: even pitch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch_deg: Option<Vec<f64>>,
    /// Milling (optional): the radial runout of each tooth (micrometres, one per tooth, none
    /// negative; [`crate::Milling::with_runout_um`]); used by the time-domain simulator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runout_um: Option<Vec<f64>>,
    /// Turning: workpiece diameter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub workpiece_diameter_mm: Option<f64>,
}

/// `cutting` object: kt/kn or ks/beta.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CuttingFile {
    /// Tangential coefficient.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kt_n_per_mm2: Option<f64>,
    /// Normal (milling) or feed (turning) coefficient.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kn_n_per_mm2: Option<f64>,
    /// Resultant coefficient.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ks_n_per_mm2: Option<f64>,
    /// Force angle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beta_deg: Option<f64>,
}

/// One entry of `modes`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ModeFile {
    /// Natural frequency.
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
    /// Stiffness (with `direction`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness_n_per_m: Option<f64>,
    /// Coordinate name (with `stiffness_n_per_m`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<String>,
    /// Mass-normalized shape over coordinate names, 1/sqrt(kg).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<BTreeMap<String, f64>>,
    /// Residue phase of a non-proportional (complex) mode, degrees in (-180, 180]; absent or 0
    /// for a real mode ([`crate::model`] module docs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub residue_phase_deg: Option<f64>,
}

/// One entry of `residuals`: G_ii += upper_m_per_n - lower_per_kg / w^2 for coordinate i.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ResidualFile {
    /// Coordinate name (`x`, `y`, `feed`, `cutting`).
    pub direction: String,
    /// Upper residual U (m/N): the modes above the fitted band.
    #[serde(default)]
    pub upper_m_per_n: f64,
    /// Lower residual L (1/kg): the modes below the fitted band, the term -L / w^2.
    #[serde(default)]
    pub lower_per_kg: f64,
}

/// `process_damping` object.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ProcessDampingFile {
    /// Coefficient C in F_d = -C b ydot / V.
    pub c_n_per_m: f64,
}

fn finite_in(field: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(DynamicsError::value(field, v, "a finite number"))
    }
}

/// `operation.helix_deg`: one angle for every tooth or one per tooth.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum HelixDeg {
    /// The same helix on every tooth.
    One(f64),
    /// One helix angle per tooth (variable helix).
    PerTooth(Vec<f64>),
}

impl HelixDeg {
    /// The angles as a slice (one value or one per tooth).
    pub fn as_slice(&self) -> &[f64] {
        match self {
            HelixDeg::One(v) => std::slice::from_ref(v),
            HelixDeg::PerTooth(v) => v,
        }
    }
}

fn opt_f(field: &str, v: Option<f64>) -> Result<Option<f64>> {
    match v {
        Some(x) if !x.is_finite() => Err(DynamicsError::value(field, x, "a finite number")),
        other => Ok(other),
    }
}

impl OperationFile {
    fn validate(&self) -> Result<Operation> {
        match self.kind.as_str() {
            "milling" => {
                if self.workpiece_diameter_mm.is_some() {
                    return Err(DynamicsError::invalid(
                        "operation.workpiece_diameter_mm",
                        "only for turning; milling uses tool_diameter_mm",
                    ));
                }
                let teeth = self.teeth.ok_or_else(|| {
                    DynamicsError::invalid(
                        "operation.teeth",
                        "missing: milling needs the number of teeth",
                    )
                })?;
                if teeth < 1 {
                    return Err(DynamicsError::value(
                        "operation.teeth",
                        teeth as f64,
                        "an integer >= 1",
                    ));
                }
                let r = self.radial_immersion.ok_or_else(|| {
                    DynamicsError::invalid(
                        "operation.radial_immersion",
                        "missing: milling needs the radial immersion a/D in (0, 1]",
                    )
                })?;
                let direction = match self.direction.as_deref() {
                    Some("up") => MillingDirection::Up,
                    Some("down") => MillingDirection::Down,
                    Some(other) => {
                        return Err(DynamicsError::invalid(
                            "operation.direction",
                            format!("`{other}`: expected \"up\" or \"down\""),
                        ));
                    }
                    None => {
                        return Err(DynamicsError::invalid(
                            "operation.direction",
                            "missing: expected \"up\" or \"down\"",
                        ));
                    }
                };
                let d = opt_f("operation.tool_diameter_mm", self.tool_diameter_mm)?;
                let slices = match self.axial_slices {
                    Some(s) if s < 1 => {
                        return Err(DynamicsError::value(
                            "operation.axial_slices",
                            s as f64,
                            "a number of axial slices >= 1",
                        ));
                    }
                    other => other.map(|s| s as usize),
                };
                Ok(Operation::Milling(
                    Milling::new(teeth as usize, r, direction, d.map(|d| d * 1e-3), None)?
                        .with_helix_deg(self.helix_deg.as_ref().map(HelixDeg::as_slice))?
                        .with_axial_slices(slices)?
                        .with_runout_um(self.runout_um.as_deref())?
                        .with_pitch_deg(self.pitch_deg.as_deref())?,
                ))
            }
            "turning" => {
                for (set, name) in [
                    (self.teeth.is_some(), "teeth"),
                    (self.radial_immersion.is_some(), "radial_immersion"),
                    (self.direction.is_some(), "direction"),
                    (self.tool_diameter_mm.is_some(), "tool_diameter_mm"),
                    (self.helix_deg.is_some(), "helix_deg"),
                    (self.axial_slices.is_some(), "axial_slices"),
                    (self.runout_um.is_some(), "runout_um"),
                    (self.pitch_deg.is_some(), "pitch_deg"),
                ] {
                    if set {
                        return Err(DynamicsError::invalid(
                            format!("operation.{name}"),
                            "only for milling",
                        ));
                    }
                }
                let d = opt_f(
                    "operation.workpiece_diameter_mm",
                    self.workpiece_diameter_mm,
                )?;
                Ok(Operation::Turning(Turning::new(d.map(|d| d * 1e-3))?))
            }
            other => Err(DynamicsError::invalid(
                "operation.kind",
                format!("`{other}`: expected \"milling\" or \"turning\""),
            )),
        }
    }
}

impl CuttingFile {
    fn validate(&self) -> Result<CuttingCoefficients> {
        match (
            self.kt_n_per_mm2,
            self.kn_n_per_mm2,
            self.ks_n_per_mm2,
            self.beta_deg,
        ) {
            (Some(kt), Some(kn), None, None) => CuttingCoefficients::new(kt * 1e6, kn * 1e6),
            (None, None, Some(ks), Some(beta)) => {
                CuttingCoefficients::from_ks_beta(ks * 1e6, beta.to_radians())
            }
            _ => Err(DynamicsError::invalid(
                "cutting",
                "expected either kt_n_per_mm2 and kn_n_per_mm2, or ks_n_per_mm2 and beta_deg",
            )),
        }
    }
}

impl ModeFile {
    fn validate(&self, index: usize, operation: &Operation) -> Result<Mode> {
        let field = |f: &str| format!("modes[{index}].{f}");
        let coordinate = |name: &str, f: &str| {
            operation.coordinate_index(name).ok_or_else(|| {
                let names: Vec<_> = operation.coordinates().iter().map(|c| c.name()).collect();
                DynamicsError::invalid(
                    field(f),
                    format!(
                        "`{name}` is not a coordinate of this operation; expected one of {names:?}"
                    ),
                )
            })
        };
        let shape = match (&self.direction, self.stiffness_n_per_m, &self.shape) {
            (Some(dir), Some(k), None) => ModeShape::Directional {
                coordinate: coordinate(dir, "direction")?,
                stiffness_n_per_m: k,
            },
            (None, None, Some(map)) => {
                let mut phi = [0.0; 2];
                for (name, &v) in map {
                    phi[coordinate(name, "shape")?] = v;
                }
                ModeShape::MassNormalized(phi)
            }
            _ => {
                return Err(DynamicsError::invalid(
                    field("shape"),
                    "expected either `direction` with `stiffness_n_per_m`, or `shape`",
                ));
            }
        };
        let mode = Mode::new(self.frequency_hz, self.damping_ratio, shape).and_then(|m| {
            self.residue_phase_deg
                .map_or(Ok(m), |a| m.with_residue_phase(a.to_radians()))
        });
        mode.map_err(|e| match e {
            DynamicsError::InvalidValue {
                field: f,
                value,
                expected,
            } => DynamicsError::InvalidValue {
                field: field(&f),
                value,
                expected,
            },
            DynamicsError::Invalid { field: f, message } => DynamicsError::Invalid {
                field: field(&f),
                message,
            },
            other => other,
        })
    }
}

impl OperationFile {
    /// Plausible values in the file's units ([`crate::limits`]).
    fn check_plausible(&self) -> Result<()> {
        if let Some(t) = self.teeth
            && !(1..=limits::MAX_TEETH).contains(&t)
        {
            return Err(DynamicsError::invalid(
                "operation.teeth",
                format!(
                    "{t}: expected a number of teeth from 1 to {}",
                    limits::MAX_TEETH
                ),
            ));
        }
        if let Some(r) = self.radial_immersion {
            limits::RADIAL_IMMERSION.check("operation.radial_immersion", r)?;
        }
        limits::TOOL_DIAMETER_MM
            .check_optional("operation.tool_diameter_mm", self.tool_diameter_mm)?;
        if let Some(h) = &self.helix_deg {
            let h = h.as_slice();
            for (j, v) in h.iter().enumerate() {
                let field = if h.len() == 1 {
                    "operation.helix_deg".to_string()
                } else {
                    format!("operation.helix_deg[{j}]")
                };
                limits::HELIX_DEG.check(field, *v)?;
            }
        }
        if let Some(s) = self.axial_slices
            && !(1..=limits::MAX_AXIAL_SLICES).contains(&s)
        {
            return Err(DynamicsError::invalid(
                "operation.axial_slices",
                format!(
                    "{s}: expected a number of axial slices from 1 to {}",
                    limits::MAX_AXIAL_SLICES
                ),
            ));
        }
        limits::WORKPIECE_DIAMETER_MM.check_optional(
            "operation.workpiece_diameter_mm",
            self.workpiece_diameter_mm,
        )
    }
}

impl CuttingFile {
    /// Plausible values in the file's units ([`crate::limits`]).
    fn check_plausible(&self) -> Result<()> {
        limits::CUTTING_COEFFICIENT_N_PER_MM2
            .check_optional("cutting.kt_n_per_mm2", self.kt_n_per_mm2)?;
        limits::NORMAL_COEFFICIENT_N_PER_MM2
            .check_optional("cutting.kn_n_per_mm2", self.kn_n_per_mm2)?;
        limits::CUTTING_COEFFICIENT_N_PER_MM2
            .check_optional("cutting.ks_n_per_mm2", self.ks_n_per_mm2)?;
        limits::BETA_DEG.check_optional("cutting.beta_deg", self.beta_deg)
    }
}

impl ModeFile {
    /// Plausible values in the file's units ([`crate::limits`]): frequency, damping, stiffness,
    /// and for a mass-normalized shape the stiffness omega^2 / phi^2 it implies at every
    /// coordinate it moves.
    fn check_plausible(&self, index: usize) -> Result<()> {
        let field = |f: &str| format!("modes[{index}].{f}");
        limits::FREQUENCY_HZ.check(field("frequency_hz"), self.frequency_hz)?;
        limits::DAMPING_RATIO.check(field("damping_ratio"), self.damping_ratio)?;
        limits::STIFFNESS_N_PER_M
            .check_optional(field("stiffness_n_per_m"), self.stiffness_n_per_m)?;
        let omega = 2.0 * std::f64::consts::PI * self.frequency_hz;
        for (name, &phi) in self.shape.iter().flatten() {
            if phi == 0.0 {
                continue;
            }
            let k = omega * omega / (phi * phi);
            if !limits::STIFFNESS_N_PER_M.contains(k) {
                return Err(DynamicsError::value(
                    field(&format!("shape.{name}")),
                    phi,
                    format!(
                        "a mass-normalized component (1/sqrt(kg)) whose stiffness \
                         (2 pi frequency_hz)^2 / shape^2, here {} N/m, is {}",
                        limits::written(k),
                        limits::STIFFNESS_N_PER_M.expected()
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl ModelFile {
    /// Every number against its plausible range in the file's units, and no mode given twice.
    fn check_plausible(&self) -> Result<()> {
        self.operation.check_plausible()?;
        self.cutting.check_plausible()?;
        for (i, m) in self.modes.iter().enumerate() {
            m.check_plausible(i)?;
            if let Some(j) = self.modes[..i].iter().position(|earlier| earlier == m) {
                return Err(DynamicsError::invalid(
                    format!("modes[{i}]"),
                    format!(
                        "repeats modes[{j}] ({} Hz, damping ratio {}): a mode given twice doubles \
                         its flexibility; remove one, or give them different directions or shapes",
                        limits::written(m.frequency_hz),
                        limits::written(m.damping_ratio)
                    ),
                ));
            }
        }
        if let Some(p) = &self.process_damping {
            limits::PROCESS_DAMPING_N_PER_M.check("process_damping.c_n_per_m", p.c_n_per_m)?;
        }
        Ok(())
    }

    /// The validated operation and cutting coefficients alone (what a measured-FRF model needs
    /// besides its receptances).
    pub fn validate_process(&self) -> Result<(Operation, CuttingCoefficients)> {
        self.check_plausible()?;
        Ok((self.operation.validate()?, self.cutting.validate()?))
    }

    /// Validate into a [`ModalModel`] (SI units inside).
    pub fn validate(&self) -> Result<ModalModel> {
        let (operation, cutting) = self.validate_process()?;
        if self.modes.is_empty() && self.measured_frf.is_some() {
            return Err(DynamicsError::invalid(
                "modes",
                "missing: this model gives its dynamics as `measured_frf` only; the zero-order \
                 method works on it directly (`chatter lobes --method zoa`), other methods need \
                 modes (fit them with `chatter fit-frf`)",
            ));
        }
        let modes = self
            .modes
            .iter()
            .enumerate()
            .map(|(i, m)| m.validate(i, &operation))
            .collect::<Result<Vec<_>>>()?;
        let c = self.process_damping.as_ref().map(|p| p.c_n_per_m);
        let mut residuals = [ResidualTerms::default(); 2];
        let mut given = [false; 2];
        for (k, r) in self.residuals.iter().flatten().enumerate() {
            let field = |f: &str| format!("residuals[{k}].{f}");
            let i = operation.coordinate_index(&r.direction).ok_or_else(|| {
                let names: Vec<_> = operation.coordinates().iter().map(|c| c.name()).collect();
                DynamicsError::invalid(
                    field("direction"),
                    format!(
                        "`{}` is not a coordinate of this operation; expected one of {names:?}",
                        r.direction
                    ),
                )
            })?;
            if given[i] {
                return Err(DynamicsError::invalid(
                    field("direction"),
                    format!("`{}` has residual terms twice; give one entry", r.direction),
                ));
            }
            given[i] = true;
            residuals[i] = ResidualTerms {
                upper_m_per_n: finite_in(&field("upper_m_per_n"), r.upper_m_per_n)?,
                lower_per_kg: finite_in(&field("lower_per_kg"), r.lower_per_kg)?,
            };
        }
        ModalModel::new(self.name.clone(), operation, cutting, modes, c)?.with_residuals(residuals)
    }

    /// The file form of a model (inverse of [`ModelFile::validate`]).
    pub fn from_model(model: &ModalModel) -> Self {
        let coords = model.operation().coordinates();
        let operation = match model.operation() {
            Operation::Milling(m) => OperationFile {
                kind: "milling".into(),
                teeth: Some(m.teeth() as i64),
                radial_immersion: Some(m.radial_immersion()),
                direction: Some(
                    match m.direction() {
                        MillingDirection::Up => "up",
                        MillingDirection::Down => "down",
                    }
                    .into(),
                ),
                tool_diameter_mm: m.tool_diameter_m().map(|d| d * 1e3),
                helix_deg: match m.helix_per_tooth_deg() {
                    Some(h) => Some(HelixDeg::PerTooth(h)),
                    None => m.helix_rad().map(|h| HelixDeg::One(h.to_degrees())),
                },
                axial_slices: m.axial_slices().map(|s| s as i64),
                runout_um: m.runout_um(),
                pitch_deg: m.pitch_deg(),
                workpiece_diameter_mm: None,
            },
            Operation::Turning(t) => OperationFile {
                kind: "turning".into(),
                teeth: None,
                radial_immersion: None,
                direction: None,
                tool_diameter_mm: None,
                helix_deg: None,
                axial_slices: None,
                runout_um: None,
                pitch_deg: None,
                workpiece_diameter_mm: t.workpiece_diameter_m().map(|d| d * 1e3),
            },
        };
        let modes = model
            .modes()
            .iter()
            .map(|m| {
                let (stiffness_n_per_m, direction, shape) = match m.shape() {
                    ModeShape::Directional {
                        coordinate,
                        stiffness_n_per_m,
                    } => (
                        Some(stiffness_n_per_m),
                        Some(coords[coordinate].name().to_string()),
                        None,
                    ),
                    ModeShape::MassNormalized(phi) => (
                        None,
                        None,
                        Some(
                            coords
                                .iter()
                                .zip(phi)
                                .map(|(c, v)| (c.name().to_string(), v))
                                .collect(),
                        ),
                    ),
                };
                ModeFile {
                    frequency_hz: m.frequency_hz(),
                    damping_ratio: m.damping_ratio(),
                    stiffness_n_per_m,
                    direction,
                    shape,
                    residue_phase_deg: (!m.is_proportional())
                        .then(|| m.residue_phase_rad().to_degrees()),
                }
            })
            .collect();
        let cutting = model.cutting();
        ModelFile {
            name: model.name().map(str::to_string),
            operation,
            cutting: CuttingFile {
                kt_n_per_mm2: Some(cutting.kt_n_per_m2() * 1e-6),
                kn_n_per_mm2: Some(cutting.kn_n_per_m2() * 1e-6),
                ks_n_per_mm2: None,
                beta_deg: None,
            },
            modes,
            residuals: {
                let entries: Vec<ResidualFile> = coords
                    .iter()
                    .zip(model.residuals())
                    .filter(|(_, r)| !r.is_zero())
                    .map(|(c, r)| ResidualFile {
                        direction: c.name().to_string(),
                        upper_m_per_n: r.upper_m_per_n,
                        lower_per_kg: r.lower_per_kg,
                    })
                    .collect();
                (!entries.is_empty()).then_some(entries)
            },
            process_damping: model
                .process_damping_n_per_m()
                .map(|c| ProcessDampingFile { c_n_per_m: c }),
            measured_frf: None,
        }
    }
}

/// What a JSON text holds at the top level when it is not an object ("an array", "a number",
/// ...), from its first character; None for an object or text that is not JSON at all (the
/// parser names that).
pub(crate) fn non_object(text: &str) -> Option<&'static str> {
    match text.trim_start().chars().next()? {
        '[' => Some("a JSON array"),
        '"' => Some("a JSON string"),
        '-' | '0'..='9' => Some("a JSON number"),
        't' | 'f' => Some("a JSON boolean"),
        'n' => Some("JSON null"),
        _ => None,
    }
}

/// Deserialize the JSON `text` of the file `origin`. A type error names the path of the field
/// (`operation.teeth: invalid type: floating point `2.5`, expected usize at line 1 column 40`):
/// serde_json alone gives only the line and column, and derived deserializers cannot know
/// their own path, so serde_path_to_error (by serde's author, one small dependency-free wrapper
/// over any serde deserializer) tracks it.
pub(crate) fn from_json<T: serde::de::DeserializeOwned>(text: &str, origin: &Path) -> Result<T> {
    let parse_error = |message: String| DynamicsError::Parse {
        path: origin.to_path_buf(),
        message,
    };
    let mut de = serde_json::Deserializer::from_str(text);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        if path.is_empty() || path == "." {
            parse_error(inner.to_string())
        } else {
            parse_error(format!("`{path}`: {inner}"))
        }
    })?;
    // trailing characters after the object, as serde_json::from_str checks them
    de.end().map_err(|e| parse_error(e.to_string()))?;
    Ok(value)
}

impl ModalModel {
    /// Parse and validate a model from JSON text; `origin` names the source in errors.
    pub fn from_json_str(text: &str, origin: &Path) -> Result<Self> {
        if text.trim().is_empty() {
            return Err(DynamicsError::Parse {
                path: origin.to_path_buf(),
                message: "empty file: expected a JSON model object".into(),
            });
        }
        if let Some(kind) = non_object(text) {
            return Err(DynamicsError::Parse {
                path: origin.to_path_buf(),
                message: format!(
                    "the file holds {kind}; expected a JSON model object {{\"operation\": ..., \
                     \"cutting\": ..., \"modes\": [...]}}"
                ),
            });
        }
        let file: ModelFile = from_json(text, origin)?;
        file.validate().map_err(|e| e.in_file(origin))
    }

    /// Read and validate a model file.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| DynamicsError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json_str(&text, path)
    }

    /// Pretty JSON in the formats-spec shape.
    pub fn to_json_string(&self) -> String {
        serde_json::to_string_pretty(&ModelFile::from_model(self))
            .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}
