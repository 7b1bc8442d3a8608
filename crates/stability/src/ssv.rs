//! Spindle-speed variation (SSV): a sinusoidal modulation of the spindle speed,
//! Omega(t) = Omega_0 (1 + A sin(2 pi r f_0 t)) with amplitude ratio A in [0, 1) and frequency
//! ratio r (modulation frequency over the mean spindle frequency f_0), in the full and
//! semi-discretizations with the time-varying delay (Insperger & Stépán 2004; Sastry, Kapoor &
//! DeVor 2002).
//!
//! The tooth angles are Omega_0 s(t), s(t) = t - (A / w_m) (cos(w_m t) - 1); the delay tau(t)
//! of a tooth solves s(t) - s(t - tau) = pitch / Omega_0, so the delayed displacement lies
//! between grid points and is interpolated from the history (the step program of the variable
//! pitch, [`crate::monodromy`]). The monodromy is over the modulation period T_m = 1 / (r f_0),
//! which must hold a whole number q = N / r of mean tooth periods (revolutions in turning, N = 1)
//! so that the cutting coefficients repeat. At A = 0 the solver is the constant-speed
//! discretization, to the bit.

use crate::StabilitySolver;
use crate::error::{Result, StabilityError};
use crate::monodromy::{Discretization, Monodromy};
use crate::multiplier::DominantMultiplier;
use crate::step::StepPlan;
use chatter_dynamics::ModalModel;

/// A sinusoidal spindle-speed variation, validated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedVariation {
    amplitude_ratio: f64,
    frequency_ratio: f64,
}

impl SpeedVariation {
    /// `amplitude_ratio` A in [0, 1) (the speed stays positive) and `frequency_ratio` r > 0;
    /// errors name `ssv_amplitude_ratio` or `ssv_frequency_ratio` with the value.
    pub fn new(amplitude_ratio: f64, frequency_ratio: f64) -> Result<Self> {
        if !(amplitude_ratio.is_finite() && (0.0..1.0).contains(&amplitude_ratio)) {
            return Err(StabilityError::InvalidInput {
                field: "ssv_amplitude_ratio",
                value: amplitude_ratio,
                expected: "an amplitude ratio in [0, 1): the speed must stay positive",
            });
        }
        if !(frequency_ratio.is_finite() && frequency_ratio > 0.0) {
            return Err(StabilityError::InvalidInput {
                field: "ssv_frequency_ratio",
                value: frequency_ratio,
                expected: "a modulation frequency over the spindle frequency > 0",
            });
        }
        Ok(Self {
            amplitude_ratio,
            frequency_ratio,
        })
    }

    /// The amplitude ratio A.
    pub fn amplitude_ratio(&self) -> f64 {
        self.amplitude_ratio
    }

    /// The frequency ratio r.
    pub fn frequency_ratio(&self) -> f64 {
        self.frequency_ratio
    }
}

/// A discretization under a spindle-speed variation (module docs); multipliers are over the
/// modulation period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VariedSpeed {
    /// The scheme and resolution (steps per mean delay).
    pub discretization: Discretization,
    /// The speed variation.
    pub variation: SpeedVariation,
}

impl VariedSpeed {
    /// The monodromy operator at mean speed `speed_rpm` and depth `depth_m`; the constant-speed
    /// one at zero amplitude.
    pub fn monodromy(&self, model: &ModalModel, speed_rpm: f64, depth_m: f64) -> Result<Monodromy> {
        if self.variation.amplitude_ratio == 0.0 {
            return self.discretization.monodromy(model, speed_rpm, depth_m);
        }
        StepPlan::with_speed_variation(
            model,
            speed_rpm,
            self.discretization,
            (
                self.variation.amplitude_ratio,
                self.variation.frequency_ratio,
            ),
        )?
        .monodromy(depth_m)
    }
}

impl StabilitySolver for VariedSpeed {
    fn name(&self) -> &'static str {
        self.discretization.name()
    }

    fn dominant_multiplier(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<DominantMultiplier> {
        if self.variation.amplitude_ratio == 0.0 {
            return self
                .discretization
                .dominant_multiplier(model, speed_rpm, depth_m);
        }
        let op = self.monodromy(model, speed_rpm, depth_m)?;
        Ok(DominantMultiplier::new(
            op.dominant_eigenvalue()?,
            op.period_s,
        ))
    }
}
