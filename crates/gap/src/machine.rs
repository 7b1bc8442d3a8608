//! A fast zero-order representation of a machine variant: the limiting depth and chatter
//! frequency at given spindle speeds and the dominant closed-loop pole of a stable cut, cheap
//! enough to sit inside the samplers (tens of microseconds per model).
//!
//! # Boundary
//! The zero-order (Altintas-Budak) characteristic equation det(I + b (1 - e^{-i w tau}) A G(i w)) = 0,
//! with A the averaged directional matrix (milling) or K_c (turning) and G the receptance, is
//! solved as in `chatter_stability::zero_order`: with Lambda an eigenvalue of A G(i w),
//! eps = (2 arg Lambda - pi) mod 4 pi in (0, 2 pi) and b = 1 / (2 sin(eps/2) |Lambda|) = -1 / (2 Re Lambda). Here the
//! two eigenvalue branches are tabulated once per model on a frequency grid concentrated at the
//! resonances (a sinh-spaced set of points per mode plus a coarse geometric grid), and at each
//! requested speed the lobes k are the crossings of psi(w) = w tau / 2 pi - eps / 2 pi with the
//! integers; the lowest crossing is the limiting depth and its frequency the chatter frequency.
//!
//! # Speed-dependent modes
//! When every natural frequency falls with speed as w_n(Omega) = w_n (1 - c Omega^2) at constant
//! modal mass, G_s(w) = s^-2 G(w / s) with s = 1 - c Omega^2, so
//! b_lim(Omega) = s^2 b_lim,0(Omega / s) and f_c(Omega) = s f_c,0(Omega / s): one table serves
//! every speed.
//!
//! # Process damping (seed 003)
//! F_d = -C b ydot / V adds the modal damping b phi_n^T D phi_n (D the rotation-averaged C/V n n^T,
//! as in `chatter_stability::process_damping`). The iterative algorithm of 003 converges to the
//! fixed point b = b_lim(zeta(b)); here that fixed point is solved directly: starting from the
//! lowest lobe crossings of the table computed with the damping at the bare limit, Newton's method
//! on the real and imaginary parts of the characteristic function over (w, b) lands on the
//! fixed point of each lobe, and the lowest is the limiting depth.
//!
//! # Poles
//! The dominant closed-loop pole of the averaged system is a root of the entire function
//! F(lambda) = prod d_n + c sum_n a_n prod_{m != n} d_m + c^2 det(A) sum_{n<m} w_nm prod_{l != n,m} d_l,
//! with d_n = lambda^2 + 2 zeta_n w_n lambda + w_n^2, c = b (1 - e^{-lambda tau}),
//! a_n = phi_n^T A phi_n and w_nm = (phi_n x phi_m)^2 (000 Eq. 5 in physical coordinates). It is
//! continued in b from each structural pole by Newton's method, and the root with the largest
//! real part is reported as in 000 Eq. 6 (turning) or as the principal frequency and damping of
//! the multiplier e^{lambda tau} (milling, lifted once per tooth period as in 002).

use crate::error::{GapError, Result};
use chatter_dynamics::{ModalModel, Operation};
use num_complex::Complex64;
use std::f64::consts::PI;

/// A real 2 x 2 matrix, rows first.
pub(crate) type Mat2 = [[f64; 2]; 2];

/// Points per mode of the sinh-spaced resonance grid, and of the coarse geometric grid, at unit
/// density.
const MODE_POINTS: usize = 41;
const GLOBAL_POINTS: usize = 24;
/// Frequency range of the tables relative to the lowest and highest natural frequency.
const GRID_LOW: f64 = 0.5;
const GRID_HIGH: f64 = 2.0;
/// Newton iterations and tolerances of the pole continuation and the process-damping solve.
const NEWTON_ITERATIONS: usize = 30;
const POLE_TOLERANCE: f64 = 1e-10;
const STEP_TOLERANCE: f64 = 1e-6;
const LOOSE_TOLERANCE: f64 = 1e-7;
const LOBE_TOLERANCE: f64 = 1e-8;
/// A pole decaying at most this many times as fast as the dominant one may be identified
/// instead of it.
const NEAR_TIE_DECAY: f64 = 1.5;
/// Continuation steps of the pole in depth.
const POLE_STEPS: usize = 4;
/// Added process damping below this fraction of the structural damping is ignored.
const NEGLIGIBLE_DAMPING: f64 = 0.005;
/// Lowest crossings used as starting points of the process-damping solve.
const DAMPED_STARTS: usize = 2;
/// Relative added damping per step of the continuation in C, and the most steps.
const MILD_DAMPING: f64 = 1.0;
/// Relative added damping below which the check for lower lobes is skipped.
const UNCHECKED_DAMPING: f64 = 0.6;
const MAX_DAMPING_STEPS: usize = 6;
/// Rounds of the check for lower lobes, and its relative tolerance.
const VERIFY_ROUNDS: usize = 4;
const VERIFY_TOLERANCE: f64 = 1e-3;
/// Interpolation error of the tables' crossings tolerated without a Newton confirmation.
const TABLE_TOLERANCE: f64 = 0.05;
/// Lobes above the lowest reported at each speed (candidate chatter frequencies).
const NEXT_LOBES: usize = 2;
/// The plain 003 iteration (fallback): iterations and relative tolerance.
const FIXED_POINT_ITERATIONS: usize = 20;
const FIXED_POINT_TOLERANCE: f64 = 1e-4;
/// Segments moved to the front of a table's search order.
const EARLY_SEGMENTS: usize = 16;
/// Floor of the speed-softening factor s = 1 - c Omega^2.
const MIN_SOFTENING: f64 = 0.05;

