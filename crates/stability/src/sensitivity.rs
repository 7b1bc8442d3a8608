//! Gradient and Hessian of the dominant eigenvalue of the transition matrix with respect to the
//! named perturbations theta (Ahmadi 2022, seed 000, Eq. 15-16).
//!
//! With right and left eigenvectors u, v of the dominant eigenvalue mu, scaled so v^T u = 1,
//!
//! d mu / d theta_k = v^T G_k u                                                    (Eq. 15)
//! d2 mu / d theta_i d theta_j = v^T G_ij u + v^T G_i w_j + v^T G_j w_i               (Eq. 16)
//!
//! where w_j = sum_{r != m} u_r (v_r^T G_j u) / (mu - mu_r) is the sum of Eq. 16 over the other
//! eigenpairs. It is computed without them, as the solution of the bordered system
//! [[mu I - G, u], [v^T, 0]] [w; s] = [(I - u v^T) G_j u; 0] (the reduced resolvent), which is
//! the same quantity and needs one LU instead of a full eigendecomposition.
//!
//! G_k and G_ij are central finite differences of the dense transition matrix with step
//! [`THETA_STEP`] (truncation error O(h^2) ~ 1e-8 relative, round-off ~ 1e-16 / h^2 ~ 1e-8).

use crate::error::{Result, StabilityError};
use crate::monodromy::Discretization;
use chatter_dynamics::{ModalModel, Parameter};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// Finite-difference step in theta.
pub const THETA_STEP: f64 = 1e-4;

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

fn dense(
    method: Discretization,
    model: &ModalModel,
    parameters: &[Parameter],
    theta: &[f64],
    speed_rpm: f64,
    depth_m: f64,
) -> Result<DMatrix<Complex64>> {
    let m = model.perturbed(parameters, theta)?;
    Ok(method
        .monodromy(&m, speed_rpm, depth_m)?
        .dense()
        .map(|x| Complex64::new(x, 0.0)))
}

/// Solve (A - shift I) x = b repeatedly for the eigenvector of A nearest `shift`.
fn inverse_iteration(a: &DMatrix<Complex64>, shift: Complex64) -> Result<DVector<Complex64>> {
    let d = a.nrows();
    let lu = (a - DMatrix::identity(d, d) * (shift * Complex64::new(1.0 + 1e-11, 1e-13))).lu();
    let mut x = DVector::from_fn(d, |i, _| Complex64::new(1.0 + 0.1 * i as f64, 0.3));
    for _ in 0..4 {
        let y = lu.solve(&x).ok_or(StabilityError::NoConvergence {
            solver: "inverse iteration",
            detail: "singular shifted matrix".into(),
        })?;
        let n = y.norm();
        x = y / Complex64::new(n, 0.0);
    }
    Ok(x)
}

/// Gradient and Hessian of the dominant eigenvalue (Eq. 15-16) at a cutting condition.
pub fn eigenvalue_sensitivity(
    method: Discretization,
    model: &ModalModel,
    parameters: &[Parameter],
    speed_rpm: f64,
    depth_m: f64,
) -> Result<EigenvalueSensitivity> {
    let p = parameters.len();
    let zero = vec![0.0; p];
    let g0 = dense(method, model, parameters, &zero, speed_rpm, depth_m)?;
    let d = g0.nrows();
    let mut mu = method
        .monodromy(model, speed_rpm, depth_m)?
        .dominant_eigenvalue()?;
    if mu.im < 0.0 {
        mu = mu.conj();
    }
    let u = inverse_iteration(&g0, mu)?;
    let v = inverse_iteration(&g0.transpose(), mu)?;
    let scale = (v.transpose() * &u)[(0, 0)];
    let v = v / scale; // v^T u = 1
    let h = THETA_STEP;
    let at = |shifts: &[(usize, f64)]| {
        let mut t = zero.clone();
        for &(i, s) in shifts {
            t[i] += s;
        }
        dense(method, model, parameters, &t, speed_rpm, depth_m)
    };
    let mut first = Vec::with_capacity(p);
    let mut plus = Vec::with_capacity(p);
    let mut minus = Vec::with_capacity(p);
    for i in 0..p {
        let (gp, gm) = (at(&[(i, h)])?, at(&[(i, -h)])?);
        first.push((&gp - &gm) / Complex64::new(2.0 * h, 0.0));
        plus.push(gp);
        minus.push(gm);
    }
    let vt = v.transpose();
    let gradient = DVector::from_fn(p, |k, _| (&vt * &first[k] * &u)[(0, 0)]);
    // reduced-resolvent vectors w_j from the bordered system
    let mut bordered = DMatrix::zeros(d + 1, d + 1);
    bordered
        .view_mut((0, 0), (d, d))
        .copy_from(&(DMatrix::identity(d, d) * mu - &g0));
    for i in 0..d {
        bordered[(i, d)] = u[i];
        bordered[(d, i)] = v[i];
    }
    let lu = bordered.lu();
    let w: Vec<DVector<Complex64>> = first
        .iter()
        .map(|gj| {
            let gu = gj * &u;
            let proj = &gu - &u * (&vt * &gu)[(0, 0)];
            let mut rhs = DVector::zeros(d + 1);
            rhs.rows_mut(0, d).copy_from(&proj);
            lu.solve(&rhs)
                .map(|x| x.rows(0, d).into_owned())
                .ok_or(StabilityError::NoConvergence {
                    solver: "reduced resolvent",
                    detail: "singular bordered matrix (multiple dominant eigenvalue?)".into(),
                })
        })
        .collect::<Result<_>>()?;
    let mut hessian = DMatrix::zeros(p, p);
    let h2 = Complex64::new(h * h, 0.0);
    for i in 0..p {
        for j in i..p {
            let gij = if i == j {
                (&plus[i] - &g0 * Complex64::new(2.0, 0.0) + &minus[i]) / h2
            } else {
                (at(&[(i, h), (j, h)])? - at(&[(i, h), (j, -h)])? - at(&[(i, -h), (j, h)])?
                    + at(&[(i, -h), (j, -h)])?)
                    / (h2 * Complex64::new(4.0, 0.0))
            };
            let value = (&vt * &gij * &u)[(0, 0)]
                + (&vt * &first[i] * &w[j])[(0, 0)]
                + (&vt * &first[j] * &w[i])[(0, 0)];
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
        let method = Discretization::full().with_steps(60);
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
        /// dominant eigenvalue is separated (1e-4 of the gradient's largest entry).
        #[test]
        fn gradient_property(rpm in 6900.0..7600.0f64, mm in 0.5..2.5f64) {
            let model = examples::ahmadi_2022_turning();
            let params: Vec<Parameter> = ["theta_omega_2", "theta_zeta_2", "theta_phi_2"]
                .iter()
                .map(|s| s.parse().unwrap())
                .collect();
            let method = Discretization::full().with_steps(40);
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
            for i in 0..3 {
                let mut tp = [0.0; 3];
                let mut tm = [0.0; 3];
                tp[i] = 1e-6;
                tm[i] = -1e-6;
                let fd = (mu_at(method, &model, &params, &tp, rpm, b)
                    - mu_at(method, &model, &params, &tm, rpm, b))
                    / 2e-6;
                proptest::prop_assert!((fd - s.gradient[i]).norm() < 1e-4 * gmax);
            }
        }
    }
}
