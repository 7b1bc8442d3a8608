//! First singular value of the cross power spectral density matrix over frequency, the curve
//! stabilization diagrams are drawn on (000 Fig. 3, 002 Fig. 5).
//!
//! The PSD matrix G(f) (channels x channels, Hermitian) is estimated by Welch's method: Hann
//! windowed segments of `segment_len` samples with 50 % overlap, G_ij = sum_s X_i conj(X_j)
//! scaled to a one-sided density (units^2 / Hz). Its singular values at each frequency are
//! those of nalgebra's complex SVD; the first (largest) is returned.

use crate::error::{OmaError, Result};
use nalgebra::DMatrix;
use num_complex::Complex64;
use rustfft::FftPlanner;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A real spectrum over frequency.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Spectrum {
    /// Frequencies (Hz), 0 to the Nyquist frequency.
    pub frequencies_hz: Vec<f64>,
    /// Value at each frequency.
    pub values: Vec<f64>,
}

/// First singular value of the Welch cross-PSD matrix of `data` (equal-length channels sampled
/// at `sample_rate_hz`) with segments of `segment_len` samples (>= 4 and at most the record).
pub fn first_singular_value(
    data: &[Vec<f64>],
    sample_rate_hz: f64,
    segment_len: usize,
) -> Result<Spectrum> {
    let l = data.first().map_or(0, Vec::len);
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(OmaError::InvalidInput {
            field: "sample_rate_hz",
            message: format!("{sample_rate_hz}; expected a rate > 0"),
        });
    }
    if segment_len < 4 || segment_len > l || data.iter().any(|c| c.len() != l) {
        return Err(OmaError::InvalidInput {
            field: "segment_len",
            message: format!(
                "{segment_len} samples per segment of {} channels of {l} samples; expected 4 \
                 to the (common) record length",
                data.len()
            ),
        });
    }
    let window: Vec<f64> = (0..segment_len)
        .map(|k| 0.5 - 0.5 * (2.0 * PI * k as f64 / segment_len as f64).cos())
        .collect();
    let fft = FftPlanner::<f64>::new().plan_fft_forward(segment_len);
    let bins = segment_len / 2 + 1;
    let nc = data.len();
    let step = segment_len / 2;
    let starts: Vec<usize> = (0..=(l - segment_len) / step).map(|s| s * step).collect();
    let mut g = vec![DMatrix::<Complex64>::zeros(nc, nc); bins];
    for &s in &starts {
        let spectra: Vec<Vec<Complex64>> = data
            .iter()
            .map(|ch| {
                let mut buf: Vec<Complex64> = ch[s..s + segment_len]
                    .iter()
                    .zip(&window)
                    .map(|(v, w)| Complex64::new(v * w, 0.0))
                    .collect();
                fft.process(&mut buf);
                buf
            })
            .collect();
        for (k, gk) in g.iter_mut().enumerate() {
            for i in 0..nc {
                for j in 0..nc {
                    gk[(i, j)] += spectra[i][k] * spectra[j][k].conj();
                }
            }
        }
    }
    // one-sided density: 2 / (fs sum w^2) per segment, averaged (DC and Nyquist not doubled)
    let power: f64 = window.iter().map(|w| w * w).sum();
    let scale = 1.0 / (sample_rate_hz * power * starts.len() as f64);
    let values = g
        .into_iter()
        .enumerate()
        .map(|(k, gk)| {
            let one_sided = if k == 0 || 2 * k == segment_len {
                1.0
            } else {
                2.0
            };
            one_sided * scale * gk.singular_values().max()
        })
        .collect();
    Ok(Spectrum {
        frequencies_hz: (0..bins)
            .map(|k| k as f64 * sample_rate_hz / segment_len as f64)
            .collect(),
        values,
    })
}

/// One-sided Welch power spectral density of one channel (units^2 / Hz): Hann segments of
/// `segment_len` samples (>= 4, at most the record) with 50 % overlap, averaged.
pub fn power_spectral_density(
    x: &[f64],
    sample_rate_hz: f64,
    segment_len: usize,
) -> Result<Spectrum> {
    let densities = segment_densities(x, sample_rate_hz, segment_len)?;
    let mut values = vec![0.0; segment_len / 2 + 1];
    for d in &densities {
        for (a, b) in values.iter_mut().zip(d) {
            *a += b;
        }
    }
    let count = densities.len() as f64;
    values.iter_mut().for_each(|v| *v /= count);
    Ok(Spectrum {
        frequencies_hz: (0..values.len())
            .map(|k| k as f64 * sample_rate_hz / segment_len as f64)
            .collect(),
        values,
    })
}

