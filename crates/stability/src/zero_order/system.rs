//! The oriented frequency response of the zero-order method (Altintas and Budak 1995): the two
//! eigenvalues Lambda(w) of A_0 G(i w), with A_0 the delay-averaged directional matrix (N/m^2)
//! and G the receptance of 000 Eq. 1,
//!
//! G(i w) = sum_n phi_n phi_n^T / (w_n^2 - w^2 + 2 i zeta_n w_n w),
//!
//! over mass-normalized mode shapes phi_n, plus the residual terms U_i - L_i / w^2 of the direct
//! receptances (`chatter_dynamics::ResidualTerms`); a non-proportional (complex) mode multiplies its term
//! by n_0 + n_1 i w ([`chatter_dynamics::model::complex_mode_numerator`]). Process damping (003 Section 2) enters as the
//! equivalent damping ratios zeta_n + b s_n of [`crate::process_damping::with_equivalent_damping`],
//! with s_n = d zeta_n / d b from [`crate::process_damping::damping_ratio_slope_per_m`].
//!
//! Where Re(Lambda) < 0 the eigenvalue is a point of a lobe: the phase
//! eps = (2 arg(Lambda) - pi) mod 4 pi lies in (0, 2 pi) and the depth is b = -1 / (2 Re(Lambda)).

use super::Lobe;
use crate::error::{Result, invalid};
use chatter_dynamics::{ModalModel, ResidualTerms};
use num_complex::Complex64;
use std::f64::consts::PI;

/// Real parts above this fraction of the pair's size (|Lambda_1|^2 + |Lambda_2|^2)^(1/2) below zero
/// count as rounding, so a zero eigenvalue (every mode along one direction) is not a lobe.
const ROUNDING: f64 = 1e-10;

/// One vibration mode as the zero-order method sees it (000 Eq. 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModalTerm {
    /// Natural frequency w_n (rad/s).
    pub omega_rad_s: f64,
    /// Damping ratio zeta_n (structural; process damping is added per depth).
    pub damping_ratio: f64,
    /// Mass-normalized shape phi_n over the two coordinates (1/sqrt(kg)).
    pub shape: [f64; 2],
    /// Receptance numerator (n_0, n_1 in s) of a non-proportional mode
    /// ([`chatter_dynamics::model::complex_mode_numerator`]); (1, 0) for a real mode.
    pub numerator: (f64, f64),
}

/// The structure and the averaged cutting forces of a zero-order problem.
#[derive(Debug, Clone, PartialEq)]
pub struct OrientedSystem {
    modes: Vec<ModalTerm>,
    directional_n_per_m2: [[f64; 2]; 2],
    /// Residual terms of the direct receptances (`chatter_dynamics::ResidualTerms`).
    residuals: [ResidualTerms; 2],
    /// Whether a mode is non-proportional or a residual term is set: the general receptance
    /// (the tables' hot loop skips both otherwise).
    general: bool,
}

/// Process damping folded into the modal damping ratios at one depth: zeta_n + b s_n.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AddedDamping<'a> {
    /// s_n = d zeta_n / d b per mode (1/m); empty for none.
    pub slopes_per_m: &'a [f64],
    /// b (m).
    pub depth_m: f64,
}

impl AddedDamping<'_> {
    /// No process damping.
    pub const NONE: AddedDamping<'static> = AddedDamping {
        slopes_per_m: &[],
        depth_m: 0.0,
    };

    /// The damping ratio of mode `n`, or None where the added damping takes it to 1 (no finite
    /// fixed point there, as in [`crate::process_damping::process_damping_limiting_depth`]).
    fn damping_ratio(&self, n: usize, mode: &ModalTerm) -> Option<f64> {
        let slope = self.slopes_per_m.get(n).copied().unwrap_or(0.0);
        let zeta = mode.damping_ratio + self.depth_m * slope;
        (slope <= 0.0 || zeta < 1.0).then_some(zeta)
    }
}

/// The eigenvalue pair of A_0 G(i w) at one frequency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct EigenPair(pub [Complex64; 2]);

/// A point of a lobe: the phase eps in (0, 2 pi) and the depth b (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LobePhase {
    pub eps: f64,
    pub depth_m: f64,
}

