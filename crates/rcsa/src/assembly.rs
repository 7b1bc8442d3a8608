//! Tool-holder-spindle assemblies: the assembly file, the spindle-machine receptances (rigid,
//! measured, or decoupled from an artifact tap test by Eq. 1) and the tool-tip FRF (Eq. 3).
//!
//! The assembly is coupled from the spindle outward: the holder (a free-free beam, end 1 its free
//! face, end 2 the spindle side) is joined rigidly to the spindle receptance S, then the tool
//! (end 1 its tip, end 2 its shank end) is joined to the holder face through the connection of
//! Eq. 4:
//!
//! G_holder = H11 - H12 (H22 + S)^-1 H21, G_tip = T11 - T12 (T22 + K^-1 + G_holder)^-1 T21.
//!
//! Without a holder the tool joins the spindle directly (G_holder = S). The tool-tip FRF is
//! h of G_tip, the (1, 1) entry of Schmitz et al. (2022, Eq. 3).
//!
//! File format (JSON, unknown fields rejected; paths relative to the assembly file):
//!
//! ```json
//! {
//!   "tool":   [{"length_mm": 65, "outer_diameter_mm": 10.2, "youngs_modulus_gpa": 585,
//!               "density_kg_per_m3": 14500, "poisson_ratio": 0.22}],
//!   "holder": [{"length_mm": 40, "outer_diameter_mm": 32, "inner_diameter_mm": 12.7,
//!               "youngs_modulus_gpa": 200, "density_kg_per_m3": 7800, "poisson_ratio": 0.29,
//!               "loss_factor": 0.002}],
//!   "connection": {"k_n_per_rad": 5e6, "c_n_s_per_rad": 15},
//!   "spindle": "rigid",
//!   "fmin_hz": 100, "fmax_hz": 5000, "points": 2000
//! }
//! ```
//!
//! `connection` is `"rigid"` or a [`FlexibleConnection`]; `spindle` is `"rigid"`,
//! `{"measured_frf": {"h": {"file": F}, "l": ..., "n": ..., "p": ...}}` (the spindle-nose
//! receptances; `l`, `p` absent = rigid in rotation, `n` absent = `l`) or
//! `{"artifact": {"segments": [...], "tip_frf": {"h": ..., "l": ..., "p": ...}}}` (the
//! receptances measured at the free end of an artifact clamped in the spindle, decoupled by
//! Eq. 1). Each FRF entry is `{"file": PATH, "dataset": N}` with the readers of `chatter-frf`.

use crate::beam::{Receptance, Segment, free_free_receptances};
use crate::coupling::{Connection, FlexibleConnection, couple, decouple};
use crate::error::{RcsaError, Result};
use chatter_frf::{Frf, read_frf};
use num_complex::Complex64;
use serde::Deserialize;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// One measured FRF in an assembly file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrfEntry {
    /// CSV, UFF dataset 58, CutPro `.frf` or text columns (see `chatter_frf::read_frf`).
    pub file: PathBuf,
    /// Dataset 58 record of a universal file (0-based).
    #[serde(default)]
    pub dataset: Option<usize>,
}

/// Measured 2 x 2 receptances [[h, l], [n, p]] at one point.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReceptanceFiles {
    /// Displacement per force (m/N).
    pub h: FrfEntry,
    /// Displacement per moment (1/N).
    #[serde(default)]
    pub l: Option<FrfEntry>,
    /// Rotation per force (1/N); `l` when absent (reciprocity).
    #[serde(default)]
    pub n: Option<FrfEntry>,
    /// Rotation per moment (1/(N m)).
    #[serde(default)]
    pub p: Option<FrfEntry>,
}

/// A standard artifact clamped in the spindle and tap-tested at its free end.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArtifactFile {
    /// The artifact's segments from its free end inward.
    pub segments: Vec<Segment>,
    /// The receptances measured at its free end (`h`, `l` and `p` required).
    pub tip_frf: ReceptanceFiles,
}

/// The `spindle` entry of an assembly file.
#[derive(Debug, Clone, PartialEq)]
pub enum SpindleFile {
    /// A rigid spindle (zero receptance).
    Rigid,
    /// Measured spindle-nose receptances.
    Measured(ReceptanceFiles),
    /// An artifact tap test to decouple (Eq. 1).
    Artifact(ArtifactFile),
}

