//! The characteristic-equation residual likelihood for turning (Ahmadi 2022, seed 000,
//! Eq. 28-31).
//!
//! An identified closed-loop pole lambda_hat at width a and spindle period tau should be a root of
//! the characteristic equation. Substituting it gives the residual (Eq. 28, written with this
//! toolkit's sign convention q'' + 2 Omega Z q' + Omega^2 q = -a Phi^T K_c Phi (q - q_tau))
//!
//! e_R + i e_I = det(lambda^2 I + 2 Omega Z lambda + Omega^2 + a Phi^T K_c Phi (1 - e^{-lambda tau})),
//!
//! with Omega, Z, Phi functions of theta. The real and imaginary parts are normalized by their
//! mean absolute values at theta = 0 and taken as independent zero-mean Gaussians with variances
//! sigma_R^2 and sigma_I^2 = alpha sigma_R^2 (Eq. 29-31); sigma_R^2 is sampled with the modal
//! parameters (the last entry of theta) and alpha defines the model class.

use crate::error::{Result, UpdatingError};
use chatter_dynamics::{ModalModel, Operation, Parameter, PoleObservation};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::f64::consts::PI;

/// An identified pole at a cutting condition, in SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObservedPole {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Width of cut (m).
    pub depth_m: f64,
    /// Continuous-time pole lambda = -zeta w + i w sqrt(1 - zeta^2) (rad/s).
    pub lambda: Complex64,
}

impl ObservedPole {
    /// The pole of frequency f (Hz) and damping ratio zeta (000 Eq. 25 inverted).
    pub fn from_frequency_damping(
        speed_rpm: f64,
        depth_m: f64,
        frequency_hz: f64,
        zeta: f64,
    ) -> Self {
        let w = 2.0 * PI * frequency_hz;
        Self {
            speed_rpm,
            depth_m,
            lambda: Complex64::new(-zeta * w, w * (1.0 - zeta * zeta).max(0.0).sqrt()),
        }
    }
}

/// Expand tabulated poles (mean and standard deviation over `repetitions`) into individual
/// identifications, as the likelihood of 000 sums over all N_r x N_s poles. The repetitions are
/// placed deterministically at the normal quantiles (k - 1/2)/N_s of frequency and damping (in
/// opposite order, so they are uncorrelated), which reproduces the table's mean and spread
/// without random numbers. Entries without a standard deviation count once at their mean.
pub fn expand_repetitions(poles: &[PoleObservation]) -> Vec<ObservedPole> {
    let mut out = Vec::new();
    for p in poles {
        let n = p.repetitions.unwrap_or(1).max(1) as usize;
        let (sf, sz) = (
            p.frequency_std_hz.unwrap_or(0.0),
            p.damping_std.unwrap_or(0.0),
        );
        let depth_m = p.depth_mm * 1e-3;
        if n == 1 || (sf == 0.0 && sz == 0.0) {
            out.push(ObservedPole::from_frequency_damping(
                p.speed_rpm,
                depth_m,
                p.frequency_hz,
                p.damping_ratio,
            ));
            continue;
        }
        let z: Vec<f64> = (0..n)
            .map(|k| normal_quantile((k as f64 + 0.5) / n as f64))
            .collect();
        // rescale so the sample standard deviation equals the table's
        let s = (z.iter().map(|v| v * v).sum::<f64>() / (n - 1) as f64).sqrt();
        for k in 0..n {
            out.push(ObservedPole::from_frequency_damping(
                p.speed_rpm,
                depth_m,
                p.frequency_hz + sf * z[k] / s,
                p.damping_ratio + sz * z[n - 1 - k] / s,
            ));
        }
    }
    out
}

/// Inverse standard normal CDF (Acklam's rational approximation, relative error < 1.2e-9).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let p = p.clamp(1e-300, 1.0 - 1e-16);
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// The characteristic-equation residual det(D(lambda)) of a turning model (Eq. 28).
pub fn characteristic_residual(model: &ModalModel, pole: &ObservedPole) -> Complex64 {
    let n = model.mode_count();
    let tau = model.operation().delay_s(pole.speed_rpm);
    let lambda = pole.lambda;
    let phi = model.shape_matrix();
    let h = model.directional_matrix(0.0, pole.speed_rpm);
    // a Phi^T H Phi (N x N)
    let hm = nalgebra::DMatrix::from_fn(2, 2, |i, j| h[(i, j)]);
    let coupling = phi.transpose() * hm * &phi * pole.depth_m;
    let regen = Complex64::new(1.0, 0.0) - (-lambda * tau).exp();
    let omegas = model.omegas_rad_s();
    let zetas = model.damping_ratios();
    let d = DMatrix::from_fn(n, n, |i, j| {
        let mut v = regen * coupling[(i, j)];
        if i == j {
            v += lambda * lambda + 2.0 * zetas[i] * omegas[i] * lambda + omegas[i] * omegas[i];
        }
        v
    });
    d.determinant()
}

/// Likelihood of identified turning poles (000 Eq. 31) for one model class alpha.
///
/// theta = [theta_m..., sigma_R^2]: the named modal perturbations followed by the variance of the
/// normalized real residual.
#[derive(Debug, Clone)]
pub struct TurningPoleLikelihood {
    nominal: ModalModel,
    parameters: Vec<Parameter>,
    poles: Vec<ObservedPole>,
    alpha: f64,
    scale_re: f64,
    scale_im: f64,
}

