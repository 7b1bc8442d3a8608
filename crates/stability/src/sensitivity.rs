//! Gradient and Hessian of the dominant eigenvalue of the transition matrix with respect to the
//! named perturbations theta (Ahmadi 2022, seed 000, Eq. 15-16).
//!
//! With right and left eigenvectors u, v of the dominant eigenvalue mu, scaled so v^T u = 1,
//!
//! d mu / d theta_k = v^T G_k u                                                    (Eq. 15)
//! d2 mu / d theta_i d theta_j = v^T G_ij u + v^T G_i w_j + v^T G_j w_i               (Eq. 16)
//!
//! where w_j = sum_{r != m} u_r (v_r^T G_j u) / (mu - mu_r) is the sum of Eq. 16 over the other
//! eigenpairs. It is computed without them as the reduced resolvent: the solution of
//! (mu I - G) w_j = (I - u v^T) G_j u with v^T w_j = 0, by GMRES on the projected operator
//! (I - u v^T)(mu I - G) (the projector commutes with G because u, v are eigenvectors).
//!
//! Nothing of the monodromy's dimension (2N + N M, about a thousand for the seed-000 turning
//! case) is formed densely: u and v come from restarted Arnoldi on U and U^T, and G_k x, G_ij x
//! are central differences of matrix-free products with the operators at theta +- h e_k and
//! theta +- h/2 e_k (h = [`THETA_STEP`]), Richardson-extrapolated to truncation O(h^4): a frequency
//! parameter turns the phase of the highest mode over the delay, omega tau ~ 100 rad for the
//! seed-000 case, so the O(h^2) term of a plain central difference, (h omega tau)^2 / 6, would
//! reach 1e-4 relative; round-off stays ~ 1e-16 / (h/2)^2 ~ 1e-8. Mixed second derivatives use
//! the four-point formula at h.

use crate::error::{Result, StabilityError};
use crate::monodromy::{Discretization, Monodromy};
use chatter_dynamics::{ModalModel, Parameter};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// Finite-difference step in theta.
pub const THETA_STEP: f64 = 1e-4;
/// Relative residual at which GMRES stops.
const GMRES_TOL: f64 = 1e-11;
/// Krylov dimension of one GMRES cycle.
const GMRES_DIM: usize = 40;
/// Maximum GMRES cycles.
const GMRES_CYCLES: usize = 10;

/// The dominant eigenvalue with its derivatives at theta = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct EigenvalueSensitivity {
    /// mu(0), upper half-plane representative.
    pub mu: Complex64,
    /// Eq. 15, one entry per parameter.
    pub gradient: DVector<Complex64>,
    /// Eq. 16, symmetric.
    pub hessian: DMatrix<Complex64>,
}

type CVec = Vec<Complex64>;

/// G x for a complex x (two real products).
fn apply_complex(op: &Monodromy, x: &[Complex64]) -> CVec {
    let d = x.len();
    let (re, im): (Vec<f64>, Vec<f64>) = x.iter().map(|z| (z.re, z.im)).unzip();
    let (mut a, mut b) = (vec![0.0; d], vec![0.0; d]);
    op.apply(&re, &mut a);
    op.apply(&im, &mut b);
    a.iter()
        .zip(&b)
        .map(|(x, y)| Complex64::new(*x, *y))
        .collect()
}

/// a^T b (no conjugation: the bilinear form of Eq. 15-16).
fn dot(a: &[Complex64], b: &[Complex64]) -> Complex64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// a^H b.
fn inner(a: &[Complex64], b: &[Complex64]) -> Complex64 {
    a.iter().zip(b).map(|(x, y)| x.conj() * y).sum()
}

fn norm(a: &[Complex64]) -> f64 {
    a.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt()
}

/// mu (upper half-plane) with right and left eigenvectors scaled so v^T u = 1.
fn eigen(op: &Monodromy) -> Result<(Complex64, CVec, CVec)> {
    let upper = |(mu, x): (Complex64, CVec)| {
        if mu.im < 0.0 {
            (mu.conj(), x.iter().map(|z| z.conj()).collect())
        } else {
            (mu, x)
        }
    };
    let (mu, u) = upper(op.dominant_eigenpair()?);
    let (mu_left, v) = upper(op.dominant_left_eigenpair()?);
    let scale = dot(&v, &u);
    if (mu_left - mu).norm() > 1e-6 * mu.norm() || scale.norm() < 1e-300 {
        return Err(StabilityError::NoConvergence {
            solver: "eigenvalue sensitivity",
            detail: format!(
                "left ({mu_left}) and right ({mu}) dominant eigenvalues differ: the dominant \
                 eigenvalue is not simple here"
            ),
        });
    }
    Ok((mu, u, v.iter().map(|z| z / scale).collect()))
}

