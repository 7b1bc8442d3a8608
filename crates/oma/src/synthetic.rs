//! Seeded synthetic records with known poles: the reference problems shared by the tests, the
//! bench and the example program.
//!
//! Each mode n obeys q_n'' + 2 zeta_n w_n q_n' + w_n^2 q_n = f_n(t) with its own unit-variance
//! Gaussian white force f_n, held over each sample (zero-order hold), and is advanced with the
//! exact transition of the hold, so the sampled response has the discrete poles
//! mu = e^{lambda T_s} exactly. Channel c records its modal response m_c = sum_n shape_n(c) q_n
//! plus the harmonics a_k(c) rms(m_c) cos(2 pi f_k t + phi_k) plus Gaussian measurement noise of
//! RMS `noise_fraction` rms(m_c): both are scaled by the RMS of the modal response, so adding
//! harmonics changes neither the modal response nor the noise of a seed.

use crate::error::{OmaError, Result};
use crate::signals::Signals;
use chatter_modal::ModalPole;
use nalgebra::Matrix3;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A mode of the synthetic system: a modal pole with its participation per channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SyntheticMode {
    /// Natural frequency (Hz) and damping ratio, in [0, 1): the modal pole every mode type
    /// holds (written as the two fields `frequency_hz`, `damping_ratio`).
    #[serde(flatten)]
    pub pole: ModalPole,
    /// Participation in each channel (one value per channel).
    pub shape: Vec<f64>,
}

/// An undamped harmonic added to every channel (a spindle harmonic).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SyntheticHarmonic {
    /// Frequency (Hz).
    pub frequency_hz: f64,
    /// Amplitude in each channel (one value per channel), relative to the RMS of that channel's
    /// modal response.
    pub amplitude: Vec<f64>,
    /// Phase (rad).
    pub phase_rad: f64,
}

/// A synthetic multi-channel record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SyntheticRecord {
    /// Channel names (the first is the reference).
    pub channels: Vec<String>,
    /// The modes.
    pub modes: Vec<SyntheticMode>,
    /// The harmonics.
    pub harmonics: Vec<SyntheticHarmonic>,
    /// Measurement noise RMS as a fraction of the RMS of each channel's modal response.
    pub noise_fraction: f64,
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// Seed of the forces and the noise.
    pub seed: u64,
}

impl SyntheticRecord {
    /// A single channel `y` with one mode under white noise and no harmonics.
    pub fn single_mode(
        frequency_hz: f64,
        damping_ratio: f64,
        noise_fraction: f64,
        sample_rate_hz: f64,
        duration_s: f64,
        seed: u64,
    ) -> Self {
        Self {
            channels: vec!["y".into()],
            modes: vec![SyntheticMode {
                pole: ModalPole::new(frequency_hz, damping_ratio),
                shape: vec![1.0],
            }],
            harmonics: Vec::new(),
            noise_fraction,
            sample_rate_hz,
            duration_s,
            seed,
        }
    }

    /// The reference problem of the bench and the example program: four channels `a1`..`a4`
    /// with three modes (1200 Hz at 2 %, 2470 Hz at 0.5 %, 4100 Hz at 1 %) and the 20th and
    /// 22nd harmonics of a 7150 rpm spindle (2383.3 and 2621.7 Hz) either side of the
    /// 2470 Hz mode, each with an amplitude of 2 to 4 times the modal response RMS, plus 10 %
    /// measurement noise.
    pub fn four_channel_reference(sample_rate_hz: f64, duration_s: f64, seed: u64) -> Self {
        let spindle_hz = 7150.0 / 60.0;
        let mode = |frequency_hz, damping_ratio, shape: [f64; 4]| SyntheticMode {
            pole: ModalPole::new(frequency_hz, damping_ratio),
            shape: shape.to_vec(),
        };
        Self {
            channels: (1..=4).map(|c| format!("a{c}")).collect(),
            modes: vec![
                mode(1200.0, 0.02, [1.0, 0.6, -0.4, 0.2]),
                mode(2470.0, 0.005, [0.5, 1.0, 0.8, -0.6]),
                mode(4100.0, 0.01, [-0.3, 0.4, 1.0, 0.9]),
            ],
            harmonics: [20.0, 22.0]
                .iter()
                .enumerate()
                .map(|(k, h)| SyntheticHarmonic {
                    frequency_hz: h * spindle_hz,
                    amplitude: vec![4.0, 3.0, 3.0, 2.0],
                    phase_rad: 0.9 * k as f64,
                })
                .collect(),
            noise_fraction: 0.1,
            sample_rate_hz,
            duration_s,
            seed,
        }
    }

