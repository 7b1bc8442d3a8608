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
//!
//! Files: the grid in the crate's `grid` module, the step blocks and their depth-independent
//! plan in `step` ([`StepPlan`]), the operator here, the eigen-solver in `krylov`.

use crate::StabilitySolver;
use crate::eigen::dense_eigenvalues;
use crate::error::{Result, check_condition};
use crate::grid::segments;
pub use crate::krylov::{DENSE_FALLBACK_MAX_DIM, KRYLOV_TOL};
use crate::krylov::{DENSE_MAX_DIM, largest, robust_eigenpair};
use crate::multiplier::DominantMultiplier;
pub use crate::step::StepPlan;
use chatter_dynamics::ModalModel;
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::f64::consts::PI;
use std::num::NonZeroUsize;

/// Which discretization scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    /// First-order full discretization (Ding et al. 2010).
    Full,
    /// First-order semi-discretization (Insperger and Stépán).
    Semi,
}

impl Scheme {
    /// Short name (`"fdm"`, `"sdm"`).
    pub fn name(self) -> &'static str {
        match self {
            Scheme::Full => "fdm",
            Scheme::Semi => "sdm",
        }
    }
}

/// How many steps cover the cutting part of one delay.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepsPerDelay {
    /// Chosen from the physics: at least [`AUTO_MIN_STEPS`] and at least
    /// [`AUTO_STEPS_PER_CYCLE`] steps per period of the highest natural frequency while cutting.
    Auto,
    /// A fixed number of cutting steps (m = 40 is the usual speed benchmark); never zero, so a
    /// discretization without steps cannot be built.
    Fixed(NonZeroUsize),
}

/// `N` cutting steps for [`Discretization::with_steps`], checked when the program is compiled:
/// `steps::<0>()` does not build. Counts known only at run time come as [`NonZeroUsize`]
/// (`NonZeroUsize::new(n)` is `None` for zero).
pub const fn steps<const N: usize>() -> NonZeroUsize {
    const {
        match NonZeroUsize::new(N) {
            Some(n) => n,
            None => panic!("a discretization needs at least one cutting step"),
        }
    }
}

/// `n` cutting steps, or `floor` where `n` is smaller (zero included): a count computed from the
/// physics with a least resolution.
pub fn steps_at_least(n: usize, floor: NonZeroUsize) -> NonZeroUsize {
    NonZeroUsize::new(n).map_or(floor, |n| n.max(floor))
}

/// Minimum number of cutting steps of the automatic resolution.
pub const AUTO_MIN_STEPS: NonZeroUsize = steps::<40>();
/// Steps per vibration cycle of the highest mode in the automatic resolution; chosen so that the
/// limiting depth is within 2 % of the converged one over the speed range (see the tests).
pub const AUTO_STEPS_PER_CYCLE: f64 = 24.0;

