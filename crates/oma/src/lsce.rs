//! Least-squares complex exponential on correlation functions (000 Eq. 19-20, 25) and the
//! modified LSCE with known spindle harmonics (Mohanty and Rixen; 000 Eq. 22-24).
//!
//! Correlations of a linear system under broadband loads are sums of damped exponentials whose
//! discrete poles mu are the roots of a characteristic polynomial of order 2P:
//! sum_j beta_j r(i + j) = -r(i + 2P) for every channel and lag i (Eq. 20). The betas come from a
//! least-squares solve by SVD (never normal equations), the poles from the eigenvalues of the
//! companion matrix, lambda = ln(mu) / T_s, frequency |lambda| / 2 pi and damping
//! -Re(lambda) / |lambda| (Eq. 25).
//!
//! Known harmonics at w_k are imposed exactly by deflation, which is equivalent to the partition
//! of Eq. 22-24: the polynomial is K(z) U(z) with the known factor
//! K(z) = prod_k (z^2 - 2 cos(w_k T_s) z + 1). Filtering each correlation by K's coefficients
//! annihilates the harmonic components, and U (order 2P - 2H) is fitted to the filtered sequence.

use crate::error::{OmaError, Result};
use chatter_modal::pole::{multiplier_pole, pole_frequency_damping};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::PI;

/// An identified pole.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Pole {
    /// Discrete-time pole mu.
    pub multiplier: Complex64,
    /// Continuous-time pole lambda = ln(mu) / T_s (rad/s).
    pub lambda: Complex64,
    /// |lambda| / 2 pi (Hz).
    pub frequency_hz: f64,
    /// -Re(lambda) / |lambda|.
    pub damping_ratio: f64,
    /// Whether it is one of the imposed harmonics.
    pub harmonic: bool,
}

impl Pole {
    /// The pole of a discrete multiplier at sample interval `ts`.
    pub fn from_multiplier(mu: Complex64, ts: f64, harmonic: bool) -> Self {
        let lambda = multiplier_pole(mu, ts);
        let (frequency_hz, damping_ratio) = pole_frequency_damping(lambda);
        Self {
            multiplier: mu,
            lambda,
            frequency_hz,
            damping_ratio,
            harmonic,
        }
    }

    /// Principal frequency arg(mu) / (2 pi T_s) = Im(lambda) / 2 pi (Hz), in [0, 1 / (2 T_s)]
    /// for the upper half-plane representative: the frequency seen in data sampled at T_s (for
    /// lifted data, the principal frequency of the Floquet multiplier, as in 002 Table 2).
    pub fn principal_frequency_hz(&self) -> f64 {
        self.lambda.im.abs() / (2.0 * PI)
    }
}

/// The non-harmonic poles of the discrete roots `mu` in the closed upper half-plane (one of each
/// conjugate pair; real roots included), leaving out the zero root, which has no continuous-time
/// counterpart.
pub(crate) fn upper_poles(mu: impl IntoIterator<Item = Complex64>, ts: f64) -> Vec<Pole> {
    mu.into_iter()
        .filter(|z| z.im >= 0.0 && z.norm() > 0.0)
        .map(|z| Pole::from_multiplier(z, ts, false))
        .collect()
}

/// Polynomial coefficients (ascending, monic) of prod_k (z^2 - 2 cos(w_k ts) z + 1).
fn harmonic_factor(harmonics_hz: &[f64], ts: f64) -> Vec<f64> {
    let mut c = vec![1.0];
    for &f in harmonics_hz {
        let q = [1.0, -2.0 * (2.0 * PI * f * ts).cos(), 1.0];
        let mut next = vec![0.0; c.len() + 2];
        for (i, a) in c.iter().enumerate() {
            for (j, b) in q.iter().enumerate() {
                next[i + j] += a * b;
            }
        }
        c = next;
    }
    c
}

/// Roots of the monic polynomial with ascending coefficients `beta` (length n, leading 1 implied).
fn roots(beta: &[f64]) -> Vec<Complex64> {
    let n = beta.len();
    if n == 0 {
        return Vec::new();
    }
    let mut companion = DMatrix::zeros(n, n);
    for i in 1..n {
        companion[(i, i - 1)] = 1.0;
    }
    for (i, b) in beta.iter().enumerate() {
        companion[(i, n - 1)] = -b;
    }
    companion.complex_eigenvalues().iter().copied().collect()
}