    fn validate(&self) -> Result<usize> {
        let invalid =
            |field: &'static str, message: String| Err(OmaError::InvalidInput { field, message });
        let nc = self.channels.len();
        let nyquist = 0.5 * self.sample_rate_hz;
        if !(self.sample_rate_hz.is_finite() && self.sample_rate_hz > 0.0) {
            return invalid("sample_rate_hz", format!("{}", self.sample_rate_hz));
        }
        let samples = self.duration_s * self.sample_rate_hz;
        if !(samples.is_finite() && (2.0..=1e9).contains(&samples)) {
            return invalid(
                "duration_s",
                format!("{} s; expected 2 to 1e9 samples", self.duration_s),
            );
        }
        if !(self.noise_fraction.is_finite() && self.noise_fraction >= 0.0) {
            return invalid("noise_fraction", format!("{}", self.noise_fraction));
        }
        for (i, m) in self.modes.iter().enumerate() {
            let valid = m.pole.frequency_hz > 0.0
                && m.pole.frequency_hz < nyquist
                && (0.0..1.0).contains(&m.pole.damping_ratio)
                && m.shape.len() == nc;
            if !valid {
                return invalid(
                    "modes",
                    format!(
                        "mode {i}: expected 0 < f < {nyquist} Hz, 0 <= zeta < 1 and {nc} shape \
                         values"
                    ),
                );
            }
        }
        for (i, h) in self.harmonics.iter().enumerate() {
            if !(h.frequency_hz >= 0.0 && h.frequency_hz < nyquist) || h.amplitude.len() != nc {
                return invalid(
                    "harmonics",
                    format!("harmonic {i}: expected 0 <= f < {nyquist} Hz and {nc} amplitudes"),
                );
            }
        }
        Ok(samples.floor() as usize)
    }

    /// Generate the record.
    pub fn generate(&self) -> Result<Signals> {
        let n = self.validate()?;
        let nc = self.channels.len();
        let ts = 1.0 / self.sample_rate_hz;
        let mut rng = rand::rngs::StdRng::seed_from_u64(self.seed);
        let mut data = vec![vec![0.0; n]; nc];
        for mode in &self.modes {
            let (phi, gamma) = zoh_transition(mode.pole.frequency_hz, mode.pole.damping_ratio, ts);
            let (mut q, mut qd) = (0.0, 0.0);
            // start in the stationary state: discard ten decay times (at most 1e6 samples)
            let w = mode.pole.omega_rad_s();
            let warmup = (10.0 / (mode.pole.damping_ratio * w).max(1e-12) / ts).min(1e6) as usize;
            for k in 0..warmup + n {
                let f: f64 = StandardNormal.sample(&mut rng);
                (q, qd) = (
                    phi[0] * q + phi[1] * qd + gamma[0] * f,
                    phi[2] * q + phi[3] * qd + gamma[1] * f,
                );
                if k >= warmup {
                    for (c, ch) in data.iter_mut().enumerate() {
                        ch[k - warmup] += mode.shape[c] * q;
                    }
                }
            }
        }
        let rms: Vec<f64> = data
            .iter()
            .map(|ch| (ch.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt())
            .collect();
        for (ch, rms) in data.iter_mut().zip(&rms) {
            for v in ch.iter_mut() {
                let e: f64 = StandardNormal.sample(&mut rng);
                *v += self.noise_fraction * rms * e;
            }
        }
        for h in &self.harmonics {
            for k in 0..n {
                let v = (2.0 * PI * h.frequency_hz * k as f64 * ts + h.phase_rad).cos();
                for (c, ch) in data.iter_mut().enumerate() {
                    ch[k] += h.amplitude[c] * rms[c] * v;
                }
            }
        }
        Signals::new(self.channels.clone(), self.sample_rate_hz, data)
    }
}

/// Exact zero-order-hold transition of q'' + 2 zeta w q' + w^2 q = f over `ts`: the state matrix
/// (row-major 2x2) and the input vector.
fn zoh_transition(frequency_hz: f64, damping_ratio: f64, ts: f64) -> ([f64; 4], [f64; 2]) {
    let w = 2.0 * PI * frequency_hz;
    #[rustfmt::skip]
    let m = Matrix3::new(
        0.0, 1.0, 0.0,
        -w * w, -2.0 * damping_ratio * w, 1.0,
        0.0, 0.0, 0.0,
    ) * ts;
    let e = m.exp();
    (
        [e[(0, 0)], e[(0, 1)], e[(1, 0)], e[(1, 1)]],
        [e[(0, 2)], e[(1, 2)]],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_has_the_requested_shape_and_noise_level() {
        let mut rec = SyntheticRecord::single_mode(800.0, 0.02, 0.0, 10_000.0, 1.0, 3);
        let clean = rec.generate().unwrap();
        assert_eq!(clean.data[0].len(), 10_000);
        rec.noise_fraction = 0.1;
        let noisy = rec.generate().unwrap();
        // same seed: same forces, so the difference is the noise, 10 % of the clean RMS
        let rms = |x: &[f64]| (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
        let diff: Vec<f64> = noisy.data[0]
            .iter()
            .zip(&clean.data[0])
            .map(|(a, b)| a - b)
            .collect();
        let ratio = rms(&diff) / rms(&clean.data[0]);
        // 10 000 Gaussian samples: the RMS is within 3 % of its value
        assert!((ratio - 0.1).abs() < 0.003, "{ratio}");
        rec.modes[0].shape.push(1.0);
        assert!(rec.generate().is_err());
    }

    #[test]
    fn zoh_transition_matches_the_free_decay() {
        // free response from q = 1, q' = -zeta w: e^{-zeta w t} cos(w_d t)
        let (f, z, ts) = (800.0, 0.02, 1e-4);
        let (phi, _) = zoh_transition(f, z, ts);
        let w = 2.0 * PI * f;
        let wd = w * (1.0 - z * z).sqrt();
        let (mut q, mut qd) = (1.0, -z * w);
        for k in 1..=50 {
            (q, qd) = (phi[0] * q + phi[1] * qd, phi[2] * q + phi[3] * qd);
            let t = k as f64 * ts;
            let exact = (-z * w * t).exp() * (wd * t).cos();
            assert!((q - exact).abs() < 1e-12, "step {k}: {q} vs {exact}");
        }
    }
}
