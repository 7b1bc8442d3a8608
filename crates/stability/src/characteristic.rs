//! The characteristic equation of turning (Ahmadi 2022, seed 000, Section 2.1, Eq. 5-6 and 28)
//! and Newton's method on it: the one home of the closed-loop poles, for the frequency-domain
//! solver ([`crate::frequency_domain`]) and the pole likelihood of `chatter-updating`.
//!
//! In modal coordinates (N x N; the force written as -a K_c (x - x_tau))
//!
//! D(lambda) = lambda^2 I + 2 Omega Z lambda + Omega^2 + a Phi^T K_c Phi (1 - e^{-lambda tau})
//!           + a lambda Phi^T D Phi,
//!
//! and the closed-loop poles at width a are the roots of det D(lambda) = 0. The last term is the
//! optional process damping (003 Eq. 1), F_d = -a D xdot with the constant
//! D = (C / V) e_feed e_feed^T of turning ([`ModalModel::process_damping_matrix`]; zero for a
//! model without process damping): exact, as in the discretizations, since nothing is averaged.
//!
//! Newton's step is det D / (det D)' = 1 / tr(D^{-1} D') (Jacobi's formula), with
//! D' = 2 lambda I + 2 Omega Z + a tau Phi^T K_c Phi e^{-lambda tau} + a Phi^T D Phi.

use crate::error::{Result, StabilityError};
use chatter_dynamics::{ModalModel, Operation};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Relative Newton step on lambda below which a root counts as converged.
const NEWTON_TOL: f64 = 1e-13;
/// A relative Newton step below which a step that stops shrinking is round-off (the floor of
/// det D near a multiple or clustered root).
const ROUND_OFF_TOL: f64 = 1e-10;

/// The characteristic matrix D(lambda) of a turning model at one spindle speed, per unit width
/// in its cutting terms.
#[derive(Debug, Clone)]
pub struct Characteristic {
    omegas: Vec<f64>,
    zetas: Vec<f64>,
    /// Phi^T K_c Phi (N x N, per unit width).
    coupling: DMatrix<f64>,
    /// Phi^T D Phi: process damping per unit width in modal coordinates (zero without it).
    process_damping: DMatrix<f64>,
    tau: f64,
}

