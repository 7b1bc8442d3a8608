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
use crate::resonance::{SUBSTRUCTURAL, near_harmonic};
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
/// Newton iterations from a grid start: a start a quarter of the root spacing from a root
/// converges quadratically within a few; one that wanders is abandoned.
const GRID_NEWTON_ITERATIONS: usize = 12;
/// Starts -x / tau on the negative real axis of the dominant-root search.
const REAL_STARTS: [f64; 4] = [0.05, 0.3, 1.0, 3.0];
/// A relative Newton step below which a step that stops shrinking is round-off.
const ROUND_OFF_TOL: f64 = 1e-10;

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
        model.require_proportional("the frequency-domain method")?;
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

    /// Newton step 1 / tr(D^{-1} D') at width `a`. With one or two modes (most models inside
    /// samplers) tr(D^{-1} D') = (det D)' / det D in closed form, without allocation.
    fn newton_step(&self, lambda: Complex64, a: f64) -> Option<Complex64> {
        let n = self.omegas.len();
        let e = (-lambda * self.tau).exp();
        let regen = Complex64::new(1.0, 0.0) - e;
        let entry = |i: usize, j: usize| {
            let mut v =
                regen * a * self.coupling[(i, j)] + lambda * a * self.process_damping[(i, j)];
            if i == j {
                v += lambda * lambda
                    + 2.0 * self.zetas[i] * self.omegas[i] * lambda
                    + self.omegas[i] * self.omegas[i];
            }
            v
        };
        let derivative = |i: usize, j: usize| {
            let mut v = e * a * self.tau * self.coupling[(i, j)] + a * self.process_damping[(i, j)];
            if i == j {
                v += 2.0 * lambda + 2.0 * self.zetas[i] * self.omegas[i];
            }
            v
        };
        let (det, det_derivative) = match n {
            1 => (entry(0, 0), derivative(0, 0)),
            2 => {
                let (d00, d01, d10, d11) = (entry(0, 0), entry(0, 1), entry(1, 0), entry(1, 1));
                let (p00, p01, p10, p11) = (
                    derivative(0, 0),
                    derivative(0, 1),
                    derivative(1, 0),
                    derivative(1, 1),
                );
                (
                    d00 * d11 - d01 * d10,
                    p00 * d11 + d00 * p11 - p01 * d10 - d01 * p10,
                )
            }
            _ => {
                let d = DMatrix::from_fn(n, n, entry);
                let dd = DMatrix::from_fn(n, n, derivative);
                // an exactly singular D means lambda is already a root: no step
                let Some(x) = d.lu().solve(&dd) else {
                    return Some(Complex64::new(0.0, 0.0));
                };
                let tr = x.trace();
                return (tr.norm() > 0.0).then(|| Complex64::new(1.0, 0.0) / tr);
            }
        };
        if det.norm() == 0.0 {
            return Some(Complex64::new(0.0, 0.0));
        }
        (det_derivative.norm() > 0.0).then(|| det / det_derivative)
    }

    /// Newton from `lambda` at width `a`; `None` when it does not converge. Converged when the
    /// step falls below `NEWTON_TOL` |lambda|, or below `ROUND_OFF_TOL` |lambda| without
    /// shrinking further (the round-off floor of det D near a multiple or clustered root).
    fn newton(&self, mut lambda: Complex64, a: f64, iterations: usize) -> Option<Complex64> {
        let mut previous = f64::INFINITY;
        for _ in 0..iterations {
            let step = self.newton_step(lambda, a)?;
            lambda -= step;
            if !(lambda.re.is_finite() && lambda.im.is_finite()) {
                return None;
            }
            let size = step.norm() / lambda.norm();
            if size <= NEWTON_TOL || (size <= ROUND_OFF_TOL && size >= 0.5 * previous) {
                return Some(lambda);
            }
            previous = size;
        }
        None
    }

    fn continue_pole(&self, mut lambda: Complex64, width_m: f64) -> Result<Complex64> {
        for k in 1..=CONTINUATION_STEPS {
            let a = width_m * k as f64 / CONTINUATION_STEPS as f64;
            lambda = self.newton(lambda, a, NEWTON_ITERATIONS).ok_or_else(|| {
                StabilityError::NoConvergence {
                    solver: "characteristic-equation Newton",
                    detail: format!("width {a} m"),
                }
            })?;
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
    continued_poles(model, speed_rpm, width_m)?
        .into_iter()
        .collect()
}

/// Every structural pole continued in the width, each with its own outcome.
fn continued_poles(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<Vec<Result<ClosedLoopPole>>> {
    check_condition(speed_rpm, width_m)?;
    let ch = Characteristic::new(model, speed_rpm)?;
    Ok(model
        .modes()
        .iter()
        .map(|m| {
            let (w, z) = (m.omega_rad_s(), m.damping_ratio());
            let start = Complex64::new(-z * w, w * (1.0 - z * z).sqrt());
            ch.continue_pole(start, width_m).map(ClosedLoopPole::new)
        })
        .collect())
}

/// The dominant (largest real part) closed-loop pole. Delay equations have infinitely many
/// roots; near each mode they form a chain spaced about 2 pi / tau in frequency. Continuing
/// the structural pole in the width does not always end on the dominant root, nor always
/// succeed (at long delays e^{-lambda tau} is large at a damped pole and Newton's basin
/// small), so Newton is started on the imaginary axis, where stability is decided, on a grid
/// around every mode (spacing a quarter of the spindle frequency, from 15 % below the lower to
/// 15 % above the higher of the natural frequency and the frequency with the cut's mean
/// stiffness sqrt(omega^2 + b W_ii), which deep cuts reach, at most 12 iterations each) and on the negative real axis at -x / tau
/// (x = 0.05, 0.3, 1, 3: the real root of slow surface regeneration, which dominates with
/// process damping at low speed), and the root with the largest real part wins; an error only
/// when no start converges. Checked against the first-order full discretization at
/// 4000 steps (tests here) and against the semi-discretization at 4x resolution on the gap
/// proving ground's turning machine (|mu| within 4e-4 from 0.3x to 2x the limiting depth).
pub fn dominant_pole(model: &ModalModel, speed_rpm: f64, width_m: f64) -> Result<ClosedLoopPole> {
    grid_roots(model, speed_rpm, width_m)?
        .into_iter()
        .max_by(|a, b| a.re.total_cmp(&b.re))
        .map(ClosedLoopPole::new)
        .ok_or_else(|| no_root(speed_rpm, width_m))
}

/// The resonance of a cut: the closed-loop pole with the largest real part whose multiplier
/// e^{lambda tau} keeps clear of the spindle harmonics and whose frequency is structural
/// ([`crate::resonance`]), from the starts of [`dominant_pole`]. It is what an identification of a stable cut sees when the dominant
/// roots are the real one of slow surface regeneration and its chain at spindle harmonics
/// (process damping at low speed).
pub fn dominant_resonance_pole(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<ClosedLoopPole> {
    let tau = model.operation().delay_s(speed_rpm);
    let lowest = model
        .omegas_rad_s()
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    grid_roots(model, speed_rpm, width_m)?
        .into_iter()
        .filter(|r| !near_harmonic((r * tau).exp()) && r.im >= SUBSTRUCTURAL * lowest)
        .max_by(|a, b| a.re.total_cmp(&b.re))
        .map(ClosedLoopPole::new)
        .ok_or_else(|| no_root(speed_rpm, width_m))
}

/// The dominant pole ([`dominant_pole`]) and every other distinct unstable (Re lambda > 0)
/// closed-loop pole that the same starts reach, by decreasing real part (none when the cut is
/// stable), from one Newton pass. Past the boundary several roots of a chain can be unstable; a
/// nonlinear limit cycle (loss of contact) may grow from any of them, not always the most
/// unstable (on the gap proving ground's lathe at 1.4-1.6 |mu| the simulated chatter settles
/// 25-50 Hz from the dominant root, on the root that crossed the axis first).
pub fn dominant_and_unstable_poles(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<(ClosedLoopPole, Vec<ClosedLoopPole>)> {
    let mut roots = grid_roots(model, speed_rpm, width_m)?;
    roots.sort_by(|a, b| b.re.total_cmp(&a.re));
    let Some(&dominant) = roots.first() else {
        return Err(no_root(speed_rpm, width_m));
    };
    let mut distinct = vec![dominant];
    for r in roots.into_iter().filter(|r| r.re > 0.0) {
        if distinct.iter().all(|d| (d - r).norm() > 1e-6 * r.norm()) {
            distinct.push(r);
        }
    }
    Ok((
        ClosedLoopPole::new(dominant),
        distinct[1..]
            .iter()
            .map(|&r| ClosedLoopPole::new(r))
            .collect(),
    ))
}

/// The error when no Newton start converges.
fn no_root(speed_rpm: f64, width_m: f64) -> StabilityError {
    StabilityError::NoConvergence {
        solver: "characteristic-equation Newton",
        detail: format!("no root found at {speed_rpm} rpm, width {width_m} m"),
    }
}

/// The roots (upper half plane) that Newton reaches from the starts of [`dominant_pole`].
fn grid_roots(model: &ModalModel, speed_rpm: f64, width_m: f64) -> Result<Vec<Complex64>> {
    check_condition(speed_rpm, width_m)?;
    let ch = Characteristic::new(model, speed_rpm)?;
    let spacing = 2.0 * PI / ch.tau / 4.0;
    // the real (non-oscillating) root of the slow surface regeneration, which dominates with
    // process damping at low speed: |lambda| ~ 1 / tau
    let real_starts = REAL_STARTS.iter().map(|x| Complex64::new(-x / ch.tau, 0.0));
    // the cutting stiffness moves the roots of a deep cut away from the structural frequency:
    // the grid also covers sqrt(omega^2 + b W_ii), the frequency with the cut's mean stiffness
    let shifted = |i: usize| {
        let w = ch.omegas[i];
        (w * w + width_m * ch.coupling[(i, i)])
            .max(0.01 * w * w)
            .sqrt()
    };
    Ok((0..ch.omegas.len())
        .flat_map(|i| {
            let (w, w_cut) = (ch.omegas[i], shifted(i));
            let below = ((w - w.min(w_cut) + 0.15 * w) / spacing).ceil() as i64;
            let above = ((w.max(w_cut) - w + 0.15 * w) / spacing).ceil() as i64;
            (-below..=above).map(move |j| Complex64::new(0.0, w + j as f64 * spacing))
        })
        .chain(real_starts)
        .filter_map(|start| ch.newton(start, width_m, GRID_NEWTON_ITERATIONS))
        .filter(|root| root.im >= 0.0)
        .collect())
}

/// Each mode's own closed-loop pole, continued in the width from its structural pole as
/// [`closed_loop_poles`] does, `None` where the continuation fails: the pole an identification
/// sees near that mode, which need not be the dominant one.
pub fn mode_poles(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<Vec<Option<ClosedLoopPole>>> {
    Ok(continued_poles(model, speed_rpm, width_m)?
        .into_iter()
        .map(Result::ok)
        .collect())
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

    /// The one-pass dominant pole is [`dominant_pole`]'s; the other poles are unstable, slower
    /// than it and distinct; a stable cut has none and a cut far past the boundary several.
    #[test]
    fn unstable_poles_follow_the_dominant_one() {
        let model = examples::ahmadi_2022_turning();
        let options = crate::boundary::BoundaryOptions::default();
        let limit = crate::boundary::limiting_depth(&FrequencyDomain, &model, 7150.0, &options)
            .unwrap()
            .depth_m;
        let (_, none) = dominant_and_unstable_poles(&model, 7150.0, 0.5 * limit).unwrap();
        assert!(none.is_empty());
        let mut seen_others = false;
        for factor in [1.5, 3.0, 6.0] {
            let b = factor * limit;
            let (dominant, others) = dominant_and_unstable_poles(&model, 7150.0, b).unwrap();
            assert_eq!(dominant, dominant_pole(&model, 7150.0, b).unwrap());
            for p in &others {
                assert!(p.lambda.re > 0.0 && p.lambda.re <= dominant.lambda.re);
                assert!((p.lambda - dominant.lambda).norm() > 1e-6 * dominant.lambda.norm());
            }
            seen_others |= !others.is_empty();
        }
        assert!(seen_others, "no second unstable root up to 6x the limit");
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
