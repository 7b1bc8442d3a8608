//! Posterior samples as an ArviZ `InferenceData` netCDF-4 file, the layout `arviz.from_netcdf`
//! reads: one HDF5 group per InferenceData group (`posterior`, `prior`, `log_likelihood`), each
//! with the coordinate variables `chain` and `draw` (one chain: iTMCMC and TMCMC give one set of
//! equally weighted samples) and one variable per parameter over (chain, draw); the pointwise
//! log-likelihood is the variable `y` over (chain, draw, observation). Written by the pure-Rust
//! `netcdf-writer` crate (no C library), so the command-line program writes the same file the
//! Python package's `idata.to_netcdf` would, without Python.
//!
//! ```
//! use chatter_jobs::inference_data::{Draws, InferenceData};
//! let names = vec!["theta_omega".to_string()];
//! let rows = vec![vec![0.1], vec![0.2], vec![0.3]];
//! let data = InferenceData {
//!     posterior: Draws { names: &names, rows: &rows },
//!     prior: None,
//!     log_likelihood: None,
//!     attributes: vec![("log_evidence", -12.5)],
//! };
//! let bytes = data.to_netcdf()?;
//! assert_eq!(&bytes[..8], b"\x89HDF\r\n\x1a\n"); // an HDF5 (netCDF-4) file
//! # Ok::<(), chatter_jobs::JobError>(())
//! ```

use crate::error::{JobError, Result};
use netcdf_writer::{DimensionId, NcAttrValue, NcFileBuilder, NcWriteFormat, NcWriteOptions};

/// Equally weighted draws of named parameters.
#[derive(Debug, Clone, Copy)]
pub struct Draws<'a> {
    /// Parameter names (units in the names), the columns of `rows`.
    pub names: &'a [String],
    /// One row per draw.
    pub rows: &'a [Vec<f64>],
}

/// The groups of one InferenceData file.
#[derive(Debug, Clone)]
pub struct InferenceData<'a> {
    /// The posterior samples.
    pub posterior: Draws<'a>,
    /// Draws from the prior, in the same parameters.
    pub prior: Option<Draws<'a>>,
    /// ln p(y_i | theta_s) (nats): one row per posterior draw, one column per observation.
    pub log_likelihood: Option<&'a [Vec<f64>]>,
    /// Numeric attributes of the file (e.g. `log_evidence` in nats).
    pub attributes: Vec<(&'a str, f64)>,
}

impl InferenceData<'_> {
    /// The netCDF-4 file's bytes.
    pub fn to_netcdf(&self) -> Result<Vec<u8>> {
        let mut b = NcFileBuilder::new();
        let mut groups = vec![("posterior", self.posterior)];
        groups.extend(self.prior.map(|p| ("prior", p)));
        for (group, draws) in groups {
            let (chain, draw) = chain_and_draw(&mut b, group, draws.rows.len())?;
            for (k, name) in draws.names.iter().enumerate() {
                let column: Vec<f64> = draws
                    .rows
                    .iter()
                    .map(|r| r.get(k).copied().ok_or_else(|| ragged(group, k)))
                    .collect::<Result<_>>()?;
                let path = format!("{group}/{}", name.replace('/', "_"));
                let v = b
                    .add_variable_path::<f64>(path, &[chain, draw])
                    .map_err(nc)?;
                b.write_variable(v, &column).map_err(nc)?;
            }
            tag(&mut b, group)?;
        }
        if let Some(ll) = self.log_likelihood {
            let group = "log_likelihood";
            let (chain, draw) = chain_and_draw(&mut b, group, ll.len())?;
            let n = ll.first().map_or(0, Vec::len);
            if ll.iter().any(|r| r.len() != n) {
                return Err(ragged(group, n));
            }
            let obs = b
                .add_dimension_path(format!("{group}/observation"), n as u64)
                .map_err(nc)?;
            let index = b
                .add_variable_path::<i64>(format!("{group}/observation"), &[obs])
                .map_err(nc)?;
            b.write_variable(index, &(0..n as i64).collect::<Vec<_>>())
                .map_err(nc)?;
            let y = b
                .add_variable_path::<f64>(format!("{group}/y"), &[chain, draw, obs])
                .map_err(nc)?;
            b.write_variable(y, &ll.concat()).map_err(nc)?;
            tag(&mut b, group)?;
        }
        for (name, value) in &self.attributes {
            b.add_attribute(*name, NcAttrValue::Doubles(vec![*value]))
                .map_err(nc)?;
        }
        b.add_attribute("inference_library", NcAttrValue::Chars("chatter".into()))
            .map_err(nc)?;
        let options = NcWriteOptions {
            format: NcWriteFormat::Nc4,
        };
        Ok(b.to_vec(options).map_err(nc)?.1)
    }
}

