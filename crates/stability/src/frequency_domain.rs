//! Closed-loop poles of turning from the characteristic equation (Ahmadi 2022, seed 000,
//! Section 2.1, Eq. 5-6):
//!
//! det D(lambda) = 0, D(lambda) = lambda^2 I + 2 Omega Z lambda + Omega^2 + a Phi^T K_c Phi (1 - e^{-lambda tau})
//!
//! (N x N in modal coordinates; our sign convention writes the force as -a K_c (x - x_tau)). Each
//! structural pole lambda_n = -zeta_n w_n + i w_n sqrt(1 - zeta_n^2) (the root at a = 0) is
//! continued in the width a by Newton's method with Jacobi's formula
//! d/dlambda ln det D = tr(D^{-1} D'), D' = 2 lambda I + 2 Omega Z + a tau Phi^T K_c Phi e^{-lambda tau}.
//! The dominant pole is the continued pole with the largest real part; its frequency is |lambda|
//! and its damping -Re(lambda) / |lambda| (Eq. 6).
//!
//! Process damping (003 Eq. 1), F_d = -a D xdot with the constant D = (C / V) e_feed e_feed^T of
//! turning ([`ModalModel::process_damping_matrix`]), adds a lambda Phi^T D Phi to D(lambda) and
//! a Phi^T D Phi to D'(lambda): exact, as in the discretizations, since nothing is averaged.

use crate::StabilitySolver;
use crate::error::{Result, StabilityError, check_condition};
use crate::multiplier::DominantMultiplier;
use chatter_dynamics::pole::pole_frequency_damping;
use chatter_dynamics::{ModalModel, Operation};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::f64::consts::PI;

/// Width steps of the continuation from a = 0.
const CONTINUATION_STEPS: usize = 24;
/// Newton iterations per step and their relative tolerance on lambda.
const NEWTON_ITERATIONS: usize = 30;
const NEWTON_TOL: f64 = 1e-13;

/// A closed-loop pole with its frequency and damping (000 Eq. 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosedLoopPole {
    /// lambda (rad/s).
    pub lambda: Complex64,
    /// |lambda| / 2 pi.
    pub frequency_hz: f64,
    /// -Re(lambda) / |lambda|.
    pub damping_ratio: f64,
}

impl ClosedLoopPole {
    fn new(lambda: Complex64) -> Self {
        let (frequency_hz, damping_ratio) = pole_frequency_damping(lambda);
        Self {
            lambda,
            frequency_hz,
            damping_ratio,
        }
    }
}

struct Characteristic {
    omegas: Vec<f64>,
    zetas: Vec<f64>,
    coupling: DMatrix<f64>,
    /// Phi^T D Phi: process damping per unit width in modal coordinates (zero without it).
    process_damping: DMatrix<f64>,
    tau: f64,
}

impl Characteristic {
    fn new(model: &ModalModel, speed_rpm: f64) -> Result<Self> {
        if !matches!(model.operation(), Operation::Turning(_)) {
            return Err(StabilityError::Unsupported {
                method: "frequency-domain poles",
                reason: "the characteristic equation with constant K_c is for turning".into(),
            });
        }
        let phi = model.shape_matrix();
        let h = model.directional_matrix(0.0, speed_rpm);
        let hm = DMatrix::from_fn(2, 2, |i, j| h[(i, j)]);
        let d = model.process_damping_matrix(0.0, speed_rpm);
        let dm = DMatrix::from_fn(2, 2, |i, j| d[(i, j)]);
        Ok(Self {
            omegas: model.omegas_rad_s(),
            zetas: model.damping_ratios(),
            coupling: phi.transpose() * hm * &phi,
            process_damping: phi.transpose() * dm * &phi,
            tau: model.operation().delay_s(speed_rpm),
        })
    }

