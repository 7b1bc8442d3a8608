//! Full- and semi-discretization of the time-periodic delay equation and its monodromy operator.
//!
//! In modal coordinates (N modes, state `y = [q; q']` of size 2N) the cut obeys
//!
//! ```text
//! y' = (A_0 + A(t)) y + B(t) q(t - tau),
//! A_0 = [[0, I], [-Omega^2, -2 Z Omega]], A(t) = [[0, 0], [-b W(t), -b P(t)]], B(t) = [[0], [b W(t)]],
//! ```
//!
//! with W = Phi^T H(t) Phi (cutting, 000 Eq. 7-8, 002 Eq. 1-3) and P = Phi^T D(t) Phi (process damping,
//! 003 Eq. 1).
//!
//! # Grid
//! One delay tau is cut at every tooth entry and exit into segments. A segment where no tooth cuts
//! (free flight, H = 0) is crossed exactly in one step, y -> e^{A_0 L} y; cutting segments get
//! steps in proportion to their length. The grid is therefore aligned with the discontinuities of
//! H(t), and the accuracy at low radial immersion does not stall at O(1/m).
//!
//! # Step
//! Over a cutting step of length h, with the delayed displacement interpolated linearly between
//! grid points, F_1 = int_0^h e^{A_0 s} ds and F_2 = int_0^h e^{A_0 (h - s)} s ds (both read off
//! one exponential of an augmented matrix, Van Loan), the schemes give
//! - first-order full discretization (Ding et al. 2010, 000 Eq. 9-11): the periodic terms are also
//!   interpolated, (I - F_2/h A_{i+1}) y_{i+1} = [e^{A_0 h} + (F_1 - F_2/h) A_i] y_i
//!   + (F_1 - F_2/h) B_i q_{i-m} + F_2/h B_{i+1} q_{i-m+1};
//! - semi-discretization (Insperger and Stépán; 002 Eq. 3-5): A_0 + A is frozen at the step's
//!   mean and integrated exactly, y_{i+1} = e^{A_i h} y_i + (F_1 - F_2/h) B_i q_{i-m} + F_2/h B_i q_{i-m+1}
//!   with F_1, F_2 of A_i.
//!
//! Both become a "step program" y_{i+1} = P_i y_i + R_i q_{i-m} + S_i q_{i-m+1} applied to the
//! state [y_0; q(t_0 - tau); ...; q(t_{M-1} - tau)] of size 2N + N M: the monodromy operator is a
//! shift plus these few dense blocks, applied matrix-free in O(M N^2). The dominant multiplier is
//! found by Krylov–Schur (Stewart 2002's thick-restart Arnoldi, in the crate's `krylov` module)
//! on that operator; the dense matrix is built column by column in O(M^2 N^3) only when all
//! eigenpairs are needed (sensitivities, cross-checks).

use crate::StabilitySolver;
use crate::eigen::dense_eigenvalues;
use crate::error::{Result, StabilityError, check_condition};
pub use crate::krylov::DENSE_FALLBACK_MAX_DIM;
use crate::krylov::{DENSE_MAX_DIM, largest, robust_eigenpair};
use crate::multiplier::DominantMultiplier;
use chatter_dynamics::{ModalModel, Operation};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::f64::consts::PI;

/// Which discretization scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    /// First-order full discretization (Ding et al. 2010).
    Full,
    /// First-order semi-discretization (Insperger and Stépán).
    Semi,
}

/// How many steps cover the cutting part of one delay.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepsPerDelay {
    /// Chosen from the physics: at least [`AUTO_MIN_STEPS`] and at least
    /// [`AUTO_STEPS_PER_CYCLE`] steps per period of the highest natural frequency while cutting.
    Auto,
    /// A fixed number of cutting steps (m = 40 is the usual speed benchmark).
    Fixed(usize),
}

/// Minimum number of cutting steps of the automatic resolution.
pub const AUTO_MIN_STEPS: usize = 40;
/// Steps per vibration cycle of the highest mode in the automatic resolution; chosen so that the
/// limiting depth is within 2 % of the converged one over the speed range (see the tests).
pub const AUTO_STEPS_PER_CYCLE: f64 = 24.0;

/// A discretization solver: scheme plus resolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Discretization {
    /// Full or semi-discretization.
    pub scheme: Scheme,
    /// Resolution.
    pub steps: StepsPerDelay,
}