impl Characteristic {
    /// The characteristic equation of the turning `model` at `speed_rpm`, with the model's
    /// process damping when it has one; milling is [`StabilityError::Unsupported`] (its
    /// directional matrix is periodic, not constant).
    pub fn new(model: &ModalModel, speed_rpm: f64) -> Result<Self> {
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

    /// The delay tau (s).
    pub fn delay_s(&self) -> f64 {
        self.tau
    }

    /// The natural frequencies (rad/s) of the modes.
    pub fn omegas_rad_s(&self) -> &[f64] {
        &self.omegas
    }

    /// The diagonal entry i of Phi^T K_c Phi (N/m^2 per unit width): the cutting stiffness mode
    /// i sees.
    pub fn coupling_diagonal(&self, i: usize) -> f64 {
        self.coupling[(i, i)]
    }

    /// Entry (i, j) of D(lambda) at width `a`; `e` = e^{-lambda tau}.
    fn entry(&self, lambda: Complex64, a: f64, e: Complex64, i: usize, j: usize) -> Complex64 {
        let mut v = (Complex64::new(1.0, 0.0) - e) * a * self.coupling[(i, j)]
            + lambda * a * self.process_damping[(i, j)];
        if i == j {
            v += lambda * lambda
                + 2.0 * self.zetas[i] * self.omegas[i] * lambda
                + self.omegas[i] * self.omegas[i];
        }
        v
    }

    /// Entry (i, j) of D'(lambda) at width `a`; `e` = e^{-lambda tau}.
    fn derivative(&self, lambda: Complex64, a: f64, e: Complex64, i: usize, j: usize) -> Complex64 {
        let mut v = e * a * self.tau * self.coupling[(i, j)] + a * self.process_damping[(i, j)];
        if i == j {
            v += 2.0 * lambda + 2.0 * self.zetas[i] * self.omegas[i];
        }
        v
    }

    /// det D(lambda) at width `a` (000 Eq. 28).
    pub fn determinant(&self, lambda: Complex64, a: f64) -> Complex64 {
        let e = (-lambda * self.tau).exp();
        let d = |i, j| self.entry(lambda, a, e, i, j);
        match self.omegas.len() {
            1 => d(0, 0),
            2 => d(0, 0) * d(1, 1) - d(0, 1) * d(1, 0),
            n => DMatrix::from_fn(n, n, d).determinant(),
        }
    }

    /// Newton step 1 / tr(D^{-1} D') at width `a`; `None` where D' vanishes. With one or two
    /// modes (most models inside samplers) tr(D^{-1} D') = (det D)' / det D in closed form;
    /// with more, by an LU factorization with partial pivoting in place, D' eliminated
    /// alongside and the trace by back substitution; neither allocates up to four modes.
    pub fn newton_step(&self, lambda: Complex64, a: f64) -> Option<Complex64> {
        let n = self.omegas.len();
        let e = (-lambda * self.tau).exp();
        let entry = |i: usize, j: usize| self.entry(lambda, a, e, i, j);
        let derivative = |i: usize, j: usize| self.derivative(lambda, a, e, i, j);
        let zero = Complex64::new(0.0, 0.0);
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
                let trace = if n <= STACK_MODES {
                    let mut buffer = [zero; 2 * STACK_MODES * STACK_MODES];
                    filled_inverse_trace(&mut buffer[..2 * n * n], n, entry, derivative)
                } else {
                    filled_inverse_trace(&mut vec![zero; 2 * n * n], n, entry, derivative)
                };
                // an exactly singular D means lambda is already a root: no step
                let Some(tr) = trace else {
                    return Some(zero);
                };
                return (tr != zero).then(|| Complex64::new(1.0, 0.0) / tr);
            }
        };
        if det == zero {
            return Some(zero);
        }
        (det_derivative != zero).then(|| det / det_derivative)
    }

    /// The root reached by Newton's method from `start` at width `a` within `iterations`;
    /// `None` when it does not converge. Converged when the step falls below 1e-13 |lambda|, or
    /// below 1e-10 |lambda| without shrinking further (the round-off floor of det D near a
    /// multiple or clustered root).
    pub fn newton(&self, start: Complex64, a: f64, iterations: usize) -> Option<Complex64> {
        self.newton_within(start, a, iterations, f64::INFINITY)
    }

    /// [`Self::newton`], abandoned (`None`) as soon as an iterate lies farther than
    /// `max_distance` x |start| from `start`: the root of the branch that `start` identifies,
    /// not another one.
    pub fn newton_within(
        &self,
        start: Complex64,
        a: f64,
        iterations: usize,
        max_distance: f64,
    ) -> Option<Complex64> {
        let mut lambda = start;
        let mut previous = f64::INFINITY;
        for _ in 0..iterations {
            let step = self.newton_step(lambda, a)?;
            lambda -= step;
            if !(lambda.re.is_finite() && lambda.im.is_finite())
                || (max_distance.is_finite()
                    && (lambda - start).norm_sqr() > max_distance.powi(2) * start.norm_sqr())
            {
                return None;
            }
            let size = (step.norm_sqr() / lambda.norm_sqr()).sqrt();
            if size <= NEWTON_TOL || (size <= ROUND_OFF_TOL && size >= 0.5 * previous) {
                return Some(lambda);
            }
            previous = size;
        }
        None
    }
}

