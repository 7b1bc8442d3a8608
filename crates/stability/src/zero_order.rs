//! Zero-order approximation (Altintas and Budak 1995) for multi-mode milling and, with the
//! constant K_c, the classic oriented-FRF solution for turning.
//!
//! Averaging H(t) over a delay gives A_0 ([`ModalModel::average_directional_matrix`]) and the
//! characteristic equation det(I + b (1 - e^{-i w tau}) A_0 G(i w)) = 0 at the chatter frequency
//! w. With Lambda an eigenvalue of A_0 G(i w) it reads 1 + b (1 - e^{-i eps}) Lambda = 0,
//! eps = w tau. Writing 1 - e^{-i eps} = 2 sin(eps/2) e^{i (pi - eps)/2} for eps in (0, 2 pi):
//! eps = (2 arg(Lambda) - pi) mod 4 pi must fall in (0, 2 pi) (this is Re(Lambda) < 0), and then
//! b = 1 / (2 sin(eps/2) |Lambda|) = -1 / (2 Re(Lambda)) (1 + kappa^2) with kappa = Im/Re,
//! the familiar form; tau = (eps + 2 pi k) / w for lobe k = 0, 1, 2, ...
//!
//! Lobes are traced over a fine chatter-frequency grid and the limiting depth at a speed is the
//! lowest lobe crossing that speed.

use crate::boundary::LobePoint;
use crate::error::{Result, StabilityError};
use chatter_dynamics::ModalModel;
use num_complex::Complex64;
use std::f64::consts::PI;

/// Chatter-frequency samples per lobe trace.
const FREQUENCY_SAMPLES: usize = 6000;
/// Lobes traced (k = 0..MAX_LOBES).
const MAX_LOBES: usize = 400;

/// Eigenvalues of a 2 x 2 complex matrix.
fn eig2(m: [[Complex64; 2]; 2]) -> [Complex64; 2] {
    let tr = m[0][0] + m[1][1];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let disc = (tr * tr * 0.25 - det).sqrt();
    [tr * 0.5 + disc, tr * 0.5 - disc]
}

/// One traced branch: (chatter Hz, eps, depth m) per frequency sample.
fn branches(model: &ModalModel) -> Vec<Vec<(f64, f64, f64)>> {
    let a0 = model.average_directional_matrix();
    let (f_lo, f_hi) = model
        .modes()
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), m| {
            (lo.min(m.frequency_hz()), hi.max(m.frequency_hz()))
        });
    let (f0, f1) = (0.5 * f_lo, 2.0 * f_hi);
    let mut out: Vec<Vec<(f64, f64, f64)>> = (0..2)
        .map(|_| Vec::with_capacity(FREQUENCY_SAMPLES))
        .collect();
    let mut previous: Option<[Complex64; 2]> = None;
    for i in 0..FREQUENCY_SAMPLES {
        // geometric spacing concentrates samples at low frequency; resonances get enough either way
        let f = f0 * (f1 / f0).powf(i as f64 / (FREQUENCY_SAMPLES - 1) as f64);
        let g = model.receptance_matrix(f);
        let mut m = [[Complex64::new(0.0, 0.0); 2]; 2];
        for (r, row) in m.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = (0..2).map(|k| g[k][c] * a0[(r, k)]).sum();
            }
        }
        let mut lam = eig2(m);
        // keep branches continuous: match to the previous sample's eigenvalues
        if let Some(p) = previous {
            let straight = (lam[0] - p[0]).norm() + (lam[1] - p[1]).norm();
            let swapped = (lam[1] - p[0]).norm() + (lam[0] - p[1]).norm();
            if swapped < straight {
                lam.swap(0, 1);
            }
        }
        previous = Some(lam);
        for (branch, l) in out.iter_mut().zip(lam) {
            let eps = (2.0 * l.arg() - PI).rem_euclid(4.0 * PI);
            let valid = l.norm() > 1e-300 && eps > 0.0 && eps < 2.0 * PI;
            let b = if valid {
                1.0 / (2.0 * (eps / 2.0).sin() * l.norm())
            } else {
                f64::NAN
            };
            branch.push((f, eps, b));
        }
    }
    out
}