impl EigenPair {
    /// The pair ordered to continue `previous` (the sum of distances is the smaller one).
    pub fn matched(self, previous: &EigenPair) -> Self {
        let ([a, b], [p, q]) = (self.0, previous.0);
        if (b - p).norm_sqr() + (a - q).norm_sqr() < (a - p).norm_sqr() + (b - q).norm_sqr() {
            Self([b, a])
        } else {
            self
        }
    }

    /// The eigenvalue closest to `reference`.
    pub fn closest(&self, reference: Complex64) -> usize {
        let [a, b] = self.0;
        usize::from((b - reference).norm_sqr() < (a - reference).norm_sqr())
    }

    /// Whether eigenvalue `branch` has a real part negative beyond rounding.
    pub fn is_lobe(&self, branch: usize) -> bool {
        let re = self.0[branch].re;
        re < 0.0 && re * re > ROUNDING * ROUNDING * (self.0[0].norm_sqr() + self.0[1].norm_sqr())
    }

    /// The lobe point of eigenvalue `branch`, or None where it is not a lobe
    /// ([`Self::is_lobe`]).
    pub fn lobe(&self, branch: usize) -> Option<LobePhase> {
        let l = self.0[branch];
        self.is_lobe(branch).then(|| {
            // 2 arg - pi lies in (-3 pi, pi]: one turn of 4 pi brings it to [0, 4 pi)
            let e = 2.0 * l.arg() - PI;
            LobePhase {
                eps: if e < 0.0 { e + 4.0 * PI } else { e },
                depth_m: -0.5 / l.re,
            }
        })
    }
}

impl ModalTerm {
    fn validate(&self) -> Result<()> {
        if !(self.omega_rad_s.is_finite() && self.omega_rad_s > 0.0) {
            return invalid("omega_rad_s", self.omega_rad_s, "a natural frequency > 0");
        }
        if !(self.damping_ratio.is_finite() && self.damping_ratio >= 0.0) {
            return invalid("damping_ratio", self.damping_ratio, "a damping ratio >= 0");
        }
        if let Some(&v) = self.shape.iter().find(|v| !v.is_finite()) {
            return invalid("shape", v, "a finite mode shape");
        }
        let (n0, n1) = self.numerator;
        if !(n0.is_finite() && n1.is_finite()) {
            return invalid("numerator", n0 + n1, "a finite receptance numerator");
        }
        if self.numerator != (1.0, 0.0) && self.damping_ratio == 0.0 {
            return invalid(
                "damping_ratio",
                0.0,
                "a damping ratio > 0 for a non-proportional mode",
            );
        }
        Ok(())
    }
}

impl OrientedSystem {
    /// A system from its modes and the averaged directional matrix A_0 (N/m^2; K_c for turning).
    pub fn new(modes: Vec<ModalTerm>, directional_n_per_m2: [[f64; 2]; 2]) -> Result<Self> {
        if modes.is_empty() {
            return invalid("modes", 0.0, "at least one mode");
        }
        for m in &modes {
            m.validate()?;
        }
        if let Some(&v) = directional_n_per_m2
            .iter()
            .flatten()
            .find(|v| !v.is_finite())
        {
            return invalid("directional_n_per_m2", v, "a finite directional matrix");
        }
        let general = modes.iter().any(|m| m.numerator != (1.0, 0.0));
        Ok(Self {
            modes,
            directional_n_per_m2,
            residuals: [ResidualTerms::default(); 2],
            general,
        })
    }

    /// The system of `model`: its modes and [`ModalModel::average_directional_matrix`]. A
    /// helical cutter's average is the straight one's (the helix only shifts the slices'
    /// phases). A variable-pitch or variable-helix cutter is refused by field name: its lobes
    /// are not one delay's ([`super::PreparedZeroOrder`] searches a variable pitch).
    pub fn from_model(model: &ModalModel) -> Result<Self> {
        if let Some(pitches_rad) = variable_pitch_of(model)? {
            return Err(crate::StabilityError::Unsupported {
                method: "zoa",
                reason: format!(
                    "operation.pitch_deg = {:?}: one delay per tooth; the lobe table is for even \
                     pitch (the prepared zero-order solver searches a variable pitch)",
                    pitches_rad
                        .iter()
                        .map(|p| p.to_degrees())
                        .collect::<Vec<_>>()
                ),
            });
        }
        Self::averaged(model)
    }

