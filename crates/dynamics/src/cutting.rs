//! Cutting-force models: the directional matrix H(t) that maps the regenerative displacement
//! difference to force, f(t) = -b H(t) (x(t) - x(t - tau)), and process damping.
//!
//! - Turning (000 Eq. 3): f = a K_c (x(t - tau) - x(t)) with K_c = [k_fc, k_tc]^T [1, 0] over
//!   (feed, cutting), so H = K_c is constant.
//! - Milling (Insperger and Stépán; 002 Eq. 1-2): with tooth angles phi_j(t) = Omega t + 2 pi j/N
//!   measured from the y axis and g_j = 1 while tooth j cuts,
//!   h_xx = sum g sin(phi) (kt cos(phi) + kn sin(phi)), h_xy = sum g cos(phi) (kt cos(phi) + kn sin(phi)),
//!   h_yx = sum g sin(phi) (-kt sin(phi) + kn cos(phi)), h_yy = sum g cos(phi) (-kt sin(phi) + kn cos(phi)).
//!   Its average over a tooth period, (N / 2 pi) int_{entry}^{exit} h(phi) dphi, is the matrix the
//!   zero-order approximation (Altintas and Budak) uses.
//! - Process damping (003 Eq. 1): F_d = -C b ydot / V along the surface normal (the direction in
//!   which the chip thickness is measured), with V the cutting speed.

use crate::model::{CuttingCoefficients, ModalModel};
use crate::operation::{CuttingEdge, Milling, Operation};
use nalgebra::Matrix2;
use std::f64::consts::PI;

/// Directional matrix of a single milling tooth at angle `phi` (rad) if it cuts, else zero.
pub fn milling_tooth_matrix(cutting: CuttingCoefficients, phi: f64) -> Matrix2<f64> {
    let (kt, kn) = (cutting.kt_n_per_m2(), cutting.kn_n_per_m2());
    let (s, c) = phi.sin_cos();
    Matrix2::new(
        s * (kt * c + kn * s),
        c * (kt * c + kn * s),
        s * (-kt * s + kn * c),
        c * (-kt * s + kn * c),
    )
}

/// Whether a tooth at angle `phi` (any real, reduced modulo 2 pi) is in the cut.
pub fn tooth_in_cut(milling: &Milling, phi: f64) -> bool {
    let (entry, exit) = milling.entry_exit_rad();
    let p = phi.rem_euclid(2.0 * PI);
    p >= entry && p <= exit
}

/// Surface normal (chip-thickness) direction of a tooth at `phi`: h = sin(phi) dx + cos(phi) dy.
pub fn milling_chip_direction(phi: f64) -> [f64; 2] {
    let (s, c) = phi.sin_cos();
    [s, c]
}

impl ModalModel {
    /// H(t) at time `t_s` (s) and spindle speed `speed_rpm`: the sum over teeth in the cut for
    /// milling (tooth 0 at phi = 0 when t = 0), the constant K_c for turning. In N/m^2.
    pub fn directional_matrix(&self, t_s: f64, speed_rpm: f64) -> Matrix2<f64> {
        let cutting = self.cutting();
        match self.operation() {
            Operation::Turning(_) => turning_matrix(cutting),
            Operation::Milling(m) => {
                let omega = 2.0 * PI * speed_rpm / 60.0;
                let n = m.teeth();
                (0..n)
                    .map(|j| omega * t_s + m.tooth_offset_rad(j))
                    .filter(|&phi| tooth_in_cut(m, phi))
                    .map(|phi| milling_tooth_matrix(cutting, phi))
                    .sum()
            }
        }
    }