/// One structural mode: natural frequency (rad/s), damping ratio, mass-normalized shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FastMode {
    pub omega: f64,
    pub zeta: f64,
    pub phi: [f64; 2],
}

/// How identified poles are reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PoleConvention {
    /// Turning: |lambda| / 2 pi and -Re(lambda) / |lambda| (000 Eq. 6).
    Physical,
    /// Milling: principal frequency and damping of the multiplier over one tooth period (002).
    Lifted,
}

/// The cutting geometry of one group of cuts (one radial immersion).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Geometry {
    /// Averaged directional matrix (milling) or K_c (turning) at the nominal coefficients, N/m^2.
    pub directional: Mat2,
    /// Rotation-averaged process-damping matrix per unit C / V (dimensionless).
    pub damping_per_cv: Mat2,
}

/// A limiting depth and its chatter frequency, with the next lobes above it at the same speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BoundaryPoint {
    /// Limiting depth (m); infinite when no lobe crosses the speed.
    pub depth_m: f64,
    /// Chatter frequency (Hz); NaN when unbounded.
    pub chatter_hz: f64,
    /// The next lowest lobe crossings (depth m, Hz); NaN where there are none.
    pub next: [(f64, f64); NEXT_LOBES],
}

impl BoundaryPoint {
    pub(crate) const UNBOUNDED: Self = Self {
        depth_m: f64::INFINITY,
        chatter_hz: f64::NAN,
        next: [(f64::NAN, f64::NAN); NEXT_LOBES],
    };

    /// From lobe crossings (depth m, Hz), lowest first.
    fn from_crossings(crossings: &[(f64, f64)]) -> Self {
        let Some(&(depth_m, chatter_hz)) = crossings.first() else {
            return Self::UNBOUNDED;
        };
        let mut next = [(f64::NAN, f64::NAN); NEXT_LOBES];
        for (slot, c) in next.iter_mut().zip(&crossings[1..]) {
            *slot = *c;
        }
        Self {
            depth_m,
            chatter_hz,
            next,
        }
    }

    /// Every lobe's (depth m, Hz), lowest first.
    pub fn lobes(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        std::iter::once((self.depth_m, self.chatter_hz))
            .chain(self.next.iter().copied())
            .filter(|(b, f)| b.is_finite() && f.is_finite())
    }

    /// The same point with every depth divided by `factor`.
    pub fn scaled_depth(&self, factor: f64) -> Self {
        if factor.is_nan() || factor <= 0.0 {
            return Self::UNBOUNDED;
        }
        let mut p = *self;
        p.depth_m /= factor;
        for n in &mut p.next {
            n.0 /= factor;
        }
        p
    }
}

/// A predicted pole as it would be identified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PredictedPole {
    pub frequency_hz: f64,
    pub damping_ratio: f64,
}

/// A machine variant in the fast zero-order form.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Machine {
    /// Modes at zero speed.
    pub modes: Vec<FastMode>,
    /// Geometries of the cut groups.
    pub geometries: Vec<Geometry>,
    /// Scale of the cutting coefficients relative to the geometries' matrices.
    pub gain: f64,
    /// Regenerative delays per revolution (teeth, or 1 for turning).
    pub delays_per_rev: f64,
    /// Diameter that sets the cutting speed (m).
    pub diameter_m: Option<f64>,
    /// Process-damping coefficient C (N/m).
    pub process_damping_n_per_m: f64,
    /// c in w_n(Omega) = w_n (1 - c Omega^2), 1/rpm^2.
    pub softening_per_rpm2: f64,
    /// Relative change of the cutting coefficients over the campaign: gain (1 + r u), u in [0, 1].
    pub drift_rate: f64,
    /// Pole convention.
    pub convention: PoleConvention,
    /// Grid density multiplier (1 for inference, more for synthetic truth).
    pub density: usize,
}

/// The two eigenvalue branches tabulated on a frequency grid, with the grid segments of both
/// branches and their lower depth, the lowest few first, so a crossing search skips most.
struct Table {
    f_hz: Vec<f64>,
    eps: [Vec<f64>; 2],
    depth: [Vec<f64>; 2],
    /// (lower depth of the segment, first point, branch).
    segments: Vec<(f64, u32, u8)>,
}

/// Receptance matrix entries (g00, g01, g11) at s (i w for FRFs).
fn receptance(modes: &[FastMode], s: Complex64) -> [Complex64; 3] {
    let mut g = [Complex64::new(0.0, 0.0); 3];
    for m in modes {
        let d = s * s + 2.0 * m.zeta * m.omega * s + m.omega * m.omega;
        let inv = d.inv();
        g[0] += m.phi[0] * m.phi[0] * inv;
        g[1] += m.phi[0] * m.phi[1] * inv;
        g[2] += m.phi[1] * m.phi[1] * inv;
    }
    g
}

/// Eigenvalues of A G.
fn eigen_ag(a: &Mat2, g: [Complex64; 3]) -> [Complex64; 2] {
    let m00 = a[0][0] * g[0] + a[0][1] * g[1];
    let m01 = a[0][0] * g[1] + a[0][1] * g[2];
    let m10 = a[1][0] * g[0] + a[1][1] * g[1];
    let m11 = a[1][0] * g[1] + a[1][1] * g[2];
    let tr = m00 + m11;
    let det = m00 * m11 - m01 * m10;
    let disc = (tr * tr * 0.25 - det).sqrt();
    [tr * 0.5 + disc, tr * 0.5 - disc]
}

fn scaled(a: &Mat2, k: f64) -> Mat2 {
    [[a[0][0] * k, a[0][1] * k], [a[1][0] * k, a[1][1] * k]]
}

