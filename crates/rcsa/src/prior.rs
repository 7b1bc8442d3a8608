//! Seed 004's prior (Schmitz et al. 2022, Section 2 and Fig. 2): the uncertain holder-tool
//! connection k ~ U(k_lo, k_hi), c ~ U(c_lo, c_hi) is propagated through RCSA to an ensemble of
//! tool-tip FRFs; each FRF is fitted with two modes (`chatter_frf::fit_modes`), and the modal
//! parameters' mean and covariance, together with the independent force-model priors
//! K_s ~ N(600, 60) N/mm^2 and beta ~ N(68, 13.6) deg, give the multivariate normal prior over
//! u = [K_s, beta, f_n1, k_1, zeta_1, f_n2, k_2, zeta_2]. Monte Carlo draws of u give stability
//! boundaries (zero-order, Altintas-Budak, with K_t = K_s sin beta, K_n = K_s cos beta as in 001)
//! and so the probability-of-stability map and the chatter-frequency distribution of Fig. 2.
//!
//! The tool is taken as symmetric: each fitted mode acts in x and in y with the same
//! parameters.

use crate::assembly::Assembly;
use crate::coupling::{Connection, FlexibleConnection};
use crate::error::{RcsaError, Result};
use chatter_dynamics::{
    CuttingCoefficients, Milling, MillingDirection, ModalModel, Mode, ModeShape, Operation,
};
use chatter_frf::{FitOptions, fit_modes};
use chatter_uncertainty::montecarlo::{
    FailureKind, SampleFailure, SampledBoundaries, gaussian_draws,
};
use nalgebra::DMatrix;
use rand::SeedableRng;
use rand_distr::{Distribution, Uniform};
use rayon::prelude::*;

/// Names of u, in order (the prior file's `parameter_names`).
pub const PRIOR_PARAMETER_NAMES: [&str; 8] = [
    "ks_n_per_mm2",
    "beta_deg",
    "fn1_hz",
    "k1_n_per_m",
    "zeta1",
    "fn2_hz",
    "k2_n_per_m",
    "zeta2",
];

/// Settings of the FRF ensemble and the force-model prior; `Default` is 004's values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PriorSettings {
    /// Range of the rotational connection stiffness k (N m/rad); 004: 1e6 to 1e7.
    pub k_n_per_rad: (f64, f64),
    /// Range of the rotational connection damping c (N m s/rad); 004: 11 to 20.
    pub c_n_s_per_rad: (f64, f64),
    /// Number of RCSA FRFs in the ensemble; default 200.
    pub frfs: usize,
    /// Band of the two-mode fits (Hz).
    pub fit_band_hz: (f64, f64),
    /// K_s mean and standard deviation (N/mm^2); 004: 600, 60.
    pub ks_n_per_mm2: (f64, f64),
    /// beta mean and standard deviation (deg); 004: 68, 13.6.
    pub beta_deg: (f64, f64),
    /// Seed of the connection draws.
    pub seed: u64,
}

impl Default for PriorSettings {
    fn default() -> Self {
        Self {
            k_n_per_rad: (1e6, 1e7),
            c_n_s_per_rad: (11.0, 20.0),
            frfs: 200,
            fit_band_hz: (500.0, 6000.0),
            ks_n_per_mm2: (600.0, 60.0),
            beta_deg: (68.0, 13.6),
            seed: 4,
        }
    }
}

/// The multivariate normal prior N(mean, covariance) over u ([`PRIOR_PARAMETER_NAMES`]), and
/// the FRF ensemble's fitted modal parameters it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalPrior {
    /// Mean of u.
    pub mean: Vec<f64>,
    /// Covariance of u.
    pub covariance: DMatrix<f64>,
    /// Fitted [f_n1, k_1, zeta_1, f_n2, k_2, zeta_2] per ensemble FRF.
    pub fitted: Vec<[f64; 6]>,
}

