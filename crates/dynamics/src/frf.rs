//! Receptance frequency response functions.
//!
//! G_ij(i omega) = sum_n phi_in phi_jn / (omega_n^2 - omega^2 + 2 i zeta_n omega_n omega), the
//! displacement at coordinate i per unit force at coordinate j (m/N), from 000 Eq. 1; a
//! non-proportional mode multiplies its term by the numerator n_0 + n_1 i omega
//! ([`crate::model::complex_mode_numerator`]).

use crate::model::{ModalModel, Mode};
use num_complex::Complex64;
use std::f64::consts::PI;

impl Mode {
    /// This mode's term of G_ij at `frequency_hz` (m/N).
    pub fn receptance(&self, frequency_hz: f64, i: usize, j: usize) -> Complex64 {
        let w = 2.0 * PI * frequency_hz;
        let phi = self.mass_normalized_shape();
        let wn = self.omega_rad_s();
        let den = Complex64::new(wn * wn - w * w, 2.0 * self.damping_ratio() * wn * w);
        let (n0, n1) = self.receptance_numerator();
        Complex64::new(n0, n1 * w) * (phi[i] * phi[j]) / den
    }
}

impl ModalModel {
    /// Receptance G_ij at `frequency_hz` (m/N) between coordinate indices `i` and `j` (0 or 1).
    ///
    /// ```
    /// use chatter_dynamics::examples;
    /// let model = examples::schmitz_2023_milling();
    /// let g0 = model.receptance(0.0, 0, 0);
    /// // static compliance of one 3e6 N/m mode in x
    /// assert!((g0.re - 1.0 / 3.0e6).abs() < 1e-15);
    /// ```
    pub fn receptance(&self, frequency_hz: f64, i: usize, j: usize) -> Complex64 {
        self.modes()
            .iter()
            .map(|m| m.receptance(frequency_hz, i, j))
            .sum()
    }

    /// The 2 x 2 receptance matrix at `frequency_hz`, rows = response, columns = force.
    pub fn receptance_matrix(&self, frequency_hz: f64) -> [[Complex64; 2]; 2] {
        [
            [
                self.receptance(frequency_hz, 0, 0),
                self.receptance(frequency_hz, 0, 1),
            ],
            [
                self.receptance(frequency_hz, 1, 0),
                self.receptance(frequency_hz, 1, 1),
            ],
        ]
    }
}