/// The frequency grid (Hz) of the tables: sinh-spaced around every mode plus a coarse geometric
/// grid over [0.5 f_min, 2 f_max].
fn frequency_grid(modes: &[FastMode], density: usize) -> Vec<f64> {
    let hz = |m: &FastMode| m.omega / (2.0 * PI);
    let f_min = modes.iter().map(hz).fold(f64::INFINITY, f64::min);
    let f_max = modes.iter().map(hz).fold(0.0, f64::max);
    let (lo, hi) = (GRID_LOW * f_min, GRID_HIGH * f_max);
    let density = density.max(1);
    let global = GLOBAL_POINTS * density;
    let local = MODE_POINTS * density;
    let mut f: Vec<f64> = (0..global)
        .map(|i| lo * (hi / lo).powf(i as f64 / (global - 1) as f64))
        .collect();
    for m in modes {
        let fn_hz = hz(m);
        let zeta = m.zeta.max(1e-4);
        for i in 0..local {
            let u = -2.5 + 6.0 * i as f64 / (local - 1) as f64;
            let v = fn_hz * (1.0 + 2.0 * zeta * u.sinh());
            if v > lo && v < hi {
                f.push(v);
            }
        }
    }
    f.sort_by(f64::total_cmp);
    f.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * *b);
    f
}

fn table(modes: &[FastMode], a: &Mat2, f_hz: Vec<f64>) -> Table {
    let n = f_hz.len();
    let mut eps = [Vec::with_capacity(n), Vec::with_capacity(n)];
    let mut depth = [Vec::with_capacity(n), Vec::with_capacity(n)];
    let mut previous: Option<[Complex64; 2]> = None;
    for &f in &f_hz {
        let g = receptance(modes, Complex64::new(0.0, 2.0 * PI * f));
        let mut lam = eigen_ag(a, g);
        if let Some(p) = previous {
            let straight = (lam[0] - p[0]).norm_sqr() + (lam[1] - p[1]).norm_sqr();
            let swapped = (lam[1] - p[0]).norm_sqr() + (lam[0] - p[1]).norm_sqr();
            if swapped < straight {
                lam.swap(0, 1);
            }
        }
        previous = Some(lam);
        for (k, l) in lam.iter().enumerate() {
            // Re(Lambda) < 0 is eps in (0, 2 pi); then b = 1 / (2 sin(eps/2) |Lambda|) = -1 / (2 Re(Lambda))
            if l.re < 0.0 {
                eps[k].push((2.0 * l.arg() - PI).rem_euclid(4.0 * PI));
                depth[k].push(-0.5 / l.re);
            } else {
                eps[k].push(f64::NAN);
                depth[k].push(f64::NAN);
            }
        }
    }
    let mut segments = Vec::with_capacity(2 * n);
    for k in 0..2 {
        for j in 0..n.saturating_sub(1) {
            let (b0, b1) = (depth[k][j], depth[k][j + 1]);
            if b0.is_finite() && b1.is_finite() && (eps[k][j + 1] - eps[k][j]).abs() <= PI {
                segments.push((b0.min(b1), j as u32, k as u8));
            }
        }
    }
    // the lowest segments first, so the search below finds a tight bound early
    if segments.len() > EARLY_SEGMENTS {
        segments.select_nth_unstable_by(EARLY_SEGMENTS, |x, y| x.0.total_cmp(&y.0));
    }
    Table {
        f_hz,
        eps,
        depth,
        segments,
    }
}

impl Table {
    /// The `n` lowest lobe crossings at delay `tau` (s), lowest first, as (depth m, Hz).
    fn lowest_crossings(&self, tau: f64, n: usize) -> Vec<(f64, f64)> {
        let mut best: Vec<(f64, f64)> = Vec::with_capacity(n + 1);
        for &(lower, j, k) in &self.segments {
            if best.len() == n && best.last().is_some_and(|l| l.0 <= lower) {
                continue;
            }
            let (j, k) = (j as usize, k as usize);
            let (b0, b1) = (self.depth[k][j], self.depth[k][j + 1]);
            let (f0, f1) = (self.f_hz[j], self.f_hz[j + 1]);
            let p0 = f0 * tau - self.eps[k][j] / (2.0 * PI);
            let p1 = f1 * tau - self.eps[k][j + 1] / (2.0 * PI);
            if p0 == p1 {
                continue;
            }
            let (lo, hi) = if p0 < p1 { (p0, p1) } else { (p1, p0) };
            let first = lo.ceil().max(0.0) as i64;
            let last = hi.floor() as i64;
            for lobe in first..=last {
                let t = (lobe as f64 - p0) / (p1 - p0);
                // -2 Re(Lambda) = 1 / b is smooth in frequency; b itself is not near lobe sides
                let b = 1.0 / (1.0 / b0 + t * (1.0 / b1 - 1.0 / b0));
                if best.len() == n && best.last().is_some_and(|l| l.0 <= b) {
                    continue;
                }
                let at = best.partition_point(|x| x.0 <= b);
                best.insert(at, (b, f0 + t * (f1 - f0)));
                best.truncate(n);
            }
        }
        best
    }
}

