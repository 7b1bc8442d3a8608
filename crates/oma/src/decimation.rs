//! Low-pass filtering and decimation by a whole factor before identification.
//!
//! LSCE fits a polynomial in the discrete pole mu = e^{lambda T_s}; a pole far below the
//! Nyquist frequency crowds next to mu = 1 with its neighbours and noise poles, and the
//! correlation window it needs spans thousands of samples (on seed 000's P3 cut at 100 kHz, the
//! 2.5 kHz pole at 2.5 % of the rate was identified 200 % too damped). Decimating by D moves it
//! to D times its angle without touching lambda: a linear filter h applied to a record whose
//! correlation is r(i) = c delta(i) + sum_j A_j mu_j^|i| (measurement noise and force
//! feed-through in the delta) gives the correlation (h * h~ * r)(i), which for
//! |i| > 2 x [`HALF_WIDTH_PERIODS`] output samples (beyond the support of h * h~) is again
//! sum_j A'_j mu_j^|i| with the same poles; dropping the lags where h * h~ is still above
//! [`SUPPORT_LEVEL`] of its peak ([`correlation_support_lags`]) leaves the model of 000
//! Eq. 19-20 exact to that level.
//!
//! The filter is a Blackman-windowed sinc of cutoff [`CUTOFF_FRACTION`] of the output rate
//! (half-amplitude point) and half-width [`HALF_WIDTH_PERIODS`] output periods, normalized to
//! unit gain at DC: its transition band is about 5.5 / (2 x 16) = 0.17 of the output rate wide,
//! so it passes up to [`PASSBAND_FRACTION`] of the output rate, and its stopband (below -74 dB)
//! starts under the output Nyquist frequency, so nothing folds into the passband.

use std::f64::consts::PI;

/// Cutoff (half-amplitude point) of the anti-aliasing low-pass as a fraction of the output
/// rate.
pub const CUTOFF_FRACTION: f64 = 0.4;
/// Half-width of the filter in output periods.
pub const HALF_WIDTH_PERIODS: usize = 16;
/// Upper end of the passband as a fraction of the output rate: the cutoff less half the
/// Blackman transition band 5.5 / (2 x [`HALF_WIDTH_PERIODS`]).
pub const PASSBAND_FRACTION: f64 = CUTOFF_FRACTION - 5.5 / (4.0 * HALF_WIDTH_PERIODS as f64);

/// Level of the filter's own correlation, relative to its peak, below which the smeared delta
/// of the noise is neglected (-60 dB).
pub const SUPPORT_LEVEL: f64 = 1e-3;

/// Correlation lags (in output samples) in which the filter's own correlation h * h~ mixes the
/// delta at lag 0 (noise, feed-through) into the exponentials: the first lag m from which
/// |(h * h~)(m D)| stays at or below [`SUPPORT_LEVEL`] of (h * h~)(0) (at most
/// 2 x [`HALF_WIDTH_PERIODS`], the whole support). 1 for `factor` 1.
pub fn correlation_support_lags(factor: usize) -> usize {
    if factor <= 1 {
        return 1;
    }
    let h = taps(factor);
    let at = |lag: usize| -> f64 {
        h.iter()
            .zip(&h[lag.min(h.len())..])
            .map(|(a, b)| a * b)
            .sum()
    };
    let peak = at(0);
    (0..=2 * HALF_WIDTH_PERIODS)
        .rev()
        .find(|m| at(m * factor).abs() > SUPPORT_LEVEL * peak)
        .map_or(1, |m| m + 1)
}

