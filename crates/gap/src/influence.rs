//! Whether the case against the nominal model rests on a single observation.
//!
//! The likelihood lets any observation be an outlier with the lapse probability, but a gross
//! error of one identification (a pole whose damping ratio is off by a factor three, as an
//! operational modal analysis of a short or disturbed record gives) still costs the nominal model
//! more than the few nats a recalibration needs to beat it. A verdict that a model is wrong
//! should survive the loss of any one observation, as a regression coefficient should survive
//! the deletion of its most influential point (Cook 1977, "Detection of influential observation
//! in linear regression"). The most influential observation is the one whose log-likelihood the
//! best class's posterior-mean machine raises most over the nominal model's; without it:
//! - the nominal model's predictive check is repeated on the other observations, and
//! - the ln Bayes factor against it is the full one less that observation's gain, and the
//!   practical shift is recomputed.
//!
//! If the nominal model then passes as `consistent` would require, the gap rests on that one
//! observation: the diagnosis says `consistent` and names the observation to repeat.

use crate::check::predictive_check;
use crate::data::Dataset;
use crate::equivalence::largest_shift;
use crate::likelihood::{NoiseModel, terms};
use crate::predict::{Prediction, predict};
use crate::variant::Variant;

/// The observation the gap rests on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LoneObservation {
    /// A pole (true) or a cut (false).
    pub pole: bool,
    /// Index in the observations' `cuts` or `poles`.
    pub index: usize,
    /// Its spindle speed (rpm).
    pub speed_rpm: f64,
    /// Its depth of cut (mm).
    pub depth_mm: f64,
    /// How much more likely the best class makes it than the nominal model (ln).
    pub gain: f64,
}

impl LoneObservation {
    /// The note of the diagnosis, in plain words.
    pub fn note(&self) -> String {
        format!(
            "only one observation disagrees with the nominal model: the {} at {:.0} rpm and \
             {:.2} mm ({} {} of the observations; it alone gives the alternative {:.1} nats); \
             without it the nominal model passes its check. Repeat that measurement before \
             changing the model",
            if self.pole { "pole" } else { "cut" },
            self.speed_rpm,
            self.depth_mm,
            if self.pole { "pole" } else { "cut" },
            self.index,
            self.gain
        )
    }
}

/// What the consistency rule needs besides the data.
pub(crate) struct Rule<'a> {
    pub noise: &'a NoiseModel,
    pub check_level: f64,
    pub seed: u64,
    /// ln Bayes factor of the alternative over the nominal model needed to reject it.
    pub min_log_bayes_factor: f64,
    /// Practical equivalence, in noise standard deviations.
    pub equivalence_std: f64,
}

impl Rule<'_> {
    /// The `consistent` rule: the nominal model passes its check and either the alternative does
    /// not beat it by the Bayes factor or no prediction moves by more than the equivalence.
    pub fn consistent(&self, check_passed: bool, log_bayes_factor: f64, shift: f64) -> bool {
        check_passed
            && (log_bayes_factor < self.min_log_bayes_factor || shift < self.equivalence_std)
    }
}

/// Each observation's log-likelihood under `to` less that under `from`, as (pole, index in the
/// observations' `cuts` or `poles`, gain): the cuts first, then the poles.
pub(crate) fn gains(
    from: &Prediction,
    to: &Prediction,
    data: &Dataset,
    noise: &NoiseModel,
) -> Vec<(bool, usize, f64)> {
    let (t0, t1) = (terms(from, data, noise), terms(to, data, noise));
    let cuts = (0..data.cuts.len()).map(|i| (false, i, t1.cut(i) - t0.cut(i)));
    let poles = (0..data.poles.len()).map(|j| (true, j, t1.pole(j) - t0.pole(j)));
    cuts.chain(poles).collect()
}