    /// Tooth j's part of H(t) (N/m^2): its directional matrix while it cuts, else zero (tooth j
    /// at phi_j = Omega t + offset_j, [`Milling::tooth_offset_rad`]); its force acts on the
    /// displacement difference over its own delay, pitch_j / Omega. Turning has one edge (j = 0),
    /// K_c. The sum over j is [`Self::directional_matrix`].
    pub fn tooth_directional_matrix(&self, tooth: usize, t_s: f64, speed_rpm: f64) -> Matrix2<f64> {
        let cutting = self.cutting();
        match self.operation() {
            Operation::Turning(_) => turning_matrix(cutting),
            Operation::Milling(m) => {
                let phi = 2.0 * PI * speed_rpm / 60.0 * t_s + m.tooth_offset_rad(tooth);
                if tooth_in_cut(m, phi) {
                    milling_tooth_matrix(cutting, phi)
                } else {
                    Matrix2::zeros()
                }
            }
        }
    }

    /// A cutting edge element's part of H(t) per unit depth (N/m^2): its weight times the tooth
    /// directional matrix at phi = Omega t + lead while it cuts, else zero ([`CuttingEdge`],
    /// [`Milling::cutting_edges`]); its force acts on the displacement difference over its own
    /// delay. Turning has one edge, K_c times the weight.
    pub fn edge_directional_matrix(
        &self,
        edge: &CuttingEdge,
        t_s: f64,
        speed_rpm: f64,
    ) -> Matrix2<f64> {
        let cutting = self.cutting();
        match self.operation() {
            Operation::Turning(_) => turning_matrix(cutting) * edge.weight,
            Operation::Milling(m) => {
                let phi = 2.0 * PI * speed_rpm / 60.0 * t_s + edge.lead_rad;
                if tooth_in_cut(m, phi) {
                    milling_tooth_matrix(cutting, phi) * edge.weight
                } else {
                    Matrix2::zeros()
                }
            }
        }
    }

    /// The average of H(t) over one delay: exact integral for milling, K_c for turning (N/m^2).
    pub fn average_directional_matrix(&self) -> Matrix2<f64> {
        average_directional_matrix(self.operation(), self.cutting())
    }

    /// Process-damping coefficient per unit chip width and velocity, C / V (N s/m^3), at
    /// `speed_rpm`, or 0 when the model has no process damping (003 Eq. 1).
    pub fn process_damping_per_width(&self, speed_rpm: f64) -> f64 {
        match (
            self.process_damping_n_per_m(),
            self.operation().cutting_speed_m_per_s(speed_rpm),
        ) {
            (Some(c), Some(v)) if v > 0.0 => c / v,
            _ => 0.0,
        }
    }

    /// Process-damping matrix D(t) (N s/m^3) at time `t_s`: the force is F_d = -b D(t) xdot.
    /// Turning: C/V on the feed coordinate. Milling: C/V n n^T summed over teeth in the cut,
    /// n the chip-thickness direction of each tooth.
    pub fn process_damping_matrix(&self, t_s: f64, speed_rpm: f64) -> Matrix2<f64> {
        let cv = self.process_damping_per_width(speed_rpm);
        if cv == 0.0 {
            return Matrix2::zeros();
        }
        match self.operation() {
            Operation::Turning(_) => Matrix2::new(cv, 0.0, 0.0, 0.0),
            Operation::Milling(m) => {
                let omega = 2.0 * PI * speed_rpm / 60.0;
                let n = m.teeth();
                (0..n)
                    .map(|j| omega * t_s + m.tooth_offset_rad(j))
                    .filter(|&phi| tooth_in_cut(m, phi))
                    .map(|phi| {
                        let d = milling_chip_direction(phi);
                        Matrix2::new(d[0] * d[0], d[0] * d[1], d[1] * d[0], d[1] * d[1]) * cv
                    })
                    .sum()
            }
        }
    }
}

