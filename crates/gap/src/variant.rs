//! A machine variant: the nominal model changed by a class's parameters (or by a hidden effect),
//! turned into the concrete modal model of each cut.
//!
//! Every variant is a [`ModalModel`] at zero speed and at the start of the campaign (modes,
//! cutting coefficients, process damping) plus the effects that a model file cannot hold yet:
//! - speed-dependent modes, w_n(Omega) = w_n (1 - c Omega^2) at constant modal mass (the
//!   mass-normalized shape is unchanged, the stiffness falls with w_n^2);
//! - drift, cutting coefficients x (1 + r u) with u in [0, 1] the campaign position;
//! - a speed band where the cutting coefficients change by a factor (used only by the proving
//!   ground, as an effect outside the candidate list);
//! - a smooth bump of the cutting coefficients in log speed (the open alternative
//!   [`crate::EffectClass::SpeedBand`]: a gap confined to one region of speeds).
//!
//! [`Variant::at`] applies them for one cut (radial immersion, speed, campaign position), so
//! that any stability solver of `chatter-stability` evaluates the variant exactly.

use crate::error::{GapError, Result};
use chatter_dynamics::{ModalModel, Mode, ModeShape, Operation};
use serde::Serialize;

/// Floor of the speed-softening factor s = 1 - c Omega^2.
const MIN_SOFTENING: f64 = 0.05;

/// Cutting coefficients multiplied by `factor` between two speeds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CuttingBand {
    /// Lowest speed of the band (rpm).
    pub from_rpm: f64,
    /// Highest speed of the band (rpm).
    pub to_rpm: f64,
    /// Factor on both cutting coefficients inside the band.
    pub factor: f64,
}

/// Cutting coefficients multiplied by exp(a exp(-x^2 / 2w^2)), x = ln(Omega / Omega_c): a
/// Gaussian bump of the log factor in log speed, peak factor e^a at the centre speed Omega_c,
/// half-width w (a standard deviation in ln speed). A narrow bump is a band of speeds; one
/// centred at or beyond an end of the observed range with a wide w is a trend toward that end.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CuttingBump {
    /// Centre speed Omega_c (rpm).
    pub center_rpm: f64,
    /// Half-width w in ln speed.
    pub width_ln: f64,
    /// a: the log of the factor at the centre.
    pub ln_factor: f64,
}

impl CuttingBump {
    /// The factor on the cutting coefficients at `speed_rpm`.
    pub fn factor(&self, speed_rpm: f64) -> f64 {
        let x = (speed_rpm / self.center_rpm).ln() / self.width_ln;
        (self.ln_factor * (-0.5 * x * x).exp()).exp()
    }
}

/// A machine variant (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    /// The model at zero speed and campaign start.
    pub model: ModalModel,
    /// c in w_n(Omega) = w_n (1 - c Omega^2) (1/rpm^2).
    pub softening_per_rpm2: f64,
    /// r in cutting x (1 + r u).
    pub drift_rate: f64,
    /// A speed band with other cutting coefficients.
    pub cutting_band: Option<CuttingBand>,
    /// A smooth bump of the cutting coefficients in log speed.
    pub cutting_bump: Option<CuttingBump>,
}

impl Variant {
    /// The model itself, without speed- or time-dependent effects.
    pub fn new(model: ModalModel) -> Self {
        Self {
            model,
            softening_per_rpm2: 0.0,
            drift_rate: 0.0,
            cutting_band: None,
            cutting_bump: None,
        }
    }

    /// The speed-softening factor s = 1 - c Omega^2 (floored at 0.05).
    pub fn softening(&self, speed_rpm: f64) -> f64 {
        (1.0 - self.softening_per_rpm2 * speed_rpm * speed_rpm).max(MIN_SOFTENING)
    }

    /// The factor on the cutting coefficients at a speed and campaign position.
    pub fn cutting_factor(&self, speed_rpm: f64, u: f64) -> f64 {
        let band = match self.cutting_band {
            Some(b) if (b.from_rpm..=b.to_rpm).contains(&speed_rpm) => b.factor,
            _ => 1.0,
        };
        let bump = self.cutting_bump.map_or(1.0, |b| b.factor(speed_rpm));
        band * bump * (1.0 + self.drift_rate * u)
    }

