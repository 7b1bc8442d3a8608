//! Gradient and Hessian of the dominant eigenvalue of the transition matrix with respect to the
//! named perturbations theta (Ahmadi 2022, seed 000, Eq. 15-16).
//!
//! With right and left eigenvectors u, v of the dominant eigenvalue mu, scaled so v^T u = 1,
//!
//! d mu / d theta_k = v^T G_k u                                                    (Eq. 15)
//!
//! G_k u is the central difference (step [`THETA_STEP`]) of the matrix-free products
//! G(theta +- h e_k) u, and u, v come from restarted Arnoldi on U and U^T, so no dense matrix of
//! the monodromy's dimension (2N + N M, about a thousand for the seed-000 turning case) is
//! formed. The Hessian of Eq. 16 is the derivative of Eq. 15; it is evaluated as the central
//! difference of the Eq. 15 gradient with step [`HESSIAN_STEP`] and symmetrized, which equals
//! Eq. 16 (v^T G_ij u + v^T G_i w_j + v^T G_j w_i, w_j the reduced-resolvent term) to
//! O(h^2) without the dense solve that w_j needs. Errors: O(THETA_STEP^2) ~ 1e-8 relative in
//! the gradient, O(HESSIAN_STEP^2) ~ 1e-6 plus the Arnoldi tolerance over the step ~ 1e-7 in the
//! Hessian.

use crate::error::{Result, StabilityError};
use crate::monodromy::{Discretization, Monodromy};
use chatter_dynamics::{ModalModel, Parameter};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// Finite-difference step in theta for G_k.
pub const THETA_STEP: f64 = 1e-4;
/// Finite-difference step in theta for the Hessian (difference of gradients).
pub const HESSIAN_STEP: f64 = 1e-3;

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

/// Operators of one cutting condition under perturbations theta of one model.
struct Perturbed<'a> {
    method: Discretization,
    model: &'a ModalModel,
    parameters: &'a [Parameter],
    speed_rpm: f64,
    depth_m: f64,
}

impl Perturbed<'_> {
    fn operator(&self, theta: &[f64]) -> Result<Monodromy> {
        let m = self.model.perturbed(self.parameters, theta)?;
        self.method.monodromy(&m, self.speed_rpm, self.depth_m)
    }

    /// mu (upper half-plane) with right and left eigenvectors scaled so v^T u = 1.
    fn eigen(&self, theta: &[f64]) -> Result<(Complex64, Vec<Complex64>, Vec<Complex64>)> {
        let op = self.operator(theta)?;
        let upper = |(mu, x): (Complex64, Vec<Complex64>)| {
            if mu.im < 0.0 {
                (mu.conj(), x.iter().map(|z| z.conj()).collect())
            } else {
                (mu, x)
            }
        };
        let (mu, u) = upper(op.dominant_eigenpair()?);
        let (mu_left, v) = upper(op.dominant_left_eigenpair()?);
        let scale: Complex64 = v.iter().zip(&u).map(|(a, b)| a * b).sum();
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

    /// Eq. 15 at theta.
    fn gradient(&self, theta: &[f64]) -> Result<(Complex64, DVector<Complex64>)> {
        let (mu, u, v) = self.eigen(theta)?;
        let d = u.len();
        let (ur, ui): (Vec<f64>, Vec<f64>) = u.iter().map(|z| (z.re, z.im)).unzip();
        let mut gradient = DVector::zeros(theta.len());
        let (mut a, mut b) = (vec![0.0; d], vec![0.0; d]);
        for k in 0..theta.len() {
            let mut product = vec![Complex64::new(0.0, 0.0); d];
            for (sign, step) in [(1.0, THETA_STEP), (-1.0, -THETA_STEP)] {
                let mut t = theta.to_vec();
                t[k] += step;
                let op = self.operator(&t)?;
                op.apply(&ur, &mut a);
                op.apply(&ui, &mut b);
                for ((p, x), y) in product.iter_mut().zip(&a).zip(&b) {
                    *p += Complex64::new(sign * x, sign * y);
                }
            }
            let vgu: Complex64 = v.iter().zip(&product).map(|(vi, pi)| vi * pi).sum();
            gradient[k] = vgu / (2.0 * THETA_STEP);
        }
        Ok((mu, gradient))
    }
}

/// Gradient and Hessian of the dominant eigenvalue (Eq. 15-16) at a cutting condition.
pub fn eigenvalue_sensitivity(
    method: Discretization,
    model: &ModalModel,
    parameters: &[Parameter],
    speed_rpm: f64,
    depth_m: f64,
) -> Result<EigenvalueSensitivity> {
    let problem = Perturbed {
        // one grid for the nominal and every perturbed model
        method: method.resolved(model, speed_rpm)?,
        model,
        parameters,
        speed_rpm,
        depth_m,
    };
    let p = parameters.len();
    let zero = vec![0.0; p];
    let (mu, gradient) = problem.gradient(&zero)?;
    let mut hessian = DMatrix::zeros(p, p);
    for j in 0..p {
        let mut t = zero.clone();
        t[j] = HESSIAN_STEP;
        let plus = problem.gradient(&t)?.1;
        t[j] = -HESSIAN_STEP;
        let minus = problem.gradient(&t)?.1;
        hessian.set_column(
            j,
            &((plus - minus) / Complex64::new(2.0 * HESSIAN_STEP, 0.0)),
        );
    }
    let hessian = (&hessian + hessian.transpose()) * Complex64::new(0.5, 0.0);
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