/// The characteristic function F(s) (entire; see the module docs) of modes with depth `b`,
/// delay `tau` and directional matrix `a`, and its derivative F'(s).
fn characteristic(
    modes: &[FastMode],
    a: &Mat2,
    b: f64,
    tau: f64,
    s: Complex64,
) -> (Complex64, Complex64) {
    let one = Complex64::new(1.0, 0.0);
    let zero = Complex64::new(0.0, 0.0);
    let n = modes.len();
    let mut stack = [(one, zero); 8];
    let mut heap = Vec::new();
    let d: &mut [(Complex64, Complex64)] = if n <= stack.len() {
        &mut stack[..n]
    } else {
        heap.resize(n, (one, zero));
        &mut heap
    };
    for (di, m) in d.iter_mut().zip(modes) {
        *di = (
            s * s + 2.0 * m.zeta * m.omega * s + m.omega * m.omega,
            2.0 * s + 2.0 * m.zeta * m.omega,
        );
    }
    // the product of d over the modes not in `skip`, and its derivative
    let product = |skip: [usize; 2]| -> (Complex64, Complex64) {
        let mut p = one;
        let mut dp = zero;
        for (i, (v, dv)) in d.iter().enumerate() {
            if i != skip[0] && i != skip[1] {
                dp = dp * v + p * dv;
                p *= v;
            }
        }
        (p, dp)
    };
    let det_a = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let (p0, dp0) = product([n, n]);
    let (mut p1, mut dp1) = (zero, zero);
    for (i, m) in modes.iter().enumerate() {
        let (p, dp) = product([i, n]);
        let w = quadratic(a, m.phi);
        p1 += w * p;
        dp1 += w * dp;
    }
    let (mut p2, mut dp2) = (zero, zero);
    if det_a != 0.0 {
        for i in 0..n {
            for j in (i + 1)..n {
                let (p, r) = (modes[i].phi, modes[j].phi);
                let w = det_a * (p[0] * r[1] - p[1] * r[0]).powi(2);
                if w != 0.0 {
                    let (q, dq) = product([i, j]);
                    p2 += w * q;
                    dp2 += w * dq;
                }
            }
        }
    }
    let e = (-s * tau).exp();
    let c = b * (one - e);
    let dc = b * tau * e;
    (
        p0 + c * (p1 + c * p2),
        dp0 + dc * p1 + c * dp1 + 2.0 * c * dc * p2 + c * c * dp2,
    )
}

/// Newton's method on F(s) = 0 from `s` to the relative `tolerance`. A root that is (nearly)
/// double converges only linearly; a last step below `LOOSE_TOLERANCE` is then accepted.
fn pole_newton(
    modes: &[FastMode],
    a: &Mat2,
    b: f64,
    tau: f64,
    mut s: Complex64,
    tolerance: f64,
) -> Option<Complex64> {
    let mut last = f64::INFINITY;
    for _ in 0..NEWTON_ITERATIONS {
        let (f, df) = characteristic(modes, a, b, tau, s);
        if df.norm() == 0.0 || !df.re.is_finite() {
            return None;
        }
        let step = f / df;
        s -= step;
        if !(s.re.is_finite() && s.im.is_finite()) {
            return None;
        }
        last = step.norm() / s.norm();
        if last <= tolerance {
            return Some(s);
        }
    }
    (last <= LOOSE_TOLERANCE.max(tolerance)).then_some(s)
}

/// The root of F continued in depth from the structural pole `start` (depth 0) to `depth_m`
/// in `steps` equal steps, each a Newton corrector from the linear extrapolation of the last two
/// roots.
fn continue_root(
    modes: &[FastMode],
    a: &Mat2,
    tau: f64,
    depth_m: f64,
    start: Complex64,
    steps: usize,
) -> Option<Complex64> {
    let (mut previous, mut s) = (start, start);
    for k in 1..=steps {
        let predicted = if k == 1 { s } else { 2.0 * s - previous };
        let b = depth_m * k as f64 / steps as f64;
        let tolerance = if k == steps {
            POLE_TOLERANCE
        } else {
            STEP_TOLERANCE
        };
        let root = pole_newton(modes, a, b, tau, predicted, tolerance)?;
        previous = s;
        s = root;
    }
    Some(s)
}

/// The geometry of `model`'s operation at each radial immersion in `immersions` (`None`: the
/// model's own; ignored for turning).
pub(crate) fn geometries(model: &ModalModel, immersions: &[Option<f64>]) -> Result<Vec<Geometry>> {
    immersions
        .iter()
        .map(|r| {
            let m = match (model.operation(), r) {
                (Operation::Milling(op), Some(r)) => {
                    model.with_operation(Operation::Milling(op.with_radial_immersion(*r)?))?
                }
                _ => model.clone(),
            };
            let h = m.average_directional_matrix();
            let damping_per_cv = match m.operation() {
                Operation::Turning(_) => [[1.0, 0.0], [0.0, 0.0]],
                Operation::Milling(op) => {
                    let (a, b) = op.entry_exit_rad();
                    let f = op.teeth() as f64 / (2.0 * PI);
                    let ss = |p: f64| 0.5 * p - 0.25 * (2.0 * p).sin();
                    let cc = |p: f64| 0.5 * p + 0.25 * (2.0 * p).sin();
                    let sc = |p: f64| 0.5 * p.sin().powi(2);
                    let (iss, icc, isc) = (ss(b) - ss(a), cc(b) - cc(a), sc(b) - sc(a));
                    [[f * iss, f * isc], [f * isc, f * icc]]
                }
            };
            Ok(Geometry {
                directional: [[h[(0, 0)], h[(0, 1)]], [h[(1, 0)], h[(1, 1)]]],
                damping_per_cv,
            })
        })
        .collect()
}

impl Machine {
    /// The fast form of `model` with the given cut geometries and grid density.
    pub fn from_model(
        model: &ModalModel,
        geometries: Vec<Geometry>,
        density: usize,
    ) -> Result<Self> {
        let modes = model
            .modes()
            .iter()
            .map(|m| FastMode {
                omega: m.omega_rad_s(),
                zeta: m.damping_ratio(),
                phi: m.mass_normalized_shape(),
            })
            .collect();
        if geometries.is_empty() {
            return Err(GapError::Model("no cut geometry".into()));
        }
        Ok(Self {
            modes,
            geometries,
            gain: 1.0,
            delays_per_rev: model.operation().delays_per_revolution() as f64,
            diameter_m: model.operation().cutting_diameter_m(),
            process_damping_n_per_m: model.process_damping_n_per_m().unwrap_or(0.0),
            softening_per_rpm2: 0.0,
            drift_rate: 0.0,
            convention: match model.operation() {
                Operation::Milling(_) => PoleConvention::Lifted,
                Operation::Turning(_) => PoleConvention::Physical,
            },
            density,
        })
    }