impl Characteristic {
    /// Where the branch of the unstable root `lambda` at width `a` crosses the imaginary axis
    /// as the width is lowered: `(a_c, lambda_c)` with Re lambda_c = 0 (to 1e-9 |lambda_c|),
    /// `None` when the root is not unstable or the branch is lost (no crossing above zero width,
    /// Newton leaves the branch). The root is followed by Newton's method from width to width
    /// (each step at most a fifth of the width, halved up to six times where Newton does not
    /// converge, the iterate kept within 5 % of its start) and a_c found by the secant rule on
    /// Re lambda(a).
    ///
    /// This is the describing-function frequency of a limit cycle with loss of contact: the
    /// tool leaving the cut scales the cutting force's first harmonic by a real gain below one,
    /// i.e. lowers the effective width, until the branch sits on the axis; a chattering cut
    /// past the boundary therefore vibrates near Im lambda_c, not near Im lambda at its own
    /// width (checked against time-domain simulations in `chatter-gap`).
    pub fn axis_crossing(&self, lambda: Complex64, a: f64) -> Option<(f64, Complex64)> {
        const ITERATIONS: usize = 60;
        const MAX_STEP: f64 = 0.2;
        const BRANCH: f64 = 0.05;
        const HALVINGS: usize = 6;
        if lambda.re <= 0.0 || a <= 0.0 {
            return None;
        }
        // the bracket: `high` unstable, `low` (once found) stable, and the last iterate
        let mut high = (a, lambda);
        let mut low: Option<(f64, Complex64)> = None;
        let mut last = high;
        let mut previous: Option<(f64, Complex64)> = None;
        for _ in 0..ITERATIONS {
            let (a1, l1) = last;
            if l1.re.abs() <= 1e-9 * l1.norm() {
                return Some(last);
            }
            let secant = previous
                .filter(|(_, l0)| l0.re != l1.re)
                .map(|(a0, l0)| a1 - l1.re * (a1 - a0) / (l1.re - l0.re));
            let mut target = secant.unwrap_or(a1 * (1.0 - MAX_STEP));
            target = target.clamp(a1 * (1.0 - MAX_STEP), a1 * (1.0 + MAX_STEP));
            // the crossing lies below the narrowest unstable width (and above the widest stable
            // one): a secant pointing elsewhere (Re lambda need not fall with the width) is
            // replaced by a step down or a bisection
            match low {
                Some((a_low, _)) if target.is_nan() || target <= a_low || target >= high.0 => {
                    target = 0.5 * (a_low + high.0);
                }
                None if target >= high.0 => target = high.0 * (1.0 - MAX_STEP),
                _ => {}
            }
            if target.is_nan() || target <= 0.0 {
                return None;
            }
            // follow the branch from the bracket end nearer in width; where Newton fails (two
            // roots of the chain close together) halve the step towards that end and retry
            let (from_a, start) = match low {
                Some(lo) if (lo.0 - target).abs() < (high.0 - target).abs() => lo,
                _ => high,
            };
            let (target, l) = (0..HALVINGS).find_map(|k| {
                let t = from_a + (target - from_a) * 0.5f64.powi(k as i32);
                self.newton_within(start, t, 30, BRANCH).map(|l| (t, l))
            })?;
            if l.re > 0.0 {
                high = (target, l);
            } else {
                low = Some((target, l));
            }
            previous = Some(last);
            last = (target, l);
        }
        None
    }
}

/// Modes up to which [`Characteristic::newton_step`] factorizes on the stack.
const STACK_MODES: usize = 4;

/// [`inverse_trace`] of D and D' given entry by entry, in `buffer` (2 n^2 entries: D then D',
/// row-major).
fn filled_inverse_trace(
    buffer: &mut [Complex64],
    n: usize,
    entry: impl Fn(usize, usize) -> Complex64,
    derivative: impl Fn(usize, usize) -> Complex64,
) -> Option<Complex64> {
    let (d, dd) = buffer.split_at_mut(n * n);
    for i in 0..n {
        for j in 0..n {
            d[i * n + j] = entry(i, j);
            dd[i * n + j] = derivative(i, j);
        }
    }
    inverse_trace(d, dd, n)
}

