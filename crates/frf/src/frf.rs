//! One measured FRF: a receptance H(i w) (m/N) at sampled frequencies, with the conversions
//! from the other forms a tap test may export, mobility Y = i w H and accelerance
//! A = -w^2 H.

use crate::error::{FrfError, Result};
use num_complex::Complex64;
use std::f64::consts::PI;

/// What an FRF file holds per unit force.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Displacement per force, m/N.
    Receptance,
    /// Velocity per force, m/(s N).
    Mobility,
    /// Acceleration per force, m/(s^2 N).
    Accelerance,
}

impl Quantity {
    /// The receptance of `value` of this quantity at `frequency_hz`; None at 0 Hz for mobility
    /// and accelerance (no displacement follows from them there).
    pub fn to_receptance(self, frequency_hz: f64, value: Complex64) -> Option<Complex64> {
        let w = 2.0 * PI * frequency_hz;
        match self {
            Quantity::Receptance => Some(value),
            _ if w == 0.0 => None,
            Quantity::Mobility => Some(value / Complex64::new(0.0, w)),
            Quantity::Accelerance => Some(value / (-w * w)),
        }
    }
}

/// A measured receptance: strictly increasing frequencies (Hz, >= 0) and finite values (m/N).
#[derive(Debug, Clone, PartialEq)]
pub struct Frf {
    frequencies_hz: Vec<f64>,
    receptance_m_per_n: Vec<Complex64>,
}

impl Frf {
    /// Validated: equal lengths, at least two points, frequencies finite, >= 0 and strictly
    /// increasing, values finite.
    pub fn new(frequencies_hz: Vec<f64>, receptance_m_per_n: Vec<Complex64>) -> Result<Self> {
        if frequencies_hz.len() != receptance_m_per_n.len() {
            return Err(FrfError::value(
                "receptance_m_per_n",
                receptance_m_per_n.len() as f64,
                format!("one value per frequency ({})", frequencies_hz.len()),
            ));
        }
        if frequencies_hz.len() < 2 {
            return Err(FrfError::value(
                "frequencies_hz",
                frequencies_hz.len() as f64,
                "at least 2 frequencies",
            ));
        }
        if let Some(&f) = frequencies_hz
            .iter()
            .find(|f| !(f.is_finite() && **f >= 0.0))
        {
            return Err(FrfError::value(
                "frequency_hz",
                f,
                "a finite frequency >= 0",
            ));
        }
        if let Some(w) = frequencies_hz.windows(2).find(|w| w[1] <= w[0]) {
            return Err(FrfError::value(
                "frequency_hz",
                w[1],
                format!("above the previous frequency {} Hz", w[0]),
            ));
        }
        if let Some((f, _)) = frequencies_hz
            .iter()
            .zip(&receptance_m_per_n)
            .find(|(_, g)| !(g.re.is_finite() && g.im.is_finite()))
        {
            return Err(FrfError::value(
                "receptance_m_per_n at frequency_hz",
                *f,
                "a finite receptance",
            ));
        }
        Ok(Self {
            frequencies_hz,
            receptance_m_per_n,
        })
    }

    /// An FRF from values of `quantity`, converted to receptance; for mobility and accelerance
    /// a 0 Hz point is dropped.
    pub fn from_quantity(
        frequencies_hz: Vec<f64>,
        values: Vec<Complex64>,
        quantity: Quantity,
    ) -> Result<Self> {
        let (f, g): (Vec<f64>, Vec<Complex64>) = frequencies_hz
            .into_iter()
            .zip(values)
            .filter_map(|(f, v)| quantity.to_receptance(f, v).map(|g| (f, g)))
            .unzip();
        Self::new(f, g)
    }

    /// The receptance H(i w) of a modal model between coordinates `i` and `j` at `frequencies_hz`.
    pub fn from_model(
        model: &chatter_dynamics::ModalModel,
        i: usize,
        j: usize,
        frequencies_hz: Vec<f64>,
    ) -> Result<Self> {
        let g = frequencies_hz
            .iter()
            .map(|&f| model.receptance(f, i, j))
            .collect();
        Self::new(frequencies_hz, g)
    }

    /// The frequencies (Hz).
    pub fn frequencies_hz(&self) -> &[f64] {
        &self.frequencies_hz
    }

    /// The receptance values (m/N).
    pub fn receptance_m_per_n(&self) -> &[Complex64] {
        &self.receptance_m_per_n
    }