    /// The speed-softening factor s = 1 - c Omega^2 (floored).
    fn softening(&self, speed_rpm: f64) -> f64 {
        (1.0 - self.softening_per_rpm2 * speed_rpm * speed_rpm).max(MIN_SOFTENING)
    }

    /// The regenerative delay (s).
    pub fn delay_s(&self, speed_rpm: f64) -> f64 {
        60.0 / (self.delays_per_rev * speed_rpm)
    }

    /// The gain at normalized campaign position `u`.
    fn gain_at(&self, u: f64) -> f64 {
        self.gain * (1.0 + self.drift_rate * u)
    }

    /// Modes at a speed, softened, with the process damping of depth `depth_m` in `geometry`
    /// folded into the damping ratios.
    fn modes_at(&self, speed_rpm: f64, depth_m: f64, geometry: usize) -> Vec<FastMode> {
        self.modes_with(
            speed_rpm,
            depth_m,
            geometry,
            self.process_damping_per_velocity(speed_rpm),
        )
    }

    /// [`Self::modes_at`] with the process damping C / V given (`cv`, N s/m^3 per m width).
    fn modes_with(&self, speed_rpm: f64, depth_m: f64, geometry: usize, cv: f64) -> Vec<FastMode> {
        let s = self.softening(speed_rpm);
        let d = self.geometries.get(geometry).map(|g| g.damping_per_cv);
        self.modes
            .iter()
            .map(|m| {
                let omega = m.omega * s;
                let added = match d {
                    Some(d) if cv > 0.0 => depth_m * cv * quadratic(&d, m.phi) / (2.0 * omega),
                    _ => 0.0,
                };
                FastMode {
                    omega,
                    zeta: m.zeta + added,
                    phi: m.phi,
                }
            })
            .collect()
    }

    /// C / V (N s / m^2 per m of width) at a speed, 0 without process damping.
    fn process_damping_per_velocity(&self, speed_rpm: f64) -> f64 {
        match self.diameter_m {
            Some(d) if self.process_damping_n_per_m > 0.0 => {
                self.process_damping_n_per_m / (PI * d * speed_rpm / 60.0)
            }
            _ => 0.0,
        }
    }

    /// Limiting depth and chatter frequency at each (speed, geometry) request, at campaign
    /// position 0 (drift scales the depth by 1 / (1 + r u) afterwards).
    pub fn boundary(&self, requests: &[(f64, usize)]) -> Vec<BoundaryPoint> {
        let grid = frequency_grid(&self.modes, self.density);
        let tables: Vec<Table> = self
            .geometries
            .iter()
            .map(|g| {
                table(
                    &self.modes,
                    &scaled(&g.directional, self.gain),
                    grid.clone(),
                )
            })
            .collect();
        let wanted = if self.process_damping_n_per_m > 0.0 {
            DAMPED_STARTS
        } else {
            1 + NEXT_LOBES
        };
        requests
            .iter()
            .map(|&(speed, geometry)| {
                let Some(tab) = tables.get(geometry) else {
                    return BoundaryPoint::UNBOUNDED;
                };
                let s = self.softening(speed);
                let crossings: Vec<(f64, f64)> = tab
                    .lowest_crossings(self.delay_s(speed / s), wanted)
                    .into_iter()
                    .map(|(b, f)| (s * s * b, s * f))
                    .collect();
                self.with_process_damping(crossings, speed, geometry, &grid)
            })
            .collect()
    }

    /// The lobes at one speed from the lowest bare lobe crossings, with the process-damping
    /// fixed point of each where process damping matters.
    fn with_process_damping(
        &self,
        crossings: Vec<(f64, f64)>,
        speed_rpm: f64,
        geometry: usize,
        grid: &[f64],
    ) -> BoundaryPoint {
        let cv = self.process_damping_per_velocity(speed_rpm);
        let (Some(geo), Some(&(b0, _))) = (self.geometries.get(geometry), crossings.first()) else {
            return BoundaryPoint::from_crossings(&crossings);
        };
        let relative = self
            .modes_with(speed_rpm, b0, geometry, cv)
            .iter()
            .zip(&self.modes)
            .map(|(d, m)| d.zeta / m.zeta.max(1e-9) - 1.0)
            .fold(0.0, f64::max);
        if cv == 0.0 || relative < NEGLIGIBLE_DAMPING {
            return BoundaryPoint::from_crossings(&crossings);
        }
        let a = scaled(&geo.directional, self.gain);
        // continuation in C from each bare lobe: Newton on (f, b) at C j / J
        let steps = ((relative / MILD_DAMPING).ceil() as usize).clamp(1, MAX_DAMPING_STEPS);
        let mut lobes: Vec<(f64, f64)> = crossings
            .iter()
            .filter_map(|&(b, f)| {
                (1..=steps).try_fold((b, f), |(b, f), j| {
                    let c = cv * j as f64 / steps as f64;
                    self.damped_lobe_newton(speed_rpm, geometry, &a, c, b, f)
                })
            })
            .collect();
        // A lobe whose fixed point lies below the lowest found would cross below it in the
        // table damped at that depth (the map b -> b_lim(zeta(b)) is a contraction): check, and
        // start Newton from such crossings until none is left.
        let tau = self.delay_s(speed_rpm);
        if relative < UNCHECKED_DAMPING && !lobes.is_empty() {
            lobes.sort_by(|x, y| x.0.total_cmp(&y.0));
            return BoundaryPoint::from_crossings(&lobes);
        }
        for _ in 0..VERIFY_ROUNDS {
            let Some(lowest) = lobes.iter().map(|l| l.0).min_by(f64::total_cmp) else {
                break;
            };
            let modes = self.modes_with(speed_rpm, lowest, geometry, cv);
            if modes.iter().any(|m| m.zeta >= 1.0) {
                break;
            }
            let below: Vec<(f64, f64)> = table(&modes, &a, grid.to_vec())
                .lowest_crossings(tau, DAMPED_STARTS)
                .into_iter()
                .filter(|c| c.0 < lowest * (1.0 - VERIFY_TOLERANCE))
                .collect();
            // Newton from a crossing below may land on a known lobe: the crossing was the
            // table's interpolation error
            let solved: Vec<Option<(f64, f64)>> = below
                .iter()
                .map(|&(b, f)| self.damped_lobe_newton(speed_rpm, geometry, &a, cv, b, f))
                .collect();
            let lower: Vec<(f64, f64)> = solved
                .iter()
                .flatten()
                .copied()
                .filter(|l| l.0 < lowest * (1.0 - VERIFY_TOLERANCE))
                .collect();
            let unresolved = below
                .iter()
                .zip(&solved)
                .any(|(c, l)| l.is_none() && c.0 < lowest * (1.0 - TABLE_TOLERANCE));
            if lower.is_empty() && !unresolved {
                lobes.sort_by(|x, y| x.0.total_cmp(&y.0));
                lobes.dedup_by(|x, y| (x.0 - y.0).abs() <= VERIFY_TOLERANCE * y.0);
                return BoundaryPoint::from_crossings(&lobes);
            }
            if lower.is_empty() {
                break;
            }
            lobes.extend(lower);
        }
        let mut lobes = self.damped_by_iteration(speed_rpm, geometry, &a, b0, grid);
        lobes.sort_by(|x, y| x.0.total_cmp(&y.0));
        BoundaryPoint::from_crossings(&lobes)
    }

