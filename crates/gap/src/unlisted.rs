//! Whether the gap is one none of the listed effects describes: the open alternative
//! [`crate::EffectClass::SpeedBand`] against the best explanation the list (or the nominal model) gives.
//!
//! A model-class selection can only name a class it was given. An effect outside the list (the
//! cutting coefficients changed in a band of speeds, damping raised in a band, built-up edge
//! raising the cutting coefficients at low cutting speed) is absorbed by the listed class that
//! bends the lobes most like it, which then passes its check on a few dozen cuts. Adding an
//! open, flexible alternative turns "none of them" into a hypothesis with its own evidence (the
//! "catch-all" model of Bayesian model criticism; Box 1980, "Sampling and Bayes' inference in
//! scientific modelling and robustness"): the gap is confined to a band of speeds, in a shape no
//! listed effect has. It is believed when
//! - its ln evidence beats the best of the nominal model's likelihood and the listed classes'
//!   evidences by the Bayes factor an effect needs (`DiagnoseOptions::min_log_bayes_factor`),
//! - and still does after the observation it helps most is removed (the rule of
//!   `influence`: a band resting on one surprising label is that label's lapse as
//!   likely as a band),
//! - and its posterior-mean machine moves some observation's prediction by more than the
//!   practical equivalence ([`crate::equivalence`]) from the best explanation's: the band
//!   contains plain recalibration (a factor of 1), so on data without a band its evidence is
//!   recalibration's up to the sampler's scatter (1-2.5 nats), which a Bayes factor alone would
//!   read as a band.
//!
//! The band's own parameters (more than any listed effect has) are paid for by its evidence
//! (Occam's factor): on data a listed effect made, that class fits as well with fewer
//! parameters and wins.

use crate::data::Dataset;
use crate::equivalence::largest_shift;
use crate::influence::gains;
use crate::likelihood::NoiseModel;
use crate::predict::Prediction;
use serde::Serialize;

/// A gap the open alternative explains and no listed class does.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct UnlistedBand {
    /// The band's factor on the cutting coefficients over the stiffness at its centre.
    pub cutting_factor: f64,
    /// Centre speed (rpm).
    pub center_rpm: f64,
    /// Centre speed divided and multiplied by e^w (rpm): where the factor's log is above 0.6 of
    /// its peak.
    pub from_rpm: f64,
    /// See `from_rpm`.
    pub to_rpm: f64,
    /// ln Bayes factor of the band over the best explanation from the list.
    pub log_bayes_factor: f64,
    /// The same without the observation the band helps most.
    pub log_bayes_factor_without_best: f64,
    /// The largest move of an observation's prediction from the best explanation's, in noise
    /// standard deviations ([`crate::equivalence`]).
    pub practical_shift: f64,
}

impl UnlistedBand {
    /// The note of the diagnosis, in plain words; `against` names the best explanation from the
    /// list.
    pub fn note(&self, against: &str) -> String {
        format!(
            "the gap is confined to speeds around {:.0} rpm ({:.0}-{:.0} rpm), where the \
             machine behaves as if the cutting coefficients were x{:.2}: a band that none of the \
             listed effects describes (ln Bayes factor {:.1} over {against}, {:.1} without the \
             observation it helps most). Look for a speed-dependent effect there (built-up \
             edge, a resonance of the workpiece or fixture, a band of higher damping)",
            self.center_rpm,
            self.from_rpm,
            self.to_rpm,
            self.cutting_factor,
            self.log_bayes_factor,
            self.log_bayes_factor_without_best
        )
    }
}

/// The rule of the module docs: `band` and `best` are the open alternative's and the best
/// listed explanation's ln evidence with their posterior-mean predictions, `band_parameters` the
/// band's physical parameters at its posterior mean ([`crate::classes`]), `equivalence_std` the
/// practical equivalence in noise standard deviations. None when the band is not believed.
pub(crate) fn judge(
    band: (f64, &Prediction),
    best: (f64, &Prediction),
    band_parameters: &[(&'static str, f64)],
    data: &Dataset,
    noise: &NoiseModel,
    (min_log_bayes_factor, equivalence_std): (f64, f64),
) -> Option<UnlistedBand> {
    let log_bayes_factor = band.0 - best.0;
    if log_bayes_factor.is_nan() || log_bayes_factor < min_log_bayes_factor {
        return None;
    }
    let largest = gains(best.1, band.1, data, noise)
        .into_iter()
        .map(|(_, _, g)| g)
        .filter(|g| g.is_finite())
        .fold(0.0, f64::max);
    let without = log_bayes_factor - largest;
    let practical_shift = largest_shift(best.1, band.1, data, noise);
    let value = |name: &str| {
        band_parameters
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| *v)
    };
    (without >= min_log_bayes_factor && practical_shift >= equivalence_std).then_some(
        UnlistedBand {
            cutting_factor: value("band_cutting_factor")?,
            center_rpm: value("band_center_rpm")?,
            from_rpm: value("band_from_rpm")?,
            to_rpm: value("band_to_rpm")?,
            log_bayes_factor,
            log_bayes_factor_without_best: without,
            practical_shift,
        },
    )
}