/// The observation the rejection of the nominal model rests on, if it rests on one (module
/// docs): `log_bayes_factor` is the alternative's over the nominal model on all of `data`.
pub(crate) fn lone_observation(
    nominal: (&Variant, &Prediction),
    candidate: (&Variant, &Prediction),
    data: &Dataset,
    log_bayes_factor: f64,
    rule: &Rule,
) -> Option<LoneObservation> {
    let (pole, at, gain) = gains(nominal.1, candidate.1, data, rule.noise)
        .into_iter()
        .filter(|(_, _, g)| g.is_finite())
        .max_by(|a, b| a.2.total_cmp(&b.2))?;
    if gain <= 0.0 {
        return None;
    }
    let others =
        |n: usize, skip: bool| -> Vec<usize> { (0..n).filter(|&k| !(skip && k == at)).collect() };
    let rest = data.subset(
        &others(data.cuts.len(), !pole),
        &others(data.poles.len(), pole),
    );
    let (p0, p1) = (predict(nominal.0, &rest), predict(candidate.0, &rest));
    let check = predictive_check(
        std::slice::from_ref(&p0),
        &rest,
        rule.noise,
        rule.check_level,
        rule.seed,
    );
    let shift = largest_shift(&p0, &p1, &rest, rule.noise);
    rule.consistent(check.passed, log_bayes_factor - gain, shift)
        .then(|| {
            let (index, speed_rpm, depth_m) = if pole {
                let p = &data.poles[at];
                (p.index, p.speed_rpm, p.depth_m)
            } else {
                let c = &data.cuts[at];
                (c.index, c.speed_rpm, c.depth_m)
            };
            LoneObservation {
                pole,
                index,
                speed_rpm,
                depth_mm: depth_m * 1e3,
                gain,
            }
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::prepare;
    use crate::generator::proving_machines;
    use crate::variant::recalibrated_per_mode;
    use crate::{HiddenEffect, Scenario, synthesize};

    /// On a lathe campaign where the nominal model is right but one identified pole's damping
    /// and frequency are those of a machine with ten times the damping, that machine gains most on that
    /// pole; with a Bayes factor that the pole alone carries, the rejection rests on it, and with
    /// one far beyond any single observation's gain it does not.
    #[test]
    fn a_rejection_carried_by_one_corrupted_pole_rests_on_it() {
        let machine = &proving_machines().unwrap()[3];
        let (lo, hi) = machine.speed_range_rpm;
        let mut scenario =
            Scenario::new(HiddenEffect::ParameterError, 5).with_speed_range(lo, hi, 2);
        scenario.cuts = 12;
        let mut observations = synthesize(&machine.model, &scenario).unwrap();
        assert!(!observations.poles.is_empty());
        let noise = NoiseModel::default();
        let modes = machine.model.modes().len();
        let damped = recalibrated_per_mode(&machine.model, &vec![1.0; modes], 10.0, 1.0).unwrap();
        let candidate = Variant::new(damped);
        let clean = prepare(&machine.model, &observations, &noise).unwrap();
        let corrupted = predict(&candidate, &clean.data).poles[0].unwrap();
        observations.poles[0].frequency_hz = corrupted.frequency_hz;
        observations.poles[0].damping_ratio = corrupted.damping_ratio;
        let prepared = prepare(&machine.model, &observations, &noise).unwrap();
        let nominal = prepared.nominal.variant();
        let data = &prepared.data;
        let (p0, p1) = (predict(&nominal, data), predict(&candidate, data));
        let rule = Rule {
            noise: &noise,
            check_level: 0.01,
            seed: 1,
            min_log_bayes_factor: 10f64.ln(),
            equivalence_std: 1.0,
        };
        let lone = lone_observation((&nominal, &p0), (&candidate, &p1), data, 4.0, &rule)
            .expect("the corrupted pole carries the rejection");
        assert!(lone.pole && lone.index == 0, "{lone:?}");
        assert!(lone.gain > 0.0 && lone.note().contains("pole 0"));
        assert_eq!(
            lone_observation((&nominal, &p0), (&candidate, &p1), data, 60.0, &rule),
            None
        );
    }
}
