//! The iterative process-damping stability algorithm (Karandikar, Tyler and Schmitz, seed 003,
//! Section 2).
//!
//! Process damping adds the force F_d = -C b ydot / V along the surface normal (Eq. 1). Its
//! damping grows with the chip width b and falls with the cutting speed V, so the analytical
//! boundary is found by iteration: (1) the boundary without process damping gives b; (2) b and
//! V give the added damping; (3) the analysis is repeated with the new damping; (4) until b
//! converges. Here the iteration runs per spindle speed on the zero-order (oriented FRF) limit.
//! The added damping is the rotation average of [`ModalModel::process_damping_matrix`] times b,
//! projected on the modes (its diagonal in modal coordinates adds c_n to 2 zeta_n omega_n);
//! for a single mode or a mode aligned with the surface normal the projection is exact.
//!
//! The discretized solvers ([`crate::monodromy`]) carry the same term exactly as -b D(t) xdot,
//! so both routes agree where the zero-order method holds (checked in the tests). The fast
//! zero-order solver ([`crate::zero_order::limiting_depths`]) reaches the limit of this iteration
//! directly; the iteration stays here as 003 states it, as the reference.

use crate::boundary::LobePoint;
use crate::error::{Result, StabilityError};
use crate::zero_order::zoa_limiting_depth;
use chatter_dynamics::{ModalModel, Mode, Operation};

/// Maximum fixed-point iterations per speed.
const MAX_ITERATIONS: usize = 200;
/// Relative convergence of the limiting depth.
const TOLERANCE: f64 = 1e-6;

/// The surface-normal projector n n^T averaged over one delay (dimensionless): the feed
/// coordinate for turning, (N / 2 pi) times the integral of n n^T over the cut for milling with
/// n = (sin(phi), cos(phi)) the chip-thickness direction (003 Eq. 1 with
/// [`ModalModel::process_damping_matrix`]). Times C / V it is the averaged process-damping matrix
/// per unit width.
pub fn average_normal_projector(operation: &Operation) -> [[f64; 2]; 2] {
    match operation {
        Operation::Turning(_) => [[1.0, 0.0], [0.0, 0.0]],
        Operation::Milling(m) => {
            let (a, b) = m.entry_exit_rad();
            let f = m.teeth() as f64 / (2.0 * std::f64::consts::PI);
            let ss = |p: f64| 0.5 * p - 0.25 * (2.0 * p).sin();
            let cc = |p: f64| 0.5 * p + 0.25 * (2.0 * p).sin();
            let sc = |p: f64| 0.5 * p.sin().powi(2);
            let (iss, icc, isc) = (ss(b) - ss(a), cc(b) - cc(a), sc(b) - sc(a));
            [[f * iss, f * isc], [f * isc, f * icc]]
        }
    }
}

/// d zeta_n / d b (1/m) of a mode with mass-normalized `shape` and natural frequency
/// `omega_rad_s` under the averaged process-damping matrix `damping` per unit width
/// (N s/m^3): the modal damping phi^T D phi adds to 2 zeta_n omega_n per unit width.
pub fn damping_ratio_slope_per_m(
    shape: [f64; 2],
    omega_rad_s: f64,
    damping: &[[f64; 2]; 2],
) -> f64 {
    let [p, q] = shape;
    let quadratic =
        p * (damping[0][0] * p + damping[0][1] * q) + q * (damping[1][0] * p + damping[1][1] * q);
    quadratic / (2.0 * omega_rad_s)
}

/// d zeta_n / d b (1/m) of every mode of `model` at `speed_rpm`: the equivalent damping ratio
/// at width b is zeta_n + b s_n (all zero without process damping).
pub fn damping_ratio_slopes_per_m(model: &ModalModel, speed_rpm: f64) -> Vec<f64> {
    let cv = model.process_damping_per_width(speed_rpm);
    damping_ratio_slopes_per_cv(model)
        .into_iter()
        .map(|s| cv * s)
        .collect()
}

/// [`damping_ratio_slopes_per_m`] per unit C / V ([`ModalModel::process_damping_per_width`]),
/// whatever the model's C: the slopes at a speed are these times C / V there.
pub fn damping_ratio_slopes_per_cv(model: &ModalModel) -> Vec<f64> {
    let d = average_normal_projector(model.operation());
    model
        .modes()
        .iter()
        .map(|m| damping_ratio_slope_per_m(m.mass_normalized_shape(), m.omega_rad_s(), &d))
        .collect()
}