    /// The process-damping fixed point by the plain iteration of 003 on the tables (the fallback
    /// where no lobe continuation converges).
    fn damped_by_iteration(
        &self,
        speed_rpm: f64,
        geometry: usize,
        a: &Mat2,
        b0: f64,
        grid: &[f64],
    ) -> Vec<(f64, f64)> {
        let tau = self.delay_s(speed_rpm);
        let step = |x: f64| -> Vec<(f64, f64)> {
            let modes = self.modes_at(speed_rpm, x, geometry);
            if modes.iter().any(|m| m.zeta >= 1.0) {
                return Vec::new();
            }
            table(&modes, a, grid.to_vec()).lowest_crossings(tau, 1 + NEXT_LOBES)
        };
        let mut history = vec![b0];
        let mut lobes = Vec::new();
        for _ in 0..FIXED_POINT_ITERATIONS {
            let Some(&x) = history.last() else {
                break;
            };
            lobes = step(x);
            let Some(&(next, _)) = lobes.first() else {
                return Vec::new();
            };
            if (next - x).abs() <= FIXED_POINT_TOLERANCE * next {
                break;
            }
            history.push(next);
            // Aitken's extrapolation every third step (kept above the last iterate)
            if let [.., x0, x1, x2] = history[..]
                && history.len() % 3 == 0
            {
                let denominator = x2 - 2.0 * x1 + x0;
                if denominator < 0.0 {
                    let extrapolated = x0 - (x1 - x0).powi(2) / denominator;
                    history.push(extrapolated.clamp(x2, x2 + 3.0 * (x2 - x1).abs()));
                }
            }
        }
        lobes
    }

    /// Newton on (f, b) for F(i w; modes damped at b with C / V = `cv`) = 0 from a lobe point.
    fn damped_lobe_newton(
        &self,
        speed_rpm: f64,
        geometry: usize,
        a: &Mat2,
        cv: f64,
        mut b: f64,
        mut f: f64,
    ) -> Option<(f64, f64)> {
        let tau = self.delay_s(speed_rpm);
        let base = self.modes_with(speed_rpm, 0.0, geometry, 0.0);
        let d = self.geometries.get(geometry)?.damping_per_cv;
        let rate: Vec<f64> = base
            .iter()
            .map(|m| cv * quadratic(&d, m.phi) / (2.0 * m.omega))
            .collect();
        let mut modes = base.clone();
        // F(i 2 pi f) and dF/df at depth b
        let mut eval = |f: f64, b: f64| -> Option<(Complex64, Complex64)> {
            for ((m, m0), r) in modes.iter_mut().zip(&base).zip(&rate) {
                m.zeta = m0.zeta + b * r;
                if m.zeta >= 1.0 {
                    return None;
                }
            }
            let (v, dv) = characteristic(&modes, a, b, tau, Complex64::new(0.0, 2.0 * PI * f));
            Some((v, dv * Complex64::new(0.0, 2.0 * PI)))
        };
        let (f_start, b_start) = (f, b);
        for _ in 0..NEWTON_ITERATIONS {
            let (r, rf) = eval(f, b)?;
            let hb = 1e-7 * b;
            let rb = (eval(f, b + hb)?.0 - r) / hb;
            // solve [rf.re rb.re; rf.im rb.im] [df db]^T = -[r.re r.im]^T
            let det = rf.re * rb.im - rb.re * rf.im;
            if det == 0.0 || !det.is_finite() {
                return None;
            }
            let df = -(r.re * rb.im - rb.re * r.im) / det;
            let db = -(rf.re * r.im - r.re * rf.im) / det;
            f += df;
            b += db;
            if !(f > 0.0 && b > 0.0) || (f / f_start - 1.0).abs() > 0.1 || b > 4.0 * b_start {
                return None;
            }
            if df.abs() <= LOBE_TOLERANCE * f && db.abs() <= LOBE_TOLERANCE * b {
                return Some((b, f));
            }
        }
        None
    }