/// The filter taps for decimation by `factor` (odd length 2 x 16 x factor + 1, unit DC gain).
fn taps(factor: usize) -> Vec<f64> {
    let half = HALF_WIDTH_PERIODS * factor;
    let fc = CUTOFF_FRACTION / factor as f64; // cycles per input sample
    let raw: Vec<f64> = (0..=2 * half)
        .map(|i| {
            let k = i as f64 - half as f64;
            let sinc = if k == 0.0 {
                2.0 * fc
            } else {
                (2.0 * PI * fc * k).sin() / (PI * k)
            };
            let u = PI * (k / half as f64 + 1.0);
            sinc * (0.42 - 0.5 * u.cos() + 0.08 * (2.0 * u).cos())
        })
        .collect();
    let gain: f64 = raw.iter().sum();
    raw.into_iter().map(|t| t / gain).collect()
}

/// Low-pass `x` and keep every `factor`-th sample, where the filter lies wholly inside the
/// record (the first output is the filtered input sample 16 x `factor`). `factor` 1 (or 0)
/// returns the record.
pub fn decimate(x: &[f64], factor: usize) -> Vec<f64> {
    if factor <= 1 {
        return x.to_vec();
    }
    let h = taps(factor);
    let half = HALF_WIDTH_PERIODS * factor;
    if x.len() <= 2 * half {
        return Vec::new();
    }
    (half..x.len() - half)
        .step_by(factor)
        .map(|n| {
            h.iter()
                .zip(&x[n - half..=n + half])
                .map(|(t, v)| t * v)
                .sum()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gain of the decimated sinusoid at `f` (fraction of the output rate).
    fn gain(f: f64, factor: usize) -> f64 {
        let x: Vec<f64> = (0..4000 * factor)
            .map(|k| (2.0 * PI * f * k as f64 / factor as f64).cos())
            .collect();
        let y = decimate(&x, factor);
        let rms = |v: &[f64]| (v.iter().map(|a| a * a).sum::<f64>() / v.len() as f64).sqrt();
        rms(&y) / rms(&x)
    }

    #[test]
    fn passes_the_band_and_stops_what_would_fold() {
        // passband within 1e-3 (Blackman ripple is below 1e-4; the rest is the finite record),
        // stopband from the output Nyquist frequency below -70 dB
        for f in [0.05, 0.2, PASSBAND_FRACTION] {
            assert!((gain(f, 5) - 1.0).abs() < 1e-3, "{f}: {}", gain(f, 5));
        }
        for f in [0.5, 0.7, 1.3] {
            assert!(gain(f, 5) < 3e-4, "{f}: {}", gain(f, 5));
        }
        assert_eq!(decimate(&[1.0, 2.0], 1), vec![1.0, 2.0]);
        let support = correlation_support_lags(10);
        assert!((2..=2 * HALF_WIDTH_PERIODS).contains(&support), "{support}");
        assert_eq!(correlation_support_lags(1), 1);
        assert!(decimate(&[1.0; 10], 4).is_empty());
    }

    #[test]
    fn damped_exponential_keeps_its_pole() {
        // a free decay sampled at 10 kHz, decimated by 4: beyond the filter's half-width the
        // output is the same exponential at 2.5 kHz, so y(k+1) / y(k) for the complex analytic
        // envelope is e^{lambda 4 T_s}: checked through the ratio of successive peaks
        let (f, z, fs) = (300.0, 0.02, 10_000.0);
        let w = 2.0 * PI * f;
        let x: Vec<f64> = (0..4000)
            .map(|k| {
                let t = k as f64 / fs;
                (-z * w * t).exp() * (w * (1.0 - z * z).sqrt() * t).cos()
            })
            .collect();
        let y = decimate(&x, 4);
        // second-order recursion of one pole pair holds from the first output on
        let mu = num_complex::Complex64::new(-z * w, w * (1.0 - z * z).sqrt()) * (4.0 / fs);
        let mu = mu.exp();
        let (a1, a2) = (-2.0 * mu.re, mu.norm_sqr());
        let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for k in 2..y.len() {
            let residual = y[k] + a1 * y[k - 1] + a2 * y[k - 2];
            assert!(residual.abs() < 1e-4 * scale, "{k}: {residual}");
        }
    }
}
