//! Models whose dynamics are measured FRFs: the `measured_frf` list of a model file
//! ([`chatter_dynamics::MeasuredFrfFile`]), each file read by its extension and assembled into
//! the 2 x 2 receptance matrix of the operation's coordinates on one frequency grid.
//!
//! The grid is the first entry's frequencies inside the band every entry covers (and inside
//! each entry's optional `fmin_hz` / `fmax_hz`); the other entries are interpolated onto it,
//! linear in real and imaginary parts. A cross entry G_rf also fills G_fr unless that is given
//! too (reciprocity); entries not given are zero, so one direct FRF of a milling model is the
//! oriented single-direction case.

use crate::error::{FrfError, Result};
use crate::frf::Frf;
use crate::text::{parse_columns, parse_csv, read_text};
use crate::uff::read_uff58;
use chatter_dynamics::{
    CuttingCoefficients, DynamicsError, MeasuredFrfFile, ModelFile, Operation, SampledReceptance,
};
use num_complex::Complex64;
use std::path::{Path, PathBuf};

/// Read one FRF file by its extension: `.csv`, `.uff` / `.unv` (dataset 58 number `dataset`,
/// counting dataset-58 records from 0; default 0) or anything else as whitespace columns
/// (`.frf`, `.txt`).
pub fn read_frf(path: &Path, dataset: Option<usize>) -> Result<Frf> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if dataset.is_some() && !matches!(ext.as_str(), "uff" | "unv") {
        return Err(FrfError::parse(
            path,
            0,
            "`dataset` applies to universal files (.uff, .unv) only",
        ));
    }
    match ext.as_str() {
        "csv" => parse_csv(&read_text(path)?, path),
        "uff" | "unv" => {
            let records = read_uff58(path)?;
            let k = dataset.unwrap_or(0);
            let Some(r) = records.get(k) else {
                return Err(FrfError::parse(
                    path,
                    0,
                    format!(
                        "dataset {k} requested but the file holds {} dataset-58 records",
                        records.len()
                    ),
                ));
            };
            r.to_frf(path)
        }
        _ => parse_columns(&read_text(path)?, path),
    }
}

/// Read a model file's JSON (no validation of the modes).
pub fn read_model_file(path: &Path) -> Result<ModelFile> {
    let text = read_text(path)?;
    serde_json::from_str(&text).map_err(|e| {
        FrfError::Dynamics(DynamicsError::Parse {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
    })
}

/// A model whose structure is a measured receptance.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredModel {
    /// Free-text name.
    pub name: Option<String>,
    /// The operation.
    pub operation: Operation,
    /// The cutting coefficients.
    pub cutting: CuttingCoefficients,
    /// The measured receptance matrix.
    pub receptance: SampledReceptance,
}

impl MeasuredModel {
    /// Read a model file whose `measured_frf` gives its dynamics; FRF paths are relative to the
    /// model file.
    pub fn from_path(path: &Path) -> Result<Self> {
        let file = read_model_file(path)?;
        let base = path.parent().unwrap_or(Path::new("."));
        Self::from_file(&file, base).map_err(|e| match e {
            FrfError::Dynamics(d) => FrfError::Dynamics(d.in_file(path)),
            other => other,
        })
    }

    /// The model of a parsed model file, FRF paths relative to `base_dir`.
    pub fn from_file(file: &ModelFile, base_dir: &Path) -> Result<Self> {
        let (operation, cutting) = file.validate_process()?;
        let Some(entries) = file.measured_frf.as_deref().filter(|e| !e.is_empty()) else {
            return Err(DynamicsError::invalid(
                "measured_frf",
                "missing: expected a list of {\"file\": PATH, \"direction\": \"x\"} entries",
            )
            .into());
        };
        let mut loaded: Vec<((usize, usize), Frf, PathBuf)> = Vec::new();
        for (k, entry) in entries.iter().enumerate() {
            let ij = entry.coordinates(k, &operation)?;
            if loaded.iter().any(|(c, _, _)| *c == ij) {
                return Err(DynamicsError::invalid(
                    format!("measured_frf[{k}]"),
                    "a second FRF for the same coordinates; give each direct or cross term once",
                )
                .into());
            }
            let p = base_dir.join(&entry.file);
            let frf = read_frf(&p, entry.dataset)?;
            let frf = band(entry, k, frf)?;
            loaded.push((ij, frf, p));
        }
        let lo = loaded
            .iter()
            .map(|(_, f, _)| f.frequencies_hz()[0])
            .fold(f64::NEG_INFINITY, f64::max);
        let hi = loaded
            .iter()
            .map(|(_, f, _)| f.frequencies_hz()[f.len() - 1])
            .fold(f64::INFINITY, f64::min);
        let grid: Vec<f64> = loaded[0]
            .1
            .frequencies_hz()
            .iter()
            .copied()
            .filter(|&f| f >= lo && f <= hi)
            .collect();
        if grid.len() < 2 {
            return Err(DynamicsError::invalid(
                "measured_frf",
                format!(
                    "the files share no band of at least two frequencies (common band {lo} to {hi} Hz)"
                ),
            )
            .into());
        }
        let zero = Complex64::new(0.0, 0.0);
        let mut matrices = vec![[[zero; 2]; 2]; grid.len()];
        let explicit: Vec<(usize, usize)> = loaded.iter().map(|(c, _, _)| *c).collect();
        for ((i, j), frf, _) in &loaded {
            for (m, &f) in matrices.iter_mut().zip(&grid) {
                let g = frf.interpolate(f).unwrap_or(zero);
                m[*i][*j] = g;
                if i != j && !explicit.contains(&(*j, *i)) {
                    m[*j][*i] = g;
                }
            }
        }
        Ok(Self {
            name: file.name.clone(),
            operation,
            cutting,
            receptance: SampledReceptance::new(grid, matrices)?,
        })
    }
}

/// The entry's FRF inside its optional band.
fn band(entry: &MeasuredFrfFile, k: usize, frf: Frf) -> Result<Frf> {
    match (entry.fmin_hz, entry.fmax_hz) {
        (None, None) => Ok(frf),
        (lo, hi) => frf
            .band(lo.unwrap_or(0.0), hi.unwrap_or(f64::MAX))
            .map_err(|e| {
                DynamicsError::invalid(format!("measured_frf[{k}].fmin_hz/fmax_hz"), e.to_string())
                    .into()
            }),
    }
}