/// The reduced resolvent: w with (mu I - G) w = r and v^T w = 0, for r with v^T r = 0, by
/// restarted GMRES on x -> (I - u v^T)(mu x - G x).
fn reduced_resolvent(
    op: &Monodromy,
    mu: Complex64,
    u: &[Complex64],
    v: &[Complex64],
    r: &[Complex64],
) -> Result<CVec> {
    let d = r.len();
    let project = |mut x: CVec| {
        let c = dot(v, &x);
        for (xi, ui) in x.iter_mut().zip(u) {
            *xi -= c * ui;
        }
        x
    };
    let operator = |x: &[Complex64]| {
        let gx = apply_complex(op, x);
        project(x.iter().zip(&gx).map(|(a, b)| mu * a - b).collect())
    };
    let r_norm = norm(r);
    let mut w = vec![Complex64::new(0.0, 0.0); d];
    if r_norm == 0.0 {
        return Ok(w);
    }
    let k = GMRES_DIM.min(d);
    for _ in 0..GMRES_CYCLES {
        let aw = operator(&w);
        let res: CVec = r.iter().zip(&aw).map(|(a, b)| a - b).collect();
        let beta = norm(&res);
        if beta <= GMRES_TOL * r_norm {
            return Ok(w);
        }
        let mut basis: Vec<CVec> = vec![res.iter().map(|z| z / beta).collect()];
        let mut h = DMatrix::<Complex64>::zeros(k + 1, k);
        // Givens rotations (c, s) and the rotated right-hand side g
        let mut rot: Vec<(Complex64, Complex64)> = Vec::with_capacity(k);
        let mut g = vec![Complex64::new(0.0, 0.0); k + 1];
        g[0] = Complex64::new(beta, 0.0);
        let mut used = 0;
        for j in 0..k {
            let mut q = operator(&basis[j]);
            for _ in 0..2 {
                for (i, b) in basis.iter().enumerate() {
                    let c = inner(b, &q);
                    h[(i, j)] += c;
                    for (qx, bx) in q.iter_mut().zip(b) {
                        *qx -= c * bx;
                    }
                }
            }
            let hn = norm(&q);
            h[(j + 1, j)] = Complex64::new(hn, 0.0);
            for (i, &(c, s)) in rot.iter().enumerate() {
                let (a, b) = (h[(i, j)], h[(i + 1, j)]);
                h[(i, j)] = c.conj() * a + s.conj() * b;
                h[(i + 1, j)] = -s * a + c * b;
            }
            let (a, b) = (h[(j, j)], h[(j + 1, j)]);
            let rr = (a.norm_sqr() + b.norm_sqr()).sqrt();
            let (c, s) = if rr == 0.0 {
                (Complex64::new(1.0, 0.0), Complex64::new(0.0, 0.0))
            } else {
                (a / rr, b / rr)
            };
            h[(j, j)] = Complex64::new(rr, 0.0);
            h[(j + 1, j)] = Complex64::new(0.0, 0.0);
            g[j + 1] = -s * g[j];
            g[j] = c.conj() * g[j];
            rot.push((c, s));
            used = j + 1;
            if g[j + 1].norm() <= GMRES_TOL * r_norm || hn < 1e-300 {
                break;
            }
            basis.push(q.iter().map(|z| z / hn).collect());
        }
        // back substitution of the triangular least-squares system
        let mut y = vec![Complex64::new(0.0, 0.0); used];
        for i in (0..used).rev() {
            let mut t = g[i];
            for (l, yl) in y.iter().enumerate().skip(i + 1) {
                t -= h[(i, l)] * yl;
            }
            y[i] = t / h[(i, i)];
        }
        for (yi, b) in y.iter().zip(&basis) {
            for (wx, bx) in w.iter_mut().zip(b) {
                *wx += yi * bx;
            }
        }
    }
    let aw = operator(&w);
    let res = norm(&r.iter().zip(&aw).map(|(a, b)| a - b).collect::<CVec>());
    if res <= 1e3 * GMRES_TOL * r_norm {
        return Ok(w);
    }
    Err(StabilityError::NoConvergence {
        solver: "reduced resolvent (GMRES)",
        detail: format!("relative residual {:.1e}", res / r_norm),
    })
}

