//! Likelihoods of test-cut results: stable or chatter at (speed, depth), with the chatter
//! frequency when it was measured.
//!
//! A sampled model predicts the limiting depth b_lim and the boundary chatter frequency f_lim at
//! the cut's speed. With b_test the tested depth (Schmitz et al. 2022, seed 004, Section 4):
//!
//! - Delta_b = 0 when the prediction is right (stable and b_test < b_lim, or chatter and
//!   b_test >= b_lim), otherwise Delta_b = b_test - b_lim;
//! - Delta_fc = 0 for a stable cut or when no frequency was measured, otherwise
//!   Delta_fc = f_test - f_lim;
//! - P(a | u) = exp(-1/2 ((Delta_b / s_S)^2 + (Delta_fc / s_fc)^2))   (004 Eq. 5).
//!
//! Without the frequency term this is the one-sided likelihood of Karandikar, Tyler and Schmitz
//! (seed 003, Eq. 3 for a stable and Eq. 4 for an unstable result): l = 1 on the side of the path
//! that agrees with the result and exp(-(b - b_test)^2 / k), k = 2 sigma^2, on the other.

use crate::error::{Result, UpdatingError};
use crate::parameters::Parameterization;
use chatter_bayes::LikelihoodFailure;
use chatter_dynamics::Cut;
use chatter_stability::boundary::LobePoint;
use chatter_stability::prepared::SolverOptions;

/// The kernel of a cut likelihood: allowed disagreement in depth and chatter frequency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutKernel {
    /// s_S (004) or sigma (003): standard deviation of the boundary depth (m).
    pub sigma_depth_m: f64,
    /// s_fc (004): allowed chatter-frequency disagreement (Hz); `None` ignores frequencies (003).
    pub sigma_chatter_hz: Option<f64>,
}

impl CutKernel {
    /// 003: one-sided, sigma = 0.5 mm, no frequency term.
    pub fn karandikar() -> Self {
        Self {
            sigma_depth_m: 0.5e-3,
            sigma_chatter_hz: None,
        }
    }

    /// 004: s_S = 0.125 mm and s_fc = 50 Hz.
    pub fn schmitz() -> Self {
        Self {
            sigma_depth_m: 0.125e-3,
            sigma_chatter_hz: Some(50.0),
        }
    }

    /// Validated: positive, finite widths.
    pub fn validated(self) -> Result<Self> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if !ok(self.sigma_depth_m) || !self.sigma_chatter_hz.is_none_or(ok) {
            return Err(UpdatingError::InvalidInput {
                field: "cut likelihood",
                message: format!("{self:?}: widths must be finite and > 0"),
            });
        }
        Ok(self)
    }

    /// ln P(a | u) of one cut given the sampled boundary `boundary` at the cut's speed (004 Eq. 5,
    /// 003 Eq. 3-4). An infinite limiting depth predicts stability at every depth.
    pub fn ln_likelihood(&self, cut: &Cut, boundary: &LobePoint) -> f64 {
        let b_test = cut.depth_mm * 1e-3;
        let predicted_stable = b_test < boundary.depth_m;
        let delta_b = if predicted_stable == cut.stable {
            0.0
        } else {
            b_test - boundary.depth_m
        };
        let mut chi2 = (delta_b / self.sigma_depth_m).powi(2);
        if let (false, Some(f), Some(s)) = (cut.stable, cut.chatter_hz, self.sigma_chatter_hz)
            && boundary.chatter_hz.is_finite()
        {
            chi2 += ((f - boundary.chatter_hz) / s).powi(2);
        }
        -0.5 * chi2
    }
}

/// The cut-result likelihood of a set of cuts as a function of the model parameters (for the
/// samplers): the product of [`CutKernel::ln_likelihood`] over the cuts, each with the sampled
/// model's boundary at its speed ([`SolverOptions`]: full discretization with process damping
/// by default, on the nominal model's grid).
#[derive(Debug, Clone)]
pub struct CutsLikelihood {
    parameterization: Parameterization,
    cuts: Vec<Cut>,
    /// Distinct speeds and, per cut, the index of its speed.
    speeds_rpm: Vec<f64>,
    speed_of: Vec<usize>,
    kernel: CutKernel,
    options: SolverOptions,
}

