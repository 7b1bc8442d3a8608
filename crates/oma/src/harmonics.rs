//! Spindle harmonics: which ones the modified LSCE imposes as undamped poles (000 Eq. 22-24 and
//! Fig. 3, where the dominant pole is identified with three of its neighbouring harmonics).
//!
//! Imposing works in the correlation domain, over a window of lags much shorter than the record,
//! so a spindle speed known to 0.1 % is enough; subtracting fitted sinusoids from the record
//! instead would need the frequency to within a fraction of 1 / T.
//!
//! Imposing has a price: the known factor K(z) of 000 Eq. 22-24 is a notch at each harmonic, and
//! a notch near the pole weights the pole's part of the correlations down against the estimation
//! noise elsewhere, which biases its damping upwards unless the order is raised. So
//! [`Harmonics::Spindle`] imposes only the multiples that are actually present: spectral lines
//! that stand [`LINE_FACTOR`] times above the neighbouring spectrum of the record
//! ([`present_lines`]).

use crate::error::{OmaError, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Spindle multiples closer to the dominant pole than this many half-power half-bandwidths
/// -Re(lambda) / 2 pi are not imposed (their notch would cancel the pole).
pub const SPINDLE_CLEARANCE: f64 = 3.0;

/// Which harmonics the modified LSCE imposes.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub enum Harmonics {
    /// None: plain LSCE.
    #[default]
    None,
    /// These frequencies (Hz).
    Known(Vec<f64>),
    /// Up to `count` multiples of `fundamental_hz` (the spindle frequency, rpm / 60): those
    /// nearest the dominant pole that are present as spectral lines ([`present_lines`]), leaving
    /// out any within [`SPINDLE_CLEARANCE`] half-power half-bandwidths -Re(lambda) / 2 pi of it.
    /// The pole is located by a first plain-LSCE pass in which every multiple (and poles within
    /// the picking band around it) is excluded from the pick.
    Spindle {
        /// Spindle rotation frequency (Hz).
        fundamental_hz: f64,
        /// How many multiples to impose (000 Fig. 3 shows three).
        count: usize,
    },
}

impl Harmonics {
    /// Check frequencies against the Nyquist frequency `nyquist_hz`.
    pub fn validate(&self, nyquist_hz: f64) -> Result<()> {
        let in_band = |f: f64| f.is_finite() && f > 0.0 && f < nyquist_hz;
        match self {
            Self::None => Ok(()),
            Self::Known(list) => match list.iter().find(|f| !in_band(**f)) {
                Some(f) => Err(OmaError::InvalidInput {
                    field: "known_harmonics_hz",
                    message: format!("{f} Hz; expected frequencies in (0, {nyquist_hz}) Hz"),
                }),
                None => Ok(()),
            },
            Self::Spindle {
                fundamental_hz,
                count,
            } => {
                if !in_band(*fundamental_hz) {
                    return Err(OmaError::InvalidInput {
                        field: "fundamental_hz",
                        message: format!(
                            "{fundamental_hz} Hz; expected a frequency in (0, {nyquist_hz}) Hz"
                        ),
                    });
                }
                if *count == 0 {
                    return Err(OmaError::InvalidInput {
                        field: "count",
                        message: "0 harmonics; expected at least 1".into(),
                    });
                }
                Ok(())
            }
        }
    }
}

/// The multiples k f_0 (k >= 1) of `fundamental_hz` below `nyquist_hz`.
pub fn multiples_below(fundamental_hz: f64, nyquist_hz: f64) -> Vec<f64> {
    if !(fundamental_hz.is_finite() && fundamental_hz > 0.0) {
        return Vec::new();
    }
    (1..)
        .map(|k| k as f64 * fundamental_hz)
        .take_while(|f| *f < nyquist_hz)
        .collect()
}

/// The multiples of `fundamental_hz` below `nyquist_hz` at least `min_distance_hz` from
/// `center_hz`, nearest first.
pub fn multiples_by_distance(
    fundamental_hz: f64,
    center_hz: f64,
    min_distance_hz: f64,
    nyquist_hz: f64,
) -> Vec<f64> {
    let mut all: Vec<f64> = multiples_below(fundamental_hz, nyquist_hz)
        .into_iter()
        .filter(|f| (f - center_hz).abs() >= min_distance_hz)
        .collect();
    all.sort_by(|a, b| (a - center_hz).abs().total_cmp(&(b - center_hz).abs()));
    all
}