impl Discretization {
    /// Full discretization with the automatic resolution.
    pub fn full() -> Self {
        Self {
            scheme: Scheme::Full,
            steps: StepsPerDelay::Auto,
        }
    }
    /// Semi-discretization with the automatic resolution.
    pub fn semi() -> Self {
        Self {
            scheme: Scheme::Semi,
            steps: StepsPerDelay::Auto,
        }
    }
    /// The same scheme with a fixed number of cutting steps.
    pub fn with_steps(self, m: usize) -> Self {
        Self {
            steps: StepsPerDelay::Fixed(m),
            ..self
        }
    }

    /// The same solver with the step count that [`StepsPerDelay::Auto`] picks for `model` at
    /// `speed_rpm` made fixed, so that models perturbed around `model` (finite differences,
    /// samplers) share one grid and their operators have the same dimension.
    pub fn resolved(self, model: &ModalModel, speed_rpm: f64) -> Result<Self> {
        let tau = model.operation().delay_s(speed_rpm);
        let cutting_time: f64 = segments(model, speed_rpm, tau)
            .iter()
            .filter(|s| s.2)
            .map(|s| s.1 - s.0)
            .sum();
        Ok(self.with_steps(self.cutting_steps(model, cutting_time)?))
    }

    /// Cutting steps per delay for a delay that cuts during `cutting_time` seconds.
    fn cutting_steps(&self, model: &ModalModel, cutting_time: f64) -> Result<usize> {
        match self.steps {
            StepsPerDelay::Fixed(0) => Err(StabilityError::InvalidInput {
                field: "steps_per_delay",
                value: 0.0,
                expected: "at least 1 step",
            }),
            StepsPerDelay::Fixed(m) => Ok(m),
            StepsPerDelay::Auto => {
                let f_max = model
                    .modes()
                    .iter()
                    .map(|m| m.frequency_hz())
                    .fold(0.0, f64::max);
                Ok(AUTO_MIN_STEPS
                    .max((AUTO_STEPS_PER_CYCLE * cutting_time * f_max).ceil() as usize))
            }
        }
    }

    /// The monodromy operator at a cutting condition (depth in m).
    pub fn monodromy(&self, model: &ModalModel, speed_rpm: f64, depth_m: f64) -> Result<Monodromy> {
        Monodromy::new(model, speed_rpm, depth_m, *self)
    }
}

impl StabilitySolver for Discretization {
    fn name(&self) -> &'static str {
        match self.scheme {
            Scheme::Full => "fdm",
            Scheme::Semi => "sdm",
        }
    }

    fn dominant_multiplier(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<DominantMultiplier> {
        let op = self.monodromy(model, speed_rpm, depth_m)?;
        Ok(DominantMultiplier::new(
            op.dominant_eigenvalue()?,
            op.period_s,
        ))
    }

    fn chatter_frequency_hz(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)> {
        self.chatter_frequency_from(model, speed_rpm, depth_m, None)
    }
}

impl Discretization {
    /// [`StabilitySolver::chatter_frequency_hz`] with the Krylov iteration started from `start` (see
    /// [`Monodromy::dominant_eigenpair_from`]).
    pub fn chatter_frequency_from(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
        start: Option<&[f64]>,
    ) -> Result<(DominantMultiplier, f64)> {
        let op = self.monodromy(model, speed_rpm, depth_m)?;
        let (mu, vector) = op.dominant_eigenpair_from(start)?;
        Ok(op.multiplier_and_frequency(model, mu, &vector))
    }
}

impl Monodromy {
    /// The multiplier `mu` with eigenvector `vector` and its chatter frequency: the member of its
    /// frequency family that [`Self::eigenvector_frequency_hz`] picks within half the lowest to
    /// twice the highest natural frequency, or the member nearest the dominant mode when the
    /// eigenfunction is not sampled over the whole delay.
    pub(crate) fn multiplier_and_frequency(
        &self,
        model: &ModalModel,
        mu: Complex64,
        vector: &[Complex64],
    ) -> (DominantMultiplier, f64) {
        let mu = DominantMultiplier::new(mu, self.period_s);
        let (lo, hi) = model
            .modes()
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), m| {
                (lo.min(m.frequency_hz()), hi.max(m.frequency_hz()))
            });
        let f = self
            .eigenvector_frequency_hz(vector, &mu, (0.5 * lo, 2.0 * hi))
            .unwrap_or_else(|| {
                mu.chatter_frequency_near_hz(crate::boundary::dominant_mode_frequency_hz(model))
            });
        (mu, f)
    }
}