impl TurningPoleLikelihood {
    /// Build from a turning model, the parameters to update and the identified poles.
    pub fn new(
        nominal: ModalModel,
        parameters: Vec<Parameter>,
        poles: Vec<ObservedPole>,
        alpha: f64,
    ) -> Result<Self> {
        if !matches!(nominal.operation(), Operation::Turning(_)) {
            return Err(UpdatingError::Observations(
                "the characteristic-equation likelihood is for turning models".into(),
            ));
        }
        if poles.is_empty() {
            return Err(UpdatingError::Observations("no identified poles".into()));
        }
        if !(alpha.is_finite() && alpha > 0.0) {
            return Err(UpdatingError::InvalidInput {
                field: "alpha",
                message: format!("{alpha}; expected > 0"),
            });
        }
        let residuals: Vec<Complex64> = poles
            .iter()
            .map(|p| characteristic_residual(&nominal, p))
            .collect();
        let n = residuals.len() as f64;
        let scale_re = residuals.iter().map(|e| e.re.abs()).sum::<f64>() / n;
        let scale_im = residuals.iter().map(|e| e.im.abs()).sum::<f64>() / n;
        if !(scale_re > 0.0 && scale_im > 0.0 && scale_re.is_finite() && scale_im.is_finite()) {
            return Err(UpdatingError::Observations(
                "the nominal residuals vanish or are not finite; cannot normalize".into(),
            ));
        }
        Ok(Self {
            nominal,
            parameters,
            poles,
            alpha,
            scale_re,
            scale_im,
        })
    }

    /// Number of sampled parameters (modal perturbations plus sigma_R^2).
    pub fn dimension(&self) -> usize {
        self.parameters.len() + 1
    }

    /// The model class weight alpha = sigma_I^2 / sigma_R^2.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Normalized residuals (e_R, e_I) at the modal perturbation `theta_m`.
    pub fn normalized_residuals(&self, theta_m: &[f64]) -> Result<Vec<(f64, f64)>> {
        let model = self.nominal.perturbed(&self.parameters, theta_m)?;
        Ok(self
            .poles
            .iter()
            .map(|p| {
                let e = characteristic_residual(&model, p);
                (e.re / self.scale_re, e.im / self.scale_im)
            })
            .collect())
    }

    /// ln p(D | theta, M(alpha)) (Eq. 31); -inf where the model cannot be built.
    pub fn ln_likelihood(&self, theta: &[f64]) -> f64 {
        let Some((&var_r, theta_m)) = theta.split_last() else {
            return f64::NEG_INFINITY;
        };
        if var_r.is_nan() || var_r <= 0.0 || theta_m.len() != self.parameters.len() {
            return f64::NEG_INFINITY;
        }
        let Ok(res) = self.normalized_residuals(theta_m) else {
            return f64::NEG_INFINITY;
        };
        let var_i = self.alpha * var_r;
        let n = res.len() as f64;
        let chi2: f64 = res.iter().map(|(r, i)| r * r / var_r + i * i / var_i).sum();
        -0.5 * chi2 - n * (2.0 * PI * (var_r * var_i).sqrt()).ln()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    #[test]
    fn structural_poles_are_roots_at_zero_width() {
        let model = examples::ahmadi_2022_turning();
        for m in model.modes() {
            let w = m.omega_rad_s();
            let z = m.damping_ratio();
            let pole = ObservedPole {
                speed_rpm: 7000.0,
                depth_m: 0.0,
                lambda: Complex64::new(-z * w, w * (1.0 - z * z).sqrt()),
            };
            let e = characteristic_residual(&model, &pole);
            // det scale ~ w^4; a root leaves only rounding
            assert!(e.norm() < 1e-6 * w.powi(4), "{e}");
        }
    }

    #[test]
    fn expanded_repetitions_keep_mean_and_spread() {
        let obs = examples::ahmadi_2022_turning_observations();
        let poles = expand_repetitions(&obs.poles[..1]);
        assert_eq!(poles.len(), 10);
        let f: Vec<f64> = poles.iter().map(|p| p.lambda.norm() / (2.0 * PI)).collect();
        let mean = f.iter().sum::<f64>() / 10.0;
        let sd = (f.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 9.0).sqrt();
        assert!((mean - 2473.0).abs() < 1e-3, "{mean}");
        assert!((sd - 0.56).abs() < 0.01, "{sd}");
    }

    #[test]
    fn normal_quantile_matches_known_values() {
        assert!(normal_quantile(0.5).abs() < 1e-12);
        assert!((normal_quantile(0.975) - 1.959_963_984_540_054).abs() < 1e-8);
        assert!((normal_quantile(0.001) + 3.090_232_306_167_813).abs() < 1e-8);
    }

    #[test]
    fn likelihood_prefers_the_true_model() {
        // poles generated from a model with mode 2 frequency +1 %: the likelihood at the true
        // theta beats the nominal one.
        let nominal = examples::ahmadi_2022_turning();
        let p = vec!["theta_omega_2".parse::<Parameter>().unwrap()];
        let truth = nominal.perturbed(&p, &[0.01]).unwrap();
        let w = truth.modes()[1].omega_rad_s();
        let poles: Vec<ObservedPole> = [(7150.0, 0.5e-3), (7500.0, 0.3e-3)]
            .iter()
            .map(|&(s, b)| ObservedPole {
                speed_rpm: s,
                depth_m: b,
                lambda: Complex64::new(-0.009 * w, w),
            })
            .collect();
        let like = TurningPoleLikelihood::new(nominal, p, poles, 0.5).unwrap();
        assert!(like.ln_likelihood(&[0.01, 0.01]) > like.ln_likelihood(&[0.0, 0.01]));
        assert_eq!(like.ln_likelihood(&[0.0, -1.0]), f64::NEG_INFINITY);
        assert_eq!(like.ln_likelihood(&[]), f64::NEG_INFINITY);
    }
}