    /// The modes and the averaged directional matrix of `model`, whatever its pitch.
    pub(crate) fn averaged(model: &ModalModel) -> Result<Self> {
        let a = model.average_directional_matrix();
        let modes = model
            .modes()
            .iter()
            .map(|m| ModalTerm {
                omega_rad_s: m.omega_rad_s(),
                damping_ratio: m.damping_ratio(),
                shape: m.mass_normalized_shape(),
                numerator: m.receptance_numerator(),
            })
            .collect();
        let mut system = Self::new(modes, [[a[(0, 0)], a[(0, 1)]], [a[(1, 0)], a[(1, 1)]]])?;
        system.residuals = model.residuals();
        system.general |= system.residuals.iter().any(|r| !r.is_zero());
        Ok(system)
    }

    /// The modes.
    pub fn modes(&self) -> &[ModalTerm] {
        &self.modes
    }

    /// The natural frequencies (Hz), lowest and highest.
    pub(crate) fn frequency_span_hz(&self) -> (f64, f64) {
        self.modes
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), m| {
                let f = m.omega_rad_s / (2.0 * PI);
                (lo.min(f), hi.max(f))
            })
    }

    /// Eigenvalues of A_0 G(i w) with `added` process damping; None where a damping ratio
    /// raised by process damping reaches 1.
    pub(crate) fn eigenvalues(&self, omega_rad_s: f64, added: AddedDamping) -> Option<EigenPair> {
        let w = omega_rad_s;
        // symmetric receptance: g00, g01, g11
        let mut g = [Complex64::new(0.0, 0.0); 3];
        for (n, m) in self.modes.iter().enumerate() {
            let zeta = added.damping_ratio(n, m)?;
            let wn = m.omega_rad_s;
            // 1 / (w_n^2 - w^2 + 2 i zeta w_n w) with one division (the tables' hot loop)
            let (re, im) = (wn * wn - w * w, 2.0 * zeta * wn * w);
            let scale = 1.0 / (re * re + im * im);
            let mut inv = Complex64::new(re * scale, -im * scale);
            if self.general {
                inv *= Complex64::new(m.numerator.0, m.numerator.1 * w);
            }
            let [p, q] = m.shape;
            g[0] += inv * (p * p);
            g[1] += inv * (p * q);
            g[2] += inv * (q * q);
        }
        if self.general {
            let hz = w / (2.0 * PI);
            g[0] += self.residuals[0].receptance(hz);
            g[2] += self.residuals[1].receptance(hz);
        }
        let a = &self.directional_n_per_m2;
        let m00 = g[0] * a[0][0] + g[1] * a[0][1];
        let m01 = g[1] * a[0][0] + g[2] * a[0][1];
        let m10 = g[0] * a[1][0] + g[1] * a[1][1];
        let m11 = g[1] * a[1][0] + g[2] * a[1][1];
        let half_trace = 0.5 * (m00 + m11);
        let disc = principal_sqrt(half_trace * half_trace - (m00 * m11 - m01 * m10));
        Some(EigenPair([half_trace + disc, half_trace - disc]))
    }
}