/// One step of the program: y_{k+1} = P y_k + R q_a + S q_b where q_a, q_b are the delayed
/// values at the step's start and end grid points. The blocks live in [`Monodromy::coefficients`]
/// from `offset`: P (2N x 2N), then for cutting steps R and S (2N x N each), row-major.
#[derive(Debug, Clone, Copy)]
struct Step {
    offset: usize,
    /// Index of the grid point at the start of the step (its delayed value is R's input); the
    /// end point is `start + 1` (or y_0 when it equals the grid size).
    start: usize,
    cutting: bool,
}

/// The discretized monodromy operator over one delay.
#[derive(Debug, Clone)]
pub struct Monodromy {
    /// Number of modes N.
    modes: usize,
    /// Grid points per delay M.
    grid: usize,
    steps: Vec<Step>,
    /// Step blocks, row-major, one contiguous buffer (steps of constant-coefficient segments
    /// share one block).
    coefficients: Vec<f64>,
    /// Length (s) of the step leaving each grid point.
    step_s: Vec<f64>,
    /// The delay tau (s).
    pub period_s: f64,
}

/// Grid of one delay: breakpoints and whether each segment cuts.
fn segments(model: &ModalModel, speed_rpm: f64, tau: f64) -> Vec<(f64, f64, bool)> {
    let mut cuts = vec![0.0, tau];
    if let Operation::Milling(m) = model.operation() {
        let omega = 2.0 * PI * speed_rpm / 60.0;
        let (entry, exit) = m.entry_exit_rad();
        let teeth = m.teeth();
        for j in 0..teeth {
            let offset = 2.0 * PI * j as f64 / teeth as f64;
            for angle in [entry, exit] {
                // times in [0, tau) at which tooth j reaches `angle` (mod 2 pi)
                let t0 = (angle - offset).rem_euclid(2.0 * PI) / omega;
                let t = t0.rem_euclid(tau);
                if t > 1e-12 * tau && t < tau * (1.0 - 1e-12) {
                    cuts.push(t);
                }
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-12 * tau);
    cuts.windows(2)
        .map(|w| {
            let mid = 0.5 * (w[0] + w[1]);
            let h = model.directional_matrix(mid, speed_rpm);
            (w[0], w[1], h.abs().max() > 0.0)
        })
        .collect()
}

/// Van Loan: exp of [[A, I, 0], [0, 0, I], [0, 0, 0]] h gives e^{A h}, F_1 and F_2.
fn exp_integrals(a: &DMatrix<f64>, h: f64) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let n = a.nrows();
    let mut big = DMatrix::zeros(3 * n, 3 * n);
    big.view_mut((0, 0), (n, n)).copy_from(&(a * h));
    for i in 0..n {
        big[(i, n + i)] = h;
        big[(n + i, 2 * n + i)] = h;
    }
    let e = big.exp();
    let phi0 = e.view((0, 0), (n, n)).into_owned();
    let f1 = e.view((0, n), (n, n)).into_owned();
    // top-right block = int_0^h e^{A(h-s)} s ds / h ... scaled: block (0,2n) of exp(M h) with the
    // unit blocks scaled by h equals int_0^h e^{A(h-s)} s ds.
    let f2 = e.view((0, 2 * n), (n, n)).into_owned();
    (phi0, f1, f2)
}

/// Row-major copy of a matrix.
fn row_major(m: &DMatrix<f64>) -> Vec<f64> {
    m.transpose().as_slice().to_vec()
}

/// The periodic coefficients at one time in modal coordinates: M = [b W | b P] (N x 2N,
/// row-major), so that A(t) = [[0, 0], [-M]] and B(t) = [[0], [b W]].
struct Periodic<'a> {
    model: &'a ModalModel,
    speed_rpm: f64,
    depth_m: f64,
    /// Phi (2 x N), row-major.
    phi: Vec<f64>,
    modes: usize,
}

