//! Spectral support of a pole: how high the record's power spectral density stands at its
//! frequency, against the highest peak of the response that is not a forced line and against
//! the density's floor.
//!
//! A stabilization cluster is a pole of the correlation model; whether the record's response
//! actually has power there is a separate question, answered by the Welch densities S_c(f) of
//! the channels (Hann segments, 50 % overlap, [`crate::spectrum::power_spectral_density`]).
//! Each channel's density is divided by its mean over the analysed band (so that channels of
//! different units and sizes weigh alike) and the channels are summed:
//! S(f) = sum_c S_c(f) / mean_band S_c. The reference level S_ref is the highest S(f) in the
//! band outside the excluded frequencies (spindle multiples and spectral lines: forced
//! responses and limit cycles, which are not resonances), each excluded over
//! [`LINE_HALF_WIDTH_BINS`] density bins on either side. The support of a pole of frequency f
//! is
//!
//!   L(f) = 10 log10( max { S(g) : |g - f| <= [`PEAK_HALF_WIDTH_BINS`] df } / S_ref )
//!
//! in dB (df the density's bin width): the height of the spectrum at the pole, zero for the
//! highest resonance peak of the record, negative below it. The window is not widened by the
//! pole's bandwidth: a heavily damped pole (the envelope of several close roots that a low
//! model order fits as one) would then borrow the height of a neighbouring sharp peak. The
//! prominence is the same height against the floor S_floor, the median of S over the bins
//! S_ref is taken from: P(f) = L(f) + 10 log10(S_ref / S_floor). A density without resonances
//! (white measurement noise, as in a lifted record where the noise buries the response) has P
//! of about 2 dB at its highest bin (the Welch scatter with 32 segments or more is
//! 1 / sqrt(32) = 18 % per bin).
//!
//! # Spectral peak (half-power estimate)
//! [`SpectralSupport::peak`] reads the local maximum of S nearest a pole (within
//! [`PEAK_SEARCH_FRACTION`] of its frequency) as an independent estimate of the pole: its
//! frequency f_p by a parabola through the log densities of the three top bins, and its damping
//! ratio by the half-power bandwidth, zeta = B / (2 f_p), with B the distance between the
//! frequencies where S falls to half the peak (linear interpolation between bins) and the Hann
//! window's own half-power width (1.44 bins) removed in quadrature,
//! B = sqrt(B_measured^2 - (1.44 df)^2) (a Gaussian approximation of the convolution with the
//! window's main lobe). For a single lightly damped mode the half-power bandwidth is
//! 2 zeta f_n (Ewins, Modal Testing, Sec. 4.3); neighbouring poles closer than a few bandwidths
//! and the Welch estimate's scatter (relative standard deviation 1 / sqrt(segments) per bin)
//! make it a cross-check rather than a general estimator.

use crate::error::{OmaError, Result};
use crate::harmonics::LineSpectrum;
use crate::spectrum::{power_spectral_density, refine_peak_hz};
use serde::{Deserialize, Serialize};

/// Welch segments of the densities: the largest power of two that leaves at least this many
/// half-overlapping segments in the record (a 16 s record at 5 kHz: 4096 samples, 1.2 Hz bins,
/// 38 segments; the issue-16 record, 10 s at 10 240 Hz: 4096, 2.5 Hz, 49 segments). On the gap
/// proving ground's lathe (closed-loop poles of damping 0.002-0.013 near 720 Hz, 16 s at
/// 5 kHz), 8192-sample segments (19 of them) put the half-power damping 0.5-2.3 times the
/// truth's, 4096 (38) 0.9-1.6 times.
pub const MIN_WELCH_SEGMENTS: usize = 32;
/// Most samples per Welch segment.
pub const MAX_SEGMENT_LEN: usize = 16_384;
/// Density bins on either side of an excluded frequency left out of the reference peak: the
/// Hann window's main lobe is 2 bins wide on each side.
pub const LINE_HALF_WIDTH_BINS: f64 = 2.0;
/// Half-width of the window in which a pole's support is read, in density bins (its estimated
/// frequency can be off by a bin).
pub const PEAK_HALF_WIDTH_BINS: f64 = 1.5;
/// [`SpectralSupport::peak`] looks for the local maximum within this fraction of the pole's
/// frequency (1 %, the stabilization diagram's frequency tolerance).
pub const PEAK_SEARCH_FRACTION: f64 = 0.01;
/// Half-power width of the Hann window's main lobe, in bins.
pub const HANN_HALF_POWER_BINS: f64 = 1.44;

