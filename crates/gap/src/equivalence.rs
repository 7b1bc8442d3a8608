//! Practical equivalence of two machines on the observations: how far one moves the prediction of
//! any observation from the other's, in units of that observation's noise.
//!
//! A Bayes factor answers "which machine fits better", not "does the difference matter". With
//! many observations it resolves differences far below what any single observation can show: a
//! limit cycle with loss of contact chatters 0.1-0.25 % below the linear root, and 14 chatter
//! frequencies with 0.5 % noise give a recalibrated model a ln Bayes factor above ln 3 for that
//! shift alone (issue 15, simulated-signal control). The region of practical equivalence
//! (Kruschke, "Rejecting or accepting parameter values in Bayesian estimation", 2018) asks
//! instead whether the fitted alternative changes any prediction by more than the noise of the
//! observation: the largest shift, over every observation, of
//! - a cut's signed log-depth distance to the boundary, in label widths w (ln(b_lim'/b_lim)),
//!   each clipped to +-3 w: farther out the label is certain either way;
//! - a chattering cut's chatter frequency, in its standard deviation (nearest image for milling);
//! - a pole's frequency and damping ratio, in the pole's standard deviations.
//!
//! Below one standard deviation everywhere, no single test could tell the two machines apart,
//! and the diagnosis calls the data `consistent` with the nominal model.

use crate::data::Dataset;
use crate::likelihood::{NoiseModel, chatter_residual, pole_frequency_residual, terms};
use crate::predict::{CutPrediction, Prediction};

/// Half-width, in label widths, of the band of log-depth distances where a cut's label is
/// uncertain: beyond 3 w the probit gives a label with probability above 0.9987.
const LABEL_RANGE: f64 = 3.0;

/// The largest shift, in noise standard deviations, between the predictions `base` and `other`
/// of any observation of `data` (module docs). Observations that either prediction failed on are
/// skipped (failures are counted elsewhere); 0 when nothing is comparable.
pub(crate) fn largest_shift(
    base: &Prediction,
    other: &Prediction,
    data: &Dataset,
    noise: &NoiseModel,
) -> f64 {
    let cuts = data.cuts.iter().enumerate().filter_map(|(i, c)| {
        let (b, o) = (base.cuts[i]?, other.cuts[i]?);
        // beyond LABEL_RANGE widths from the boundary a label is certain either way
        let w = noise.label_width_log_depth;
        let d = |q: CutPrediction| q.log_distance().clamp(-LABEL_RANGE * w, LABEL_RANGE * w);
        let label = (d(o) - d(b)).abs() / w;
        let chatter = c.chatter_hz.map_or(0.0, |_| {
            chatter_residual(o.chatter_hz, b.chatter_hz, base.cut_fold_hz[i]).abs()
                / data.chatter_std_hz
        });
        Some(label.max(chatter))
    });
    // the poles' noise at the scale the data imply under the base model
    let scale = terms(base, data, noise).pole_scale;
    let poles = data.poles.iter().enumerate().filter_map(|(i, p)| {
        let (b, o) = (base.poles[i]?, other.poles[i]?);
        let frequency =
            pole_frequency_residual(o.frequency_hz, b.frequency_hz, base.pole_fold_hz[i]).abs()
                / p.frequency_std_hz(scale);
        let damping = (o.damping_ratio - b.damping_ratio).abs() / p.damping_std;
        Some(frequency.max(damping))
    });
    cuts.chain(poles)
        .filter(|s| s.is_finite())
        .fold(0.0, f64::max)
}
