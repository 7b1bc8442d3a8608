//! The demo job (`chatter demo`): the main jobs on the embedded examples, each through its own
//! request, with the demo's grids and seeds in one [`DemoRequest`]:
//! 1. seed 000's turning tool (Ahmadi 2022): FDM lobes over the tested speeds and the limits at
//!    the speeds of 000 Table 3;
//! 2. its second-order credibility bounds after updating (000 Section 6.4, Eq. 14-18, Fig. 8):
//!    the model at the mean of Eq. 34's posterior with its covariance;
//! 3. seed 001's milling example (Schmitz 2023): zero-order lobes with Type B offsets of
//!    100 rpm and 0.2 mm (001 Sec. 4) and its FRF;
//! 4. a synthetic shop-floor campaign of a milling machine whose process damping the nominal
//!    model leaves out ([`crate::synthetic`]), for the gap diagnosis ([`crate::diagnose`]).
//!
//! The stages are separate calls so that a front end can report progress between them and
//! write each stage's files as it likes.

use crate::bands::PerturbationBands;
use crate::diagnose::DiagnoseRequest;
use crate::error::{JobError, Result};
use crate::frf::{FrfOutcome, FrfRequest};
use crate::lobes::{Dynamics, Lobes, LobesRequest};
use crate::synthetic::{SyntheticCampaignRequest, synthetic_campaign};
use chatter_dynamics::{ModalModel, Observations, examples};
use chatter_gap::EffectClass;
use chatter_progress::Observer;
use chatter_stability::Method;
use chatter_stability::boundary::LobePoint;
use chatter_uncertainty::geometric::OffsetBoundaries;
use chatter_uncertainty::parameters::ParameterDistribution;
use chatter_uncertainty::perturbation::BoundRule;

/// The demo's grids, seeds and settings.
#[derive(Debug, Clone, PartialEq)]
pub struct DemoRequest {
    /// Speeds of the turning lobes (rpm): 6800 to 7700 every 7.5 rpm, the tested range.
    pub turning_speeds_rpm: Vec<f64>,
    /// Speeds at which the summary quotes the turning limit (rpm): 000 Table 3's 6950, 7150,
    /// 7300 and 7500.
    pub limit_speeds_rpm: Vec<f64>,
    /// Speeds of the credibility bounds (rpm): 6800 to 7700 every 25 rpm.
    pub credibility_speeds_rpm: Vec<f64>,
    /// Depth step of the credibility grid (mm), which covers the updated model's lobes: 0.025.
    pub credibility_depth_step_mm: f64,
    /// The bound rule of the credibility bounds: the complex multiplier's standard deviation.
    pub credibility_rule: BoundRule,
    /// The milling example's FRF: 0 to 1500 Hz, 301 frequencies.
    pub milling_frf: FrfRequest,
    /// The synthetic campaign: process damping at twice its reference size, seed 101.
    pub campaign: SyntheticCampaignRequest,
    /// Its diagnosis: seed 1, 120 samples per class, 3-fold validation.
    pub diagnosis: DiagnoseRequest,
}

impl Default for DemoRequest {
    fn default() -> Self {
        Self {
            turning_speeds_rpm: (0..=120).map(|i| 6800.0 + 7.5 * i as f64).collect(),
            limit_speeds_rpm: vec![6950.0, 7150.0, 7300.0, 7500.0],
            credibility_speeds_rpm: (0..=36).map(|i| 6800.0 + 25.0 * i as f64).collect(),
            credibility_depth_step_mm: 0.025,
            credibility_rule: BoundRule::ComplexSd,
            milling_frf: FrfRequest {
                fmin_hz: Some(0.0),
                fmax_hz: Some(1500.0),
                points: 301,
                ..FrfRequest::default()
            },
            campaign: SyntheticCampaignRequest::new(Some(EffectClass::ProcessDamping), 2.0, 101),
            diagnosis: DiagnoseRequest::new(1),
        }
    }
}

/// The FDM lobes of `model` at `speeds_rpm` (the lobe job); `observer` hears of each speed.
fn fdm_lobes(
    model: &ModalModel,
    speeds_rpm: &[f64],
    observer: &dyn Observer,
) -> Result<Vec<LobePoint>> {
    let dynamics = Dynamics::Modal(model.clone());
    let request = LobesRequest {
        method: Method::Fdm,
        speeds_rpm: Some(speeds_rpm.to_vec()),
        ..LobesRequest::default()
    };
    Lobes::new(&dynamics, request)?.lobes(observer)
}