/// The `chain` (one) and `draw` dimensions of `group` with their coordinate variables.
fn chain_and_draw(
    b: &mut NcFileBuilder,
    group: &str,
    draws: usize,
) -> Result<(DimensionId, DimensionId)> {
    let chain = b
        .add_dimension_path(format!("{group}/chain"), 1)
        .map_err(nc)?;
    let draw = b
        .add_dimension_path(format!("{group}/draw"), draws as u64)
        .map_err(nc)?;
    let c = b
        .add_variable_path::<i64>(format!("{group}/chain"), &[chain])
        .map_err(nc)?;
    b.write_variable(c, &[0i64]).map_err(nc)?;
    let d = b
        .add_variable_path::<i64>(format!("{group}/draw"), &[draw])
        .map_err(nc)?;
    b.write_variable(d, &(0..draws as i64).collect::<Vec<_>>())
        .map_err(nc)?;
    Ok((chain, draw))
}

/// The group attribute ArviZ writes on every group.
fn tag(b: &mut NcFileBuilder, group: &str) -> Result<()> {
    b.add_group_attribute(
        group,
        "inference_library",
        NcAttrValue::Chars("chatter".into()),
    )
    .map_err(nc)
}

fn ragged(group: &str, column: usize) -> JobError {
    JobError::Invalid {
        field: "inference data",
        value: format!("group {group}, column {column}"),
        expected: "rows of equal length".into(),
    }
}

fn nc(e: netcdf_writer::Error) -> JobError {
    JobError::File {
        path: "netCDF".into(),
        message: e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use netcdf_reader::NcFile;

    /// The file read back by an independent reader (`netcdf-reader`, the sibling crate that
    /// decodes HDF5 itself): groups, dimensions and every value.
    #[test]
    fn posterior_prior_and_log_likelihood_read_back() -> Result<()> {
        let names = vec!["a_mm".to_string(), "b_hz".to_string()];
        let post = vec![vec![1.0, 10.0], vec![2.0, 20.0], vec![3.0, 30.0]];
        let prior = vec![vec![-1.0, 5.0], vec![0.5, 6.0], vec![4.0, 7.0]];
        let ll = vec![vec![-0.5, -1.5], vec![-0.25, -2.0], vec![-1.0, -0.75]];
        let bytes = InferenceData {
            posterior: Draws {
                names: &names,
                rows: &post,
            },
            prior: Some(Draws {
                names: &names,
                rows: &prior,
            }),
            log_likelihood: Some(&ll),
            attributes: vec![("log_evidence", -3.5)],
        }
        .to_netcdf()?;
        let file = NcFile::from_bytes(&bytes).unwrap();
        let read = |path: &str| -> Vec<f64> {
            file.read_variable_as_f64(path)
                .unwrap()
                .iter()
                .copied()
                .collect()
        };
        assert_eq!(read("posterior/a_mm"), vec![1.0, 2.0, 3.0]);
        assert_eq!(read("posterior/b_hz"), vec![10.0, 20.0, 30.0]);
        assert_eq!(read("prior/a_mm"), vec![-1.0, 0.5, 4.0]);
        assert_eq!(read("log_likelihood/y"), ll.concat());
        assert_eq!(read("posterior/draw"), vec![0.0, 1.0, 2.0]);
        let group = file.group("log_likelihood").unwrap();
        assert_eq!(group.name, "log_likelihood");
        Ok(())
    }

    #[test]
    fn ragged_rows_are_an_error() {
        let names = vec!["a".to_string(), "b".to_string()];
        let rows = vec![vec![1.0, 2.0], vec![3.0]];
        let e = InferenceData {
            posterior: Draws {
                names: &names,
                rows: &rows,
            },
            prior: None,
            log_likelihood: None,
            attributes: vec![],
        }
        .to_netcdf()
        .unwrap_err();
        assert!(e.to_string().contains("group posterior"), "{e}");
    }
}