/// LSCE of order `order` (= 2P, the number of poles) on correlation sets `r[c][i]` sampled at
/// `sample_rate_hz`, with `harmonics_hz` imposed as undamped poles (empty for plain LSCE).
/// Returns the structural poles (upper half-plane) and the harmonics.
pub fn lsce(
    r: &[Vec<f64>],
    sample_rate_hz: f64,
    order: usize,
    harmonics_hz: &[f64],
) -> Result<Vec<Pole>> {
    let ts = 1.0 / sample_rate_hz;
    let h = 2 * harmonics_hz.len();
    if order <= h || sample_rate_hz.is_nan() || sample_rate_hz <= 0.0 {
        return Err(OmaError::InvalidInput {
            field: "order",
            message: format!(
                "order {order} must exceed twice the {} harmonics",
                harmonics_hz.len()
            ),
        });
    }
    let k = harmonic_factor(harmonics_hz, ts);
    // filtered correlations g(i) = sum_m k_m r(i + m)
    let g: Vec<Vec<f64>> = r
        .iter()
        .map(|rc| {
            (0..rc.len().saturating_sub(h))
                .map(|i| k.iter().enumerate().map(|(m, km)| km * rc[i + m]).sum())
                .collect()
        })
        .collect();
    let p = order - h;
    let rows_per = g.first().map_or(0, |gc| gc.len().saturating_sub(p));
    let rows = rows_per * g.len();
    if rows < p {
        return Err(OmaError::InvalidInput {
            field: "correlations",
            message: format!("{rows} equations for {p} unknowns: use more lags"),
        });
    }
    let mut a = DMatrix::zeros(rows, p);
    let mut b = DVector::zeros(rows);
    let mut row = 0;
    for gc in &g {
        for i in 0..rows_per {
            for j in 0..p {
                a[(row, j)] = gc[i + j];
            }
            b[row] = -gc[i + p];
            row += 1;
        }
    }
    let svd = a.svd(true, true);
    let beta = svd
        .solve(&b, 1e-13 * svd.singular_values.max())
        .map_err(|e| OmaError::Numerical(format!("least squares failed: {e}")))?;
    let mut poles = upper_poles(roots(beta.as_slice()), ts);
    poles.extend(harmonics_hz.iter().map(|&f| {
        let w = 2.0 * PI * f * ts;
        Pole::from_multiplier(Complex64::new(w.cos(), w.sin()), ts, true)
    }));
    Ok(poles)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// r(i) = sum of damped cosines plus undamped harmonics, sampled at fs.
    fn analytic(
        modes: &[(f64, f64, f64)],
        harmonics: &[(f64, f64)],
        fs: f64,
        n: usize,
    ) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let t = i as f64 / fs;
                let m: f64 = modes
                    .iter()
                    .map(|&(f, z, a)| {
                        let w = 2.0 * PI * f;
                        a * (-z * w * t).exp() * (w * (1.0 - z * z).sqrt() * t + 0.3).cos()
                    })
                    .sum();
                let h: f64 = harmonics
                    .iter()
                    .map(|&(f, a)| a * (2.0 * PI * f * t + 1.1).cos())
                    .sum();
                m + h
            })
            .collect()
    }

    #[test]
    fn exact_sequences_recover_poles_to_1e9() {
        let fs = 10_000.0;
        let modes = [(800.0, 0.02, 1.0), (1730.0, 0.01, 0.5)];
        let r = vec![
            analytic(&modes, &[], fs, 400),
            analytic(&modes, &[], fs, 400)
                .iter()
                .map(|v| 0.7 * v)
                .collect(),
        ];
        let poles = lsce(&r, fs, 4, &[]).unwrap();
        assert_recovered(&poles, &modes, 1e-9, 1e-9);
        // with harmonics imposed: exact too
        let harmonics = [(700.0, 3.0), (933.3, 2.0)];
        let r = vec![analytic(&modes, &harmonics, fs, 400)];
        let hz: Vec<f64> = harmonics.iter().map(|h| h.0).collect();
        let poles = lsce(&r, fs, 8, &hz).unwrap();
        assert_recovered(&poles, &modes, 1e-9, 1e-8);
    }

    /// Every (frequency, damping) of `modes` is matched by the nearest structural pole to the
    /// given relative tolerances.
    fn assert_recovered(poles: &[Pole], modes: &[(f64, f64, f64)], tol_f: f64, tol_z: f64) {
        for &(f, z, _) in modes {
            let p = poles
                .iter()
                .filter(|p| !p.harmonic)
                .min_by(|a, b| {
                    (a.frequency_hz - f)
                        .abs()
                        .total_cmp(&(b.frequency_hz - f).abs())
                })
                .unwrap();
            assert!(
                (p.frequency_hz - f).abs() < tol_f * f,
                "{} vs {f}",
                p.frequency_hz
            );
            assert!(
                (p.damping_ratio - z).abs() < tol_z * z,
                "{} vs {z}",
                p.damping_ratio
            );
        }
    }

    #[test]
    fn plain_lsce_is_biased_by_strong_harmonics_modified_is_not() {
        // a mode at 800 Hz with strong harmonics at 780 and 830 Hz; modest order 4
        let fs = 10_000.0;
        let modes = [(800.0, 0.02, 1.0)];
        let harmonics = [(780.0, 5.0), (830.0, 5.0)];
        let r = vec![analytic(&modes, &harmonics, fs, 600)];
        let plain = lsce(&r, fs, 4, &[]).unwrap();
        let best = |poles: &[Pole]| {
            poles
                .iter()
                .filter(|p| !p.harmonic && p.damping_ratio > 0.005)
                .map(|p| {
                    (p.frequency_hz - 800.0).abs() / 800.0 + (p.damping_ratio - 0.02).abs() / 0.02
                })
                .fold(f64::INFINITY, f64::min)
        };
        assert!(
            best(&plain) > 0.05,
            "plain LSCE unexpectedly accurate: {plain:?}"
        );
        let modified = lsce(&r, fs, 6, &[780.0, 830.0]).unwrap();
        assert!(best(&modified) < 1e-6, "modified LSCE: {modified:?}");
    }
}
