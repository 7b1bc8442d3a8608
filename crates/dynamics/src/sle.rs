//! Surface location error of a stable milling cut (Schmitz & Mann 2006, "Closed-form solutions
//! for surface location error in milling", IJMTM 46).
//!
//! In a stable cut the steady response repeats every tooth period tau, so x(t) - x(t - tau) = 0
//! and the chip is the static one, h = f_z sin(phi): the regenerative term drops out and the
//! steady vibration is the forced response to the periodic static-chip force
//! f(t) = sum_j g_j b f_z sin(phi_j) u(phi_j), with u = (k_t cos phi + k_n sin phi,
//! -k_t sin phi + k_n cos phi) the force direction of [`crate::simulate`] and
//! [`crate::cutting`] (tooth j at phi_j = Omega t + 2 pi j / N from the y axis). Its Fourier
//! series over tau has the coefficients (one tooth over its whole arc, phi = Omega t)
//!
//! ```text
//! F_k = (N / 2 pi) int_{entry}^{exit} b f_z sin(phi) u(phi) e^{-i k N phi} dphi,
//! ```
//!
//! integrated in closed form, and the steady displacement is
//! x(t) = sum_k G(k f_T) F_k e^{i k 2 pi f_T t} (f_T = N n / 60 the tooth-passing frequency,
//! G the receptance matrix of [`ModalModel::receptance_matrix`]), summed over
//! |k| <= [`harmonics`].
//!
//! The wall is generated where a tooth passes the surface-generating angle phi_g: the entry
//! (phi = 0) in up milling, the exit (phi = pi) in down milling. There the edge stands short of
//! its commanded path by n_g . x (the edge position along the chip direction n = (sin phi,
//! cos phi) is n . (feed t - x), as in the simulator), so
//!
//! ```text
//! SLE = n_g . x(t_g),   n_g = (sin phi_g, cos phi_g),
//! ```
//!
//! positive for an undercut (material left on the wall), negative for an overcut. The
//! peak-to-valley is the range of n_g . x(t) over one tooth period (the steady vibration normal to
//! the wall).

use crate::error::{DynamicsError, Result, positive};
use crate::model::ModalModel;
use crate::operation::{MillingDirection, Operation};
use nalgebra::Vector2;
use num_complex::Complex64;
use std::f64::consts::PI;

/// The steady surface of one stable milling cut.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceLocation {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Surface location error (m): positive undercut, negative overcut (module docs).
    pub sle_m: f64,
    /// Peak-to-valley of the surface-normal displacement over one tooth period (m).
    pub peak_to_valley_m: f64,
    /// The surface-generating angle (rad from the y axis): 0 up milling, pi down milling.
    pub generating_angle_rad: f64,
}

/// Tooth-passing harmonics summed for a model whose highest mode is `f_max_hz` at tooth-passing
/// frequency `f_tooth_hz`: up to 40 times the highest mode (the response's terms fall as k^-3
/// above it: the force's as 1/k at its jumps, the receptance's as 1/k^2), at least 64, at most
/// 20 000.
pub fn harmonics(f_max_hz: f64, f_tooth_hz: f64) -> usize {
    ((40.0 * f_max_hz / f_tooth_hz).ceil() as usize).clamp(64, 20_000)
}

/// int_a^b e^{i p phi} dphi.
fn e_integral(p: f64, a: f64, b: f64) -> Complex64 {
    if p == 0.0 {
        return Complex64::new(b - a, 0.0);
    }
    let i = Complex64::i();
    ((i * p * b).exp() - (i * p * a).exp()) / (i * p)
}

/// The Fourier coefficient F_k (N) of the static-chip force per unit depth and feed (module
/// docs), in closed form: sin(phi) u(phi) = (k_t sin 2phi / 2 + k_n sin^2 phi,
/// -k_t sin^2 phi + k_n sin 2phi / 2).
fn force_coefficient(
    k: usize,
    teeth: usize,
    (entry, exit): (f64, f64),
    (kt, kn): (f64, f64),
) -> [Complex64; 2] {
    let m = (k * teeth) as f64;
    let i = Complex64::i();
    let one = e_integral(-m, entry, exit);
    let (plus, minus) = (
        e_integral(2.0 - m, entry, exit),
        e_integral(-2.0 - m, entry, exit),
    );
    let cos2 = (plus + minus) / 2.0;
    let sin2 = (plus - minus) / (2.0 * i);
    let sc = sin2 / 2.0; // int sin cos e^{-i m phi}
    let ss = (one - cos2) / 2.0; // int sin^2 e^{-i m phi}
    let scale = teeth as f64 / (2.0 * PI);
    [scale * (kt * sc + kn * ss), scale * (-kt * ss + kn * sc)]
}