/// tr(D^{-1} D') for row-major n x n `d` and `dd`, both overwritten: LU of D with partial
/// pivoting (pivot by |re| + |im|, which orders the candidates as well as the modulus without
/// its square root), then D^{-1} D' column by column. None when D is exactly singular.
fn inverse_trace(d: &mut [Complex64], dd: &mut [Complex64], n: usize) -> Option<Complex64> {
    let size = |z: Complex64| z.re.abs() + z.im.abs();
    for k in 0..n {
        let p = (k..n).max_by(|&a, &b| size(d[a * n + k]).total_cmp(&size(d[b * n + k])))?;
        if size(d[p * n + k]) == 0.0 {
            return None;
        }
        if p != k {
            for j in 0..n {
                d.swap(k * n + j, p * n + j);
                dd.swap(k * n + j, p * n + j);
            }
        }
        let pivot = d[k * n + k];
        for i in k + 1..n {
            let f = d[i * n + k] / pivot;
            for j in k + 1..n {
                let u = d[k * n + j];
                d[i * n + j] -= f * u;
            }
            // forward elimination of D' alongside: dd becomes L^{-1} P D'
            for j in 0..n {
                let u = dd[k * n + j];
                dd[i * n + j] -= f * u;
            }
        }
    }
    // back substitution U x = (L^{-1} P D')_{:, j}, keeping x_j for the trace
    let mut trace = Complex64::new(0.0, 0.0);
    for j in 0..n {
        for i in (0..n).rev() {
            let mut v = dd[i * n + j];
            for m in i + 1..n {
                v -= d[i * n + m] * dd[m * n + j];
            }
            dd[i * n + j] = v / d[i * n + i];
        }
        trace += dd[j * n + j];
    }
    Some(trace)
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    /// At zero width the structural poles -zeta w + i w sqrt(1 - zeta^2) are roots: det D is
    /// rounding (its scale is w^4), and Newton stays there.
    #[test]
    fn structural_poles_are_roots_at_zero_width() {
        let model = examples::ahmadi_2022_turning();
        let ch = Characteristic::new(&model, 7000.0).unwrap();
        for m in model.modes() {
            let (w, z) = (m.omega_rad_s(), m.damping_ratio());
            let pole = Complex64::new(-z * w, w * (1.0 - z * z).sqrt());
            assert!(ch.determinant(pole, 0.0).norm() < 1e-6 * w.powi(4));
            let root = ch.newton(pole, 0.0, 5).unwrap();
            assert!((root - pole).norm() < 1e-9 * w, "{root} {pole}");
        }
        let mill = examples::schmitz_2023_milling();
        assert!(Characteristic::new(&mill, 7000.0).is_err());
    }

    /// With three and four modes (the in-place LU) the Newton step equals det D / (det D)'
    /// from nalgebra's determinant and a central difference (step 1e-4 rad/s, relative
    /// truncation error ~1e-12 on |lambda| ~ 1e4; 1e-6 allowed for round-off).
    #[test]
    fn newton_step_of_three_and_four_modes_matches_the_determinant() {
        use chatter_dynamics::{Mode, ModeShape};
        let model = examples::ahmadi_2022_turning();
        for extra in [1usize, 2] {
            let mut modes = model.modes().to_vec();
            for k in 0..extra {
                let f = 900.0 + 350.0 * k as f64;
                let angle = 0.3 + 0.9 * k as f64;
                let amplitude = 2.0 * std::f64::consts::PI * f / 3e7f64.sqrt();
                let shape =
                    ModeShape::MassNormalized([amplitude * angle.cos(), amplitude * angle.sin()]);
                modes.push(Mode::new(f, 0.02, shape).unwrap());
            }
            let m = model.with_modes(modes).unwrap();
            let ch = Characteristic::new(&m, 2400.0).unwrap();
            let a = 1.5e-3;
            for lambda in [Complex64::new(-40.0, 4500.0), Complex64::new(15.0, 6100.0)] {
                let h = 1e-4;
                let derivative =
                    (ch.determinant(lambda + h, a) - ch.determinant(lambda - h, a)) / (2.0 * h);
                let expected = ch.determinant(lambda, a) / derivative;
                let step = ch.newton_step(lambda, a).unwrap();
                assert!(
                    (step - expected).norm() < 1e-6 * expected.norm(),
                    "{} modes: {step} against {expected}",
                    m.modes().len()
                );
            }
        }
    }

    /// Near a root the Newton step is the distance to it (to first order), and a bound on the
    /// distance from the start rejects a start on another branch.
    #[test]
    fn newton_step_is_the_distance_to_the_root() {
        let model = examples::ahmadi_2022_turning();
        let ch = Characteristic::new(&model, 7150.0).unwrap();
        let start = chatter_dynamics::pole::pole_from_frequency_damping(2473.0, 0.0012);
        let root = ch.newton_within(start, 2.286e-3, 60, 0.2).unwrap();
        let near = root + Complex64::new(0.05, 0.3);
        let step = ch.newton_step(near, 2.286e-3).unwrap();
        assert!((step - (near - root)).norm() < 1e-3 * (near - root).norm());
        assert!(ch.newton_within(start, 2.286e-3, 60, 1e-9).is_none());
    }
}
