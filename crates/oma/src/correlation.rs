//! Correlation functions of every channel with the reference (000 Eq. 21), computed with FFTs.
//!
//! r_c(i) = 1/(L - i) sum_{k=1}^{L-i} y_c(k) y_0(k + i) (the unbiased estimator; a windowed
//! Welch route biases damping upwards, so it is not used for identification).

use crate::error::{OmaError, Result};
use num_complex::Complex64;
use rustfft::FftPlanner;

/// Unbiased correlations `r[c][i]`, i = 0..max_lag, of each channel `data[c]` with
/// `data[reference]`.
pub fn correlate(data: &[Vec<f64>], reference: usize, max_lag: usize) -> Result<Vec<Vec<f64>>> {
    let l = data.first().map_or(0, Vec::len);
    if reference >= data.len() || max_lag == 0 || max_lag >= l {
        return Err(OmaError::InvalidInput {
            field: "max_lag",
            message: format!(
                "{max_lag} lags of {l} samples with reference {reference} of {} channels",
                data.len()
            ),
        });
    }
    let n = (l + max_lag + 1).next_power_of_two();
    let mut planner = FftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(n);
    let ifft = planner.plan_fft_inverse(n);
    let spectrum = |x: &[f64]| {
        let mut buf: Vec<Complex64> = x.iter().map(|&v| Complex64::new(v, 0.0)).collect();
        buf.resize(n, Complex64::new(0.0, 0.0));
        fft.process(&mut buf);
        buf
    };
    let r0 = spectrum(&data[reference]);
    Ok(data
        .iter()
        .map(|ch| {
            // sum_k y_c(k) y_0(k + i) is the cross-correlation: IFFT(conj(Y_c) Y_0)
            let yc = spectrum(ch);
            let mut prod: Vec<Complex64> = yc.iter().zip(&r0).map(|(a, b)| a.conj() * b).collect();
            ifft.process(&mut prod);
            (0..=max_lag)
                .map(|i| prod[i].re / n as f64 / (l - i) as f64)
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
    fn rejects_bad_lags() {
        assert!(correlate(&[vec![1.0, 2.0]], 0, 5).is_err());
        assert!(correlate(&[vec![1.0, 2.0, 3.0]], 1, 1).is_err());
    }
}
