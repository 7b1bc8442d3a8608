//! The simulation job (`chatter simulate`, `chatter.simulate`): a time-domain regenerative cut
//! with loss of contact ([`chatter_dynamics::simulate`]) from options in user units, checked
//! once: plausible speed, depth, duration, rate, forces and feed, and a signal of 2 to
//! [`MAX_SIMULATED_SAMPLES`] samples.

use crate::checks::in_range;
use crate::error::{JobError, Result};
use chatter_dynamics::ModalModel;
use chatter_dynamics::limits::{
    DEPTH_MM, Plausible, SAMPLE_RATE_HZ, SPEED_RPM, closed, open_closed, written,
};
use chatter_dynamics::simulate::{Quantity, Simulation, SimulationSettings};
use chatter_progress::Observer;

/// Signal length.
pub const DURATION_S: Plausible = open_closed(0.0, 3600.0, "a signal length", "s");
/// Feed per tooth (milling) or per revolution (turning).
pub const FEED_MM: Plausible = open_closed(0.0, 10.0, "a feed", "mm");
/// RMS or amplitude of a simulated force (zero allowed).
pub const FORCE_N: Plausible = closed(0.0, 1e6, "a force", "N");
/// Most output samples (duration times sample rate).
pub const MAX_SIMULATED_SAMPLES: f64 = 1e8;

/// What the simulation was asked, in user units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimulateRequest {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Depth (milling) or width (turning) of cut (mm).
    pub depth_mm: f64,
    /// Signal length (s).
    pub duration_s: f64,
    /// Output sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Seed of the random force.
    pub seed: u64,
    /// Output quantity (default acceleration).
    pub quantity: Quantity,
    /// RMS of the broadband random force on each coordinate (N; default 1).
    pub random_force_n: f64,
    /// Amplitude of the spindle-harmonic forcing (N; default 0).
    pub harmonic_force_n: f64,
    /// Feed per tooth or per revolution (mm; default 0.05).
    pub feed_per_tooth_mm: f64,
}

impl SimulateRequest {
    /// A cut with the default forcing and feed ([`SimulationSettings::new`]).
    pub fn new(
        speed_rpm: f64,
        depth_mm: f64,
        duration_s: f64,
        sample_rate_hz: f64,
        seed: u64,
    ) -> Self {
        Self {
            speed_rpm,
            depth_mm,
            duration_s,
            sample_rate_hz,
            seed,
            quantity: Quantity::Acceleration,
            random_force_n: 1.0,
            harmonic_force_n: 0.0,
            feed_per_tooth_mm: 0.05,
        }
    }

    /// The checked settings of the simulator (SI inside).
    pub fn check(&self) -> Result<SimulationSettings> {
        in_range("speed_rpm", self.speed_rpm, &SPEED_RPM)?;
        in_range("depth_mm", self.depth_mm, &DEPTH_MM)?;
        in_range("duration_s", self.duration_s, &DURATION_S)?;
        in_range("sample_rate_hz", self.sample_rate_hz, &SAMPLE_RATE_HZ)?;
        in_range("random_force_n", self.random_force_n, &FORCE_N)?;
        in_range("harmonic_force_n", self.harmonic_force_n, &FORCE_N)?;
        in_range("feed_per_tooth_mm", self.feed_per_tooth_mm, &FEED_MM)?;
        let samples = self.duration_s * self.sample_rate_hz;
        if !(2.0..=MAX_SIMULATED_SAMPLES).contains(&samples) {
            return Err(JobError::Refused(format!(
                "`duration_s` {} at `sample_rate_hz` {}: {} samples; expected 2 to {} samples",
                written(self.duration_s),
                written(self.sample_rate_hz),
                written(samples.floor()),
                written(MAX_SIMULATED_SAMPLES)
            )));
        }
        let mut s = SimulationSettings::new(
            self.speed_rpm,
            self.depth_mm * 1e-3,
            self.duration_s,
            self.sample_rate_hz,
            self.seed,
        );
        s.quantity = self.quantity;
        s.random_force_rms_n = self.random_force_n;
        s.harmonic_force_n = self.harmonic_force_n;
        s.feed_per_tooth_m = self.feed_per_tooth_mm * 1e-3;
        Ok(s)
    }
}

/// Simulate the checked `settings` on `model`; `observer` hears of the progress and may cancel.
pub fn simulate(
    model: &ModalModel,
    settings: &SimulationSettings,
    observer: &dyn Observer,
) -> Result<Simulation> {
    Ok(chatter_dynamics::simulate::simulate_with_observer(
        model, settings, observer,
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The defaults are the simulator's own, and the length limit names both fields.
    #[test]
    fn defaults_and_the_length_limit() {
        let s = SimulateRequest::new(7000.0, 1.0, 0.5, 20_000.0, 3)
            .check()
            .unwrap();
        let mut reference = SimulationSettings::new(7000.0, 1e-3, 0.5, 20_000.0, 3);
        reference.feed_per_tooth_m = 0.05 * 1e-3;
        assert_eq!(s, reference);
        let e = SimulateRequest::new(7000.0, 1.0, 3600.0, 1e6, 3)
            .check()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`duration_s` 3600 at `sample_rate_hz` 1e6"),
            "{e}"
        );
    }
}