/// Propagate the connection uncertainty through RCSA and fit two modes to each FRF (parallel
/// over the ensemble, seeded; the result does not depend on the thread count).
pub fn rcsa_prior(assembly: &Assembly, settings: &PriorSettings) -> Result<ModalPrior> {
    let range = |(lo, hi): (f64, f64), name: &str| {
        Uniform::new_inclusive(lo, hi)
            .map_err(|_| RcsaError::value(name, lo, format!("a range with lower <= upper ({hi})")))
    };
    let (uk, uc) = (
        range(settings.k_n_per_rad, "k_n_per_rad")?,
        range(settings.c_n_s_per_rad, "c_n_s_per_rad")?,
    );
    if settings.frfs < 10 {
        return Err(RcsaError::value(
            "frfs",
            settings.frfs as f64,
            "at least 10 FRFs",
        ));
    }
    let mut rng = rand::rngs::StdRng::seed_from_u64(settings.seed);
    let draws: Vec<(f64, f64)> = (0..settings.frfs)
        .map(|_| (uk.sample(&mut rng), uc.sample(&mut rng)))
        .collect();
    let (f0, f1) = settings.fit_band_hz;
    let options = FitOptions {
        modes: Some(2),
        ..FitOptions::default()
    };
    let fitted = draws
        .par_iter()
        .map(|&(k, c)| {
            let a = assembly.with_connection(Connection::Flexible(FlexibleConnection {
                k_n_per_rad: k,
                c_n_s_per_rad: c,
                k_n_per_m: None,
                c_n_s_per_m: None,
            }));
            let fit = fit_modes(&a.tool_tip_frf()?, f0, f1, &options)?;
            let mut modes: Vec<[f64; 3]> = fit
                .modes
                .iter()
                .map(|m| {
                    m.stiffness_n_per_m
                        .map(|s| [m.pole.frequency_hz, s, m.pole.damping_ratio])
                        .ok_or_else(|| {
                            RcsaError::Frf(chatter_frf::FrfError::Fit(format!(
                                "the mode at {:.1} Hz (k = {k:.3e}, c = {c:.2}) is not a real mode",
                                m.pole.frequency_hz
                            )))
                        })
                })
                .collect::<Result<_>>()?;
            if modes.len() != 2 {
                return Err(RcsaError::Frf(chatter_frf::FrfError::Fit(format!(
                    "{} modes fitted for k = {k:.3e}, c = {c:.2}, 2 expected",
                    modes.len()
                ))));
            }
            modes.sort_by(|a, b| a[0].total_cmp(&b[0]));
            Ok([
                modes[0][0],
                modes[0][1],
                modes[0][2],
                modes[1][0],
                modes[1][1],
                modes[1][2],
            ])
        })
        .collect::<Result<Vec<[f64; 6]>>>()?;
    let n = fitted.len() as f64;
    let modal_mean: Vec<f64> = (0..6)
        .map(|j| fitted.iter().map(|r| r[j]).sum::<f64>() / n)
        .collect();
    let mut covariance = DMatrix::zeros(8, 8);
    covariance[(0, 0)] = settings.ks_n_per_mm2.1.powi(2);
    covariance[(1, 1)] = settings.beta_deg.1.powi(2);
    for a in 0..6 {
        for b in 0..6 {
            covariance[(a + 2, b + 2)] = fitted
                .iter()
                .map(|r| (r[a] - modal_mean[a]) * (r[b] - modal_mean[b]))
                .sum::<f64>()
                / (n - 1.0);
        }
    }
    let mut mean = vec![settings.ks_n_per_mm2.0, settings.beta_deg.0];
    mean.extend(modal_mean);
    Ok(ModalPrior {
        mean,
        covariance,
        fitted,
    })
}

impl ModalPrior {
    /// The prior as the samplers take it: [`chatter_bayes::prior::MultivariateNormalPrior`] over
    /// u, an error where the covariance is not positive definite (too few FRFs for 8 parameters).
    pub fn bayes_prior(&self) -> Result<chatter_bayes::prior::MultivariateNormalPrior> {
        let cov: Vec<Vec<f64>> = (0..self.mean.len())
            .map(|i| {
                (0..self.mean.len())
                    .map(|j| self.covariance[(i, j)])
                    .collect()
            })
            .collect();
        chatter_bayes::prior::MultivariateNormalPrior::new(self.mean.clone(), &cov)
            .map_err(|e| RcsaError::value("prior covariance", f64::NAN, e.to_string()))
    }