/// The `connection` entry of an assembly file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConnectionFile(pub Connection);

fn one_of_words(value: &serde_json::Value, expected: &str) -> String {
    format!("{value} (expected {expected})")
}

impl<'de> Deserialize<'de> for ConnectionFile {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Error;
        let v = serde_json::Value::deserialize(d)?;
        match &v {
            serde_json::Value::String(s) if s == "rigid" => Ok(Self(Connection::Rigid)),
            serde_json::Value::Object(_) => serde_json::from_value::<FlexibleConnection>(v)
                .map(|c| Self(Connection::Flexible(c)))
                .map_err(|e| D::Error::custom(format!("connection: {e}"))),
            _ => Err(D::Error::custom(format!(
                "connection: {}",
                one_of_words(
                    &v,
                    "\"rigid\" or {\"k_n_per_rad\": .., \"c_n_s_per_rad\": ..}"
                )
            ))),
        }
    }
}

impl<'de> Deserialize<'de> for SpindleFile {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Error;
        let v = serde_json::Value::deserialize(d)?;
        let expected = "\"rigid\", {\"measured_frf\": {..}} or {\"artifact\": {..}}";
        match &v {
            serde_json::Value::String(s) if s == "rigid" => Ok(Self::Rigid),
            serde_json::Value::Object(map) if map.len() == 1 => {
                let (key, inner) = map.iter().next().expect("one entry");
                let inner = inner.clone();
                let err = |e: serde_json::Error| D::Error::custom(format!("spindle.{key}: {e}"));
                match key.as_str() {
                    "measured_frf" => serde_json::from_value(inner)
                        .map(Self::Measured)
                        .map_err(err),
                    "artifact" => serde_json::from_value(inner)
                        .map(Self::Artifact)
                        .map_err(err),
                    _ => Err(D::Error::custom(format!(
                        "spindle: {}",
                        one_of_words(&v, expected)
                    ))),
                }
            }
            _ => Err(D::Error::custom(format!(
                "spindle: {}",
                one_of_words(&v, expected)
            ))),
        }
    }
}

/// An assembly file as written (see the module docs).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AssemblyFile {
    /// Tool segments from the tip inward (the stick-out).
    pub tool: Vec<Segment>,
    /// Holder segments from its free face inward; empty = the tool is clamped directly.
    pub holder: Vec<Segment>,
    /// Holder-tool connection (Eq. 4).
    pub connection: ConnectionFile,
    /// Spindle-machine receptance at the holder's spindle end.
    pub spindle: SpindleFile,
    /// Lowest frequency of the predicted FRF (Hz, > 0).
    pub fmin_hz: f64,
    /// Highest frequency (Hz).
    pub fmax_hz: f64,
    /// Number of evenly spaced frequencies (>= 2).
    pub points: usize,
}

/// Receptance matrices sampled at strictly increasing frequencies, linearly interpolated.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledReceptance {
    frequencies_hz: Vec<f64>,
    values: Vec<Receptance>,
}