    /// The dominant closed-loop pole (rad/s) at a speed, depth, geometry and campaign position:
    /// the continued root with the largest real part.
    pub fn dominant_pole(
        &self,
        speed_rpm: f64,
        depth_m: f64,
        geometry: usize,
        u: f64,
    ) -> Option<Complex64> {
        self.continued_poles(speed_rpm, depth_m, geometry, u, POLE_STEPS)
            .into_iter()
            .max_by(|a, b| a.re.total_cmp(&b.re))
    }

    /// The roots continued from every structural pole in `steps` equal steps in depth.
    fn continued_poles(
        &self,
        speed_rpm: f64,
        depth_m: f64,
        geometry: usize,
        u: f64,
        steps: usize,
    ) -> Vec<Complex64> {
        let Some(geo) = self.geometries.get(geometry) else {
            return Vec::new();
        };
        let modes = self.modes_at(speed_rpm, depth_m, geometry);
        let a = scaled(&geo.directional, self.gain_at(u));
        let tau = self.delay_s(speed_rpm);
        let mut roots = Vec::with_capacity(modes.len());
        for (i, m) in modes.iter().enumerate() {
            let wd = m.omega * (1.0 - m.zeta * m.zeta).max(0.0).sqrt();
            let mut s = Complex64::new(-m.zeta * m.omega, wd);
            // a repeated structural pole: start the copies slightly apart
            let twins = modes[..i]
                .iter()
                .filter(|o| (o.omega - m.omega).abs() <= 1e-6 * m.omega)
                .count();
            s += Complex64::new(0.0, 0.05 * m.zeta * m.omega * twins as f64);
            if let Some(s) = continue_root(&modes, &a, tau, depth_m, s, steps)
                && s.im > 0.0
            {
                roots.push(s);
            }
        }
        roots
    }

    /// A pole as it would be identified: physical (turning) or lifted over `tau_s` (milling).
    pub fn observed_pole(&self, lambda: Complex64, tau_s: f64) -> PredictedPole {
        let s = match self.convention {
            PoleConvention::Physical => lambda,
            PoleConvention::Lifted => (lambda * tau_s).exp().ln() / tau_s,
        };
        let w = s.norm();
        let frequency_hz = match self.convention {
            PoleConvention::Physical => w / (2.0 * PI),
            PoleConvention::Lifted => s.im.abs() / (2.0 * PI),
        };
        PredictedPole {
            frequency_hz,
            damping_ratio: if w > 0.0 { -s.re / w } else { 0.0 },
        }
    }

    /// The poles an identification at a stable cut may report, as [`Self::observed_pole`] over
    /// the machine's delay, with weights: the dominant pole (weight 1) and every other continued
    /// pole that decays at most 1.5 times as fast (weight 1/2: a near tie OMA may resolve
    /// either way). Dominant first; empty when no continuation converged.
    pub fn poles(
        &self,
        speed_rpm: f64,
        depth_m: f64,
        geometry: usize,
        u: f64,
    ) -> Vec<(PredictedPole, f64)> {
        let mut roots = self.continued_poles(speed_rpm, depth_m, geometry, u, POLE_STEPS);
        roots.sort_by(|a, b| b.re.total_cmp(&a.re));
        let Some(&dominant) = roots.first() else {
            return Vec::new();
        };
        let tau = self.delay_s(speed_rpm);
        roots
            .iter()
            .enumerate()
            .filter(|(k, r)| *k == 0 || r.re >= NEAR_TIE_DECAY * dominant.re)
            .map(|(k, r)| (self.observed_pole(*r, tau), if k == 0 { 1.0 } else { 0.5 }))
            .collect()
    }

    /// The cutting-coefficient factor of drift at campaign position `u` relative to position 0.
    pub fn drift_factor(&self, u: f64) -> f64 {
        1.0 + self.drift_rate * u
    }
}