    /// The prior file: `{"parameter_names": [...], "mean": [...], "covariance": [[...]]}`.
    pub fn to_json(&self) -> serde_json::Value {
        let cov: Vec<Vec<f64>> = (0..8)
            .map(|i| (0..8).map(|j| self.covariance[(i, j)]).collect())
            .collect();
        serde_json::json!({
            "parameter_names": PRIOR_PARAMETER_NAMES,
            "mean": self.mean,
            "covariance": cov,
        })
    }
}

/// The milling model of one u: `operation` with K_t = K_s sin beta, K_n = K_s cos beta and the
/// two modes in x and in y.
pub fn model_of(u: &[f64], operation: &Operation) -> chatter_dynamics::Result<ModalModel> {
    let (ks, beta) = (u[0] * 1e6, u[1].to_radians());
    let cutting = CuttingCoefficients::new(ks * beta.sin(), ks * beta.cos())?;
    let mut modes = Vec::with_capacity(4);
    for m in [&u[2..5], &u[5..8]] {
        for coordinate in 0..2 {
            modes.push(Mode::new(
                m[0],
                m[2],
                ModeShape::Directional {
                    coordinate,
                    stiffness_n_per_m: m[1],
                },
            )?);
        }
    }
    ModalModel::new(None, operation.clone(), cutting, modes, None)
}

/// 004's cut: three flutes, down milling at `radial_immersion` (004's tests: 0.75).
pub fn three_flute_milling(radial_immersion: f64) -> chatter_dynamics::Result<Operation> {
    Ok(Operation::Milling(Milling::new(
        3,
        radial_immersion,
        MillingDirection::Down,
        Some(12.7e-3),
        None,
    )?))
}

/// Zero-order stability boundaries of `samples` draws of the prior (seeded; parallel over the
/// draws, independent of the thread count). A draw outside the support (a negative stiffness
/// or damping) is recorded as a failure, never as a boundary.
pub fn prior_boundaries(
    prior: &ModalPrior,
    operation: &Operation,
    speeds_rpm: &[f64],
    samples: usize,
    seed: u64,
) -> Result<SampledBoundaries> {
    let draws = gaussian_draws(&prior.mean, &prior.covariance, samples, seed)
        .map_err(|e| RcsaError::value("prior covariance", f64::NAN, e.to_string()))?;
    type Row = (Vec<f64>, Vec<f64>, Option<SampleFailure>);
    let rows: Vec<Row> = draws
        .par_iter()
        .enumerate()
        .map(|(s, u)| {
            let lobes = model_of(u, operation)
                .map_err(|e| e.to_string())
                .and_then(|m| {
                    chatter_stability::zero_order::zoa_lobes(&m, speeds_rpm)
                        .map_err(|e| e.to_string())
                });
            match lobes {
                Ok(points) => (
                    points.iter().map(|p| p.depth_mm()).collect(),
                    points.iter().map(|p| p.chatter_hz).collect(),
                    None,
                ),
                Err(message) => (
                    vec![f64::NAN; speeds_rpm.len()],
                    vec![f64::NAN; speeds_rpm.len()],
                    Some(SampleFailure {
                        sample: s,
                        speed_rpm: None,
                        kind: FailureKind::InvalidSample,
                        message,
                    }),
                ),
            }
        })
        .collect();
    let mut limits = Vec::with_capacity(rows.len());
    let mut hz = Vec::with_capacity(rows.len());
    let mut failures = Vec::new();
    for (l, h, f) in rows {
        limits.push(l);
        hz.push(h);
        failures.extend(f);
    }
    Ok(SampledBoundaries::new(speeds_rpm.to_vec(), limits, hz)
        .map_err(|e| RcsaError::value("samples", samples as f64, e.to_string()))?
        .with_failures(failures))
}
