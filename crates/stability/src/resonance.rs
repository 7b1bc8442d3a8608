//! The resonance of a stable cut: the largest Floquet multiplier that an identification can see.
//!
//! With process damping at low speed the dominant roots of the turning delay equation are those
//! of slow surface regeneration (see [`crate::frequency_domain::dominant_pole`]): a real root
//! and a chain near lambda + i 2 pi k / tau, whose multipliers cluster near one real positive
//! value. The tool follows the decaying surface wave quasi-statically, below the structural
//! modes and close to spindle harmonics, the frequencies that an operational modal analysis
//! removes as forced lines. The resonance it identifies is the largest multiplier whose
//! frequency keeps [`HARMONIC_CLEARANCE`] of the spindle frequency from every spindle harmonic
//! (|arg mu| >= 2 pi [`HARMONIC_CLEARANCE`]) and lies above [`SUBSTRUCTURAL`] times the lowest
//! natural frequency (where the root search of the characteristic equation starts, see
//! [`crate::frequency_domain::dominant_resonance_pole`]).
//!
//! [`Monodromy::dominant_eigenpair_where`] finds it by Wielandt deflation. For a real
//! invariant subspace V (the eigenvector of a real multiplier, or the real and imaginary parts of
//! a complex one, U V = V B) with left subspace W, the operator U' x = U x - V B (W^T V)^-1 W^T x
//! maps V to zero and keeps every other eigenpair of U (W^T u = 0 for the other eigenvectors u);
//! repeated while the dominant multiplier of the deflated operator is rejected.

use crate::error::{Result, StabilityError};
use crate::krylov::{KRYLOV_TOL, robust_eigenpair};
use crate::monodromy::{Discretization, Monodromy};
use crate::multiplier::DominantMultiplier;
use chatter_dynamics::ModalModel;
use nalgebra::{Complex, DMatrix, Matrix2};
use std::f64::consts::PI;

/// Closest approach of a resonance to a spindle harmonic, as a fraction of the spindle
/// frequency (2 %: the real root and the first members of the chain of slow surface
/// regeneration sit within a fraction of a percent; members further up drift off the
/// harmonics, 2.5-9 % at 320 Hz on the gap proving ground's lathe at 1200 rpm, and are left out
/// by [`SUBSTRUCTURAL`] instead).
pub const HARMONIC_CLEARANCE: f64 = 0.02;

/// Lowest resonance frequency, as a fraction of the lowest natural frequency.
pub const SUBSTRUCTURAL: f64 = 0.85;

/// The lowest frequency of a resonance (Hz): [`SUBSTRUCTURAL`] times the lowest natural
/// frequency of `model` (infinite for a model without modes).
pub fn resonance_floor_hz(model: &ModalModel) -> f64 {
    SUBSTRUCTURAL
        * model
            .modes()
            .iter()
            .map(|m| m.frequency_hz())
            .fold(f64::INFINITY, f64::min)
}

/// Multipliers (real ones or conjugate pairs) deflated at most before giving up.
const MAX_DEFLATED: usize = 40;

/// Whether a multiplier lies within [`HARMONIC_CLEARANCE`] of a spindle harmonic.
pub fn near_harmonic(mu: Complex<f64>) -> bool {
    mu.arg().abs() < 2.0 * PI * HARMONIC_CLEARANCE
}