/// phi^T D phi.
pub(crate) fn quadratic(d: &Mat2, p: [f64; 2]) -> f64 {
    p[0] * (d[0][0] * p[0] + d[0][1] * p[1]) + p[1] * (d[1][0] * p[0] + d[1][1] * p[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::{Milling, MillingDirection, examples};
    use chatter_stability::frequency_domain::dominant_pole;
    use chatter_stability::process_damping::process_damping_limiting_depth;
    use chatter_stability::zero_order::zoa_lobes;

    fn fast(model: &ModalModel) -> Machine {
        Machine::from_model(model, geometries(model, &[None]).unwrap(), 1).unwrap()
    }

    fn milling_with_diameter() -> ModalModel {
        let m = examples::schmitz_2023_milling();
        let op = Milling::new(4, 0.2, MillingDirection::Down, Some(0.01905), None).unwrap();
        m.with_operation(Operation::Milling(op)).unwrap()
    }

    #[test]
    fn boundary_matches_zero_order_lobes() {
        for model in [
            examples::schmitz_2023_milling(),
            examples::ahmadi_2022_turning(),
        ] {
            let turning = matches!(model.operation(), Operation::Turning(_));
            let speeds: Vec<f64> = if turning {
                (0..100).map(|i| 2000.0 + 80.0 * i as f64).collect()
            } else {
                (0..200).map(|i| 1000.0 + 65.0 * i as f64).collect()
            };
            let reference = zoa_lobes(&model, &speeds).unwrap();
            let requests: Vec<(f64, usize)> = speeds.iter().map(|&s| (s, 0)).collect();
            let ours = fast(&model).boundary(&requests);
            let mut sum = 0.0;
            let mut switched = 0;
            for (r, o) in reference.iter().zip(&ours) {
                let rel = o.depth_m / r.depth_m - 1.0;
                sum += rel * rel;
                assert!(
                    rel.abs() < 0.06,
                    "{} rpm: {} vs {} m",
                    r.speed_rpm,
                    o.depth_m,
                    r.depth_m
                );
                // where two lobes cross, the lower one may differ in the tables
                if (o.chatter_hz - r.chatter_hz).abs() > 0.5 {
                    switched += 1;
                }
            }
            assert!(
                switched * 30 <= speeds.len(),
                "{switched} chatter frequencies differ"
            );
            let rms = (sum / speeds.len() as f64).sqrt();
            assert!(rms < 0.015, "rms relative error {rms}");
        }
    }

    #[test]
    fn process_damping_matches_iterative_algorithm() {
        let model = milling_with_diameter()
            .with_process_damping(Some(2.0e5))
            .unwrap();
        let machine = fast(&model);
        for speed in [1200.0, 2000.0, 3100.0, 6000.0] {
            let r = process_damping_limiting_depth(&model, speed).unwrap();
            let o = machine.boundary(&[(speed, 0)])[0];
            assert!(
                (o.depth_m / r.depth_m - 1.0).abs() < 0.01,
                "{speed} rpm: {} vs {} m",
                o.depth_m,
                r.depth_m
            );
        }
    }

    #[test]
    fn softening_is_a_rescaled_model() {
        let model = examples::schmitz_2023_milling();
        let mut machine = fast(&model);
        machine.softening_per_rpm2 = 0.08 / 12_000f64.powi(2);
        for speed in [3000.0, 8000.0, 12_000.0] {
            let s: f64 = 1.0 - machine.softening_per_rpm2 * speed * speed;
            let modes = model
                .modes()
                .iter()
                .map(|m| {
                    let k = m.stiffness_at(if m.mass_normalized_shape()[0] != 0.0 {
                        0
                    } else {
                        1
                    });
                    chatter_dynamics::Mode::new(
                        m.frequency_hz() * s,
                        m.damping_ratio(),
                        chatter_dynamics::ModeShape::Directional {
                            coordinate: if m.mass_normalized_shape()[0] != 0.0 {
                                0
                            } else {
                                1
                            },
                            stiffness_n_per_m: k * s * s,
                        },
                    )
                    .unwrap()
                })
                .collect();
            let soft = model.with_modes(modes).unwrap();
            let r = zoa_lobes(&soft, &[speed]).unwrap()[0];
            let o = machine.boundary(&[(speed, 0)])[0];
            assert!(
                (o.depth_m / r.depth_m - 1.0).abs() < 0.02,
                "{speed}: {} vs {}",
                o.depth_m,
                r.depth_m
            );
        }
    }

    #[test]
    fn turning_pole_matches_characteristic_equation() {
        let model = examples::ahmadi_2022_turning();
        let machine = fast(&model);
        for (speed, width) in [(7150.0, 0.5e-3), (5000.0, 1.0e-3), (9000.0, 0.2e-3)] {
            let r = dominant_pole(&model, speed, width).unwrap();
            let o = machine.poles(speed, width, 0, 0.0)[0].0;
            assert!((o.frequency_hz - r.frequency_hz).abs() < 1e-6 * r.frequency_hz);
            assert!((o.damping_ratio - r.damping_ratio).abs() < 1e-6);
        }
    }

    #[test]
    fn continuation_finds_the_finely_continued_pole() {
        let model = crate::generator::nominal_milling().unwrap();
        let machine = fast(&model);
        for i in 0..12 {
            let speed = 1500.0 + 1000.0 * i as f64;
            let b = machine.boundary(&[(speed, 0)])[0].depth_m;
            for fraction in [0.2, 0.5, 0.8] {
                let one = machine.dominant_pole(speed, fraction * b, 0, 0.0).unwrap();
                let many = machine
                    .continued_poles(speed, fraction * b, 0, 0.0, 40)
                    .into_iter()
                    .max_by(|a, b| a.re.total_cmp(&b.re))
                    .unwrap();
                let tau = machine.delay_s(speed);
                assert!(
                    (one - many).norm() < 1e-6 * many.norm(),
                    "{speed} rpm, {fraction}: {one} vs {many}, mu {} vs {}",
                    (one * tau).exp(),
                    (many * tau).exp()
                );
            }
        }
    }

    #[test]
    fn milling_pole_at_zero_depth_is_the_aliased_mode() {
        let model = examples::schmitz_2023_milling();
        let machine = fast(&model);
        let p = machine.poles(10_000.0, 1e-9, 0, 0.0)[0].0;
        // 750 Hz seen once per tooth period (666.7 Hz): 83.3 Hz
        assert!(
            (p.frequency_hz - 750.0 * (1.0 - 0.0009f64).sqrt() + 666.666_666_7).abs() < 0.05,
            "{p:?}"
        );
    }

    #[test]
    fn process_damping_over_speeds_and_strengths() {
        for c in [3e4, 1e5, 2e5] {
            let model = milling_with_diameter()
                .with_process_damping(Some(c))
                .unwrap();
            let speeds: Vec<f64> = (0..12).map(|i| 1000.0 + 1000.0 * i as f64).collect();
            let requests: Vec<(f64, usize)> = speeds.iter().map(|&s| (s, 0)).collect();
            let ours = fast(&model).boundary(&requests);
            for (s, o) in speeds.iter().zip(&ours) {
                let r = process_damping_limiting_depth(&model, *s).unwrap();
                assert!(
                    (o.depth_m / r.depth_m - 1.0).abs() < 0.02,
                    "C {c}, {s} rpm: {} vs {}",
                    o.depth_m,
                    r.depth_m
                );
            }
        }
    }
}