    /// Number of frequencies.
    pub fn len(&self) -> usize {
        self.frequencies_hz.len()
    }

    /// Always false: an FRF has at least two points.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The points with `fmin_hz <= f <= fmax_hz` (at least two).
    pub fn band(&self, fmin_hz: f64, fmax_hz: f64) -> Result<Self> {
        if !(fmin_hz.is_finite() && fmax_hz.is_finite() && fmax_hz > fmin_hz) {
            return Err(FrfError::value(
                "fmax_hz",
                fmax_hz,
                format!("a finite band above fmin_hz = {fmin_hz}"),
            ));
        }
        let (f, g): (Vec<f64>, Vec<Complex64>) = self
            .frequencies_hz
            .iter()
            .zip(&self.receptance_m_per_n)
            .filter(|(f, _)| **f >= fmin_hz && **f <= fmax_hz)
            .map(|(f, g)| (*f, *g))
            .unzip();
        if f.len() < 2 {
            return Err(FrfError::value(
                "fmin_hz",
                fmin_hz,
                format!(
                    "a band holding at least 2 of the measured frequencies ({} to {} Hz)",
                    self.frequencies_hz[0],
                    self.frequencies_hz[self.frequencies_hz.len() - 1]
                ),
            ));
        }
        Self::new(f, g)
    }

    /// The receptance at `frequency_hz`, linear in the real and imaginary parts between samples;
    /// None outside the measured band.
    pub fn interpolate(&self, frequency_hz: f64) -> Option<Complex64> {
        let f = &self.frequencies_hz;
        if !(frequency_hz >= f[0] && frequency_hz <= f[f.len() - 1]) {
            return None;
        }
        let k = f
            .partition_point(|&x| x <= frequency_hz)
            .clamp(1, f.len() - 1);
        let t = (frequency_hz - f[k - 1]) / (f[k] - f[k - 1]);
        let (a, b) = (self.receptance_m_per_n[k - 1], self.receptance_m_per_n[k]);
        Some(a + (b - a) * t)
    }

    /// The relative L2 misfit ||H_other - H|| / ||H|| over this FRF's frequencies inside
    /// [`fmin_hz`, `fmax_hz`] where `other` is defined; None when no frequency qualifies.
    pub fn relative_misfit(
        &self,
        other: impl Fn(f64) -> Option<Complex64>,
        fmin_hz: f64,
        fmax_hz: f64,
    ) -> Option<f64> {
        let (mut num, mut den) = (0.0, 0.0);
        for (&f, &g) in self.frequencies_hz.iter().zip(&self.receptance_m_per_n) {
            if f < fmin_hz || f > fmax_hz {
                continue;
            }
            if let Some(h) = other(f) {
                num += (h - g).norm_sqr();
                den += g.norm_sqr();
            }
        }
        (den > 0.0).then(|| (num / den).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accelerance_and_mobility_convert_to_the_same_receptance() {
        let f = vec![0.0, 100.0, 200.0];
        let h: Vec<Complex64> = f
            .iter()
            .map(|&f| Complex64::new(1e-7, -f * 1e-10))
            .collect();
        let w = |f: f64| 2.0 * PI * f;
        let acc: Vec<Complex64> = f.iter().zip(&h).map(|(&f, h)| h * (-w(f) * w(f))).collect();
        let mob: Vec<Complex64> = f
            .iter()
            .zip(&h)
            .map(|(&f, h)| h * Complex64::new(0.0, w(f)))
            .collect();
        let a = Frf::from_quantity(f.clone(), acc, Quantity::Accelerance).unwrap();
        let m = Frf::from_quantity(f, mob, Quantity::Mobility).unwrap();
        assert_eq!(a.frequencies_hz(), &[100.0, 200.0]);
        for k in 0..2 {
            assert!((a.receptance_m_per_n()[k] - h[k + 1]).norm() < 1e-20);
            assert!((m.receptance_m_per_n()[k] - h[k + 1]).norm() < 1e-20);
        }
    }

    #[test]
    fn invalid_frfs_are_rejected() {
        let z = Complex64::new(0.0, 0.0);
        assert!(Frf::new(vec![1.0, 1.0], vec![z, z]).is_err());
        assert!(Frf::new(vec![-1.0, 1.0], vec![z, z]).is_err());
        assert!(Frf::new(vec![1.0, 2.0], vec![z, Complex64::new(f64::NAN, 0.0)]).is_err());
        assert!(Frf::new(vec![1.0, 2.0], vec![z]).is_err());
    }
}
