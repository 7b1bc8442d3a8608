//! Limiting depth at one spindle speed by the zero-order method with process damping, fast enough
//! to compute thousands of sampled boundaries (the random-walk paths of 003 and the Monte Carlo
//! stability maps of 004).
//!
//! The solver is [`chatter_stability::zero_order`]: the zero-order characteristic equation
//! (Altintas and Budak) 1 + b (1 - e^{-i w tau}) Lambda(w; b) = 0, Lambda an eigenvalue of
//! A_0 G_b(i w) with the modal damping raised by the process damping of width b (003 Section 2),
//! solved at each speed for its lowest lobe. This module keeps the names the ensembles use and
//! maps the errors into [`crate::UpdatingError`].

use crate::error::Result;
use chatter_dynamics::ModalModel;
use chatter_stability::boundary::LobePoint;
use chatter_stability::zero_order;

/// Options of [`limiting_depth`]: the depth ceiling (default 0.1 m) and the tolerance of the
/// process-damping fixed point (default 1e-4).
pub use chatter_stability::zero_order::ZeroOrderOptions as BoundaryOptions;

/// Zero-order limiting depth at `speed_rpm`, including the model's process damping (003) when it
/// has one. `depth_m` is infinite when the cut is stable up to `options.max_depth_m`.
pub fn limiting_depth(
    model: &ModalModel,
    speed_rpm: f64,
    options: &BoundaryOptions,
) -> Result<LobePoint> {
    Ok(zero_order::limiting_depth(model, speed_rpm, options)?)
}

/// [`limiting_depth`] at several speeds of one model (its eigenvalue table is built once).
pub fn limiting_depths(
    model: &ModalModel,
    speeds_rpm: &[f64],
    options: &BoundaryOptions,
) -> Result<Vec<LobePoint>> {
    Ok(zero_order::limiting_depths(model, speeds_rpm, options)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::UpdatingError;
    use chatter_dynamics::examples;
    use chatter_stability::process_damping::process_damping_limiting_depth;

    /// The ensembles' entry is the solver of `chatter-stability` (its own tests check it against
    /// dense scans): one speed and several give the same, with process damping close to 003's
    /// iteration, and errors arrive as `UpdatingError::Stability`.
    #[test]
    fn forwards_to_the_zero_order_solver() {
        let model = examples::process_damping_flexure(Some(2.5e5));
        let options = BoundaryOptions::default();
        let speeds = [300.0, 1100.0, 2900.0];
        let all = limiting_depths(&model, &speeds, &options).unwrap();
        for (speed, together) in speeds.into_iter().zip(all) {
            let one = limiting_depth(&model, speed, &options).unwrap();
            assert_eq!(one, together);
            let iterated = process_damping_limiting_depth(&model, speed).unwrap();
            assert!((one.depth_m - iterated.depth_m).abs() < 1e-3 * iterated.depth_m);
        }
        assert!(matches!(
            limiting_depth(&model, -1.0, &options),
            Err(UpdatingError::Stability(_))
        ));
    }
}