impl SampledReceptance {
    /// Validated: one value per frequency, at least two, frequencies strictly increasing.
    pub fn new(frequencies_hz: Vec<f64>, values: Vec<Receptance>) -> Result<Self> {
        if frequencies_hz.len() != values.len() || values.len() < 2 {
            return Err(RcsaError::value(
                "receptance samples",
                values.len() as f64,
                format!("at least 2, one per frequency ({})", frequencies_hz.len()),
            ));
        }
        if let Some(w) = frequencies_hz
            .windows(2)
            .find(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
        {
            return Err(RcsaError::value(
                "frequency_hz",
                w[1],
                format!("above the previous frequency {} Hz", w[0]),
            ));
        }
        Ok(Self {
            frequencies_hz,
            values,
        })
    }

    /// The sampled frequencies (Hz).
    pub fn frequencies_hz(&self) -> &[f64] {
        &self.frequencies_hz
    }

    /// The sampled receptances.
    pub fn values(&self) -> &[Receptance] {
        &self.values
    }

    /// Linear interpolation at `frequency_hz`; an error outside the sampled band.
    pub fn at(&self, frequency_hz: f64) -> Result<Receptance> {
        let f = &self.frequencies_hz;
        let (lo, hi) = (f[0], f[f.len() - 1]);
        if !(frequency_hz >= lo && frequency_hz <= hi) {
            return Err(RcsaError::value(
                "frequency_hz",
                frequency_hz,
                format!("inside the measured spindle band {lo} - {hi} Hz"),
            ));
        }
        let i = f
            .partition_point(|&x| x <= frequency_hz)
            .clamp(1, f.len() - 1);
        let t = (frequency_hz - f[i - 1]) / (f[i] - f[i - 1]);
        Ok(self.values[i - 1] * Complex64::new(1.0 - t, 0.0)
            + self.values[i] * Complex64::new(t, 0.0))
    }
}

/// The spindle-machine receptance the holder is joined to.
#[derive(Debug, Clone, PartialEq)]
pub enum Spindle {
    /// Zero receptance.
    Rigid,
    /// Sampled receptances (measured, or decoupled from an artifact).
    Sampled(SampledReceptance),
}

impl Spindle {
    /// The receptance at `frequency_hz`.
    pub fn at(&self, frequency_hz: f64) -> Result<Receptance> {
        match self {
            Spindle::Rigid => Ok(Receptance::zeros()),
            Spindle::Sampled(s) => s.at(frequency_hz),
        }
    }