/// The average of H(t) over one delay for `operation` and `cutting` (N/m^2): the exact integral
/// (N / 2 pi) int_{entry}^{exit} h(phi) dphi for milling, K_c for turning. The matrix of the
/// zero-order method, for modal and measured-FRF models alike.
pub fn average_directional_matrix(
    operation: &Operation,
    cutting: CuttingCoefficients,
) -> Matrix2<f64> {
    match operation {
        Operation::Turning(_) => turning_matrix(cutting),
        Operation::Milling(m) => {
            let (kt, kn) = (cutting.kt_n_per_m2(), cutting.kn_n_per_m2());
            let (a, b) = m.entry_exit_rad();
            // antiderivatives of sin*cos, sin^2, cos^2
            let sc = |p: f64| 0.5 * p.sin().powi(2);
            let ss = |p: f64| 0.5 * p - 0.25 * (2.0 * p).sin();
            let cc = |p: f64| 0.5 * p + 0.25 * (2.0 * p).sin();
            let i_sc = sc(b) - sc(a);
            let i_ss = ss(b) - ss(a);
            let i_cc = cc(b) - cc(a);
            let f = m.teeth() as f64 / (2.0 * PI);
            Matrix2::new(
                f * (kt * i_sc + kn * i_ss),
                f * (kt * i_cc + kn * i_sc),
                f * (-kt * i_ss + kn * i_sc),
                f * (-kt * i_sc + kn * i_cc),
            )
        }
    }
}

/// Turning K_c over (feed, cutting): the feed displacement sets the chip thickness; the feed
/// force is k_fc h and the cutting force k_tc h (000 Eq. 3).
fn turning_matrix(cutting: CuttingCoefficients) -> Matrix2<f64> {
    Matrix2::new(cutting.kn_n_per_m2(), 0.0, cutting.kt_n_per_m2(), 0.0)
}

#[cfg(test)]
mod tests {
    use crate::examples;
    use std::f64::consts::PI;

    #[test]
    fn average_matrix_equals_numerical_time_average() {
        // 001 example (20 % down milling) and the benchmark at full and 5 % immersion.
        for model in [
            examples::schmitz_2023_milling(),
            examples::insperger_benchmark(1.0),
            examples::insperger_benchmark(0.05),
        ] {
            let rpm = 6000.0;
            let tau = model.operation().delay_s(rpm);
            let n = 200_000;
            let mut avg = nalgebra::Matrix2::zeros();
            for k in 0..n {
                let t = (k as f64 + 0.5) / n as f64 * tau;
                avg += model.directional_matrix(t, rpm);
            }
            avg /= n as f64;
            let exact = model.average_directional_matrix();
            let scale = exact.abs().max();
            // midpoint rule over a discontinuous integrand: error O(1/n) of the scale
            assert!(
                (avg - exact).abs().max() < 1e-4 * scale,
                "{:?}: numeric {avg} vs exact {exact}",
                model.name()
            );
        }
    }

    #[test]
    fn full_immersion_average_is_classic_result() {
        // Slotting: A0 = N/(4 pi) [[0, pi kt], [-pi kt, 0]]... with kn: N/(2 pi) * pi/2 [[kn, kt], [-kt, kn]]
        let model = examples::insperger_benchmark(1.0);
        let a = model.average_directional_matrix();
        let (kt, kn) = (6e8, 2e8);
        let f = 2.0 / (2.0 * PI) * PI / 2.0;
        assert!((a[(0, 0)] - f * kn).abs() < 1e-6 * kt);
        assert!((a[(0, 1)] - f * kt).abs() < 1e-6 * kt);
        assert!((a[(1, 0)] + f * kt).abs() < 1e-6 * kt);
        assert!((a[(1, 1)] - f * kn).abs() < 1e-6 * kt);
    }

    #[test]
    fn turning_matrix_is_kc() {
        let model = examples::ahmadi_2022_turning();
        let h = model.directional_matrix(0.3, 7000.0);
        assert_eq!(h[(0, 0)], 159e6);
        assert_eq!(h[(1, 0)], 635e6);
        assert_eq!(h[(0, 1)], 0.0);
        assert_eq!(h[(1, 1)], 0.0);
    }

    #[test]
    fn process_damping_turning_acts_on_feed() {
        let model = examples::ahmadi_2022_turning()
            .with_process_damping(Some(2.0e5))
            .unwrap();
        let rpm = 6000.0;
        let v = PI * 0.038 * rpm / 60.0;
        let d = model.process_damping_matrix(0.0, rpm);
        assert!((d[(0, 0)] - 2.0e5 / v).abs() < 1e-9 * d[(0, 0)]);
        assert_eq!(d[(1, 1)], 0.0);
    }
}