impl Periodic<'_> {
    fn at(&self, t: f64, m: &mut [f64]) {
        let n = self.modes;
        let h = self.model.directional_matrix(t, self.speed_rpm);
        let d = self.model.process_damping_matrix(t, self.speed_rpm);
        for p in 0..n {
            for q in 0..n {
                let (mut w, mut pd) = (0.0, 0.0);
                for a in 0..2 {
                    for c in 0..2 {
                        let f = self.phi[a * n + p] * self.phi[c * n + q];
                        w += f * h[(a, c)];
                        pd += f * d[(a, c)];
                    }
                }
                m[p * 2 * n + q] = self.depth_m * w;
                m[p * 2 * n + n + q] = self.depth_m * pd;
            }
        }
    }
}

/// Gaussian elimination with partial pivoting of the small system `a` x = `b` in place
/// (`a` d x d, `b` d x k, row-major); `false` when `a` is singular.
fn solve_small(a: &mut [f64], b: &mut [f64], d: usize, k: usize) -> bool {
    for col in 0..d {
        let pivot = (col..d)
            .max_by(|&i, &j| a[i * d + col].abs().total_cmp(&a[j * d + col].abs()))
            .unwrap_or(col);
        if a[pivot * d + col] == 0.0 || !a[pivot * d + col].is_finite() {
            return false;
        }
        if pivot != col {
            for j in 0..d {
                a.swap(col * d + j, pivot * d + j);
            }
            for j in 0..k {
                b.swap(col * k + j, pivot * k + j);
            }
        }
        let inv = 1.0 / a[col * d + col];
        for i in col + 1..d {
            let f = a[i * d + col] * inv;
            if f == 0.0 {
                continue;
            }
            for j in col..d {
                a[i * d + j] -= f * a[col * d + j];
            }
            for j in 0..k {
                b[i * k + j] -= f * b[col * k + j];
            }
        }
    }
    for col in (0..d).rev() {
        let inv = 1.0 / a[col * d + col];
        for j in 0..k {
            let mut v = b[col * k + j];
            for i in col + 1..d {
                v -= a[col * d + i] * b[i * k + j];
            }
            b[col * k + j] = v * inv;
        }
    }
    true
}

/// First-order full-discretization step (Ding et al. 2010) from the periodic coefficients at the
/// step's start (`mi`) and end (`mj`): solves (I - F_2/h A_j) [P | R | S] =
/// [e^{A_0 h} + C_1 A_i | C_1 B_i | F_2/h B_j] with C_1 = F_1 - F_2/h, appending P, R, S to
/// `out`. `scratch` holds the (2N)^2 system and the 2N x 4N right-hand side.
#[allow(clippy::too_many_arguments)]
fn full_step(
    n: usize,
    phi0: &[f64],
    c1: &[f64],
    f2h: &[f64],
    mi: &[f64],
    mj: &[f64],
    scratch: &mut (Vec<f64>, Vec<f64>),
    out: &mut Vec<f64>,
) -> bool {
    let d = 2 * n;
    let k = 4 * n;
    let (lhs, rhs) = scratch;
    lhs.clear();
    lhs.resize(d * d, 0.0);
    rhs.clear();
    rhs.resize(d * k, 0.0);
    for r in 0..d {
        lhs[r * d + r] = 1.0;
        for c in 0..d {
            // only the lower block rows of A and B are non-zero: A = [[0], [-M]], B = [[0], [W]]
            let (mut f2a, mut c1a) = (0.0, 0.0);
            for q in 0..n {
                f2a += f2h[r * d + n + q] * mj[q * d + c];
                c1a += c1[r * d + n + q] * mi[q * d + c];
            }
            lhs[r * d + c] += f2a;
            rhs[r * k + c] = phi0[r * d + c] - c1a;
        }
        for c in 0..n {
            let (mut c1b, mut f2b) = (0.0, 0.0);
            for q in 0..n {
                c1b += c1[r * d + n + q] * mi[q * d + c];
                f2b += f2h[r * d + n + q] * mj[q * d + c];
            }
            rhs[r * k + d + c] = c1b;
            rhs[r * k + d + n + c] = f2b;
        }
    }
    if !solve_small(lhs, rhs, d, k) {
        return false;
    }
    // [P | R | S] row-major blocks
    for r in 0..d {
        out.extend_from_slice(&rhs[r * k..r * k + d]);
    }
    for block in [d, d + n] {
        for r in 0..d {
            out.extend_from_slice(&rhs[r * k + block..r * k + block + n]);
        }
    }
    true
}