/// A line counts as present when its amplitude is this many times the median amplitude of the
/// neighbouring frequencies ([`present_lines`]).
pub const LINE_FACTOR: f64 = 10.0;
/// Neighbouring frequencies on each side of a candidate line, spaced [`LINE_SPACING_BINS`]
/// record bins 1 / T apart.
pub const LINE_NEIGHBOURS: usize = 8;
/// Spacing of the neighbours in record bins 1 / T (so they are uncorrelated with the line and
/// with each other under the rectangular window of the record).
pub const LINE_SPACING_BINS: f64 = 2.0;

/// The frequencies of `candidates_hz` that are spectral lines in at least one channel of `data`
/// (sampled at `sample_rate_hz`): the amplitude |sum_k y(k) e^{-i w k T_s}| of the record at the
/// candidate exceeds [`LINE_FACTOR`] times the median over [`LINE_NEIGHBOURS`] frequencies on
/// each side. A random response gives amplitudes of the same size at neighbouring frequencies,
/// a sinusoid over T seconds stands out by about its amplitude times sqrt(T / S(f)).
pub fn present_lines(data: &[Vec<f64>], sample_rate_hz: f64, candidates_hz: &[f64]) -> Vec<f64> {
    let l = data.first().map_or(0, Vec::len);
    if l == 0 || !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Vec::new();
    }
    let ts = 1.0 / sample_rate_hz;
    let step_hz = LINE_SPACING_BINS / (l as f64 * ts);
    let amplitude = |ch: &[f64], f: f64| {
        let w = 2.0 * PI * f * ts;
        let (c, s) = ch.iter().enumerate().fold((0.0, 0.0), |(c, s), (k, v)| {
            let (sin, cos) = (w * k as f64).sin_cos();
            (c + v * cos, s + v * sin)
        });
        (c * c + s * s).sqrt()
    };
    candidates_hz
        .iter()
        .copied()
        .filter(|&f| {
            data.iter().any(|ch| {
                let mut neighbours: Vec<f64> = (1..=LINE_NEIGHBOURS)
                    .flat_map(|m| [f - m as f64 * step_hz, f + m as f64 * step_hz])
                    .filter(|g| *g > 0.0 && *g < 0.5 * sample_rate_hz)
                    .map(|g| amplitude(ch, g))
                    .collect();
                if neighbours.is_empty() {
                    return false;
                }
                neighbours.sort_by(f64::total_cmp);
                amplitude(ch, f) > LINE_FACTOR * neighbours[neighbours.len() / 2]
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn multiples_are_sorted_by_distance_outside_the_clearance() {
        assert_eq!(
            multiples_by_distance(100.0, 830.0, 0.0, 1050.0),
            vec![
                800.0, 900.0, 700.0, 1000.0, 600.0, 500.0, 400.0, 300.0, 200.0, 100.0
            ]
        );
        // 800 Hz is within 40 Hz of the pole: left out
        assert_eq!(
            multiples_by_distance(100.0, 830.0, 40.0, 1000.0)[..3],
            [900.0, 700.0, 600.0]
        );
        assert!(multiples_below(0.0, 10.0).is_empty());
    }

    #[test]
    fn lines_stand_out_of_a_random_response() {
        // a seeded AR(1) process (a broadband random response, RMS 1.3) plus a line at 120 Hz
        // of amplitude 0.3: over 20 000 samples the line's amplitude 0.3 L / 2 = 3000 is 26
        // times the random part's sqrt(L S(120 Hz)) = 116, absent candidates are near 1 time
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        let fs = 1000.0;
        let mut state = 0.0;
        let ch: Vec<f64> = (0..20_000)
            .map(|k| {
                state = 0.9 * state + rng.random_range(-1.0..1.0);
                state + 0.3 * (2.0 * PI * 120.0 * k as f64 / fs).cos()
            })
            .collect();
        let found = present_lines(&[ch], fs, &[60.0, 120.0, 180.0, 240.0]);
        assert_eq!(found, vec![120.0]);
        assert!(present_lines(&[], fs, &[120.0]).is_empty());
    }

    #[test]
    fn validation_names_the_field() {
        assert!(Harmonics::None.validate(500.0).is_ok());
        assert!(Harmonics::Known(vec![100.0, 499.0]).validate(500.0).is_ok());
        assert!(Harmonics::Known(vec![600.0]).validate(500.0).is_err());
        let spindle = |fundamental_hz, count| Harmonics::Spindle {
            fundamental_hz,
            count,
        };
        assert!(spindle(100.0, 3).validate(500.0).is_ok());
        assert!(matches!(
            spindle(100.0, 0).validate(500.0),
            Err(OmaError::InvalidInput { field: "count", .. })
        ));
        assert!(matches!(
            spindle(f64::NAN, 2).validate(500.0),
            Err(OmaError::InvalidInput {
                field: "fundamental_hz",
                ..
            })
        ));
    }
}
