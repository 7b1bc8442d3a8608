//! Correlation functions of every channel with the reference (000 Eq. 21), computed with FFTs.
//!
//! r_c(i) = 1/(L - i) sum_{k=1}^{L-i} y_c(k) y_0(k + i) (the unbiased estimator; a windowed
//! Welch route biases damping upwards, so it is not used for identification).

use crate::error::{OmaError, Result};
use nalgebra::DMatrix;
use num_complex::Complex64;
use rustfft::FftPlanner;

/// Unbiased correlations `r[c][i]`, i = 0..max_lag, of each channel `data[c]` with
/// `data[reference]`.
pub fn correlate(data: &[Vec<f64>], reference: usize, max_lag: usize) -> Result<Vec<Vec<f64>>> {
    let mut by_reference = cross_correlations(data, &[reference], max_lag)?;
    Ok(by_reference.swap_remove(0))
}

/// Correlation matrices of 002 Eq. 8, R(i) = 1/(L - i) sum_k y(k) y_ref(k + i)^T for
/// i = 0..=max_lag: `R(i)[(c, j)]` is the unbiased correlation of channel `c` with reference
/// channel `references[j]` (the same estimator as [`correlate`], one column per reference).
pub fn correlation_matrices(
    data: &[Vec<f64>],
    references: &[usize],
    max_lag: usize,
) -> Result<Vec<DMatrix<f64>>> {
    let r = cross_correlations(data, references, max_lag)?;
    Ok((0..=max_lag)
        .map(|i| DMatrix::from_fn(data.len(), references.len(), |c, j| r[j][c][i]))
        .collect())
}

/// `r[j][c][i]`: correlation of channel c with reference `references[j]` at lag i, every channel
/// transformed once.
fn cross_correlations(
    data: &[Vec<f64>],
    references: &[usize],
    max_lag: usize,
) -> Result<Vec<Vec<Vec<f64>>>> {
    let l = data.first().map_or(0, Vec::len);
    if let Some(bad) = references.iter().find(|&&r| r >= data.len()) {
        return Err(OmaError::InvalidInput {
            field: "reference",
            message: format!("reference {bad} of {} channels", data.len()),
        });
    }
    if references.is_empty() || max_lag == 0 || max_lag >= l || data.iter().any(|c| c.len() != l) {
        return Err(OmaError::InvalidInput {
            field: "max_lag",
            message: format!(
                "{max_lag} lags need at least one reference and equal channels longer than \
                 that ({} channels of {l} samples)",
                data.len()
            ),
        });
    }
    let n = (l + max_lag + 1).next_power_of_two();
    let mut planner = FftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(n);
    let ifft = planner.plan_fft_inverse(n);
    let spectra: Vec<Vec<Complex64>> = data
        .iter()
        .map(|x| {
            let mut buf: Vec<Complex64> = x.iter().map(|&v| Complex64::new(v, 0.0)).collect();
            buf.resize(n, Complex64::new(0.0, 0.0));
            fft.process(&mut buf);
            buf
        })
        .collect();
    Ok(references
        .iter()
        .map(|&reference| {
            let r0 = &spectra[reference];
            spectra
                .iter()
                .map(|yc| {
                    // sum_k y_c(k) y_0(k + i) is the cross-correlation: IFFT(conj(Y_c) Y_0)
                    let mut prod: Vec<Complex64> =
                        yc.iter().zip(r0).map(|(a, b)| a.conj() * b).collect();
                    ifft.process(&mut prod);
                    (0..=max_lag)
                        .map(|i| prod[i].re / n as f64 / (l - i) as f64)
                        .collect()
                })
                .collect()
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn direct(a: &[f64], r: &[f64], lag: usize) -> f64 {
        let l = a.len();
        (0..l - lag).map(|k| a[k] * r[k + lag]).sum::<f64>() / (l - lag) as f64
    }

    proptest! {
        #[test]
        fn fft_equals_direct_sum(x in proptest::collection::vec(-1.0..1.0f64, 20..200),
                                 y in proptest::collection::vec(-1.0..1.0f64, 200)) {
            let y = y[..x.len()].to_vec();
            let data = vec![y.clone(), x.clone()];
            let r = correlate(&data, 0, 10).unwrap();
            for (lag, value) in r[1].iter().enumerate() {
                let d = direct(&x, &y, lag);
                prop_assert!((value - d).abs() < 1e-10 * (1.0 + d.abs()));
            }
        }
    }

    #[test]
    fn matrices_hold_one_column_per_reference() {
        let data = vec![
            (0..64).map(|k| (0.3 * k as f64).sin()).collect::<Vec<_>>(),
            (0..64).map(|k| (0.7 * k as f64).cos()).collect::<Vec<_>>(),
        ];
        let m = correlation_matrices(&data, &[1, 0], 5).unwrap();
        assert_eq!(m.len(), 6);
        for (lag, r) in m.iter().enumerate() {
            for (j, reference) in [1usize, 0].into_iter().enumerate() {
                for (c, channel) in data.iter().enumerate() {
                    let d = direct(channel, &data[reference], lag);
                    assert!((r[(c, j)] - d).abs() < 1e-12, "lag {lag} c {c} ref {j}");
                }
            }
        }
        assert!(correlation_matrices(&data, &[2], 5).is_err());
        assert!(correlation_matrices(&data, &[], 5).is_err());
    }

    #[test]
    fn rejects_bad_lags() {
        assert!(correlate(&[vec![1.0, 2.0]], 0, 5).is_err());
        assert!(correlate(&[vec![1.0, 2.0, 3.0]], 1, 1).is_err());
    }
}
