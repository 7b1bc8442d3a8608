//! Time-domain polyreference (TDPR) on correlation matrices (002 Eq. 8-9).
//!
//! With R(c) the n_o x n_r correlation matrices of n_o output channels with n_r references
//! (002 Eq. 8, [`crate::correlation::correlation_matrices`]), an autoregressive model of order
//! n_a, R(c + n_a) = sum_{j < n_a} B_j R(c + j), holds for every lag c when the outputs are the
//! response of a linear (or lifted periodic) system to broadband loads. Stacking
//! U(c) = [R(c); ...; R(c + n_a - 1)] gives U(c + 1) = G U(c) with the block companion matrix
//! G (002 Eq. 9): identity blocks above the diagonal and the B_j in its last block row. The B_j
//! come from a least-squares solve by SVD over every lag, the n_a n_o poles mu from the
//! eigenvalues of G, and lambda = ln(mu) / T from the sample interval T (the tooth period for
//! lifted data).

use crate::error::{OmaError, Result};
use crate::lsce::{Pole, upper_poles};
use nalgebra::DMatrix;

/// Poles of the polyreference AR model of order `order` (n_a, number of matrix coefficients)
/// fitted to the correlation matrices `r[c]` (all n_o x n_r, lags c = 0, 1, ...) sampled every
/// `sample_interval_s`. Returns the non-zero upper half-plane poles (real ones included), none
/// flagged harmonic.
pub fn polyreference(
    r: &[DMatrix<f64>],
    sample_interval_s: f64,
    order: usize,
) -> Result<Vec<Pole>> {
    let (no, nr) = r.first().map_or((0, 0), |m| m.shape());
    if !(sample_interval_s.is_finite() && sample_interval_s > 0.0) {
        return Err(OmaError::InvalidInput {
            field: "sample_interval_s",
            message: format!("{sample_interval_s}; expected an interval > 0"),
        });
    }
    if no == 0 || nr == 0 || r.iter().any(|m| m.shape() != (no, nr)) {
        return Err(OmaError::InvalidInput {
            field: "correlations",
            message: "expected non-empty correlation matrices of one shape".into(),
        });
    }
    let unknowns = order * no;
    let lags = r.len().saturating_sub(order);
    if order == 0 || lags * nr < unknowns {
        return Err(OmaError::InvalidInput {
            field: "order",
            message: format!(
                "order {order} with {no} outputs needs {unknowns} equations per output; {} lags \
                 of {nr} references give {}: use more lags or a lower order",
                r.len(),
                lags * nr
            ),
        });
    }
    // H^T B^T = Y^T, one row per (lag, reference)
    let mut ht = DMatrix::zeros(lags * nr, unknowns);
    let mut yt = DMatrix::zeros(lags * nr, no);
    for c in 0..lags {
        for k in 0..nr {
            let row = c * nr + k;
            for j in 0..order {
                for o in 0..no {
                    ht[(row, j * no + o)] = r[c + j][(o, k)];
                }
            }
            for o in 0..no {
                yt[(row, o)] = r[c + order][(o, k)];
            }
        }
    }
    let svd = ht.svd(true, true);
    let bt = svd
        .solve(&yt, 1e-13 * svd.singular_values.max())
        .map_err(|e| OmaError::Numerical(format!("polyreference least squares failed: {e}")))?;
    let mut g = DMatrix::zeros(unknowns, unknowns);
    for i in 0..unknowns - no {
        g[(i, i + no)] = 1.0;
    }
    for o in 0..no {
        for col in 0..unknowns {
            g[(unknowns - no + o, col)] = bt[(col, o)];
        }
    }
    Ok(upper_poles(
        g.complex_eigenvalues().iter().copied(),
        sample_interval_s,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    #[test]
    fn rejects_bad_shapes_and_orders() {
        let r = vec![DMatrix::<f64>::identity(2, 2); 10];
        assert!(polyreference(&r, 0.0, 1).is_err());
        assert!(polyreference(&r, 1.0, 0).is_err());
        assert!(polyreference(&r, 1.0, 6).is_err());
        let mut ragged = r.clone();
        ragged[3] = DMatrix::identity(3, 2);
        assert!(polyreference(&ragged, 1.0, 1).is_err());
        assert!(polyreference(&[], 1.0, 1).is_err());
    }

    #[test]
    fn first_order_recovers_a_real_multiplier() {
        // R(c) = 0.9^c A: one real multiplier, n_o = 1
        let r: Vec<DMatrix<f64>> = (0..20)
            .map(|c| DMatrix::from_element(1, 2, 0.9f64.powi(c)))
            .collect();
        let poles = polyreference(&r, 0.5, 1).unwrap();
        assert_eq!(poles.len(), 1);
        assert!((poles[0].multiplier - Complex64::new(0.9, 0.0)).norm() < 1e-12);
    }
}