/// The model with the process damping of width `depth_m` at `speed_rpm` folded into the modal
/// damping ratios (and the explicit process-damping term removed).
pub fn with_equivalent_damping(
    model: &ModalModel,
    speed_rpm: f64,
    depth_m: f64,
) -> Result<ModalModel> {
    let modes = model
        .modes()
        .iter()
        .zip(damping_ratio_slopes_per_m(model, speed_rpm))
        .map(|(m, slope)| {
            let zeta = m.damping_ratio() + depth_m * slope;
            if zeta >= 1.0 {
                return Err(StabilityError::Unsupported {
                    method: "process damping",
                    reason: format!("equivalent damping ratio {zeta} >= 1 at {speed_rpm} rpm"),
                });
            }
            Ok(Mode::new(m.frequency_hz(), zeta, m.shape())?)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(model.with_modes(modes)?.with_process_damping(None)?)
}

/// Limiting depth with process damping at one speed by the iterative algorithm of 003.
pub fn process_damping_limiting_depth(model: &ModalModel, speed_rpm: f64) -> Result<LobePoint> {
    let bare = model.with_process_damping(None)?;
    let mut point = zoa_limiting_depth(&bare, speed_rpm)?;
    if model.process_damping_n_per_m().is_none() {
        return Ok(point);
    }
    for _ in 0..MAX_ITERATIONS {
        if !point.depth_m.is_finite() {
            return Ok(point);
        }
        // damping ratio >= 1: no finite fixed point, the cut is stable at every depth
        let Ok(damped) = with_equivalent_damping(model, speed_rpm, point.depth_m) else {
            return Ok(LobePoint {
                speed_rpm,
                depth_m: f64::INFINITY,
                chatter_hz: f64::NAN,
            });
        };
        let next = zoa_limiting_depth(&damped, speed_rpm)?;
        let change = (next.depth_m - point.depth_m).abs();
        point = next;
        if change <= TOLERANCE * point.depth_m {
            return Ok(point);
        }
    }
    Err(StabilityError::NoConvergence {
        solver: "process-damping iteration",
        detail: format!("{MAX_ITERATIONS} iterations at {speed_rpm} rpm"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::{BoundaryOptions, limiting_depth};
    use crate::monodromy::Discretization;
    use chatter_dynamics::{CuttingCoefficients, ModeShape, Turning};

    fn sdof_turning(c: Option<f64>) -> ModalModel {
        let mode = Mode::new(
            800.0,
            0.03,
            ModeShape::Directional {
                coordinate: 0,
                stiffness_n_per_m: 2.0e7,
            },
        )
        .unwrap();
        ModalModel::new(
            None,
            Operation::Turning(Turning::new(Some(0.05)).unwrap()),
            CuttingCoefficients::new(2.0e9, 0.7e9).unwrap(),
            vec![mode],
            c,
        )
        .unwrap()
    }

    #[test]
    fn no_process_damping_is_zero_order() {
        let m = sdof_turning(None);
        let a = process_damping_limiting_depth(&m, 1500.0).unwrap();
        let b = zoa_limiting_depth(&m, 1500.0).unwrap();
        assert_eq!(a.depth_m, b.depth_m);
    }

    /// Process damping raises the limit strongly at low speed and little at high speed, and the
    /// iterative analytical boundary agrees with full discretization carrying -b D xdot
    /// (single mode along the surface normal: the equivalent damping is exact) within 1.5 %.
    #[test]
    fn iteration_agrees_with_discretization() {
        let plain = sdof_turning(None);
        // C = 3.5e4 N/m: at 300 rpm (V = 0.79 m/s) the fixed point is about 1.5 b0
        let damped = sdof_turning(Some(3.5e4));
        let low = 300.0;
        let high = 20_000.0;
        let (b0_low, b_low) = (
            zoa_limiting_depth(&plain, low).unwrap().depth_m,
            process_damping_limiting_depth(&damped, low)
                .unwrap()
                .depth_m,
        );
        let (b0_high, b_high) = (
            zoa_limiting_depth(&plain, high).unwrap().depth_m,
            process_damping_limiting_depth(&damped, high)
                .unwrap()
                .depth_m,
        );
        assert!(b_low > 1.3 * b0_low, "low speed: {b_low} vs {b0_low}");
        assert!(b_high < 1.05 * b0_high, "high speed: {b_high} vs {b0_high}");
        for rpm in [low, 600.0, 3000.0] {
            let it = process_damping_limiting_depth(&damped, rpm)
                .unwrap()
                .depth_m;
            let fdm = limiting_depth(
                &Discretization::full(),
                &damped,
                rpm,
                &BoundaryOptions::default(),
            )
            .unwrap()
            .depth_m;
            assert!(
                (it - fdm).abs() < 0.015 * fdm,
                "{rpm} rpm: iterative {it} vs fdm {fdm}"
            );
        }
    }
}