impl CutsLikelihood {
    /// Build from the parameterization, the cuts (at least one) and the kernel; an error naming
    /// the field when the method cannot take the model (FDM or SDM with complex modes or
    /// residual terms, [`chatter_dynamics::ModalModel::require_proportional`]).
    pub fn new(
        parameterization: Parameterization,
        cuts: Vec<Cut>,
        kernel: CutKernel,
        options: SolverOptions,
    ) -> Result<Self> {
        if cuts.is_empty() {
            return Err(UpdatingError::Observations("no test cuts".into()));
        }
        let kernel = kernel.validated()?;
        // a discretization that cannot take the model (complex modes, residual terms) would fail
        // at every sample, which the samplers count as numerical failures: say so here instead
        if options.method.discretization().is_some() {
            parameterization
                .nominal()
                .require_proportional(options.method.name())?;
        }
        let mut speeds_rpm: Vec<f64> = Vec::new();
        let speed_of = cuts
            .iter()
            .map(|c| {
                speeds_rpm
                    .iter()
                    .position(|s| *s == c.speed_rpm)
                    .unwrap_or_else(|| {
                        speeds_rpm.push(c.speed_rpm);
                        speeds_rpm.len() - 1
                    })
            })
            .collect();
        Ok(Self {
            parameterization,
            cuts,
            speeds_rpm,
            speed_of,
            kernel,
            options,
        })
    }

    /// Number of sampled parameters.
    pub fn dimension(&self) -> usize {
        self.parameterization.dimension()
    }

    /// The parameterization theta -> model.
    pub fn parameterization(&self) -> &Parameterization {
        &self.parameterization
    }

    /// ln prod_i P(a_i | theta) (004 Eq. 7 without the prior); -inf where the model cannot be
    /// built or its boundary fails (see [`Self::try_ln_likelihood`] for which).
    pub fn ln_likelihood(&self, theta: &[f64]) -> f64 {
        self.try_ln_likelihood(theta).unwrap_or(f64::NEG_INFINITY)
    }

    /// ln prod_i P(a_i | theta), or why there is none: outside the support where the
    /// parameters make no valid model, numerical where the boundary solver fails.
    pub fn try_ln_likelihood(&self, theta: &[f64]) -> std::result::Result<f64, LikelihoodFailure> {
        let model = self
            .parameterization
            .model(theta)
            .map_err(|_| LikelihoodFailure::OutsideSupport)?;
        let grid = self.parameterization.nominal();
        let boundaries = self
            .options
            .prepare_on_grid_of(&model, grid)
            .and_then(|solver| solver.limiting_depths(&self.speeds_rpm))
            .map_err(|_| LikelihoodFailure::Numerical)?;
        Ok(self
            .cuts
            .iter()
            .zip(&self.speed_of)
            .map(|(c, &k)| self.kernel.ln_likelihood(c, &boundaries[k]))
            .sum())
    }
}

impl chatter_bayes::LogLikelihood for CutsLikelihood {
    fn ln_likelihood(&self, theta: &[f64]) -> f64 {
        CutsLikelihood::ln_likelihood(self, theta)
    }
    fn try_ln_likelihood(&self, theta: &[f64]) -> std::result::Result<f64, LikelihoodFailure> {
        CutsLikelihood::try_ln_likelihood(self, theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cut(depth_mm: f64, stable: bool, chatter_hz: Option<f64>) -> Cut {
        Cut {
            speed_rpm: 1000.0,
            depth_mm,
            stable,
            chatter_hz,
            sequence: None,
            radial_immersion: None,
            note: None,
            evidence: None,
        }
    }

    #[test]
    fn one_sided_likelihoods_match_003_eq_3_and_4() {
        let k = CutKernel::karandikar();
        let path = LobePoint {
            speed_rpm: 1000.0,
            depth_m: 2e-3,
            chatter_hz: 230.0,
        };
        // stable at 3 mm on a 2 mm path: exp(-(b - b_test)^2 / (2 sigma^2)) with sigma 0.5 mm
        let l = k.ln_likelihood(&cut(3.0, true, None), &path);
        assert!((l + 0.5 * (1.0f64 / 0.5).powi(2)).abs() < 1e-12);
        // stable below the path, unstable above it: likelihood 1
        assert_eq!(k.ln_likelihood(&cut(1.0, true, None), &path), 0.0);
        assert_eq!(k.ln_likelihood(&cut(3.0, false, Some(250.0)), &path), 0.0);
        // unstable below the path
        let l = k.ln_likelihood(&cut(1.5, false, None), &path);
        assert!((l + 0.5).abs() < 1e-12);
        // 004 adds the frequency term for chatter
        let s = CutKernel::schmitz();
        let l = s.ln_likelihood(&cut(3.0, false, Some(330.0)), &path);
        assert!((l + 0.5 * 4.0).abs() < 1e-12);
        // an unbounded path predicts stability everywhere
        let inf = LobePoint {
            depth_m: f64::INFINITY,
            chatter_hz: f64::NAN,
            ..path
        };
        assert_eq!(s.ln_likelihood(&cut(3.0, true, None), &inf), 0.0);
        assert_eq!(
            s.ln_likelihood(&cut(3.0, false, Some(250.0)), &inf),
            f64::NEG_INFINITY
        );
        assert!(
            CutKernel {
                sigma_depth_m: 0.0,
                sigma_chatter_hz: None
            }
            .validated()
            .is_err()
        );
    }
}