impl Monodromy {
    /// Build the step program at `speed_rpm`, depth `depth_m`.
    pub fn new(
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
        method: Discretization,
    ) -> Result<Self> {
        check_condition(speed_rpm, depth_m)?;
        let n = model.mode_count();
        let d = 2 * n;
        let tau = model.operation().delay_s(speed_rpm);
        let segs = segments(model, speed_rpm, tau);
        let cutting_time: f64 = segs.iter().filter(|s| s.2).map(|s| s.1 - s.0).sum();
        let m_cut = method.cutting_steps(model, cutting_time)?;
        // structural matrices
        let omegas = model.omegas_rad_s();
        let zetas = model.damping_ratios();
        let mut a0 = DMatrix::zeros(d, d);
        for i in 0..n {
            a0[(i, n + i)] = 1.0;
            a0[(n + i, i)] = -omegas[i] * omegas[i];
            a0[(n + i, n + i)] = -2.0 * zetas[i] * omegas[i];
        }
        let periodic = Periodic {
            model,
            speed_rpm,
            depth_m,
            phi: row_major(&model.shape_matrix()),
            modes: n,
        };
        // constant coefficients (turning): every step of a segment is the same
        let constant = matches!(model.operation(), Operation::Turning(_));
        let mut steps = Vec::with_capacity(m_cut + segs.len());
        let mut step_s = Vec::with_capacity(m_cut + segs.len());
        let mut coefficients = Vec::new();
        let mut scratch = (Vec::new(), Vec::new());
        let (mut mi, mut mj) = (vec![0.0; n * d], vec![0.0; n * d]);
        let mut grid = 0usize;
        for &(start, end, cutting) in &segs {
            let len = end - start;
            if !cutting {
                steps.push(Step {
                    offset: coefficients.len(),
                    start: grid,
                    cutting: false,
                });
                coefficients.extend(row_major(&(&a0 * len).exp()));
                step_s.push(len);
                grid += 1;
                continue;
            }
            let k = ((m_cut as f64 * len / cutting_time).round() as usize).max(1);
            let h = len / k as f64;
            let full = match method.scheme {
                Scheme::Full => {
                    let (phi0, f1, f2) = exp_integrals(&a0, h);
                    let f2h = &f2 / h;
                    Some((row_major(&phi0), row_major(&(f1 - &f2h)), row_major(&f2h)))
                }
                Scheme::Semi => None,
            };
            for i in 0..k {
                let t0 = start + i as f64 * h;
                if constant && i > 0 {
                    let mut step = steps[steps.len() - 1];
                    step.start = grid;
                    steps.push(step);
                    step_s.push(h);
                    grid += 1;
                    continue;
                }
                let offset = coefficients.len();
                match &full {
                    Some((phi0, c1, f2h)) => {
                        // products interpolated just inside the segment (H is smooth there); the
                        // end of step i is the start of step i + 1 (same smooth segment)
                        let eps = 1e-9 * h;
                        if i == 0 {
                            periodic.at(t0 + eps, &mut mi);
                        } else {
                            std::mem::swap(&mut mi, &mut mj);
                        }
                        periodic.at(t0 + h - eps, &mut mj);
                        if !full_step(n, phi0, c1, f2h, &mi, &mj, &mut scratch, &mut coefficients) {
                            return Err(StabilityError::NoConvergence {
                                solver: "full discretization",
                                detail: format!("singular step matrix at t = {t0} s"),
                            });
                        }
                    }
                    None => {
                        // mean of the periodic part over the step (3-point Gauss)
                        let g = [
                            (0.5 - 0.5 * (0.6f64).sqrt(), 5.0 / 18.0),
                            (0.5, 8.0 / 18.0),
                            (0.5 + 0.5 * (0.6f64).sqrt(), 5.0 / 18.0),
                        ];
                        let mut mean = vec![0.0; n * d];
                        for (x, wgt) in g {
                            periodic.at(t0 + x * h, &mut mi);
                            for (a, b) in mean.iter_mut().zip(&mi) {
                                *a += wgt * b;
                            }
                        }
                        let mut a = a0.clone();
                        let mut bm = DMatrix::zeros(d, n);
                        for p in 0..n {
                            for c in 0..d {
                                a[(n + p, c)] -= mean[p * d + c];
                            }
                            for c in 0..n {
                                bm[(n + p, c)] = mean[p * d + c];
                            }
                        }
                        let (e, f1, f2) = exp_integrals(&a, h);
                        coefficients.extend(row_major(&e));
                        coefficients.extend(row_major(&((&f1 - &f2 / h) * &bm)));
                        coefficients.extend(row_major(&(&f2 / h * &bm)));
                    }
                }
                steps.push(Step {
                    offset,
                    start: grid,
                    cutting: true,
                });
                step_s.push(h);
                grid += 1;
            }
        }
        Ok(Self {
            modes: n,
            grid,
            steps,
            coefficients,
            step_s,
            period_s: tau,
        })
    }