/// Zero-order limiting depths at the given speeds.
pub fn zoa_lobes(model: &ModalModel, speeds_rpm: &[f64]) -> Result<Vec<LobePoint>> {
    if speeds_rpm.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(StabilityError::InvalidInput {
            field: "speed_rpm",
            value: speeds_rpm
                .iter()
                .copied()
                .find(|s| s.is_nan() || *s <= 0.0)
                .unwrap_or(f64::NAN),
            expected: "spindle speeds > 0",
        });
    }
    let delays = model.operation().delays_per_revolution() as f64;
    let mut best: Vec<LobePoint> = speeds_rpm
        .iter()
        .map(|&s| LobePoint {
            speed_rpm: s,
            depth_m: f64::INFINITY,
            chatter_hz: f64::NAN,
        })
        .collect();
    let s_min = speeds_rpm.iter().copied().fold(f64::INFINITY, f64::min);
    for branch in branches(model) {
        for k in 0..MAX_LOBES {
            // speed of each sample on lobe k
            let pts: Vec<(f64, f64, f64)> = branch
                .iter()
                .map(|&(f, eps, b)| {
                    let tau = (eps + 2.0 * PI * k as f64) / (2.0 * PI * f);
                    (60.0 / (delays * tau), b, f)
                })
                .collect();
            if pts.iter().all(|p| p.0 < s_min || !p.1.is_finite()) {
                break;
            }
            for w in pts.windows(2) {
                let ((s0, b0, f0), (s1, b1, f1)) = (w[0], w[1]);
                if !(b0.is_finite() && b1.is_finite()) {
                    continue;
                }
                let (lo, hi) = if s0 < s1 { (s0, s1) } else { (s1, s0) };
                // a wrap of eps between samples is not a segment of the lobe
                if hi / lo > 1.05 {
                    continue;
                }
                for p in best.iter_mut() {
                    if p.speed_rpm >= lo && p.speed_rpm <= hi && hi > lo {
                        let t = (p.speed_rpm - s0) / (s1 - s0);
                        let b = b0 + t * (b1 - b0);
                        if b < p.depth_m {
                            p.depth_m = b;
                            p.chatter_hz = f0 + t * (f1 - f0);
                        }
                    }
                }
            }
        }
    }
    Ok(best)
}

/// Zero-order limiting depth at one speed.
pub fn zoa_limiting_depth(model: &ModalModel, speed_rpm: f64) -> Result<LobePoint> {
    let mut v = zoa_lobes(model, &[speed_rpm])?;
    v.pop().ok_or(StabilityError::InvalidInput {
        field: "speed_rpm",
        value: speed_rpm,
        expected: "a spindle speed > 0",
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    #[test]
    fn single_dof_minimum_is_tlusty_limit() {
        // full-immersion SDOF in x: Lambda = A0_xx G_xx, minimum b = -1 / (2 A0_xx min Re G)
        let model = examples::insperger_benchmark(1.0);
        let speeds: Vec<f64> = (0..4000).map(|i| 5000.0 + 5.0 * i as f64).collect();
        let lobes = zoa_lobes(&model, &speeds).unwrap();
        let b_min = lobes
            .iter()
            .map(|p| p.depth_m)
            .fold(f64::INFINITY, f64::min);
        let a_xx = model.average_directional_matrix()[(0, 0)];
        let re_min = (0..200_000)
            .map(|i| model.receptance(800.0 + i as f64 * 0.001, 0, 0).re)
            .fold(f64::INFINITY, f64::min);
        let exact = -1.0 / (2.0 * a_xx * re_min);
        // speed grid of 5 rpm samples the lobe bottoms to ~0.1 %
        assert!((b_min - exact).abs() < 2e-3 * exact, "{b_min} vs {exact}");
    }
}
