//! Receptances known at sampled frequencies only (a measured FRF), the input of the zero-order
//! stability of a measured structure: G(i w_k), a 2 x 2 complex matrix (m/N) over the
//! operation's two coordinates at each frequency w_k, with the entries that were not measured
//! zero.

use crate::error::{DynamicsError, Result};
use num_complex::Complex64;

/// A 2 x 2 receptance matrix (m/N), rows = response, columns = force.
pub type ReceptanceMatrix = [[Complex64; 2]; 2];

/// Receptance matrices at strictly increasing frequencies (Hz), at least two.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledReceptance {
    frequencies_hz: Vec<f64>,
    matrices_m_per_n: Vec<ReceptanceMatrix>,
}

impl SampledReceptance {
    /// Validated: as many matrices as frequencies (>= 2), frequencies finite, >= 0 and strictly
    /// increasing, every entry finite.
    pub fn new(frequencies_hz: Vec<f64>, matrices_m_per_n: Vec<ReceptanceMatrix>) -> Result<Self> {
        if frequencies_hz.len() != matrices_m_per_n.len() {
            return Err(DynamicsError::invalid(
                "receptance",
                format!(
                    "{} frequencies but {} matrices: expected one matrix per frequency",
                    frequencies_hz.len(),
                    matrices_m_per_n.len()
                ),
            ));
        }
        if frequencies_hz.len() < 2 {
            return Err(DynamicsError::value(
                "receptance.frequencies_hz",
                frequencies_hz.len() as f64,
                "at least 2 frequencies",
            ));
        }
        for (k, w) in frequencies_hz.windows(2).enumerate() {
            if !(w[0].is_finite() && w[1].is_finite() && w[0] >= 0.0 && w[1] > w[0]) {
                return Err(DynamicsError::value(
                    format!("receptance.frequencies_hz[{}]", k + 1),
                    w[1],
                    format!("finite, >= 0 and above the previous frequency {} Hz", w[0]),
                ));
            }
        }
        for (k, m) in matrices_m_per_n.iter().enumerate() {
            if let Some(v) = m
                .iter()
                .flatten()
                .find(|v| !(v.re.is_finite() && v.im.is_finite()))
            {
                return Err(DynamicsError::value(
                    format!("receptance at {} Hz", frequencies_hz[k]),
                    if v.re.is_finite() { v.im } else { v.re },
                    "a finite receptance",
                ));
            }
        }
        Ok(Self {
            frequencies_hz,
            matrices_m_per_n,
        })
    }

    /// The frequencies (Hz).
    pub fn frequencies_hz(&self) -> &[f64] {
        &self.frequencies_hz
    }

    /// The receptance matrices (m/N), one per frequency.
    pub fn matrices_m_per_n(&self) -> &[ReceptanceMatrix] {
        &self.matrices_m_per_n
    }

    /// The receptance at `frequency_hz`, linear in the real and imaginary parts between
    /// samples; None outside the sampled band.
    pub fn interpolate(&self, frequency_hz: f64) -> Option<ReceptanceMatrix> {
        let f = &self.frequencies_hz;
        let (first, last) = (f[0], f[f.len() - 1]);
        if !(frequency_hz >= first && frequency_hz <= last) {
            return None;
        }
        let k = f
            .partition_point(|&x| x <= frequency_hz)
            .clamp(1, f.len() - 1);
        let t = (frequency_hz - f[k - 1]) / (f[k] - f[k - 1]);
        let (a, b) = (&self.matrices_m_per_n[k - 1], &self.matrices_m_per_n[k]);
        Some(std::array::from_fn(|i| {
            std::array::from_fn(|j| a[i][j] + (b[i][j] - a[i][j]) * t)
        }))
    }

    /// The frequency (Hz) of the largest receptance (Frobenius norm of the matrix).
    pub fn peak_frequency_hz(&self) -> f64 {
        let norm = |m: &ReceptanceMatrix| m.iter().flatten().map(|v| v.norm_sqr()).sum::<f64>();
        self.frequencies_hz
            .iter()
            .zip(&self.matrices_m_per_n)
            .fold((self.frequencies_hz[0], -1.0), |(fb, nb), (&f, m)| {
                let n = norm(m);
                if n > nb { (f, n) } else { (fb, nb) }
            })
            .0
    }
}

impl crate::ModalModel {
    /// This model's receptance sampled at `frequencies_hz` (the FRF a perfect tap test of it
    /// would measure).
    pub fn sampled_receptance(&self, frequencies_hz: Vec<f64>) -> Result<SampledReceptance> {
        let matrices = frequencies_hz
            .iter()
            .map(|&f| self.receptance_matrix(f))
            .collect();
        SampledReceptance::new(frequencies_hz, matrices)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::examples;

    #[test]
    fn interpolation_hits_the_samples_and_rejects_outside() {
        let model = examples::schmitz_2023_milling();
        let f: Vec<f64> = (0..=100).map(|k| 10.0 * k as f64).collect();
        let s = model.sampled_receptance(f).unwrap();
        let g = s.interpolate(500.0).unwrap();
        assert!((g[0][0] - model.receptance(500.0, 0, 0)).norm() < 1e-18);
        assert!(s.interpolate(1000.5).is_none());
        assert!(s.interpolate(f64::NAN).is_none());
    }

    #[test]
    fn invalid_grids_are_rejected() {
        let z = [[Complex64::new(0.0, 0.0); 2]; 2];
        assert!(SampledReceptance::new(vec![1.0, 1.0], vec![z, z]).is_err());
        assert!(SampledReceptance::new(vec![1.0], vec![z]).is_err());
        assert!(SampledReceptance::new(vec![1.0, 2.0], vec![z]).is_err());
        let mut bad = z;
        bad[0][1] = Complex64::new(f64::NAN, 0.0);
        assert!(SampledReceptance::new(vec![1.0, 2.0], vec![z, bad]).is_err());
    }
}