impl OrientedSystem {
    /// The lobe at zero depth at delay `delay_s` (s), where undamped modes (zeta_n = 0) are
    /// destabilized by any cut; `slopes_per_m` are the process-damping slopes d zeta_n / d b
    /// (empty for none).
    ///
    /// At b = 0 an undamped mode has its roots on the imaginary axis, lambda = i w_n, and the
    /// zero-order characteristic equation has no crossing at finite frequency there (the
    /// eigenvalue of A_0 G is infinite), so the tabulated branches miss it. Its first-order
    /// shift with depth (perturbation of the modal equations
    /// q'' + diag(w_n^2) q = -b Phi^T A_0 Phi (q - q(t - tau)) - 2 b w_n diag(s_n) q') is
    /// d lambda / d b = eigenvalues of -(1 - e^{-i w_n tau}) / (2 i w_n) Phi^T A_0 Phi - w_n diag(s_n)
    /// over the undamped modes of one frequency (a cluster of equal frequencies is degenerate and
    /// is solved together). A positive real part means that any depth destabilizes the cut:
    /// the limiting depth is 0, with chatter at w_n. For a single mode without process damping
    /// the condition reads (phi^T A_0 phi) sin(w_n tau) < 0: half of every lobe interval, the
    /// limit of the lobes' flat bottoms, b_min = 2 zeta (1 + zeta) k / K, as zeta -> 0.
    pub(crate) fn zero_depth_lobe(&self, delay_s: f64, slopes_per_m: &[f64]) -> Option<Lobe> {
        if self.modes.iter().all(|m| m.damping_ratio != 0.0) {
            return None; // every query's common case, without allocating
        }
        let undamped: Vec<usize> = (0..self.modes.len())
            .filter(|&n| self.modes[n].damping_ratio == 0.0)
            .collect();
        let a = &self.directional_n_per_m2;
        let weight = |m: &ModalTerm, n: &ModalTerm| -> f64 {
            let [p, q] = m.shape;
            let [r, t] = n.shape;
            p * (a[0][0] * r + a[0][1] * t) + q * (a[1][0] * r + a[1][1] * t)
        };
        let mut lowest: Option<f64> = None;
        for (i, &n) in undamped.iter().enumerate() {
            let wn = self.modes[n].omega_rad_s;
            // each cluster once, from its first member
            if undamped[..i]
                .iter()
                .any(|&m| self.modes[m].omega_rad_s == wn)
            {
                continue;
            }
            let cluster: Vec<usize> = undamped[i..]
                .iter()
                .copied()
                .filter(|&m| self.modes[m].omega_rad_s == wn)
                .collect();
            let regenerative = (Complex64::new(1.0, 0.0)
                - Complex64::from_polar(1.0, -wn * delay_s))
                / Complex64::new(0.0, 2.0 * wn);
            let k = cluster.len();
            let shift = nalgebra::DMatrix::<Complex64>::from_fn(k, k, |r, c| {
                let (mr, mc) = (&self.modes[cluster[r]], &self.modes[cluster[c]]);
                let damping = if r == c {
                    wn * slopes_per_m.get(cluster[r]).copied().unwrap_or(0.0)
                } else {
                    0.0
                };
                -regenerative * weight(mr, mc) - damping
            });
            let scale = shift.iter().map(|z| z.norm()).fold(0.0, f64::max);
            let growth = match k {
                1 => shift[(0, 0)].re,
                _ => nalgebra::Schur::new(shift)
                    .eigenvalues()
                    .map_or(f64::NEG_INFINITY, |e| {
                        e.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max)
                    }),
            };
            if growth > ROUNDING * scale {
                lowest = Some(lowest.map_or(wn, |w: f64| w.min(wn)));
            }
        }
        lowest.map(|wn| {
            let chatter_hz = wn / (2.0 * PI);
            Lobe {
                depth_m: 0.0,
                chatter_hz,
                index: (chatter_hz * delay_s).floor() as usize,
            }
        })
    }
}

/// The principal square root of `z` in Cartesian form, sqrt(z) = t + i b / (2 t) with
/// t = sqrt((|z| + Re z) / 2) (mirrored for Re z < 0), which avoids the polar form's
/// trigonometric functions.
pub(crate) fn principal_sqrt(z: Complex64) -> Complex64 {
    // |z| without hypot's care for overflow, unless it is needed
    let modulus = match z.norm_sqr().sqrt() {
        m if m.is_finite() && m > f64::MIN_POSITIVE => m,
        _ => z.re.hypot(z.im),
    };
    if modulus == 0.0 {
        return Complex64::new(0.0, 0.0);
    }
    let t = (0.5 * (modulus + z.re.abs())).sqrt();
    if z.re >= 0.0 {
        Complex64::new(t, 0.5 * z.im / t)
    } else {
        Complex64::new(0.5 * z.im.abs() / t, t.copysign(z.im))
    }
}