/// One deflated invariant subspace: right and left bases V, W (columns of length d, one or two)
/// and C = B (W^T V)^-1.
struct Deflated {
    right: Vec<Vec<f64>>,
    left: Vec<Vec<f64>>,
    c: Matrix2<f64>,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// out -= V C W^T x, or for the transpose out -= W C^T V^T x.
fn deflate(deflated: &[Deflated], x: &[f64], out: &mut [f64], transpose: bool) {
    for d in deflated {
        let (first, second, c) = if transpose {
            (&d.right, &d.left, d.c.transpose())
        } else {
            (&d.left, &d.right, d.c)
        };
        let r = first.len();
        let p: Vec<f64> = first.iter().map(|f| dot(f, x)).collect();
        for (i, s) in second.iter().enumerate() {
            let coefficient: f64 = (0..r).map(|j| c[(i, j)] * p[j]).sum();
            for (o, v) in out.iter_mut().zip(s) {
                *o -= coefficient * v;
            }
        }
    }
}

fn deflated_dense(op: &Monodromy, deflated: &[Deflated], transpose: bool) -> DMatrix<f64> {
    let mut a = op.dense();
    let n = a.nrows();
    for d in deflated {
        let r = d.right.len();
        for i in 0..r {
            for j in 0..r {
                let c = d.c[(i, j)];
                a -= DMatrix::from_fn(n, n, |p, q| c * d.right[i][p] * d.left[j][q]);
            }
        }
    }
    if transpose { a.transpose() } else { a }
}

/// The real basis of an eigenvector's span: [v] for a real multiplier (rotated real), else
/// [Re v, Im v].
fn real_basis(v: &[Complex<f64>], real: bool) -> Vec<Vec<f64>> {
    if real {
        let pivot = v
            .iter()
            .copied()
            .max_by(|a, b| a.norm().total_cmp(&b.norm()))
            .unwrap_or(Complex::new(1.0, 0.0));
        let rotation = if pivot.norm() > 0.0 {
            pivot.conj() / pivot.norm()
        } else {
            Complex::new(1.0, 0.0)
        };
        vec![v.iter().map(|x| (x * rotation).re).collect()]
    } else {
        vec![
            v.iter().map(|x| x.re).collect(),
            v.iter().map(|x| x.im).collect(),
        ]
    }
}

fn failed(detail: String) -> StabilityError {
    StabilityError::NoConvergence {
        solver: "Wielandt deflation",
        detail,
    }
}

impl Monodromy {
    /// What `accept` makes of the eigenpair of largest modulus it takes (it returns `None` for
    /// the ones it rejects), by deflation of the larger ones (module docs). An error when the
    /// solver fails, or when more than `MAX_DEFLATED` (40) rejected multipliers lie above it.
    pub fn dominant_eigenpair_where<T>(
        &self,
        accept: impl Fn(Complex<f64>, &[Complex<f64>]) -> Option<T>,
    ) -> Result<T> {
        let d = self.dimension();
        let mut deflated: Vec<Deflated> = Vec::new();
        loop {
            let apply = |x: &[f64], out: &mut [f64]| {
                self.apply(x, out);
                deflate(&deflated, x, out, false);
            };
            let (mu, right) = robust_eigenpair(
                apply,
                d,
                || deflated_dense(self, &deflated, false),
                None,
                KRYLOV_TOL,
            )?;
            if let Some(accepted) = accept(mu, &right) {
                return Ok(accepted);
            }
            if deflated.len() == MAX_DEFLATED {
                return Err(failed(format!(
                    "{MAX_DEFLATED} rejected multipliers above every other (last {mu:.4})"
                )));
            }
            let apply_transpose = |x: &[f64], out: &mut [f64]| {
                self.apply_transpose(x, out);
                deflate(&deflated, x, out, true);
            };
            let (_, left) = robust_eigenpair(
                apply_transpose,
                d,
                || deflated_dense(self, &deflated, true),
                None,
                KRYLOV_TOL,
            )?;
            let real = mu.im.abs() <= 1e-10 * mu.norm();
            let (v, w) = (real_basis(&right, real), real_basis(&left, real));
            // B of U V = V B: [mu] or [[a, b], [-b, a]] for mu = a + i b and V = [Re v, Im v]
            let r = v.len();
            let b = if real {
                Matrix2::new(mu.re, 0.0, 0.0, 0.0)
            } else {
                Matrix2::new(mu.re, mu.im, -mu.im, mu.re)
            };
            let mut wv = Matrix2::identity();
            for i in 0..r {
                for j in 0..r {
                    wv[(i, j)] = dot(&w[i], &v[j]);
                }
            }
            let inverse = wv
                .try_inverse()
                .filter(|m| m.iter().all(|x| x.is_finite()))
                .ok_or_else(|| failed(format!("defective multiplier {mu:.4}")))?;
            let mut c = b * inverse;
            if real {
                // only the (0, 0) entry acts on one column
                c[(0, 1)] = 0.0;
                c[(1, 0)] = 0.0;
                c[(1, 1)] = 0.0;
            }
            deflated.push(Deflated {
                right: v,
                left: w,
                c,
            });
        }
    }
}

impl Discretization {
    /// The resonance at a cut (module docs) and its frequency (Hz), read off its eigenfunction
    /// as [`crate::StabilitySolver::chatter_frequency_hz`] does for the dominant multiplier: the
    /// pole an identification of the (stable) cut sees.
    pub fn resonance_frequency_hz(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)> {
        let op = self.monodromy(model, speed_rpm, depth_m)?;
        let floor_hz = resonance_floor_hz(model);
        op.dominant_eigenpair_where(|mu, vector| {
            if near_harmonic(mu) {
                return None;
            }
            let (multiplier, f) = op.multiplier_and_frequency(model, mu, vector);
            (f >= floor_hz).then_some((multiplier, f))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monodromy::steps;
    use chatter_dynamics::examples;

    /// Against the dense eigenvalues: the largest eigenvalue away from the harmonics, an
    /// eigenvector of the undeflated operator (residual 1e-8), and a real dominant multiplier
    /// deflated in at least one case.
    #[test]
    fn deflation_finds_the_largest_eigenvalue_off_the_harmonics() {
        // the proving ground's lathe with the process damping of its 2x case
        let lathe = examples::proving_ground_lathe(Some(1.76e6));
        let flexure = examples::process_damping_flexure(Some(2.5e5));
        let mut deflated = 0;
        for (model, rpm, depth_m) in [
            (&lathe, 1200.0, 15e-3),
            (&lathe, 1200.0, 30e-3),
            (&flexure, 300.0, 6e-3),
        ] {
            let op = Discretization::semi()
                .with_steps(steps::<60>())
                .monodromy(model, rpm, depth_m)
                .unwrap();
            let values = op.dense().complex_eigenvalues();
            let expected = values
                .iter()
                .filter(|v| !near_harmonic(**v))
                .max_by(|a, b| a.norm().total_cmp(&b.norm()))
                .unwrap();
            let largest = values
                .iter()
                .max_by(|a, b| a.norm().total_cmp(&b.norm()))
                .unwrap();
            deflated += usize::from(near_harmonic(*largest));
            let (mu, vector) = op
                .dominant_eigenpair_where(|mu, vector| {
                    (!near_harmonic(mu)).then(|| (mu, vector.to_vec()))
                })
                .unwrap();
            assert!(
                (mu.norm() - expected.norm()).abs() < 1e-9,
                "{mu} vs {expected}"
            );
            // U u = mu u for the returned vector
            let re: Vec<f64> = vector.iter().map(|c| c.re).collect();
            let im: Vec<f64> = vector.iter().map(|c| c.im).collect();
            let (mut ure, mut uim) = (vec![0.0; re.len()], vec![0.0; re.len()]);
            op.apply(&re, &mut ure);
            op.apply(&im, &mut uim);
            let residual: f64 = (0..re.len())
                .map(|i| (Complex::new(ure[i], uim[i]) - mu * vector[i]).norm_sqr())
                .sum::<f64>()
                .sqrt();
            let size: f64 = vector.iter().map(|c| c.norm_sqr()).sum::<f64>().sqrt();
            assert!(residual < 1e-8 * size, "{residual}");
        }
        assert!(deflated >= 2, "{deflated} cases needed a deflation");
    }
}