/// Gradient and Hessian of the dominant eigenvalue (Eq. 15-16) at a cutting condition.
pub fn eigenvalue_sensitivity(
    method: Discretization,
    model: &ModalModel,
    parameters: &[Parameter],
    speed_rpm: f64,
    depth_m: f64,
) -> Result<EigenvalueSensitivity> {
    // one grid for the nominal and every perturbed model
    let method = method.resolved(model, speed_rpm);
    let p = parameters.len();
    let h = THETA_STEP;
    let operator = |shifts: &[(usize, f64)]| -> Result<Monodromy> {
        let mut theta = vec![0.0; p];
        for &(i, s) in shifts {
            theta[i] += s;
        }
        let m = model.perturbed(parameters, &theta)?;
        method.monodromy(&m, speed_rpm, depth_m)
    };
    let g0 = operator(&[])?;
    let (mu, u, v) = eigen(&g0)?;
    let plus = (0..p)
        .map(|i| operator(&[(i, h)]))
        .collect::<Result<Vec<_>>>()?;
    let minus = (0..p)
        .map(|i| operator(&[(i, -h)]))
        .collect::<Result<Vec<_>>>()?;
    let plus_half = (0..p)
        .map(|i| operator(&[(i, 0.5 * h)]))
        .collect::<Result<Vec<_>>>()?;
    let minus_half = (0..p)
        .map(|i| operator(&[(i, -0.5 * h)]))
        .collect::<Result<Vec<_>>>()?;
    // G_k x by central differences at h and h/2, Richardson-extrapolated:
    // [8 (U(h/2) - U(-h/2)) - (U(h) - U(-h))] x / (6 h)
    let first = |k: usize, x: &[Complex64]| -> CVec {
        let (a, b) = (apply_complex(&plus[k], x), apply_complex(&minus[k], x));
        let (c, d) = (
            apply_complex(&plus_half[k], x),
            apply_complex(&minus_half[k], x),
        );
        (0..x.len())
            .map(|r| (8.0 * (c[r] - d[r]) - (a[r] - b[r])) / (6.0 * h))
            .collect()
    };
    let gu: Vec<CVec> = (0..p).map(|k| first(k, &u)).collect();
    let gradient = DVector::from_fn(p, |k, _| dot(&v, &gu[k]));
    let w = gu
        .iter()
        .map(|gj| {
            let c = dot(&v, gj);
            let rhs: CVec = gj.iter().zip(&u).map(|(a, b)| a - c * b).collect();
            reduced_resolvent(&g0, mu, &u, &v, &rhs)
        })
        .collect::<Result<Vec<_>>>()?;
    let u0 = apply_complex(&g0, &u);
    let mut hessian = DMatrix::zeros(p, p);
    for i in 0..p {
        for j in i..p {
            let gij_u: CVec = if i == j {
                // second differences at h and h/2, Richardson-extrapolated:
                // [16 (U(h/2) - 2 U + U(-h/2)) - (U(h) - 2 U + U(-h))] u / (3 h^2)
                let (a, b) = (apply_complex(&plus[i], &u), apply_complex(&minus[i], &u));
                let (c, d) = (
                    apply_complex(&plus_half[i], &u),
                    apply_complex(&minus_half[i], &u),
                );
                (0..u.len())
                    .map(|r| {
                        (16.0 * (c[r] - 2.0 * u0[r] + d[r]) - (a[r] - 2.0 * u0[r] + b[r]))
                            / (3.0 * h * h)
                    })
                    .collect()
            } else {
                let mut acc = vec![Complex64::new(0.0, 0.0); u.len()];
                for (si, sj, sign) in [(h, h, 1.0), (h, -h, -1.0), (-h, h, -1.0), (-h, -h, 1.0)] {
                    let y = apply_complex(&operator(&[(i, si), (j, sj)])?, &u);
                    for (a, b) in acc.iter_mut().zip(&y) {
                        *a += sign * b / (4.0 * h * h);
                    }
                }
                acc
            };
            let value = dot(&v, &gij_u) + dot(&v, &first(i, &w[j])) + dot(&v, &first(j, &w[i]));
            hessian[(i, j)] = value;
            hessian[(j, i)] = value;
        }
    }
    Ok(EigenvalueSensitivity {
        mu,
        gradient,
        hessian,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monodromy::steps;
    use chatter_dynamics::examples;

    fn mu_at(
        method: Discretization,
        model: &ModalModel,
        params: &[Parameter],
        theta: &[f64],
        rpm: f64,
        b: f64,
    ) -> Complex64 {
        let m = model.perturbed(params, theta).unwrap();
        let mu = method
            .monodromy(&m, rpm, b)
            .unwrap()
            .dominant_eigenvalue()
            .unwrap();
        if mu.im < 0.0 { mu.conj() } else { mu }
    }

    /// Eq. 15-16 against finite differences of the eigenvalue itself: gradient within 1e-4 of the
    /// largest entry (the reference is limited by the Arnoldi tolerance over the step, ~1e-5) and
    /// Hessian within 2e-3 (second differences of mu with step 1e-3).
    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let model = examples::ahmadi_2022_turning();
        let params: Vec<Parameter> = ["theta_omega_2", "theta_zeta_2", "theta_phi_2"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let method = Discretization::full().with_steps(steps::<60>());
        let (rpm, b) = (7150.0, 2.0e-3);
        let s = eigenvalue_sensitivity(method, &model, &params, rpm, b).unwrap();
        let hs = 1e-3;
        let gmax = s.gradient.iter().map(|z| z.norm()).fold(0.0, f64::max);
        let hmax = s.hessian.iter().map(|z| z.norm()).fold(0.0, f64::max);
        for i in 0..3 {
            let mut tp = [0.0; 3];
            let mut tm = [0.0; 3];
            tp[i] = 1e-6;
            tm[i] = -1e-6;
            let fd = (mu_at(method, &model, &params, &tp, rpm, b)
                - mu_at(method, &model, &params, &tm, rpm, b))
                / 2e-6;
            assert!(
                (fd - s.gradient[i]).norm() < 1e-4 * gmax,
                "gradient {i}: {fd} vs {}",
                s.gradient[i]
            );
            let mut tp = [0.0; 3];
            let mut tm = [0.0; 3];
            tp[i] = hs;
            tm[i] = -hs;
            let mu0 = mu_at(method, &model, &params, &[0.0; 3], rpm, b);
            let fd2 = (mu_at(method, &model, &params, &tp, rpm, b) - mu0 * 2.0
                + mu_at(method, &model, &params, &tm, rpm, b))
                / (hs * hs);
            assert!(
                (fd2 - s.hessian[(i, i)]).norm() < 2e-3 * hmax,
                "hessian {i}{i}: {fd2} vs {}",
                s.hessian[(i, i)]
            );
        }
        // one mixed entry
        let f = |a: f64, c: f64| mu_at(method, &model, &params, &[a, c, 0.0], rpm, b);
        let fd01 = (f(hs, hs) - f(hs, -hs) - f(-hs, hs) + f(-hs, -hs)) / (4.0 * hs * hs);
        assert!(
            (fd01 - s.hessian[(0, 1)]).norm() < 2e-3 * hmax,
            "hessian 01: {fd01} vs {}",
            s.hessian[(0, 1)]
        );
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(6))]
        /// Eq. 15 against central differences of mu over random turning conditions where the
        /// dominant eigenvalue is separated (2e-4 of the gradient's largest entry).
        #[test]
        fn gradient_property(rpm in 6900.0..7600.0f64, mm in 0.5..2.5f64) {
            let model = examples::ahmadi_2022_turning();
            let params: Vec<Parameter> = ["theta_omega_2", "theta_zeta_2", "theta_phi_2"]
                .iter()
                .map(|s| s.parse().unwrap())
                .collect();
            let method = Discretization::full().with_steps(steps::<40>());
            let b = mm * 1e-3;
            // the derivative of the dominant eigenvalue exists where it is simple and separated
            // in modulus from the next one (not at lobe cusps, where two pairs cross)
            let dense = method.monodromy(&model, rpm, b).unwrap().dense();
            let mut moduli: Vec<f64> = dense.complex_eigenvalues().iter().map(|z| z.norm()).collect();
            moduli.sort_by(|a, c| c.total_cmp(a));
            let next = moduli.iter().copied().find(|m| *m < moduli[0] * (1.0 - 1e-9)).unwrap_or(0.0);
            proptest::prop_assume!(next < 0.9 * moduli[0]);
            let s = eigenvalue_sensitivity(method, &model, &params, rpm, b).unwrap();
            let gmax = s.gradient.iter().map(|z| z.norm()).fold(0.0, f64::max);
            // Richardson-extrapolated central differences with steps 2e-5 and 1e-5: the
            // eigen-solver's ~1e-12 error in mu becomes ~1e-7 (a plain difference with step
            // 1e-6 reached 1.5e-6, above 1e-4 gmax, at 7277.7 rpm / 0.709 mm), and the
            // truncation is O(h^4) (a plain one with 1e-5 failed at 7322.2 rpm / 0.840 mm)
            let central = |i: usize, h: f64| {
                let mut tp = [0.0; 3];
                let mut tm = [0.0; 3];
                tp[i] = h;
                tm[i] = -h;
                (mu_at(method, &model, &params, &tp, rpm, b)
                    - mu_at(method, &model, &params, &tm, rpm, b))
                    / (2.0 * h)
            };
            for i in 0..3 {
                let fd = (central(i, 1e-5) * 4.0 - central(i, 2e-5)) / 3.0;
                // 2e-4 of the largest entry: at a separation of 0.87 (7277.7 rpm / 0.709 mm)
                // the two agreed to 1.03e-4; the error grows as the next multiplier nears
                proptest::prop_assert!((fd - s.gradient[i]).norm() < 2e-4 * gmax);
            }
        }
    }
}