/// The principal period (s) of `model` at `speed_rpm` and the number of (mean) delays in it: the
/// delay and 1, or for a variable-pitch cutter the revolution and the number of teeth (the step
/// count of a [`Discretization`] is per delay, so the revolution gets that many times as many).
pub(crate) fn principal_period(model: &ModalModel, speed_rpm: f64) -> (f64, usize) {
    let op = model.operation();
    let period = op.principal_period_s(speed_rpm);
    if op.has_uneven_teeth() {
        (period, op.delays_per_revolution())
    } else {
        (period, 1)
    }
}

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
    /// The same scheme with `m` cutting steps per delay (a literal count: [`steps`]).
    pub fn with_steps(self, m: NonZeroUsize) -> Self {
        Self {
            steps: StepsPerDelay::Fixed(m),
            ..self
        }
    }

    /// The same solver with the step count that [`StepsPerDelay::Auto`] picks for `model` at
    /// `speed_rpm` made fixed, so that models perturbed around `model` (finite differences,
    /// samplers) share one grid and their operators have the same dimension.
    pub fn resolved(self, model: &ModalModel, speed_rpm: f64) -> Self {
        self.with_steps(self.steps_at(model, speed_rpm))
    }

    /// The cutting steps per delay of this solver on `model` at `speed_rpm`: the fixed count,
    /// or the one [`StepsPerDelay::Auto`] picks there.
    pub fn steps_at(&self, model: &ModalModel, speed_rpm: f64) -> NonZeroUsize {
        let (period, delays) = principal_period(model, speed_rpm);
        let cutting_time: f64 = segments(model, speed_rpm, period)
            .iter()
            .filter(|s| s.2)
            .map(|s| s.1 - s.0)
            .sum();
        self.cutting_steps(model, cutting_time / delays as f64)
    }

    /// Cutting steps per delay for a delay that cuts during `cutting_time` seconds.
    pub(crate) fn cutting_steps(&self, model: &ModalModel, cutting_time: f64) -> NonZeroUsize {
        match self.steps {
            StepsPerDelay::Fixed(m) => m,
            StepsPerDelay::Auto => {
                let f_max = model
                    .modes()
                    .iter()
                    .map(|m| m.frequency_hz())
                    .fold(0.0, f64::max);
                steps_at_least(
                    (AUTO_STEPS_PER_CYCLE * cutting_time * f_max).ceil() as usize,
                    AUTO_MIN_STEPS,
                )
            }
        }
    }

    /// The monodromy operator at a cutting condition (depth in m).
    pub fn monodromy(&self, model: &ModalModel, speed_rpm: f64, depth_m: f64) -> Result<Monodromy> {
        Monodromy::new(model, speed_rpm, depth_m, *self)
    }

    /// The depth-independent part of the step program at `speed_rpm`, for operators at many
    /// depths (a boundary search): [`StepPlan::monodromy`] then gives each one.
    pub fn plan(&self, model: &ModalModel, speed_rpm: f64) -> Result<StepPlan> {
        StepPlan::new(model, speed_rpm, *self)
    }
}

impl StabilitySolver for Discretization {
    fn name(&self) -> &'static str {
        self.scheme.name()
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
        self.monodromy(model, speed_rpm, depth_m)?
            .chatter_frequency_from(model, start)
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
pub(crate) struct Step {
    pub(crate) offset: usize,
    /// Index of the grid point at the start of the step (its delayed value is R's input); the
    /// end point is `start + 1` (or y_0 when it equals the grid size).
    pub(crate) start: usize,
    pub(crate) cutting: bool,
    /// Variable pitch: the step's delayed inputs, `Monodromy::taps[taps.0..taps.1]` (one per
    /// tooth in the cut); empty for one delay (R and S then follow P).
    pub(crate) taps: (usize, usize),
}

/// A point of the displacement history by linear interpolation: (1 - w) q_p + w q_{p+1}, with
/// p indexing the grid points of the previous period (0..M, from the input state) followed by
/// those of the current one (M.., already computed by the sweep).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Interp {
    pub(crate) p: usize,
    pub(crate) w: f64,
}

/// One delayed input of a variable-pitch step: R (2N x N at `r`) times the history at `a` (the
/// step's start minus the tooth's delay) plus S (at `s`) times the history at `b` (its end minus
/// the delay).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tap {
    pub(crate) r: usize,
    pub(crate) s: usize,
    pub(crate) a: Interp,
    pub(crate) b: Interp,
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
    /// The delayed inputs of variable-pitch steps (empty with one delay).
    taps: Vec<Tap>,
    /// The principal period (s): the delay tau, or the revolution of a variable-pitch cutter.
    pub period_s: f64,
}

impl Monodromy {
    /// Build the step program at `speed_rpm`, depth `depth_m` (the [`StepPlan`] of the speed,
    /// used once).
    pub fn new(
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
        method: Discretization,
    ) -> Result<Self> {
        check_condition(speed_rpm, depth_m)?;
        StepPlan::new(model, speed_rpm, method)?.monodromy(depth_m)
    }

