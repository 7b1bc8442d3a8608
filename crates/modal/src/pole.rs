//! Poles and their frequency and damping ratio: the one conversion every crate uses.
//!
//! A mode of natural frequency w_n (rad/s) and damping ratio zeta has the pole
//! lambda = -zeta w_n + i w_n sqrt(1 - zeta^2), so |lambda| = w_n and -Re(lambda) / |lambda| =
//! zeta (e.g. 000 Eq. 6 and 25, 002 Section 2.1 for lambda = ln(mu) / tau of a multiplier).
//!
//! ```
//! use chatter_modal::pole::{pole_frequency_damping, pole_from_frequency_damping};
//! let lambda = pole_from_frequency_damping(2473.0, 0.02);
//! let (f, zeta) = pole_frequency_damping(lambda);
//! assert!((f - 2473.0).abs() < 1e-9 && (zeta - 0.02).abs() < 1e-15);
//! ```

use num_complex::Complex64;
use std::f64::consts::PI;

/// The continuous-time pole lambda = ln(mu) / T (rad/s, principal branch) of a multiplier mu
/// over a period T in s: a discrete-time pole of a sample interval (LSCE, LSCF) or a Floquet
/// multiplier of a delay period (000 Eq. 6, 002 Section 2.1). The one home of the conversion.
///
/// ```
/// use chatter_modal::pole::{multiplier_pole, pole_from_frequency_damping};
/// let lambda = pole_from_frequency_damping(50.0, 0.05);
/// let mu = (lambda * 1e-3).exp();
/// assert!((multiplier_pole(mu, 1e-3) - lambda).norm() < 1e-9 * lambda.norm());
/// ```
pub fn multiplier_pole(mu: Complex64, period_s: f64) -> Complex64 {
    mu.ln() / period_s
}

/// (frequency |lambda| / 2 pi in Hz, damping ratio -Re(lambda) / |lambda|) of a pole (rad/s);
/// (0, 1) at lambda = 0.
pub fn pole_frequency_damping(lambda: Complex64) -> (f64, f64) {
    let w = lambda.norm();
    if w > 0.0 {
        (w / (2.0 * PI), -lambda.re / w)
    } else {
        (0.0, 1.0)
    }
}

/// The pole (rad/s, Im >= 0) of frequency `frequency_hz` and damping ratio `damping_ratio`
/// (overdamped ratios > 1 give a real pole of modulus 2 pi f).
pub fn pole_from_frequency_damping(frequency_hz: f64, damping_ratio: f64) -> Complex64 {
    let w = 2.0 * PI * frequency_hz;
    Complex64::new(
        -damping_ratio * w,
        w * (1.0 - damping_ratio * damping_ratio).max(0.0).sqrt(),
    )
}