    /// The modal model of a cut at `speed_rpm`, campaign position `u`, and radial immersion
    /// `immersion` (`None`: the model's own; ignored for turning).
    pub fn at(&self, immersion: Option<f64>, speed_rpm: f64, u: f64) -> Result<ModalModel> {
        let mut model = match (self.model.operation(), immersion) {
            (Operation::Milling(op), Some(r)) => self
                .model
                .with_operation(Operation::Milling(op.with_radial_immersion(r)?))?,
            _ => self.model.clone(),
        };
        let s = self.softening(speed_rpm);
        if s != 1.0 {
            let modes = model
                .modes()
                .iter()
                .map(|m| {
                    Mode::new(
                        m.frequency_hz() * s,
                        m.damping_ratio(),
                        ModeShape::MassNormalized(m.mass_normalized_shape()),
                    )
                })
                .collect::<std::result::Result<Vec<_>, _>>()?;
            model = model.with_modes(modes)?;
        }
        let g = self.cutting_factor(speed_rpm, u);
        if g != 1.0 {
            if !(g.is_finite() && g > 0.0) {
                return Err(GapError::Model(format!(
                    "cutting-coefficient factor {g} at {speed_rpm} rpm, position {u}"
                )));
            }
            let c = model.cutting();
            model = model.with_cutting(chatter_dynamics::CuttingCoefficients::new(
                c.kt_n_per_m2() * g,
                c.kn_n_per_m2() * g,
            )?);
        }
        Ok(model)
    }

    /// The regenerative delay (s) at a speed.
    pub fn delay_s(&self, speed_rpm: f64) -> f64 {
        self.model.operation().delay_s(speed_rpm)
    }
}

/// A mode scaled in frequency (at constant modal stiffness, so the mass-normalized shape scales
/// with the frequency) and damping; the way a shape was given is kept.
pub(crate) fn recalibrated_mode(
    mode: &Mode,
    frequency_factor: f64,
    damping_factor: f64,
) -> Result<Mode> {
    let shape = match mode.shape() {
        ModeShape::Directional { .. } => mode.shape(),
        ModeShape::MassNormalized(phi) => {
            ModeShape::MassNormalized([phi[0] * frequency_factor, phi[1] * frequency_factor])
        }
    };
    Ok(Mode::new(
        mode.frequency_hz() * frequency_factor,
        mode.damping_ratio() * damping_factor,
        shape,
    )?)
}

/// `model` with every frequency and damping ratio scaled and the cutting coefficients scaled by
/// `cutting_factor`.
pub(crate) fn recalibrated(
    model: &ModalModel,
    frequency_factor: f64,
    damping_factor: f64,
    cutting_factor: f64,
) -> Result<ModalModel> {
    recalibrated_per_mode(
        model,
        &vec![frequency_factor; model.modes().len()],
        damping_factor,
        cutting_factor,
    )
}

/// [`recalibrated`] with one frequency factor per mode (in the model's order).
pub(crate) fn recalibrated_per_mode(
    model: &ModalModel,
    frequency_factors: &[f64],
    damping_factor: f64,
    cutting_factor: f64,
) -> Result<ModalModel> {
    let modes = model
        .modes()
        .iter()
        .zip(frequency_factors)
        .map(|(m, &f)| recalibrated_mode(m, f, damping_factor))
        .collect::<Result<Vec<_>>>()?;
    let c = model.cutting();
    Ok(model
        .with_modes(modes)?
        .with_cutting(chatter_dynamics::CuttingCoefficients::new(
            c.kt_n_per_m2() * cutting_factor,
            c.kn_n_per_m2() * cutting_factor,
        )?))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bump's factor is e^a at its centre, e^{a e^{-1/2}} one half-width away on either side
    /// in ln speed, and tends to 1 far from it (the closed form of its definition).
    #[test]
    fn the_cutting_bump_has_its_closed_form() {
        let b = CuttingBump {
            center_rpm: 8000.0,
            width_ln: 0.1,
            ln_factor: 0.7,
        };
        let close = |x: f64, y: f64| (x - y).abs() < 1e-12 * y.abs().max(1.0);
        assert!(close(b.factor(8000.0), 0.7f64.exp()));
        let side = (0.7 * (-0.5f64).exp()).exp();
        assert!(close(b.factor(8000.0 * 0.1f64.exp()), side));
        assert!(close(b.factor(8000.0 / 0.1f64.exp()), side));
        assert!((b.factor(16000.0) - 1.0).abs() < 1e-9);
        let mut v = Variant::new(crate::generator::nominal_milling().unwrap());
        v.cutting_bump = Some(b);
        v.drift_rate = 0.5;
        assert!(close(v.cutting_factor(8000.0, 1.0), 1.5 * 0.7f64.exp()));
    }
}