    /// The operator of a step program (see [`StepPlan::monodromy`]).
    pub(crate) fn from_steps(
        modes: usize,
        grid: usize,
        steps: Vec<Step>,
        coefficients: Vec<f64>,
        step_s: Vec<f64>,
        taps: Vec<Tap>,
        period_s: f64,
    ) -> Self {
        Self {
            modes,
            grid,
            steps,
            coefficients,
            step_s,
            taps,
            period_s,
        }
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
        if !self.taps.is_empty() {
            return self.sweep_taps(x, out);
        }
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
        if !self.taps.is_empty() {
            return self.transpose_taps(x, out);
        }
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

    /// The history value at `at` into `buf` (N): grid points before M from the input `x` (the
    /// previous period), from M on from `out` (this period, written by the sweep).
    fn interpolate(&self, at: Interp, x: &[f64], out: &[f64], buf: &mut [f64]) {
        let n = self.modes;
        let (s2, m) = (2 * n, self.grid);
        let value = |p: usize| {
            if p < m {
                &x[s2 + p * n..s2 + (p + 1) * n]
            } else {
                &out[s2 + (p - m) * n..s2 + (p - m + 1) * n]
            }
        };
        buf.copy_from_slice(value(at.p));
        if at.w != 0.0 {
            for (b, v) in buf.iter_mut().zip(value(at.p + 1)) {
                *b = (1.0 - at.w) * *b + at.w * v;
            }
        }
    }

    /// [`Self::apply`] of a variable-pitch program: each step y' = P y + sum over its taps of
    /// R q(t_k - tau_j) + S q(t_{k+1} - tau_j), the delayed displacements interpolated from the
    /// previous period's history (input) or this period's (already swept).
    fn sweep_taps(&self, x: &[f64], out: &mut [f64]) {
        let n = self.modes;
        let s2 = 2 * n;
        let mut y = x[..s2].to_vec();
        let mut next = vec![0.0; s2];
        let (mut qa, mut qb) = (vec![0.0; n], vec![0.0; n]);
        for step in &self.steps {
            let a = s2 + step.start * n;
            out[a..a + n].copy_from_slice(&y[..n]);
            let p = &self.coefficients[step.offset..step.offset + s2 * s2];
            for (nx, row) in next.iter_mut().zip(p.chunks_exact(s2)) {
                *nx = row.iter().zip(y.iter()).map(|(pij, yj)| pij * yj).sum();
            }
            for tap in &self.taps[step.taps.0..step.taps.1] {
                self.interpolate(tap.a, x, out, &mut qa);
                self.interpolate(tap.b, x, out, &mut qb);
                let r = &self.coefficients[tap.r..tap.r + s2 * n];
                let s = &self.coefficients[tap.s..tap.s + s2 * n];
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
        out[..s2].copy_from_slice(&y);
    }

    /// [`Self::apply_transpose`] of a variable-pitch program: the reverse sweep of
    /// [`Self::sweep_taps`], the adjoints of this period's history gathered as the steps that
    /// read them are undone (each is read only by steps at or after the point's own).
    fn transpose_taps(&self, x: &[f64], out: &mut [f64]) {
        let n = self.modes;
        let (s2, m) = (2 * n, self.grid);
        out.fill(0.0);
        let mut history = x[s2..].to_vec();
        let mut ybar = x[..s2].to_vec();
        let mut prev = vec![0.0; s2];
        let mut g = vec![0.0; n];
        for step in self.steps.iter().rev() {
            for tap in &self.taps[step.taps.0..step.taps.1] {
                for (at, block) in [(tap.a, tap.r), (tap.b, tap.s)] {
                    let blk = &self.coefficients[block..block + s2 * n];
                    for (j, gj) in g.iter_mut().enumerate() {
                        *gj = ybar
                            .iter()
                            .enumerate()
                            .map(|(i, yi)| blk[i * n + j] * yi)
                            .sum();
                    }
                    for (p, weight) in [(at.p, 1.0 - at.w), (at.p + 1, at.w)] {
                        if weight == 0.0 {
                            continue;
                        }
                        let target = if p < m {
                            &mut out[s2 + p * n..s2 + (p + 1) * n]
                        } else {
                            &mut history[(p - m) * n..(p - m + 1) * n]
                        };
                        for (t, gj) in target.iter_mut().zip(&g) {
                            *t += weight * gj;
                        }
                    }
                }
            }
            let p = &self.coefficients[step.offset..step.offset + s2 * s2];
            for (j, pj) in prev.iter_mut().enumerate() {
                *pj = ybar
                    .iter()
                    .enumerate()
                    .map(|(i, yi)| p[i * s2 + j] * yi)
                    .sum();
            }
            let a = step.start * n;
            for (pj, hj) in prev.iter_mut().zip(&history[a..a + n]) {
                *pj += hj;
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
        self.dominant_eigenpair_within(start, KRYLOV_TOL)
    }

    /// [`Self::dominant_eigenpair_from`] to the relative tolerance `tolerance` (the Krylov
    /// residual below that fraction of |mu|) instead of [`KRYLOV_TOL`]: for callers that need
    /// |mu| to a few digits many thousand times (a likelihood inside a sampler), where the
    /// default's last digits cost most of the iteration.
    pub fn dominant_eigenpair_within(
        &self,
        start: Option<&[f64]>,
        tolerance: f64,
    ) -> Result<(Complex64, Vec<Complex64>)> {
        let d = self.dimension();
        robust_eigenpair(
            |x, out| self.apply(x, out),
            d,
            || self.dense(),
            start.filter(|s| s.len() == d),
            tolerance,
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
            KRYLOV_TOL,
        )
    }

    /// The dominant multiplier of this operator (of `model`) with its chatter frequency (Hz), as
    /// `multiplier_and_frequency` picks it. The Krylov iteration starts from `start` (see
    /// [`Self::dominant_eigenpair_from`]).
    pub fn chatter_frequency_from(
        &self,
        model: &ModalModel,
        start: Option<&[f64]>,
    ) -> Result<(DominantMultiplier, f64)> {
        let (mu, vector) = self.dominant_eigenpair_from(start)?;
        Ok(self.multiplier_and_frequency(model, mu, &vector))
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
        candidates
            .into_iter()
            .filter(|f| *f >= band_hz.0 && *f <= band_hz.1)
            .map(|f| {
                // V_j(f) = sum_k v_jk e^{-2 pi i f t_k} h_k, the phasor advanced step by step
                // (a new rotation only where the step length changes); |V(f)|^2 + |V(-f)|^2 is
                // the same for the eigenvector of either member of a conjugate pair
                let mut plus = vec![Complex64::new(0.0, 0.0); n];
                let mut minus = vec![Complex64::new(0.0, 0.0); n];
                let mut phasor = Complex64::new(1.0, 0.0);
                let mut rotation = (f64::NAN, phasor);
                for (k, &h) in self.step_s.iter().enumerate() {
                    let weight = phasor * h;
                    for (j, (p, m)) in plus.iter_mut().zip(minus.iter_mut()).enumerate() {
                        let v = vector[s2 + k * n + j];
                        *p += v * weight;
                        *m += v * weight.conj();
                    }
                    if h != rotation.0 {
                        rotation = (h, Complex64::from_polar(1.0, -2.0 * PI * f * h));
                    }
                    phasor *= rotation.1;
                }
                let amplitude: f64 = plus.iter().chain(&minus).map(|z| z.norm_sqr()).sum();
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
                Discretization::full().with_steps(steps::<40>()),
                Discretization::semi().with_steps(steps::<40>()),
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
                Discretization::full().with_steps(steps::<30>()),
                Discretization::semi().with_steps(steps::<30>()),
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