    /// Inverse RCSA (Eq. 1): the spindle receptances that give the artifact tip receptances
    /// `measured` when the artifact (`segments`, free end first) is clamped rigidly in them.
    /// Frequencies at or below 0 Hz are skipped (a free-free artifact has no receptance there).
    pub fn from_artifact(segments: &[Segment], measured: &SampledReceptance) -> Result<Self> {
        let (f, g): (Vec<f64>, Vec<Receptance>) = measured
            .frequencies_hz
            .iter()
            .zip(&measured.values)
            .filter(|(f, _)| **f > 0.0)
            .map(|(&f, g)| Ok((f, decouple(&free_free_receptances(segments, f)?, g, f)?)))
            .collect::<Result<Vec<_>>>()?
            .into_iter()
            .unzip();
        Ok(Spindle::Sampled(SampledReceptance::new(f, g)?))
    }
}

/// A validated assembly: segments, connection, spindle and band.
#[derive(Debug, Clone, PartialEq)]
pub struct Assembly {
    /// Tool segments from the tip inward.
    pub tool: Vec<Segment>,
    /// Holder segments from its free face inward (empty: no holder).
    pub holder: Vec<Segment>,
    /// Holder-tool connection.
    pub connection: Connection,
    /// Spindle-machine receptance.
    pub spindle: Spindle,
    /// Frequencies of the prediction (Hz).
    pub frequencies_hz: Vec<f64>,
}

fn validate_segments(segments: &[Segment], name: &str) -> Result<()> {
    segments
        .iter()
        .enumerate()
        .try_for_each(|(i, s)| s.validate(&format!("{name}[{i}]")))
}

/// Evenly spaced frequencies from `fmin_hz` to `fmax_hz` (validated: 0 < fmin < fmax, points >= 2).
pub fn frequency_band(fmin_hz: f64, fmax_hz: f64, points: usize) -> Result<Vec<f64>> {
    if !(fmin_hz.is_finite() && fmin_hz > 0.0) {
        return Err(RcsaError::value(
            "fmin_hz",
            fmin_hz,
            "a finite frequency > 0",
        ));
    }
    if !(fmax_hz.is_finite() && fmax_hz > fmin_hz) {
        return Err(RcsaError::value(
            "fmax_hz",
            fmax_hz,
            format!("a finite frequency above fmin_hz = {fmin_hz}"),
        ));
    }
    if points < 2 {
        return Err(RcsaError::value("points", points as f64, "at least 2"));
    }
    let step = (fmax_hz - fmin_hz) / (points - 1) as f64;
    Ok((0..points).map(|i| fmin_hz + step * i as f64).collect())
}

/// Read the receptances of `files` (paths relative to `base_dir`) on the grid of `h`; the
/// missing `l`, `p` are zero unless `require_all`, `n` defaults to `l`.
fn read_receptances(
    files: &ReceptanceFiles,
    base_dir: &Path,
    at: &str,
    require_all: bool,
) -> Result<SampledReceptance> {
    let read = |e: &FrfEntry| read_frf(&base_dir.join(&e.file), e.dataset);
    let h = read(&files.h)?;
    let f = h.frequencies_hz().to_vec();
    let on_grid = |entry: Option<&FrfEntry>, name: &str| -> Result<Vec<Complex64>> {
        let Some(entry) = entry else {
            if require_all {
                return Err(RcsaError::Parse {
                    path: base_dir.join("<assembly>"),
                    message: format!(
                        "{at}.{name}: missing (the artifact's decoupling needs h, l and p)"
                    ),
                });
            }
            return Ok(vec![Complex64::new(0.0, 0.0); f.len()]);
        };
        let frf: Frf = read(entry)?;
        f.iter()
            .map(|&x| {
                frf.interpolate(x).ok_or_else(|| {
                    RcsaError::value(
                        format!("{at}.{name} ({})", entry.file.display()),
                        x,
                        "a frequency of h inside this file's band",
                    )
                })
            })
            .collect()
    };
    let l = on_grid(files.l.as_ref(), "l")?;
    let n = match &files.n {
        Some(_) => on_grid(files.n.as_ref(), "n")?,
        None => l.clone(),
    };
    let p = on_grid(files.p.as_ref(), "p")?;
    let values = (0..f.len())
        .map(|i| Receptance::new(h.receptance_m_per_n()[i], l[i], n[i], p[i]))
        .collect();
    SampledReceptance::new(f, values)
}

impl Assembly {
    /// Read and validate an assembly file (see the module docs).
    ///
    /// ```no_run
    /// let a = chatter_rcsa::Assembly::from_path(std::path::Path::new("tool.json"))?;
    /// let tip = a.tool_tip_frf()?;
    /// # Ok::<(), chatter_rcsa::RcsaError>(())
    /// ```
    pub fn from_path(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| RcsaError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let file: AssemblyFile = serde_json::from_str(&text).map_err(|e| RcsaError::Parse {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let base = path.parent().unwrap_or(Path::new("."));
        Self::from_file(&file, base).map_err(|e| match e {
            RcsaError::InvalidValue { .. } | RcsaError::Singular { .. } => RcsaError::Parse {
                path: path.to_path_buf(),
                message: e.to_string(),
            },
            other => other,
        })
    }

    /// Validate a parsed file; measured FRF paths are relative to `base_dir`.
    pub fn from_file(file: &AssemblyFile, base_dir: &Path) -> Result<Self> {
        if file.tool.is_empty() {
            return Err(RcsaError::value("tool", 0.0, "at least one segment"));
        }
        validate_segments(&file.tool, "tool")?;
        validate_segments(&file.holder, "holder")?;
        file.connection.0.validate("connection")?;
        let frequencies_hz = frequency_band(file.fmin_hz, file.fmax_hz, file.points)?;
        let spindle = match &file.spindle {
            SpindleFile::Rigid => Spindle::Rigid,
            SpindleFile::Measured(m) => Spindle::Sampled(read_receptances(
                m,
                base_dir,
                "spindle.measured_frf",
                false,
            )?),
            SpindleFile::Artifact(a) => {
                if a.segments.is_empty() {
                    return Err(RcsaError::value(
                        "spindle.artifact.segments",
                        0.0,
                        "at least one segment",
                    ));
                }
                validate_segments(&a.segments, "spindle.artifact.segments")?;
                let g = read_receptances(&a.tip_frf, base_dir, "spindle.artifact.tip_frf", true)?;
                Spindle::from_artifact(&a.segments, &g)?
            }
        };
        if let Spindle::Sampled(s) = &spindle {
            let f = s.frequencies_hz();
            let (lo, hi) = (f[0], f[f.len() - 1]);
            if file.fmin_hz < lo || file.fmax_hz > hi {
                return Err(RcsaError::value(
                    "fmin_hz/fmax_hz",
                    if file.fmin_hz < lo {
                        file.fmin_hz
                    } else {
                        file.fmax_hz
                    },
                    format!("inside the spindle's measured band {lo} - {hi} Hz"),
                ));
            }
        }
        Ok(Self {
            tool: file.tool.clone(),
            holder: file.holder.clone(),
            connection: file.connection.0,
            spindle,
            frequencies_hz,
        })
    }

    /// The full 2 x 2 tool-tip receptance G11 at `frequency_hz` (Eq. 3, module docs).
    pub fn tool_tip_receptance(&self, frequency_hz: f64) -> Result<Receptance> {
        let spindle = self.spindle.at(frequency_hz)?;
        let base = if self.holder.is_empty() {
            spindle
        } else {
            let holder = free_free_receptances(&self.holder, frequency_hz)?;
            couple(&holder, &spindle, &Receptance::zeros(), frequency_hz)?
        };
        let tool = free_free_receptances(&self.tool, frequency_hz)?;
        let joint = self.connection.compliance(2.0 * PI * frequency_hz);
        couple(&tool, &base, &joint, frequency_hz)
    }

    /// The tool-tip FRF h(G11) over the assembly's band.
    pub fn tool_tip_frf(&self) -> Result<Frf> {
        let h = self
            .frequencies_hz
            .iter()
            .map(|&f| Ok(self.tool_tip_receptance(f)?[(0, 0)]))
            .collect::<Result<Vec<_>>>()?;
        Ok(Frf::new(self.frequencies_hz.clone(), h)?)
    }

    /// The same assembly with another connection (for Monte Carlo over k and c).
    pub fn with_connection(&self, connection: Connection) -> Self {
        Self {
            connection,
            ..self.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Assembly> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.json");
        std::fs::write(&path, text).unwrap();
        Assembly::from_path(&path)
    }

    const ROD: &str = r#"{"length_mm": 100, "outer_diameter_mm": 10, "youngs_modulus_gpa": 200,
        "density_kg_per_m3": 7800, "poisson_ratio": 0.3}"#;

    fn file(tool: &str, connection: &str, spindle: &str) -> String {
        format!(
            r#"{{"tool": [{tool}], "holder": [], "connection": {connection}, "spindle": {spindle},
                "fmin_hz": 10, "fmax_hz": 2000, "points": 50}}"#
        )
    }