    /// Newton step 1 / tr(D^{-1} D') at width `a`.
    fn newton_step(&self, lambda: Complex64, a: f64) -> Option<Complex64> {
        let n = self.omegas.len();
        let e = (-lambda * self.tau).exp();
        let regen = Complex64::new(1.0, 0.0) - e;
        let d = DMatrix::from_fn(n, n, |i, j| {
            let mut v =
                regen * a * self.coupling[(i, j)] + lambda * a * self.process_damping[(i, j)];
            if i == j {
                v += lambda * lambda
                    + 2.0 * self.zetas[i] * self.omegas[i] * lambda
                    + self.omegas[i] * self.omegas[i];
            }
            v
        });
        let dd = DMatrix::from_fn(n, n, |i, j| {
            let mut v = e * a * self.tau * self.coupling[(i, j)] + a * self.process_damping[(i, j)];
            if i == j {
                v += 2.0 * lambda + 2.0 * self.zetas[i] * self.omegas[i];
            }
            v
        });
        // an exactly singular D means lambda is already a root: no step
        let Some(x) = d.lu().solve(&dd) else {
            return Some(Complex64::new(0.0, 0.0));
        };
        let tr = x.trace();
        (tr.norm() > 0.0).then(|| Complex64::new(1.0, 0.0) / tr)
    }

    /// Newton from `lambda` at width `a`; `None` when it does not converge.
    fn newton(&self, mut lambda: Complex64, a: f64) -> Option<Complex64> {
        for _ in 0..NEWTON_ITERATIONS {
            let step = self.newton_step(lambda, a)?;
            lambda -= step;
            if !(lambda.re.is_finite() && lambda.im.is_finite()) {
                return None;
            }
            if step.norm() <= NEWTON_TOL * lambda.norm() {
                return Some(lambda);
            }
        }
        None
    }

    fn continue_pole(&self, mut lambda: Complex64, width_m: f64) -> Result<Complex64> {
        for k in 1..=CONTINUATION_STEPS {
            let a = width_m * k as f64 / CONTINUATION_STEPS as f64;
            let mut converged = false;
            for _ in 0..NEWTON_ITERATIONS {
                let step = self
                    .newton_step(lambda, a)
                    .ok_or(StabilityError::NoConvergence {
                        solver: "characteristic-equation Newton",
                        detail: "singular characteristic matrix".into(),
                    })?;
                lambda -= step;
                if step.norm() <= NEWTON_TOL * lambda.norm() {
                    converged = true;
                    break;
                }
            }
            if !converged {
                return Err(StabilityError::NoConvergence {
                    solver: "characteristic-equation Newton",
                    detail: format!("width {a} m"),
                });
            }
        }
        Ok(lambda)
    }
}