/// Stage 1: the turning tool's lobes and its limits near the summary's speeds.
#[derive(Debug, Clone)]
pub struct TurningLobes {
    /// The tool (seed 000's hammer-test modes).
    pub model: ModalModel,
    /// Its test cuts.
    pub observations: Observations,
    /// FDM limiting widths at [`DemoRequest::turning_speeds_rpm`].
    pub lobes: Vec<LobePoint>,
    /// The lobe point nearest each of [`DemoRequest::limit_speeds_rpm`].
    pub limits: Vec<LobePoint>,
}

/// Stage 1 of the demo.
pub fn turning_lobes(request: &DemoRequest, observer: &dyn Observer) -> Result<TurningLobes> {
    let model = examples::ahmadi_2022_turning();
    let lobes = fdm_lobes(&model, &request.turning_speeds_rpm, observer)?;
    let limits = request
        .limit_speeds_rpm
        .iter()
        .filter_map(|&rpm| {
            lobes
                .iter()
                .min_by(|a, b| {
                    (a.speed_rpm - rpm)
                        .abs()
                        .total_cmp(&(b.speed_rpm - rpm).abs())
                })
                .copied()
        })
        .collect();
    Ok(TurningLobes {
        model,
        observations: examples::ahmadi_2022_turning_observations(),
        lobes,
        limits,
    })
}

/// The posterior of 000 Section 6.4 (the mean and the covariance of Eq. 34 of theta_omega_2,
/// theta_zeta_2, theta_phi_2), as the covariance file [`examples::AHMADI_2022_POSTERIOR`].
pub fn eq34_distribution() -> Result<ParameterDistribution> {
    let posterior = examples::ahmadi_2022_posterior();
    Ok(ParameterDistribution::new(
        &posterior.parameter_names,
        posterior.mean,
        posterior.covariance,
        None,
        std::path::Path::new("eq34_covariance.json"),
    )?)
}

/// Stage 2: the credibility bounds of the turning tool after updating, on a depth grid that
/// covers the updated model's FDM lobes in steps of [`DemoRequest::credibility_depth_step_mm`].
pub fn credibility(
    request: &DemoRequest,
    turning: &ModalModel,
    observer: &dyn Observer,
) -> Result<PerturbationBands> {
    let distribution = eq34_distribution()?;
    let updated = distribution.mean_model(turning)?;
    let updated_lobes = fdm_lobes(&updated, &request.credibility_speeds_rpm, observer)?;
    let depths = chatter_stability::speed_grid::covering_depths_mm(
        &updated_lobes,
        request.credibility_depth_step_mm,
    )
    .ok_or_else(|| JobError::Refused("no finite limiting depth to cover".into()))?;
    crate::bands::perturbation(
        turning,
        &distribution,
        Method::Fdm,
        request.credibility_rule,
        &request.credibility_speeds_rpm,
        Some(depths),
        &chatter_progress::Silent,
    )
}

/// Stage 3: the milling example's Type B offset bands (001 Sec. 4) and its FRF.
#[derive(Debug, Clone)]
pub struct MillingBands {
    /// The milling example of seed 001.
    pub model: ModalModel,
    /// Zero-order lobes offset by 100 rpm and 0.2 mm.
    pub bands: OffsetBoundaries,
    /// Its receptance on [`DemoRequest::milling_frf`].
    pub frf: FrfOutcome,
}

/// Stage 3 of the demo.
pub fn milling_bands(request: &DemoRequest) -> Result<MillingBands> {
    let model = examples::schmitz_2023_milling();
    let bands = chatter_uncertainty::geometric::schmitz2023::example_boundaries()?;
    let frf = crate::frf::frf(&model, &request.milling_frf)?;
    Ok(MillingBands { model, bands, frf })
}

/// Stage 4: the synthetic campaign's nominal model and observations (the diagnosis is
/// [`crate::diagnose`] with [`DemoRequest::diagnosis`]).
pub fn shopfloor_campaign(request: &DemoRequest) -> Result<(ModalModel, Observations)> {
    synthetic_campaign(&request.campaign)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each limit is the lobe point at the grid speed nearest the asked speed (here the grid
    /// is written so that the nearest speeds are known by eye: 6950, 7145, 7300, 7505).
    #[test]
    fn turning_limits_are_the_nearest_lobe_points() {
        let request = DemoRequest {
            turning_speeds_rpm: vec![6800.0, 6950.0, 7145.0, 7300.0, 7505.0],
            ..DemoRequest::default()
        };
        let t = turning_lobes(&request, &chatter_progress::Silent).unwrap();
        let speeds: Vec<f64> = t.limits.iter().map(|p| p.speed_rpm).collect();
        assert_eq!(speeds, vec![6950.0, 7145.0, 7300.0, 7505.0]);
        assert_eq!(t.lobes.len(), 5);
    }
}
