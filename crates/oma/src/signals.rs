//! Measured vibration records: CSV (first row names the channels, rows are samples) or WAV
//! (its own sample rate), as in the signals section of the formats spec.

use crate::error::{OmaError, Result};
use std::path::Path;

/// Equally sampled channels; the first is the reference.
#[derive(Debug, Clone, PartialEq)]
pub struct Signals {
    /// Channel names.
    pub names: Vec<String>,
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Samples per channel, all the same length.
    pub data: Vec<Vec<f64>>,
}

impl Signals {
    /// Validated signals: at least one channel, equal lengths >= 2, finite samples, rate > 0.
    pub fn new(names: Vec<String>, sample_rate_hz: f64, data: Vec<Vec<f64>>) -> Result<Self> {
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return Err(OmaError::InvalidInput {
                field: "sample_rate_hz",
                message: format!("{sample_rate_hz}; expected a rate > 0"),
            });
        }
        if data.is_empty() || names.len() != data.len() {
            return Err(OmaError::InvalidInput {
                field: "channels",
                message: format!("{} names for {} channels", names.len(), data.len()),
            });
        }
        let n = data[0].len();
        if n < 2 || data.iter().any(|c| c.len() != n) {
            return Err(OmaError::InvalidInput {
                field: "samples",
                message: "every channel needs the same number (>= 2) of samples".into(),
            });
        }
        Ok(Self {
            names,
            sample_rate_hz,
            data,
        })
    }

    /// Index of a channel by name.
    pub fn channel(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Read a CSV record at `sample_rate_hz`.
    pub fn from_csv(path: &Path, sample_rate_hz: f64) -> Result<Self> {
        let err = |message: String| OmaError::File {
            path: path.to_path_buf(),
            message,
        };
        let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines.next().ok_or_else(|| err("empty file".into()))?;
        let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
        let mut data = vec![Vec::new(); names.len()];
        for (i, line) in lines {
            let fields: Vec<&str> = line.split(',').collect();
            if fields.len() != names.len() {
                return Err(err(format!(
                    "line {}: {} values for {} channels",
                    i + 1,
                    fields.len(),
                    names.len()
                )));
            }
            for (c, f) in fields.iter().enumerate() {
                let v: f64 = f.trim().parse().map_err(|_| {
                    err(format!(
                        "line {}, channel `{}`: `{}` is not a number",
                        i + 1,
                        names[c],
                        f.trim()
                    ))
                })?;
                if !v.is_finite() {
                    return Err(err(format!(
                        "line {}, channel `{}`: not finite",
                        i + 1,
                        names[c]
                    )));
                }
                data[c].push(v);
            }
        }
        Self::new(names, sample_rate_hz, data).map_err(|e| err(e.to_string()))
    }

    /// Read a WAV record (integer or float samples, any channel count); channels are named
    /// `ch1`, `ch2`, ... unless `names` gives them.
    pub fn from_wav(path: &Path, names: Option<Vec<String>>) -> Result<Self> {
        let err = |message: String| OmaError::File {
            path: path.to_path_buf(),
            message,
        };
        let mut reader = hound::WavReader::open(path).map_err(|e| err(e.to_string()))?;
        let spec = reader.spec();
        let nc = spec.channels as usize;
        let samples: Vec<f64> = match spec.sample_format {
            hound::SampleFormat::Float => reader
                .samples::<f32>()
                .map(|s| s.map(f64::from))
                .collect::<std::result::Result<_, _>>(),
            hound::SampleFormat::Int => {
                let scale = 2f64.powi(spec.bits_per_sample as i32 - 1);
                reader
                    .samples::<i32>()
                    .map(|s| s.map(|v| v as f64 / scale))
                    .collect::<std::result::Result<_, _>>()
            }
        }
        .map_err(|e| err(e.to_string()))?;
        let mut data = vec![Vec::with_capacity(samples.len() / nc.max(1)); nc];
        for (k, v) in samples.into_iter().enumerate() {
            data[k % nc].push(v);
        }
        let names = names.unwrap_or_else(|| (1..=nc).map(|i| format!("ch{i}")).collect());
        Self::new(names, spec.sample_rate as f64, data).map_err(|e| err(e.to_string()))
    }
}
