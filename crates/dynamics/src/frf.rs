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
    /// Residual terms ([`crate::model::ResidualTerms`]) add to the direct receptances.
    pub fn receptance(&self, frequency_hz: f64, i: usize, j: usize) -> Complex64 {
        let modes: Complex64 = self
            .modes()
            .iter()
            .map(|m| m.receptance(frequency_hz, i, j))
            .sum();
        if i == j {
            modes + self.residuals()[i].receptance(frequency_hz)
        } else {
            modes
        }
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

#[cfg(test)]
mod tests {
    use crate::examples;
    use crate::model::{Mode, ModeShape};
    use num_complex::Complex64;
    use std::f64::consts::PI;

    /// A complex mode's receptance equals the pole-residue pair written out directly,
    /// A / (i w - lambda) + conj(A) / (i w - conj(lambda)), at every frequency; the residue
    /// round-trips through `Mode::from_residue`.
    #[test]
    fn complex_mode_is_the_pole_residue_pair() {
        let (f, zeta) = (1448.53, 0.01651);
        let a = Complex64::new(-4.182e-5, -3.044e-4);
        let mode = Mode::from_residue(f, zeta, 0, a).unwrap();
        let wn = 2.0 * PI * f;
        let lambda = Complex64::new(-zeta * wn, wn * (1.0 - zeta * zeta).sqrt());
        for hz in [0.0, 300.0, 1400.0, 1448.53, 1500.0, 5000.0] {
            let iw = Complex64::new(0.0, 2.0 * PI * hz);
            let direct = a / (iw - lambda) + a.conj() / (iw - lambda.conj());
            let ours = mode.receptance(hz, 0, 0);
            assert!(
                (ours - direct).norm() <= 1e-12 * direct.norm(),
                "{hz}: {ours} vs {direct}"
            );
        }
        // a real mode is the phase-0 case of the same formula
        let real = Mode::new(
            f,
            zeta,
            ModeShape::Directional {
                coordinate: 0,
                stiffness_n_per_m: 1e7,
            },
        )
        .unwrap();
        let back = Mode::from_residue(
            f,
            zeta,
            0,
            Complex64::new(0.0, -wn * wn / (2.0 * lambda.im * 1e7)),
        )
        .unwrap();
        assert!(back.residue_phase_rad().abs() < 1e-15);
        assert!((back.stiffness_at(0) / 1e7 - 1.0).abs() < 1e-12);
        assert!((real.receptance(900.0, 0, 0) - back.receptance(900.0, 0, 0)).norm() < 1e-20);
    }

    #[test]
    fn complex_modes_are_refused_where_they_are_not_defined() {
        let model = examples::schmitz_2023_milling();
        let m = model.modes()[0];
        assert!(m.with_residue_phase(4.0).is_err());
        assert!(m.with_residue_phase(f64::NAN).is_err());
        let undamped = Mode::new(500.0, 0.0, m.shape()).unwrap();
        assert!(undamped.with_residue_phase(0.1).is_err());
        let complex = model
            .with_modes(vec![m.with_residue_phase(0.3).unwrap()])
            .unwrap();
        let e = complex.require_proportional("FDM").unwrap_err().to_string();
        assert!(
            e.contains("FDM") && e.contains("modes[0].residue_phase_deg"),
            "{e}"
        );
        let e = examples::ebrahimi_2025_milling();
        let e = e
            .with_process_damping(None)
            .unwrap()
            .with_modes(vec![e.modes()[0].with_residue_phase(0.3).unwrap()])
            .unwrap()
            .with_process_damping(Some(1e4))
            .unwrap_err()
            .to_string();
        assert!(e.contains("non-proportional"), "{e}");
        // the model file keeps the phase
        let text = complex.to_json_string();
        let back = crate::ModalModel::from_json_str(&text, std::path::Path::new("m.json")).unwrap();
        assert!(
            (back.modes()[0].residue_phase_rad() - 0.3).abs() < 1e-12,
            "{text}"
        );
    }

    /// Residual terms from a model file: the direct receptances gain U - L / w^2 (written out),
    /// cross terms none; the file round-trips them; bad entries name their field.
    #[test]
    fn residual_terms_add_to_the_direct_receptances() {
        let path = std::path::Path::new("r.json");
        let file = |residuals: &str| {
            format!(
                r#"{{"operation": {{"kind": "milling", "teeth": 2, "radial_immersion": 0.5, "direction": "down"}},
                   "cutting": {{"kt_n_per_mm2": 700, "kn_n_per_mm2": 200}},
                   "modes": [{{"frequency_hz": 600, "damping_ratio": 0.03, "shape": {{"x": 2.0, "y": 1.0}}}}],
                   "residuals": [{residuals}]}}"#
            )
        };
        let model = crate::ModalModel::from_json_str(
            &file(r#"{"direction": "y", "upper_m_per_n": 2e-8}, {"direction": "x", "upper_m_per_n": 5e-8, "lower_per_kg": 0.4}"#),
            path,
        )
        .unwrap();
        let bare = model.with_residuals(Default::default()).unwrap();
        for f in [50.0, 400.0, 600.0, 1700.0] {
            let w = 2.0 * PI * f;
            let gx = model.receptance(f, 0, 0) - bare.receptance(f, 0, 0);
            let gy = model.receptance(f, 1, 1) - bare.receptance(f, 1, 1);
            assert!((gx - Complex64::new(5e-8 - 0.4 / (w * w), 0.0)).norm() < 1e-22);
            assert!((gy - Complex64::new(2e-8, 0.0)).norm() < 1e-22);
            assert_eq!(model.receptance(f, 0, 1), bare.receptance(f, 0, 1));
        }
        // without a lower term the static receptance stays finite
        assert!(
            bare.with_residuals([Default::default(), model.residuals()[1]])
                .unwrap()
                .receptance(0.0, 1, 1)
                .re
                .is_finite()
        );
        let back = crate::ModalModel::from_json_str(&model.to_json_string(), path).unwrap();
        assert_eq!(back.residuals(), model.residuals());
        assert_eq!(
            back.with_modes(back.modes().to_vec()).unwrap().residuals(),
            model.residuals()
        );
        for (entry, needle) in [
            (
                r#"{"direction": "z", "upper_m_per_n": 1e-8}"#,
                "residuals[0].direction",
            ),
            (r#"{"direction": "x"}, {"direction": "x"}"#, "twice"),
            (r#"{"direction": "x", "lower_kg": 1}"#, "lower_kg"),
        ] {
            let e = crate::ModalModel::from_json_str(&file(entry), path)
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle), "{e}");
        }
        let e = model.require_proportional("SDM").unwrap_err().to_string();
        assert!(e.contains("SDM") && e.contains("residuals[x]"), "{e}");
    }
}
