//! The synthetic shop-floor campaign of the gap diagnosis's proving ground
//! ([`chatter_gap::synthesize`] on [`chatter_gap::nominal_milling`]): the one recipe behind
//! `chatter demo`'s campaign and `chatter.synthetic_campaign`, so that the same request gives the
//! same model and observations through both.

use crate::error::Result;
use chatter_dynamics::{ModalModel, Observations};
use chatter_gap::{EffectClass, HiddenEffect, Scenario, generator::effect_at};

/// What synthetic campaign to make.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyntheticCampaignRequest {
    /// The hidden effect class (`None`: the nominal machine, no effect).
    pub effect: Option<EffectClass>,
    /// Its size, 1 the reference size of the class
    /// ([`chatter_gap::generator::effect_at`]).
    pub magnitude: f64,
    /// Seed of the speeds, depths, run order and noise.
    pub seed: u64,
    /// Number of test cuts (default 32, [`Scenario::new`]).
    pub cuts: usize,
    /// Pole speeds spread evenly over the speed range; `None`: the scenario's default pole
    /// speeds (3000, 6000, 9000 and 12 000 rpm), 0 for none.
    pub pole_speeds: Option<usize>,
}

impl SyntheticCampaignRequest {
    /// A campaign of `effect` at `magnitude` with the scenario's defaults.
    pub fn new(effect: Option<EffectClass>, magnitude: f64, seed: u64) -> Self {
        Self {
            effect,
            magnitude,
            seed,
            cuts: Scenario::new(HiddenEffect::ParameterError, seed).cuts,
            pole_speeds: None,
        }
    }
}

/// The nominal model and the campaign's observations.
pub fn synthetic_campaign(
    request: &SyntheticCampaignRequest,
) -> Result<(ModalModel, Observations)> {
    let nominal = chatter_gap::nominal_milling()?;
    let mut scenario = Scenario::new(HiddenEffect::ParameterError, request.seed);
    if let Some(n) = request.pole_speeds {
        let (lo, hi) = scenario.speed_range_rpm;
        scenario = scenario.with_speed_range(lo, hi, n);
    }
    scenario.cuts = request.cuts;
    if let Some(class) = request.effect {
        (scenario.effect, scenario.error) =
            effect_at(class, request.magnitude, &nominal, scenario.speed_range_rpm)?;
    }
    let observations = chatter_gap::synthesize(&nominal, &scenario)?;
    Ok((nominal, observations))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The request's counts reach the observations: `cuts` cuts, and two poles per pole speed.
    #[test]
    fn counts_reach_the_observations() {
        let mut request = SyntheticCampaignRequest::new(None, 1.0, 3);
        request.cuts = 8;
        request.pole_speeds = Some(1);
        let (_, obs) = synthetic_campaign(&request).unwrap();
        assert_eq!(obs.cuts.len(), 8);
        assert_eq!(obs.poles.len(), 2);
    }
}