    /// Dimension of the state [y_0; delayed q at M grid points] = 2N + N M.
    pub fn dimension(&self) -> usize {
        2 * self.modes + self.modes * self.grid
    }

    /// The blocks (P, R, S) of a step.
    fn blocks(&self, step: &Step) -> (&[f64], &[f64], &[f64]) {
        let d = 2 * self.modes;
        let p = &self.coefficients[step.offset..step.offset + d * d];
        if !step.cutting {
            return (p, &[], &[]);
        }
        let dn = d * self.modes;
        let r = &self.coefficients[step.offset + d * d..step.offset + d * d + dn];
        let s = &self.coefficients[step.offset + d * d + dn..step.offset + d * d + 2 * dn];
        (p, r, s)
    }

    /// Apply the monodromy: `out` = U `x` (both of [`Self::dimension`]).
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        // literal state sizes let the compiler unroll the small block products of `sweep`
        match 2 * self.modes {
            2 => self.sweep(2, x, out),
            4 => self.sweep(4, x, out),
            6 => self.sweep(6, x, out),
            8 => self.sweep(8, x, out),
            s2 => self.sweep(s2, x, out),
        }
    }

    /// The step program of [`Self::apply`] for the state size `s2` = 2N: each step
    /// y' = P y + R q_a + S q_b, with the delayed displacements q read from `x` and the current
    /// displacement stored as the new delayed value of its grid point.
    #[inline(always)]
    fn sweep(&self, s2: usize, x: &[f64], out: &mut [f64]) {
        const INLINE: usize = 16;
        let n = s2 / 2;
        let mut stack = [0.0; 2 * INLINE];
        let mut heap = Vec::new();
        let (mut y, mut next) = if s2 <= INLINE {
            let (a, b) = stack.split_at_mut(INLINE);
            (&mut a[..s2], &mut b[..s2])
        } else {
            heap.resize(2 * s2, 0.0);
            heap.split_at_mut(s2)
        };
        y.copy_from_slice(&x[..s2]);
        for step in &self.steps {
            let a = s2 + step.start * n;
            // the new delayed value at this grid point is the current displacement
            out[a..a + n].copy_from_slice(&y[..n]);
            let (p, r, s) = self.blocks(step);
            for (nx, row) in next.iter_mut().zip(p.chunks_exact(s2)) {
                *nx = row.iter().zip(y.iter()).map(|(pij, yj)| pij * yj).sum();
            }
            if step.cutting {
                let qa = &x[a..a + n];
                // the delayed value at the end of the delay is the input displacement y_0
                let qb = if step.start + 1 == self.grid {
                    &x[..n]
                } else {
                    &x[a + n..a + 2 * n]
                };
                for ((nx, ri), si) in next
                    .iter_mut()
                    .zip(r.chunks_exact(n))
                    .zip(s.chunks_exact(n))
                {
                    for j in 0..n {
                        *nx += ri[j] * qa[j] + si[j] * qb[j];
                    }
                }
            }
            std::mem::swap(&mut y, &mut next);
        }
        out[..s2].copy_from_slice(y);
    }

    /// Apply the transpose: `out` = U^T `x`, the reverse sweep of the step program of
    /// [`Self::apply`] (each step y' = P y + R q_a + S q_b read backwards). Used for left
    /// eigenvectors without forming U.
    pub fn apply_transpose(&self, x: &[f64], out: &mut [f64]) {
        let n = self.modes;
        let s2 = 2 * n;
        out.fill(0.0);
        let mut ybar = x[..s2].to_vec();
        let mut prev = vec![0.0; s2];
        for step in self.steps.iter().rev() {
            let a = s2 + step.start * n;
            let (p, r, s) = self.blocks(step);
            if step.cutting {
                let b = if step.start + 1 == self.grid {
                    0
                } else {
                    a + n
                };
                for j in 0..n {
                    let (mut ra, mut sb) = (0.0, 0.0);
                    for (i, yi) in ybar.iter().enumerate() {
                        ra += r[i * n + j] * yi;
                        sb += s[i * n + j] * yi;
                    }
                    out[a + j] += ra;
                    out[b + j] += sb;
                }
            }
            for (j, pj) in prev.iter_mut().enumerate() {
                *pj = ybar
                    .iter()
                    .enumerate()
                    .map(|(i, yi)| p[i * s2 + j] * yi)
                    .sum();
            }
            // the displacement at the step's start was stored as a delayed value
            for (pj, xj) in prev.iter_mut().zip(&x[a..a + n]) {
                *pj += xj;
            }
            std::mem::swap(&mut ybar, &mut prev);
        }
        for (o, yi) in out.iter_mut().zip(&ybar) {
            *o += yi;
        }
    }

    /// The dense monodromy matrix (column by column).
    pub fn dense(&self) -> DMatrix<f64> {
        let d = self.dimension();
        let mut m = DMatrix::zeros(d, d);
        let mut e = vec![0.0; d];
        let mut col = vec![0.0; d];
        for j in 0..d {
            e[j] = 1.0;
            self.apply(&e, &mut col);
            m.column_mut(j).copy_from_slice(&col);
            e[j] = 0.0;
        }
        m
    }

    /// The eigenvalue of largest modulus, by Krylov–Schur on the matrix-free operator
    /// (dense eigenvalues for tiny operators; see [`Self::dominant_eigenpair`] for the
    /// fallbacks).
    pub fn dominant_eigenvalue(&self) -> Result<Complex64> {
        let d = self.dimension();
        if d <= DENSE_MAX_DIM {
            return largest(&dense_eigenvalues(&self.dense())?);
        }
        Ok(self.dominant_eigenpair()?.0)
    }
}

