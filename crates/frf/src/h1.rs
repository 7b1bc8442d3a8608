//! The H1 estimate of an FRF from an impact (tap) test record: force f(t) and response a(t)
//! sampled together, H1(w) = S_fa(w) / S_ff(w) with the cross- and auto-spectra summed over
//! segments and over `smoothing_bins` neighbouring frequency bins on each side (so one impact
//! gives a coherence too), and the ordinary coherence
//! gamma^2 = |S_fa|^2 / (S_ff S_aa) from the same sums. An accelerance is turned into a
//! receptance by dividing by -w^2. A tap test has no spindle speed and no cut: this is plain
//! experimental modal analysis.

use crate::error::{FrfError, Result};
use crate::frf::{Frf, Quantity};
use num_complex::Complex64;
use rustfft::FftPlanner;

/// Options of [`h1_estimate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct H1Options {
    /// Samples per segment; default the whole record (one segment).
    pub segment_samples: Option<usize>,
    /// Neighbouring bins on each side summed into each spectral estimate; default 2.
    pub smoothing_bins: usize,
    /// What the response channel measures; default acceleration (m/s^2).
    pub response: Quantity,
}

impl Default for H1Options {
    fn default() -> Self {
        Self {
            segment_samples: None,
            smoothing_bins: 2,
            response: Quantity::Accelerance,
        }
    }
}

/// The H1 receptance and its coherence at each frequency bin above 0 Hz.
#[derive(Debug, Clone, PartialEq)]
pub struct H1Estimate {
    /// The receptance (m/N).
    pub frf: Frf,
    /// Coherence in [0, 1], one per frequency of `frf`.
    pub coherence: Vec<f64>,
}

/// H1 from `force_n` and `response` sampled at `sample_rate_hz`.
pub fn h1_estimate(
    force_n: &[f64],
    response: &[f64],
    sample_rate_hz: f64,
    options: &H1Options,
) -> Result<H1Estimate> {
    if force_n.len() != response.len() {
        return Err(FrfError::value(
            "response",
            response.len() as f64,
            format!("as many samples as the force ({})", force_n.len()),
        ));
    }
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(FrfError::value(
            "sample_rate_hz",
            sample_rate_hz,
            "a rate > 0",
        ));
    }
    let n = options.segment_samples.unwrap_or(force_n.len());
    if n < 8 || n > force_n.len() {
        return Err(FrfError::value(
            "segment_samples",
            n as f64,
            format!("8 to {} samples", force_n.len()),
        ));
    }
    if let Some(v) = force_n.iter().chain(response).find(|v| !v.is_finite()) {
        return Err(FrfError::value("samples", *v, "finite samples"));
    }
    let fft = FftPlanner::<f64>::new().plan_fft_forward(n);
    let bins = n / 2 + 1;
    let mut sff = vec![0.0; bins];
    let mut saa = vec![0.0; bins];
    let mut sfa = vec![Complex64::new(0.0, 0.0); bins];
    let segments = force_n.len() / n;
    for s in 0..segments {
        let mut f: Vec<Complex64> = force_n[s * n..(s + 1) * n]
            .iter()
            .map(|&v| Complex64::new(v, 0.0))
            .collect();
        let mut a: Vec<Complex64> = response[s * n..(s + 1) * n]
            .iter()
            .map(|&v| Complex64::new(v, 0.0))
            .collect();
        fft.process(&mut f);
        fft.process(&mut a);
        for k in 0..bins {
            sff[k] += f[k].norm_sqr();
            saa[k] += a[k].norm_sqr();
            sfa[k] += f[k].conj() * a[k];
        }
    }
    let m = options.smoothing_bins;
    let mut freqs = Vec::with_capacity(bins);
    let mut values = Vec::with_capacity(bins);
    let mut coherence = Vec::with_capacity(bins);
    for k in 1..bins {
        let (lo, hi) = (k.saturating_sub(m).max(1), (k + m).min(bins - 1));
        let (mut ff, mut aa, mut fa) = (0.0, 0.0, Complex64::new(0.0, 0.0));
        for j in lo..=hi {
            ff += sff[j];
            aa += saa[j];
            fa += sfa[j];
        }
        if ff <= 0.0 {
            continue;
        }
        let hz = k as f64 * sample_rate_hz / n as f64;
        freqs.push(hz);
        values.push(fa / ff);
        coherence.push(if aa > 0.0 {
            (fa.norm_sqr() / (ff * aa)).min(1.0)
        } else {
            0.0
        });
    }
    let frf = Frf::from_quantity(freqs, values, options.response)?;
    Ok(H1Estimate { frf, coherence })
}
