//! A fast zero-order representation of a machine variant: the limiting depth and chatter
//! frequency at given spindle speeds and the dominant closed-loop pole of a stable cut, cheap
//! enough to sit inside the samplers.
//!
//! # Boundary
//! The zero-order (Altintas-Budak) characteristic equation det(I + b (1 - e^{-i w tau}) A G(i w)) = 0,
//! with A the averaged directional matrix (milling) or K_c (turning) and G the receptance, is
//! solved by [`chatter_stability::zero_order::LobeTable`]: the eigenvalue branches are tabulated
//! once per model and geometry, and at each requested speed the lowest lobes are solved exactly.
//!
//! # Speed-dependent modes
//! When every natural frequency falls with speed as w_n(Omega) = w_n (1 - c Omega^2) at constant
//! modal mass, G_s(w) = s^-2 G(w / s) with s = 1 - c Omega^2, so
//! b_lim(Omega) = s^2 b_lim,0(Omega / s) and f_c(Omega) = s f_c,0(Omega / s): one table serves
//! every speed.
//!
//! # Process damping (seed 003)
//! F_d = -C b ydot / V adds the modal damping b phi_n^T D phi_n (D the rotation-averaged C/V n n^T,
//! [`chatter_stability::process_damping::average_normal_projector`]), i.e. the damping ratios
//! zeta_n + b (C / V) s_n with s_n the slopes at unit C / V. The fixed point b = b_lim(zeta(b)) of
//! 003's iterative algorithm is solved by a [`ProcessDampedTable`] per geometry, scaled by C / V at
//! each speed. With softening the same rescaling holds with the scale multiplied by s (the
//! damping ratio of the softened mode is zeta_n + s^2 b' (C / V) s_n / s at b = s^2 b').
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
use chatter_stability::process_damping::{average_normal_projector, damping_ratio_slope_per_m};
use chatter_stability::zero_order::{
    LobeTable, ModalTerm, OrientedSystem, ProcessDampedTable, ZeroOrderOptions,
};
use num_complex::Complex64;
use std::f64::consts::PI;

/// A real 2 x 2 matrix, rows first.
pub(crate) type Mat2 = [[f64; 2]; 2];

/// Newton iterations and tolerances of the pole continuation.
const NEWTON_ITERATIONS: usize = 30;
const POLE_TOLERANCE: f64 = 1e-10;
const STEP_TOLERANCE: f64 = 1e-6;
const LOOSE_TOLERANCE: f64 = 1e-7;
/// A pole decaying at most this many times as fast as the dominant one may be identified
/// instead of it.
const NEAR_TIE_DECAY: f64 = 1.5;
/// Continuation steps of the pole in depth.
const POLE_STEPS: usize = 4;
/// Lobes above the lowest reported at each speed (candidate chatter frequencies).
const NEXT_LOBES: usize = 2;
/// Lobes reported with process damping (the lowest and the next: each costs fixed points).
const DAMPED_LOBES: usize = 2;
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
}

fn scaled(a: &Mat2, k: f64) -> Mat2 {
    [[a[0][0] * k, a[0][1] * k], [a[1][0] * k, a[1][1] * k]]
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
            Ok(Geometry {
                directional: [[h[(0, 0)], h[(0, 1)]], [h[(1, 0)], h[(1, 1)]]],
                damping_per_cv: average_normal_projector(m.operation()),
            })
        })
        .collect()
}

impl Machine {
    /// The fast form of `model` with the given cut geometries.
    pub fn from_model(model: &ModalModel, geometries: Vec<Geometry>) -> Result<Self> {
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
                    Some(d) if cv > 0.0 => {
                        depth_m * damping_ratio_slope_per_m(m.phi, omega, &scaled(&d, cv))
                    }
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

    /// Limiting depth and chatter frequency at each (speed, geometry) request, with the next
    /// lobes above it, at campaign position 0 (drift scales the depth by 1 / (1 + r u)
    /// afterwards). Requests of an unknown geometry, or of modes that make no valid zero-order
    /// system (non-finite values from a sampler), are unbounded.
    pub fn boundary(&self, requests: &[(f64, usize)]) -> Vec<BoundaryPoint> {
        let modes: Vec<ModalTerm> = self
            .modes
            .iter()
            .map(|m| ModalTerm {
                omega_rad_s: m.omega,
                damping_ratio: m.zeta,
                shape: m.phi,
            })
            .collect();
        let tables: Vec<Option<LobeTable>> = self
            .geometries
            .iter()
            .map(|g| {
                OrientedSystem::new(modes.clone(), scaled(&g.directional, self.gain))
                    .ok()
                    .map(LobeTable::new)
            })
            .collect();
        // the slopes of the damping ratios at unit C / V; none without process damping
        let damped: Vec<Option<ProcessDampedTable>> = self
            .geometries
            .iter()
            .zip(&tables)
            .map(|(g, table)| {
                let table = table.as_ref()?;
                let slopes: Vec<f64> = self
                    .modes
                    .iter()
                    .map(|m| damping_ratio_slope_per_m(m.phi, m.omega, &g.damping_per_cv))
                    .collect();
                (self.process_damping_per_velocity(1.0) > 0.0)
                    .then(|| {
                        ProcessDampedTable::new(table, &slopes, &ZeroOrderOptions::unbounded())
                    })
                    .and_then(|d| d.ok())
            })
            .collect();
        requests
            .iter()
            .map(|&(speed, geometry)| {
                let s = self.softening(speed);
                let tau = self.delay_s(speed / s);
                let lobes = match (tables.get(geometry), damped.get(geometry)) {
                    (_, Some(Some(d))) => {
                        let scale = s * self.process_damping_per_velocity(speed);
                        d.lobes(tau, scale, DAMPED_LOBES)
                    }
                    (Some(Some(t)), _) => t.lobes(tau, 1 + NEXT_LOBES),
                    _ => return BoundaryPoint::UNBOUNDED,
                };
                lobes.map_or(BoundaryPoint::UNBOUNDED, |l| {
                    let scaled: Vec<(f64, f64)> = l
                        .iter()
                        .map(|l| (s * s * l.depth_m, s * l.chatter_hz))
                        .collect();
                    BoundaryPoint::from_crossings(&scaled)
                })
            })
            .collect()
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
        Machine::from_model(model, geometries(model, &[None]).unwrap()).unwrap()
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