impl Monodromy {
    /// The dominant eigenvalue and its (complex) eigenvector.
    ///
    /// Krylov–Schur on the matrix-free operator; when it does not converge, a second run
    /// with a larger Krylov space, more cycles and another start vector; when that fails too,
    /// the dense operator (up to [`DENSE_FALLBACK_MAX_DIM`]). Tiny operators go to the dense
    /// solver directly.
    pub fn dominant_eigenpair(&self) -> Result<(Complex64, Vec<Complex64>)> {
        self.dominant_eigenpair_from(None)
    }

    /// [`Self::dominant_eigenpair`] with the first Krylov–Schur run started from `start` (e.g. the
    /// real plus imaginary part of the eigenvector of a nearby operator of the same dimension:
    /// the boundary search at the previous depth), which saves most restarts where the
    /// multipliers cluster in modulus (low speeds). A start of another dimension is ignored.
    pub fn dominant_eigenpair_from(
        &self,
        start: Option<&[f64]>,
    ) -> Result<(Complex64, Vec<Complex64>)> {
        let d = self.dimension();
        robust_eigenpair(
            |x, out| self.apply(x, out),
            d,
            || self.dense(),
            start.filter(|s| s.len() == d),
        )
    }

    /// The dominant eigenvalue and its left eigenvector v (U^T v = mu v), from the transposed
    /// operator (with the fallbacks of [`Self::dominant_eigenpair`]).
    pub fn dominant_left_eigenpair(&self) -> Result<(Complex64, Vec<Complex64>)> {
        robust_eigenpair(
            |x, out| self.apply_transpose(x, out),
            self.dimension(),
            || self.dense().transpose(),
            None,
        )
    }

