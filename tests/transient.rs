//! Measurements on deterministic simulated records shared by the `sim_accuracy` test and the
//! `sim_reference` example: the dominant Floquet multiplier from a start-up transient, the RMS
//! and the dominant tone of a limit cycle.

use chatter_dynamics::simulate::{Quantity, SimulationSettings};
use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;

/// Settings of a deterministic cut (no random force) recording displacement.
pub fn deterministic(
    speed_rpm: f64,
    depth_m: f64,
    duration_s: f64,
    sample_rate_hz: f64,
) -> SimulationSettings {
    let mut s = SimulationSettings::new(speed_rpm, depth_m, duration_s, sample_rate_hz, 1);
    s.quantity = Quantity::Displacement;
    s.random_force_rms_n = 0.0;
    s
}

/// `z` or its conjugate, whichever has Im >= 0 (multipliers come in conjugate pairs).
pub fn upper(z: Complex64) -> Complex64 {
    if z.im < 0.0 { z.conj() } else { z }
}

/// Dominant multiplier from samples taken once per delay, one sequence per channel: the
/// differences d_k = s_{k+1} - s_k obey d_{k+2} = a d_{k+1} + b d_k for the dominant pair
/// (least squares over every channel); the root of z^2 = a z + b of larger modulus.
pub fn fit_multiplier(sequences: &[Vec<f64>]) -> Complex64 {
    let (mut s11, mut s12, mut s22, mut r1, mut r2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for s in sequences {
        let d: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
        for w in d.windows(3) {
            let (x1, x2, y) = (w[1], w[0], w[2]);
            s11 += x1 * x1;
            s12 += x1 * x2;
            s22 += x2 * x2;
            r1 += x1 * y;
            r2 += x2 * y;
        }
    }
    let det = s11 * s22 - s12 * s12;
    let a = (r1 * s22 - r2 * s12) / det;
    let b = (s11 * r2 - s12 * r1) / det;
    let disc = Complex64::new(a * a + 4.0 * b, 0.0).sqrt();
    let z1 = (Complex64::new(a, 0.0) + disc) / 2.0;
    let z2 = (Complex64::new(a, 0.0) - disc) / 2.0;
    upper(if z1.norm() >= z2.norm() { z1 } else { z2 })
}

/// Root mean square.
pub fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// Peak of the Hann-windowed spectrum of `x` sampled at `fs` (Hz): (its frequency by parabolic
/// interpolation of the log magnitude, Hz; its amplitude).
pub fn peak(x: &[f64], fs: f64) -> (f64, f64) {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let mut buf: Vec<Complex64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
            Complex64::new((v - mean) * w, 0.0)
        })
        .collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let mag: Vec<f64> = buf[..n / 2].iter().map(|c| c.norm()).collect();
    let i = (2..n / 2 - 1)
        .max_by(|&a, &b| mag[a].total_cmp(&mag[b]))
        .unwrap_or(2);
    let (a, b, c) = (mag[i - 1].ln(), mag[i].ln(), mag[i + 1].ln());
    let d = 0.5 * (a - c) / (a - 2.0 * b + c);
    ((i as f64 + d) * fs / n as f64, 4.0 * mag[i] / n as f64)
}