/// A resonance peak of the density (module documentation, "Spectral peak").
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpectralPeak {
    /// Peak frequency (Hz).
    pub frequency_hz: f64,
    /// Damping ratio from the half-power bandwidth.
    pub damping_ratio: f64,
    /// L at the peak (dB, module documentation).
    pub level_db: f64,
    /// Bin width of the density (Hz).
    pub bin_hz: f64,
}

/// The channels' normalized density and its reference peak (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralSupport {
    /// Bin width of the density (Hz).
    bin_hz: f64,
    /// S(f) at bins k df.
    density: Vec<f64>,
    /// S_ref.
    reference: f64,
    /// Frequency of the reference peak (Hz).
    reference_hz: f64,
    /// S_floor.
    floor: f64,
}

impl SpectralSupport {
    /// The support of `data` (equal-length channels at `sample_rate_hz`) in `band_hz`, the
    /// frequencies within [`LINE_HALF_WIDTH_BINS`] of `excluded_hz` or of a spectral line of
    /// `lines` (a local maximum of the density with a line of the record within a bin) left out
    /// of the reference peak and the floor.
    pub fn new(
        data: &[Vec<f64>],
        sample_rate_hz: f64,
        band_hz: (f64, f64),
        excluded_hz: &[f64],
        lines: Option<&LineSpectrum>,
    ) -> Result<Self> {
        let l = data.first().map_or(0, Vec::len);
        let mut segment_len = MAX_SEGMENT_LEN;
        while segment_len > 16 && (2 * l / segment_len) < MIN_WELCH_SEGMENTS + 1 {
            segment_len /= 2;
        }
        let bin_hz = sample_rate_hz / segment_len as f64;
        let bins = segment_len / 2 + 1;
        let in_band = |k: usize| {
            let f = k as f64 * bin_hz;
            f >= band_hz.0 && f <= band_hz.1
        };
        let mut density = vec![0.0; bins];
        for ch in data {
            let s = power_spectral_density(ch, sample_rate_hz, segment_len.min(l))?.values;
            let (sum, n) = s
                .iter()
                .enumerate()
                .filter(|(k, _)| in_band(*k))
                .fold((0.0, 0usize), |(a, n), (_, v)| (a + v, n + 1));
            let mean = sum / n.max(1) as f64;
            if mean > 0.0 {
                density.iter_mut().zip(&s).for_each(|(d, v)| *d += v / mean);
            }
        }
        let mut excluded = excluded_hz.to_vec();
        if let Some(lines) = lines {
            for k in 1..bins.saturating_sub(1) {
                if in_band(k) && density[k] >= density[k - 1] && density[k] >= density[k + 1] {
                    let g = lines.strongest_near(k as f64 * bin_hz, bin_hz);
                    if lines.is_line(g) {
                        excluded.push(g);
                    }
                }
            }
        }
        let near_excluded = |f: f64| {
            excluded
                .iter()
                .any(|h| (f - h).abs() <= LINE_HALF_WIDTH_BINS * bin_hz)
        };
        let kept: Vec<(usize, f64)> = density
            .iter()
            .enumerate()
            .filter(|(k, _)| in_band(*k))
            .filter(|(k, _)| !near_excluded(*k as f64 * bin_hz))
            .map(|(k, v)| (k, *v))
            .collect();
        let (reference_k, reference) =
            kept.iter().fold(
                (0, 0.0),
                |best, &(k, v)| if v > best.1 { (k, v) } else { best },
            );
        let mut values: Vec<f64> = kept.iter().map(|(_, v)| *v).collect();
        values.sort_by(f64::total_cmp);
        let floor = values.get(values.len() / 2).copied().unwrap_or(0.0);
        if !(reference > 0.0 && floor > 0.0) {
            return Err(OmaError::InvalidInput {
                field: "signals",
                message: format!(
                    "no power between {:.1} and {:.1} Hz outside the spindle harmonics and \
                     spectral lines",
                    band_hz.0, band_hz.1
                ),
            });
        }
        Ok(Self {
            bin_hz,
            density,
            reference,
            reference_hz: reference_k as f64 * bin_hz,
            floor,
        })
    }