    /// Chatter frequency (Hz) of the dominant eigenfunction: among the family f_mu + k / tau
    /// (within half the lowest to twice the highest natural frequency) the member with the largest
    /// Fourier amplitude of the delayed displacements over one delay. `None` when the grid has
    /// free flight (the eigenfunction is not sampled over the whole delay) or no candidate exists.
    pub fn eigenvector_frequency_hz(
        &self,
        vector: &[Complex64],
        multiplier: &DominantMultiplier,
        band_hz: (f64, f64),
    ) -> Option<f64> {
        if self.steps.iter().any(|s| !s.cutting) {
            return None;
        }
        let n = self.modes;
        let s2 = 2 * n;
        let ft = 1.0 / self.period_s;
        let k_max = (band_hz.1 / ft).ceil() as i32 + 1;
        let candidates = multiplier.frequency_family_hz(0..=k_max);
        let mut times = Vec::with_capacity(self.grid);
        let mut t = 0.0;
        for &h in &self.step_s {
            times.push(t);
            t += h;
        }
        candidates
            .into_iter()
            .filter(|f| *f >= band_hz.0 && *f <= band_hz.1)
            .map(|f| {
                // |V(f)|^2 + |V(-f)|^2: the same for the eigenvector of either member of a
                // complex-conjugate pair of multipliers
                let amplitude: f64 = (0..n)
                    .flat_map(|j| [(j, f), (j, -f)])
                    .map(|(j, f)| {
                        let sum: Complex64 = (0..self.grid)
                            .map(|k| {
                                let phase = -2.0 * PI * f * times[k];
                                vector[s2 + k * n + j]
                                    * Complex64::new(phase.cos(), phase.sin())
                                    * self.step_s[k]
                            })
                            .sum();
                        sum.norm_sqr()
                    })
                    .sum();
                (f, amplitude)
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|x| x.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    #[test]
    fn arnoldi_matches_dense_eigenvalues() {
        for (model, rpm, b) in [
            (examples::insperger_benchmark(1.0), 10_000.0, 0.5e-3),
            (examples::insperger_benchmark(0.05), 12_000.0, 2.0e-3),
            (examples::ahmadi_2022_turning(), 7150.0, 2.286e-3),
            (examples::schmitz_2023_milling(), 6000.0, 1.0e-3),
        ] {
            for method in [
                Discretization::full().with_steps(40),
                Discretization::semi().with_steps(40),
            ] {
                let op = method.monodromy(&model, rpm, b).unwrap();
                let fast = op.dominant_eigenvalue().unwrap();
                let dense = largest(&dense_eigenvalues(&op.dense()).unwrap()).unwrap();
                // the monodromy is far from normal: dense QR eigenvalues carry ~1e-8 errors
                assert!(
                    (fast - dense).norm() < 1e-7 * dense.norm(),
                    "{:?} {:?}: {fast} vs {dense}",
                    model.name(),
                    method.scheme
                );
            }
        }
    }

    /// <U x, y> = <x, U^T y> to round-off, and the left eigenvalue equals the right one.
    #[test]
    fn transpose_is_the_adjoint() {
        for (model, rpm, b) in [
            (examples::insperger_benchmark(0.05), 12_000.0, 2.0e-3),
            (examples::ahmadi_2022_turning(), 7150.0, 2.286e-3),
        ] {
            for method in [
                Discretization::full().with_steps(30),
                Discretization::semi().with_steps(30),
            ] {
                let op = method.monodromy(&model, rpm, b).unwrap();
                let d = op.dimension();
                let x: Vec<f64> = (0..d).map(|i| (0.3 * i as f64).sin()).collect();
                let y: Vec<f64> = (0..d).map(|i| (0.7 * i as f64 + 1.0).cos()).collect();
                let (mut ux, mut uty) = (vec![0.0; d], vec![0.0; d]);
                op.apply(&x, &mut ux);
                op.apply_transpose(&y, &mut uty);
                let lhs: f64 = ux.iter().zip(&y).map(|(a, b)| a * b).sum();
                let rhs: f64 = x.iter().zip(&uty).map(|(a, b)| a * b).sum();
                assert!(
                    (lhs - rhs).abs() < 1e-12 * lhs.abs().max(1.0),
                    "{lhs} vs {rhs}"
                );
                let right = op.dominant_eigenvalue().unwrap();
                let left = op.dominant_left_eigenpair().unwrap().0;
                assert!((left.norm() - right.norm()).abs() < 1e-9 * right.norm());
            }
        }
    }

    #[test]
    fn zero_depth_multiplier_is_free_decay() {
        // b = 0: |mu| = exp(-zeta omega_n tau) exactly (free vibration over one delay)
        let model = examples::insperger_benchmark(0.05);
        let rpm = 9000.0;
        let tau = model.operation().delay_s(rpm);
        let m = model.modes()[0];
        let expected = (-m.damping_ratio() * m.omega_rad_s() * tau).exp();
        for method in [Discretization::full(), Discretization::semi()] {
            let mu = method.dominant_multiplier(&model, rpm, 0.0).unwrap();
            assert!(
                (mu.modulus() - expected).abs() < 1e-10,
                "{} vs {expected}",
                mu.modulus()
            );
        }
    }
}
