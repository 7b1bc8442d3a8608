//! The multiplier job (`chatter multiplier`, `chatter.multiplier`): the dominant Floquet
//! multiplier mu of one cut by full or semi-discretization (Insperger-Stepan; Ding et al.
//! 2010), with its chatter frequency, or over one period of a sinusoidal spindle-speed
//! variation (SSV). The cut is stable when |mu| < 1 ([`is_stable`], the one home of the rule).

use crate::checks;
use crate::error::{JobError, Result};
use chatter_dynamics::ModalModel;
use chatter_dynamics::limits::{DEPTH_MM, SPEED_RPM};
use chatter_stability::monodromy::Discretization;
use chatter_stability::multiplier::DominantMultiplier;
use chatter_stability::ssv::{SpeedVariation, VariedSpeed};
use chatter_stability::{Method, StabilitySolver};

/// What the multiplier job was asked, in user units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MultiplierRequest {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Depth of cut (mm).
    pub depth_mm: f64,
    /// FDM (default) or SDM; zero-order is refused (it gives limits, not multipliers).
    pub method: Method,
    /// A sinusoidal spindle-speed variation around `speed_rpm`.
    pub variation: Option<SpeedVariation>,
}

impl MultiplierRequest {
    /// The cut at `speed_rpm` and `depth_mm` with the defaults (FDM, constant speed).
    pub fn new(speed_rpm: f64, depth_mm: f64) -> Self {
        Self {
            speed_rpm,
            depth_mm,
            method: Method::Fdm,
            variation: None,
        }
    }
}

/// The rule of a stable cut: the dominant multiplier inside the unit circle.
pub fn is_stable(mu: &DominantMultiplier) -> bool {
    mu.modulus() < 1.0
}

/// What the multiplier job computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MultiplierOutcome {
    /// The checked request.
    pub request: MultiplierRequest,
    /// The discretization's name (`fdm`, `sdm`).
    pub method: &'static str,
    /// The dominant multiplier (over one delay; over the variation's period with SSV).
    pub multiplier: DominantMultiplier,
    /// The chatter frequency (Hz) at constant speed; `None` with SSV.
    pub chatter_hz: Option<f64>,
    /// [`is_stable`].
    pub stable: bool,
}

/// A checked multiplier job.
pub struct Multiplier<'a> {
    model: &'a ModalModel,
    request: MultiplierRequest,
    discretization: Discretization,
}

impl<'a> Multiplier<'a> {
    /// Check the request: speed and depth plausible, FDM or SDM, and at most
    /// [`checks::MAX_STEPS_PER_DELAY`] steps per delay.
    pub fn new(model: &'a ModalModel, request: MultiplierRequest) -> Result<Self> {
        checks::in_range("speed_rpm", request.speed_rpm, &SPEED_RPM)?;
        checks::in_range("depth_mm", request.depth_mm, &DEPTH_MM)?;
        let Some(discretization) = request.method.discretization() else {
            return Err(JobError::Refused(
                "`method` zoa gives limiting depths, not multipliers; use fdm or sdm".into(),
            ));
        };
        checks::work_size(model, discretization, &[request.speed_rpm], "speed_rpm")?;
        Ok(Self {
            model,
            request,
            discretization,
        })
    }

    /// Steps per delay of the discretization at the request's speed.
    pub fn steps_per_delay(&self) -> usize {
        self.discretization
            .steps_at(self.model, self.request.speed_rpm)
            .get()
    }

    /// The discretization's name.
    pub fn method_name(&self) -> &'static str {
        self.discretization.name()
    }

    /// The dominant multiplier (and, at constant speed, the chatter frequency).
    pub fn run(&self) -> Result<MultiplierOutcome> {
        let r = &self.request;
        let depth_m = r.depth_mm * 1e-3;
        let (multiplier, chatter_hz) = match r.variation {
            Some(variation) => {
                let varied = VariedSpeed {
                    discretization: self.discretization,
                    variation,
                };
                (
                    varied.dominant_multiplier(self.model, r.speed_rpm, depth_m)?,
                    None,
                )
            }
            None => {
                let (mu, hz) =
                    self.discretization
                        .chatter_frequency_hz(self.model, r.speed_rpm, depth_m)?;
                (mu, Some(hz))
            }
        };
        Ok(MultiplierOutcome {
            request: *r,
            method: self.discretization.name(),
            multiplier,
            chatter_hz,
            stable: is_stable(&multiplier),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    /// Stability is the multiplier's modulus against 1 and agrees with the lobes of the same
    /// discretization (an independent root search): 3 % below the FDM limit stable, 3 % above
    /// it not. The margin is far beyond the boundary search's 1e-6 relative tolerance.
    #[test]
    fn stability_agrees_with_the_limiting_depth() {
        let model = examples::ahmadi_2022_turning();
        let speed = 7000.0;
        let limit = Method::Fdm
            .prepare(&model, &Default::default())
            .unwrap()
            .limiting_depth(speed)
            .unwrap()
            .depth_mm();
        for (factor, stable) in [(0.97, true), (1.03, false)] {
            let job =
                Multiplier::new(&model, MultiplierRequest::new(speed, factor * limit)).unwrap();
            let out = job.run().unwrap();
            assert_eq!(
                out.stable,
                stable,
                "{factor}: |mu| {}",
                out.multiplier.modulus()
            );
            assert!(out.chatter_hz.is_some());
        }
        let zoa = MultiplierRequest {
            method: Method::Zoa,
            ..MultiplierRequest::new(speed, 1.0)
        };
        assert!(Multiplier::new(&model, zoa).is_err());
    }
}