    /// The bins within `half_width_hz` of `frequency_hz`.
    fn bins_near(&self, frequency_hz: f64, half_width_hz: f64) -> std::ops::RangeInclusive<usize> {
        let last = self.density.len() - 1;
        let lo = ((frequency_hz - half_width_hz) / self.bin_hz)
            .ceil()
            .max(0.0) as usize;
        let hi = ((frequency_hz + half_width_hz) / self.bin_hz)
            .floor()
            .max(0.0) as usize;
        lo.min(last)..=hi.min(last).max(lo.min(last))
    }

    /// L(f) in dB at `frequency_hz` (module documentation).
    pub fn level_db(&self, frequency_hz: f64) -> f64 {
        let peak = self
            .bins_near(frequency_hz, PEAK_HALF_WIDTH_BINS * self.bin_hz)
            .map(|k| self.density[k])
            .fold(0.0, f64::max);
        10.0 * (peak / self.reference).log10()
    }

    /// P(f) in dB at `frequency_hz`: the height over the floor (module documentation).
    pub fn prominence_db(&self, frequency_hz: f64) -> f64 {
        self.level_db(frequency_hz) + 10.0 * (self.reference / self.floor).log10()
    }

    /// The resonance peak nearest `frequency_hz` (module documentation, "Spectral peak"):
    /// `None` when the density has no local maximum within [`PEAK_SEARCH_FRACTION`] of it or
    /// does not fall to half the peak on both sides.
    pub fn peak(&self, frequency_hz: f64) -> Option<SpectralPeak> {
        let d = &self.density;
        let k = self
            .bins_near(frequency_hz, PEAK_SEARCH_FRACTION * frequency_hz)
            .filter(|&k| k > 0 && k + 1 < d.len() && d[k] >= d[k - 1] && d[k] >= d[k + 1])
            .max_by(|a, b| d[*a].total_cmp(&d[*b]))?;
        let half = 0.5 * d[k];
        let lo = (0..k).rev().find(|&j| d[j] <= half)?;
        let hi = (k + 1..d.len()).find(|&j| d[j] <= half)?;
        // crossings by linear interpolation between the bins on either side of half power
        let f_lo = (lo as f64 + (half - d[lo]) / (d[lo + 1] - d[lo])) * self.bin_hz;
        let f_hi = (hi as f64 - (half - d[hi]) / (d[hi - 1] - d[hi])) * self.bin_hz;
        let window = HANN_HALF_POWER_BINS * self.bin_hz;
        let width = ((f_hi - f_lo).powi(2) - window * window).max(0.0).sqrt();
        let f_p = refine_peak_hz(d, k, self.bin_hz);
        Some(SpectralPeak {
            frequency_hz: f_p,
            damping_ratio: width / (2.0 * f_p),
            level_db: 10.0 * (d[k] / self.reference).log10(),
            bin_hz: self.bin_hz,
        })
    }

    /// Frequency of the reference peak (Hz).
    pub fn reference_hz(&self) -> f64 {
        self.reference_hz
    }

    /// Bin width of the density (Hz).
    pub fn bin_hz(&self) -> f64 {
        self.bin_hz
    }
}