    #[test]
    fn a_rigid_rod_reads() {
        let a = parse(&file(ROD, r#""rigid""#, r#""rigid""#)).unwrap();
        assert_eq!(a.tool_tip_frf().unwrap().len(), 50);
    }

    #[test]
    fn bad_input_names_file_field_value_and_expectation() {
        let e = parse(&file(&ROD.replace("100", "-5"), r#""rigid""#, r#""rigid""#))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a.json")
                && e.contains("tool[0].length_mm")
                && e.contains("-5")
                && e.contains("> 0"),
            "{e}"
        );
        let e = parse(&file(
            &ROD.replace("\"poisson_ratio\"", "\"poison\""),
            r#""rigid""#,
            r#""rigid""#,
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains("unknown field `poison`"), "{e}");
        let e = parse(&file(ROD, r#""glued""#, r#""rigid""#))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("connection") && e.contains("glued") && e.contains("rigid"),
            "{e}"
        );
        let e = parse(&file(ROD, r#"{"k_n_per_rad": 1e6, "c": 3}"#, r#""rigid""#))
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown field `c`"), "{e}");
        let e = parse(&file(
            ROD,
            r#"{"k_n_per_rad": 0, "c_n_s_per_rad": 3}"#,
            r#""rigid""#,
        ))
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("connection.k_n_per_rad") && e.contains("> 0"),
            "{e}"
        );
        let e = parse(&file(ROD, r#""rigid""#, r#"{"tap": 1}"#))
            .unwrap_err()
            .to_string();
        assert!(e.contains("spindle") && e.contains("measured_frf"), "{e}");
        let e = parse(&file(
            ROD,
            r#""rigid""#,
            r#"{"measured_frf": {"h": {"file": "nope.csv"}}}"#,
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains("nope.csv"), "{e}");
        let e = parse(
            &file(ROD, r#""rigid""#, r#""rigid""#).replace("\"points\": 50", "\"points\": 1"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("points") && e.contains("at least 2"), "{e}");
        assert!(parse("{").is_err());
    }
}