/// The closed-loop poles continued from every structural pole, at `speed_rpm` and width
/// `width_m`.
pub fn closed_loop_poles(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<Vec<ClosedLoopPole>> {
    check_condition(speed_rpm, width_m)?;
    let ch = Characteristic::new(model, speed_rpm)?;
    model
        .modes()
        .iter()
        .map(|m| {
            let (w, z) = (m.omega_rad_s(), m.damping_ratio());
            let start = Complex64::new(-z * w, w * (1.0 - z * z).sqrt());
            Ok(ClosedLoopPole::new(ch.continue_pole(start, width_m)?))
        })
        .collect()
}

/// The dominant (largest real part) closed-loop pole. Delay equations have infinitely many
/// roots and the branch continued from a structural pole is not always the dominant one, so
/// Newton is also started from a grid around every mode (spacing a quarter of the spindle
/// frequency, +-15 % of the natural frequency) and the root with the largest real part wins.
pub fn dominant_pole(model: &ModalModel, speed_rpm: f64, width_m: f64) -> Result<ClosedLoopPole> {
    let mut poles = closed_loop_poles(model, speed_rpm, width_m)?;
    let ch = Characteristic::new(model, speed_rpm)?;
    let spacing = 2.0 * PI / ch.tau / 4.0;
    for (w, z) in ch.omegas.iter().zip(&ch.zetas) {
        let k = (0.15 * w / spacing).ceil() as i64;
        for j in -k..=k {
            let start = Complex64::new(-z * w, w + j as f64 * spacing);
            if let Some(root) = ch.newton(start, width_m).filter(|r| r.im > 0.0) {
                poles.push(ClosedLoopPole::new(root));
            }
        }
    }
    poles
        .into_iter()
        .max_by(|a, b| a.lambda.re.total_cmp(&b.lambda.re))
        .ok_or(StabilityError::NoConvergence {
            solver: "characteristic-equation Newton",
            detail: "no modes".into(),
        })
}

/// The frequency-domain method as a [`StabilitySolver`]: mu = e^{lambda tau} of the dominant pole.
#[derive(Debug, Clone, Copy, Default)]
pub struct FrequencyDomain;

impl StabilitySolver for FrequencyDomain {
    fn name(&self) -> &'static str {
        "frequency-domain"
    }

    fn dominant_multiplier(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<DominantMultiplier> {
        let p = dominant_pole(model, speed_rpm, depth_m)?;
        let tau = model.operation().delay_s(speed_rpm);
        Ok(DominantMultiplier::new((p.lambda * tau).exp(), tau))
    }

    fn chatter_frequency_hz(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)> {
        let p = dominant_pole(model, speed_rpm, depth_m)?;
        let tau = model.operation().delay_s(speed_rpm);
        Ok((
            DominantMultiplier::new((p.lambda * tau).exp(), tau),
            p.lambda.im / (2.0 * PI),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    #[test]
    fn zero_width_gives_structural_poles() {
        let model = examples::ahmadi_2022_turning();
        let poles = closed_loop_poles(&model, 7150.0, 0.0).unwrap();
        for (p, m) in poles.iter().zip(model.modes()) {
            assert!((p.frequency_hz - m.frequency_hz()).abs() < 1e-9 * m.frequency_hz());
            assert!((p.damping_ratio - m.damping_ratio()).abs() < 1e-12);
        }
    }

    /// Turning with process damping (seed-000 lathe, C = 2e4 N/m, 38 mm workpiece): the poles
    /// include it as the discretization does, so the limiting depths agree to 0.2 % with FDM at
    /// 4000 steps (measured 0.11 % at 2000 rpm, 0.01 % at 7150 rpm: FDM's first-order error at
    /// 30 steps per vibration cycle), and process damping raises the limit at 2000 rpm (V = 4 m/s)
    /// from 2.880 to 3.130 mm.
    #[test]
    fn process_damping_agrees_with_discretization() {
        use crate::boundary::{BoundaryOptions, limiting_depth};
        use crate::monodromy::Discretization;
        let bare = examples::ahmadi_2022_turning();
        let model = bare.with_process_damping(Some(2e4)).unwrap();
        let options = BoundaryOptions::default();
        for speed in [2000.0, 7150.0] {
            let poles = limiting_depth(&FrequencyDomain, &model, speed, &options).unwrap();
            let fdm = limiting_depth(
                &Discretization::full().with_steps(4000),
                &model,
                speed,
                &options,
            )
            .unwrap();
            assert!(
                (poles.depth_m - fdm.depth_m).abs() < 2e-3 * fdm.depth_m,
                "{speed} rpm: poles {} mm, fdm {} mm",
                poles.depth_mm(),
                fdm.depth_mm()
            );
        }
        let without = limiting_depth(&FrequencyDomain, &bare, 2000.0, &options).unwrap();
        let with = limiting_depth(&FrequencyDomain, &model, 2000.0, &options).unwrap();
        assert!(
            with.depth_m > 1.05 * without.depth_m,
            "{with:?} vs {without:?}"
        );
    }

    #[test]
    fn milling_is_rejected() {
        let model = examples::schmitz_2023_milling();
        assert!(closed_loop_poles(&model, 7000.0, 1e-3).is_err());
    }
}