/// The pitches (rad) of a variable-pitch cutter, for the zero-order method's variable-pitch
/// search (Altintas, Engin and Budak 1999, [`super::variable_pitch_lobe`]); `None` for even
/// pitch. Refused by field name: a variable helix (its delays vary along the axis, which the
/// averaged equation does not hold) and process damping with a variable pitch.
pub(crate) fn variable_pitch_of(model: &ModalModel) -> Result<Option<Vec<f64>>> {
    let chatter_dynamics::Operation::Milling(m) = model.operation() else {
        return Ok(None);
    };
    if m.is_variable_helix() {
        return Err(crate::StabilityError::Unsupported {
            method: "zoa",
            reason: format!(
                "operation.helix_deg = {:?} is a variable-helix cutter (the delay varies along \
                 the axis); the zero-order method averages over one delay per tooth: use fdm or \
                 sdm",
                m.helix_per_tooth_deg().unwrap_or_default()
            ),
        });
    }
    if !m.is_variable_pitch() {
        return Ok(None);
    }
    if model.process_damping_n_per_m().is_some_and(|c| c > 0.0) {
        return Err(crate::StabilityError::Unsupported {
            method: "zoa",
            reason: format!(
                "operation.pitch_deg = {:?} with process_damping: the zero-order variable-pitch \
                 search has no process damping; use fdm or sdm",
                m.pitch_deg().unwrap_or_default()
            ),
        });
    }
    Ok(Some((0..m.teeth()).map(|j| m.tooth_pitch_rad(j)).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    #[test]
    fn eigenvalues_of_a_single_direction_are_the_oriented_frf() {
        // turning: A_0 = K_c maps the feed coordinate only, so one eigenvalue is zero (not a
        // lobe)
        let model = examples::ahmadi_2022_turning();
        let system = OrientedSystem::from_model(&model).unwrap();
        let a = model.average_directional_matrix();
        let f = 2400.0;
        let pair = system
            .eigenvalues(2.0 * PI * f, AddedDamping::NONE)
            .unwrap();
        // A_0 has rank one, so the other eigenvalue is trace(A_0 G)
        let g = model.receptance_matrix(f);
        let expected = (0..2)
            .flat_map(|r| (0..2).map(move |k| (r, k)))
            .map(|(r, k)| g[k][r] * a[(r, k)])
            .sum::<Complex64>();
        let k = pair.closest(expected);
        assert!((pair.0[k] - expected).norm() < 1e-12 * expected.norm());
        assert!(pair.lobe(1 - k).is_none());
    }

    #[test]
    fn principal_square_root_matches_the_polar_form() {
        for (re, im) in [
            (4.0, 0.0),
            (-4.0, 0.0),
            (-4.0, -0.0),
            (3.0, 4.0),
            (-3.0, 4.0),
            (-3.0, -4.0),
            (1e-300, -2e-300),
            (0.0, 0.0),
        ] {
            let z = Complex64::new(re, im);
            let (ours, polar) = (principal_sqrt(z), z.sqrt());
            assert!(
                (ours - polar).norm() <= 1e-15 * polar.norm(),
                "{z}: {ours} vs {polar}"
            );
        }
    }

    #[test]
    fn invalid_terms_are_rejected() {
        let good = ModalTerm {
            omega_rad_s: 1000.0,
            damping_ratio: 0.02,
            shape: [1.0, 0.0],
            numerator: (1.0, 0.0),
        };
        let a = [[1e9, 0.0], [0.0, 0.0]];
        assert!(OrientedSystem::new(vec![good], a).is_ok());
        assert!(OrientedSystem::new(vec![], a).is_err());
        for bad in [
            ModalTerm {
                omega_rad_s: -1.0,
                ..good
            },
            ModalTerm {
                damping_ratio: f64::NAN,
                ..good
            },
            ModalTerm {
                shape: [f64::INFINITY, 0.0],
                ..good
            },
            ModalTerm {
                numerator: (0.9, 1e-5),
                damping_ratio: 0.0,
                ..good
            },
        ] {
            assert!(OrientedSystem::new(vec![bad], a).is_err());
        }
        assert!(OrientedSystem::new(vec![good], [[f64::NAN, 0.0], [0.0, 0.0]]).is_err());
    }
}