/// The steady surface of a stable cut at `speed_rpm`, depth `depth_m` and feed per tooth
/// `feed_per_tooth_m` (module docs). Milling with even pitch, no process damping; other models
/// are errors naming the field.
pub fn surface_location_error(
    model: &ModalModel,
    speed_rpm: f64,
    depth_m: f64,
    feed_per_tooth_m: f64,
) -> Result<SurfaceLocation> {
    positive("speed_rpm", speed_rpm)?;
    positive("depth_m", depth_m)?;
    positive("feed_per_tooth_m", feed_per_tooth_m)?;
    let Operation::Milling(milling) = model.operation() else {
        return Err(DynamicsError::invalid(
            "operation.kind",
            "turning: the surface location error is computed for milling",
        ));
    };
    if milling.is_variable_pitch() {
        return Err(DynamicsError::invalid(
            "operation.pitch_deg",
            format!(
                "{:?}: the steady response of a variable-pitch cutter repeats once per revolution \
                 and keeps a regenerative part; the surface location error here is for even pitch",
                milling.pitch_deg().unwrap_or_default()
            ),
        ));
    }
    if milling.is_helical() {
        return Err(DynamicsError::invalid(
            "operation.helix_deg",
            "a helical cutter's force spreads along the axis; the surface location error here is \
             for a straight cutter",
        ));
    }
    if model.process_damping_n_per_m().is_some_and(|c| c > 0.0) {
        return Err(DynamicsError::invalid(
            "process_damping",
            "the surface location error here is the forced response without process damping",
        ));
    }
    let teeth = milling.teeth();
    let f_tooth = speed_rpm / 60.0 * teeth as f64;
    let f_max = model
        .modes()
        .iter()
        .map(|m| m.frequency_hz())
        .fold(0.0, f64::max);
    let k_max = harmonics(f_max, f_tooth);
    let cutting = model.cutting();
    let coefficients = (cutting.kt_n_per_m2(), cutting.kn_n_per_m2());
    let arc = milling.entry_exit_rad();
    let scale = depth_m * feed_per_tooth_m;
    // X_k = G(k f_T) F_k for k = 0..=k_max
    let response: Vec<[Complex64; 2]> = (0..=k_max)
        .map(|k| {
            let f = force_coefficient(k, teeth, arc, coefficients);
            let g = model.receptance_matrix(k as f64 * f_tooth);
            [
                scale * (g[0][0] * f[0] + g[0][1] * f[1]),
                scale * (g[1][0] * f[0] + g[1][1] * f[1]),
            ]
        })
        .collect();
    let generating_angle_rad = match milling.direction() {
        MillingDirection::Up => 0.0,
        MillingDirection::Down => PI,
    };
    let normal = Vector2::new(generating_angle_rad.sin(), generating_angle_rad.cos());
    let omega = 2.0 * PI * speed_rpm / 60.0;
    let normal_at = |t: f64| -> f64 {
        let w = 2.0 * PI * f_tooth * t;
        let mut x = [response[0][0].re, response[0][1].re];
        for (k, r) in response.iter().enumerate().skip(1) {
            let e = Complex64::from_polar(1.0, k as f64 * w);
            x[0] += 2.0 * (r[0] * e).re;
            x[1] += 2.0 * (r[1] * e).re;
        }
        normal[0] * x[0] + normal[1] * x[1]
    };
    let tau = 1.0 / f_tooth;
    let sle_m = normal_at(generating_angle_rad / omega);
    let samples = 512;
    let (lo, hi) = (0..samples)
        .map(|i| normal_at(i as f64 * tau / samples as f64))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    Ok(SurfaceLocation {
        speed_rpm,
        sle_m,
        peak_to_valley_m: hi - lo,
        generating_angle_rad,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::examples;

    /// F_0 is the mean force, (N / 2 pi) times the integral of sin(phi) u(phi) over the arc:
    /// checked against a midpoint sum.
    #[test]
    fn mean_force_is_the_numerical_average() {
        let model = examples::schmitz_2023_milling();
        let Operation::Milling(m) = model.operation() else {
            unreachable!()
        };
        let c = model.cutting();
        let (kt, kn) = (c.kt_n_per_m2(), c.kn_n_per_m2());
        let (a, b) = m.entry_exit_rad();
        let f0 = force_coefficient(0, 4, (a, b), (kt, kn));
        let f3 = force_coefficient(3, 4, (a, b), (kt, kn));
        let n = 200_000;
        let (mut s0, mut s3) = ([0.0; 2], [Complex64::new(0.0, 0.0); 2]);
        for i in 0..n {
            let phi = a + (i as f64 + 0.5) / n as f64 * (b - a);
            let (s, co) = phi.sin_cos();
            let u = [kt * co + kn * s, -kt * s + kn * co];
            let e = Complex64::from_polar(1.0, -12.0 * phi);
            for j in 0..2 {
                s0[j] += s * u[j];
                s3[j] += s * u[j] * e;
            }
        }
        let w = (b - a) / n as f64 * 4.0 / (2.0 * PI);
        for j in 0..2 {
            assert!((f0[j].re - s0[j] * w).abs() < 1e-6 * kt, "{f0:?}");
            assert!((f3[j] - s3[j] * w).norm() < 1e-6 * kt, "{f3:?}");
        }
    }
}