/// The one-sided density (units^2 / Hz) of each Hann segment of `segment_len` samples (>= 4, at
/// most the record), the segments starting every `segment_len / 2` samples: the terms whose
/// mean is Welch's estimate ([`power_spectral_density`]), kept apart so that the density of any
/// run of consecutive segments (a stretch of the record) is their mean.
pub fn segment_densities(
    x: &[f64],
    sample_rate_hz: f64,
    segment_len: usize,
) -> Result<Vec<Vec<f64>>> {
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(OmaError::InvalidInput {
            field: "sample_rate_hz",
            message: format!("{sample_rate_hz}; expected a rate > 0"),
        });
    }
    if segment_len < 4 || segment_len > x.len() {
        return Err(OmaError::InvalidInput {
            field: "segment_len",
            message: format!(
                "{segment_len} samples per segment of {} samples; expected 4 to the record length",
                x.len()
            ),
        });
    }
    let window: Vec<f64> = (0..segment_len)
        .map(|k| 0.5 - 0.5 * (2.0 * PI * k as f64 / segment_len as f64).cos())
        .collect();
    let fft = FftPlanner::<f64>::new().plan_fft_forward(segment_len);
    let bins = segment_len / 2 + 1;
    let step = segment_len / 2;
    let segments = (x.len() - segment_len) / step + 1;
    let power: f64 = window.iter().map(|w| w * w).sum();
    let scale = 1.0 / (sample_rate_hz * power);
    let mut buf = vec![Complex64::new(0.0, 0.0); segment_len];
    let mut scratch = vec![Complex64::new(0.0, 0.0); fft.get_inplace_scratch_len()];
    Ok((0..segments)
        .map(|s| {
            let start = s * step;
            for ((b, v), w) in buf
                .iter_mut()
                .zip(&x[start..start + segment_len])
                .zip(&window)
            {
                *b = Complex64::new(v * w, 0.0);
            }
            fft.process_with_scratch(&mut buf, &mut scratch);
            buf[..bins]
                .iter()
                .enumerate()
                .map(|(k, b)| {
                    let one_sided = if k == 0 || 2 * k == segment_len {
                        1.0
                    } else {
                        2.0
                    };
                    one_sided * scale * b.norm_sqr()
                })
                .collect()
        })
        .collect())
}

/// Frequency (Hz) of the peak of a density `psd` (bins `df` apart) at its local maximum `i`,
/// from a parabola through the logarithms of the densities at bins i - 1, i, i + 1 (exact for
/// a Gaussian lobe; for a Hann window's main lobe the bias is a few hundredths of a bin).
pub fn refine_peak_hz(psd: &[f64], i: usize, df: f64) -> f64 {
    if i == 0 || i + 1 >= psd.len() {
        return i as f64 * df;
    }
    let (a, b, c) = (psd[i - 1].ln(), psd[i].ln(), psd[i + 1].ln());
    let denom = a - 2.0 * b + c;
    let shift = if denom.abs() > 0.0 && denom.is_finite() {
        (0.5 * (a - c) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    (i as f64 + shift) * df
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rank_one_sines_integrate_to_their_power() {
        // two channels carrying the same 100 Hz sine (amplitudes 1 and 2): rank one, first
        // singular value = trace = (1 + 4) / 2 power spread over the Hann main lobe
        let fs = 1000.0;
        let n = 1000;
        let x: Vec<f64> = (0..8000)
            .map(|k| (2.0 * PI * 100.0 * k as f64 / fs).sin())
            .collect();
        let y: Vec<f64> = x.iter().map(|v| 2.0 * v).collect();
        let s = first_singular_value(&[x, y], fs, n).unwrap();
        let df = fs / n as f64;
        let total: f64 = s.values.iter().sum::<f64>() * df;
        // the sine's power 0.5 in each channel, 2.5 in all: integral within 1e-9
        assert!((total - 2.5).abs() < 1e-9, "{total}");
        let peak = s
            .values
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap()
            .0;
        assert_eq!(s.frequencies_hz[peak], 100.0);
        assert!(first_singular_value(&[vec![0.0; 10]], fs, 20).is_err());
        assert!(first_singular_value(&[vec![0.0; 10]], 0.0, 8).is_err());
    }
}
