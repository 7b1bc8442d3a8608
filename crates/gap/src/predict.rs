//! What a machine variant predicts for each observation, from the Floquet multiplier of the
//! periodic delay equation at the observation's own cutting condition.
//!
//! Every prediction is one dominant multiplier mu of the variant's model at the cut's speed,
//! depth, radial immersion and campaign position ([`inference_solver`]): for milling the
//! first-order full discretization (`chatter_stability::monodromy`, 000 Eq. 9-11, automatic
//! resolution: at least 40 steps and 24 steps per vibration period of the highest mode while
//! cutting); for turning, whose delay equation has constant coefficients, mu = e^{lambda tau}
//! of the rightmost characteristic root found by Newton's method
//! (`chatter_stability::frequency_domain`, exact up to the root search: no discretization).
//! No limiting depth is searched:
//! - a **cut** is described by ln|mu| at its depth and by ln|mu_0| = -min_n zeta_n w_n tau, the
//!   multiplier without cutting. Linear interpolation of ln|mu| in depth between b = 0 and the
//!   cut places the boundary at b_lim = b ln|mu_0| / (ln|mu_0| - ln|mu|), so the signed
//!   log-depth distance of the cut to the boundary is d = ln((ln|mu| - ln|mu_0|) / -ln|mu_0|).
//!   d = 0 exactly where |mu| = 1; away from it d is approximate, which only shapes the label
//!   noise.
//! - a **chattering cut**'s frequency: for milling that of the dominant multiplier at the cut's
//!   own depth (the principal frequency arg(mu) / (2 pi tau) with its images k / tau +- f_mu);
//!   for turning a mixture over root branches (`ChatterBranch`), each a segment from the
//!   frequency where the branch crosses the imaginary axis as the depth is lowered
//!   ([`chatter_stability::frequency_domain::axis_crossings`]: the describing-function limit
//!   cycle with loss of contact) to that of its root at the cut's depth (the linear growth, what
//!   the exact-monodromy proving ground reports). Past the boundary several branches are
//!   unstable, and time-domain simulations with loss of contact settle on the dominant branch or
//!   on the branch that crossed first (the boundary's), about equally often (example
//!   `chatter_frequency`: the lathe at 1.5x and 2.5x the limit, 10 speeds), between the
//!   branch's crossing and its root at depth (60-70 % of the way to the latter, 1-4 Hz from
//!   it at 720-760 Hz): weights 0.45 each (0.9 when they are one branch), 0.1 shared by the next
//!   two unstable branches. Before this the frequency was an equal mixture over the four most
//!   unstable roots at depth, and a limit cycle on the boundary's branch of a cut at |mu| 2.2
//!   (36-56 Hz from the dominant root, the boundary's branch no longer among the four) was
//!   absorbed by an extra mode.
//! - an identified **pole** at a stable cut: for milling lambda = ln(mu) / tau of the dominant
//!   multiplier, lifted over the tooth period (principal frequency |Im lambda| / 2 pi, damping
//!   -Re lambda / |lambda|, as in 002); for turning the physical root (000 Eq. 6): the
//!   resonance (the dominant root off the spindle harmonics and above 0.85 times the lowest
//!   natural frequency, `chatter_stability::resonance`: under process damping at low speed the
//!   dominant roots are those of slow surface regeneration, which respond at spindle harmonics
//!   and are removed by an identification) or a mode's own continued pole, mixed with equal
//!   weights (an identification of a two-mode lathe may report either mode's pole; the
//!   residuals and the checks take the candidate nearest the identified frequency).
//!
//! # Accuracy
//! Against the semi-discretization at four times the resolution (the proving ground's truth)
//! the automatic resolution errs by at most 0.6 % in limiting depth on the test machines (see
//! `tests/proving_ground.rs`); the label width (8 % in depth) covers it. The turning roots agree
//! with the truth to 2e-3 in |mu| and 0.05 % in frequency at 0.3x-2x the limit, and the
//! resonance under strong process damping (C = 1.76e6 N/m, 15-30 mm deep cuts) likewise.
//!
//! # Failures
//! A solver error is never read as stable: the observation gets no prediction (`None`), the
//! likelihood gives it a neutral term and the failure is counted and reported per class.

use crate::data::Dataset;
use crate::variant::Variant;
use chatter_dynamics::pole::multiplier_pole;
use chatter_dynamics::{ModalModel, Operation};
use chatter_stability::StabilitySolver;
use chatter_stability::frequency_domain::{
    CHATTER_BRANCHES as BRANCHES, FrequencyDomain, chatter_branches, dominant_resonance_pole,
    mode_poles,
};
use chatter_stability::monodromy::Discretization;
use chatter_stability::multiplier::DominantMultiplier;
use num_complex::Complex64;
use std::f64::consts::PI;

/// A predicted cut.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CutPrediction {
    /// ln|mu| at the cut's depth.
    pub ln_modulus: f64,
    /// ln|mu| without cutting.
    pub ln_modulus_free: f64,
    /// Predicted chatter frequency (Hz): principal (milling) or physical (turning), of the
    /// dominant multiplier or root at the cut's depth.
    pub chatter_hz: f64,
    /// Where a chattering cut may vibrate (module docs), with their weights (summing to 1);
    /// `None` in the unused slots. Milling: the dominant multiplier's frequency alone.
    pub branches: [Option<ChatterBranch>; BRANCHES],
}

/// A root branch a chattering cut may vibrate on: between the frequency where the branch
/// crosses the imaginary axis (the limit cycle with loss of contact) and that of its root at
/// the cut's own depth (the linear growth).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ChatterBranch {
    /// Frequency of the root at the cut's depth (Hz).
    pub at_depth_hz: f64,
    /// Frequency where the branch crosses the axis (Hz); `at_depth_hz` when not found.
    pub crossing_hz: f64,
    /// Mixture weight.
    pub weight: f64,
}

impl ChatterBranch {
    fn point(frequency_hz: f64, weight: f64) -> Self {
        Self {
            at_depth_hz: frequency_hz,
            crossing_hz: frequency_hz,
            weight,
        }
    }
}

impl CutPrediction {
    /// The branches a chattering cut may show.
    pub fn chatter_branches(&self) -> impl Iterator<Item = &ChatterBranch> + '_ {
        self.branches.iter().flatten()
    }
}

impl CutPrediction {
    /// Signed log-depth distance d = ln(b / b_lim) of the cut to the boundary (module docs).
    pub fn log_distance(&self) -> f64 {
        let l0 = self.ln_modulus_free.min(-1e-9);
        let ratio = (self.ln_modulus - l0) / -l0;
        ratio.max(1e-6).ln()
    }
}

/// A pole as an identification reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PredictedPole {
    pub frequency_hz: f64,
    pub damping_ratio: f64,
}

/// What a variant predicts for a dataset.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Prediction {
    /// Each cut (None: the solver failed).
    pub cuts: Vec<Option<CutPrediction>>,
    /// Fold of each cut's chatter frequency: tooth passing (milling), None for turning.
    pub cut_fold_hz: Vec<Option<f64>>,
    /// Each pole (None: the solver failed): the candidate nearest the identified frequency.
    pub poles: Vec<Option<PredictedPole>>,
    /// Each pole's candidates, which the likelihood mixes with equal weights: for turning
    /// every mode's continued pole and the resonance, for milling the dominant multiplier's pole
    /// alone (empty where the solver failed).
    pub pole_candidates: Vec<Vec<PredictedPole>>,
    /// Fold of each pole's principal frequency (milling only).
    pub pole_fold_hz: Vec<Option<f64>>,
    /// Solver failures among the evaluations.
    pub failures: usize,
}

impl Prediction {
    /// Multiplier evaluations behind the prediction.
    pub fn evaluations(&self) -> usize {
        self.cuts.len() + self.poles.len()
    }
}

/// The solver of every prediction for `model`: the exact characteristic roots of the
/// autonomous delay equation for turning ([`FrequencyDomain`], 000 Eq. 5-6), the first-order
/// full discretization at its automatic resolution for milling (periodic coefficients).
pub fn inference_solver(model: &ModalModel) -> Box<dyn StabilitySolver> {
    if milling(model) {
        Box::new(Discretization::full())
    } else {
        Box::new(FrequencyDomain)
    }
}

/// ln|mu| without cutting: the slowest free decay over one delay.
fn free_ln_modulus(model: &ModalModel, tau_s: f64) -> f64 {
    -model
        .modes()
        .iter()
        .map(|m| m.damping_ratio() * m.omega_rad_s())
        .fold(f64::INFINITY, f64::min)
        * tau_s
}

fn milling(model: &ModalModel) -> bool {
    matches!(model.operation(), Operation::Milling(_))
}

/// The prediction of one cut of `variant` (speed rpm, depth m, immersion, position).
pub(crate) fn predict_cut(
    variant: &Variant,
    speed_rpm: f64,
    depth_m: f64,
    immersion: Option<f64>,
    u: f64,
    with_frequency: bool,
    start: Option<&[f64]>,
) -> Option<CutPrediction> {
    let model = variant.at(immersion, speed_rpm, u).ok()?;
    let tau = model.operation().delay_s(speed_rpm);
    let s = inference_solver(&model);
    let (mu, chatter_hz, branches) = if with_frequency && !milling(&model) {
        // one Newton pass for the dominant root (FrequencyDomain's multiplier) and the others
        let found = chatter_branches(&model, speed_rpm, depth_m).ok()?;
        let dominant = found.first()?.at_width;
        let mut branches = [None; BRANCHES];
        for (slot, b) in branches.iter_mut().zip(&found) {
            *slot = Some(ChatterBranch {
                at_depth_hz: b.at_width_hz(),
                crossing_hz: b.crossing_hz(),
                weight: b.weight,
            });
        }
        (
            DominantMultiplier::new((dominant.lambda * tau).exp(), tau),
            found[0].at_width_hz(),
            branches,
        )
    } else {
        let mu = if milling(&model) {
            milling_multiplier(&model, speed_rpm, depth_m, start)?.0
        } else {
            s.dominant_multiplier(&model, speed_rpm, depth_m).ok()?
        };
        let f = mu.principal_frequency_hz();
        let mut branches = [None; BRANCHES];
        branches[0] = Some(ChatterBranch::point(f, 1.0));
        (mu, f, branches)
    };
    let ln_modulus = mu.modulus().ln();
    ln_modulus.is_finite().then_some(CutPrediction {
        ln_modulus,
        ln_modulus_free: free_ln_modulus(&model, tau),
        chatter_hz,
        branches,
    })
}

/// Relative accuracy of a milling multiplier inside the likelihood (the Krylov residual over
/// |mu|): the labels resolve ln|mu| to about 0.03 and an identified pole's damping to 20 %, so
/// 1e-7 (a multiplier within 2e-5 of |mu| of the default's: the residual times the eigenvalue's
/// condition number) is far below what any observation can see, where the default (1e-10) spends
/// iterations on the last digits: on the outside proving ground's two-mode campaign (`public_16`,
/// 39 cuts, 8 poles) the diagnosis took 163 s of CPU instead of 195 s, every class's ln evidence
/// within 0.4 of the default's (the sampler's own scatter is 1-2.5).
const INFERENCE_TOLERANCE: f64 = 1e-7;

/// The dominant multiplier of a milling model's first-order full discretization (automatic
/// resolution) at a cut, with the start vector it leaves for the next operator (real plus
/// imaginary part of its eigenvector). The Krylov iteration starts from `start` (the nominal
/// model's vector at the same cut, [`crate::data::Dataset`]) resampled to this operator's grid
/// ([`resampled_start`]): a sampler's variants lie close to the nominal model, and a start near
/// the dominant eigenvector saves most of the iteration (on the outside proving ground's xy
/// machine 95 us instead of 230-250 us per eigenvector, the operator's build 280 us; the
/// multiplier agrees to the iteration's tolerance). The start is fixed per observation, so the
/// result does not depend on which thread evaluated what before.
pub(crate) fn milling_multiplier(
    model: &ModalModel,
    speed_rpm: f64,
    depth_m: f64,
    start: Option<&[f64]>,
) -> Option<(DominantMultiplier, Vec<f64>)> {
    let op = Discretization::full()
        .monodromy(model, speed_rpm, depth_m)
        .ok()?;
    let start = start.and_then(|s| resampled_start(s, op.dimension(), model.modes().len()));
    let (mu, vector) = op
        .dominant_eigenpair_within(start.as_deref(), INFERENCE_TOLERANCE)
        .ok()?;
    Some((
        DominantMultiplier::new(mu, op.period_s),
        vector.iter().map(|c| c.re + c.im).collect(),
    ))
}

/// A start vector of the state [y_0 (2N); q at M grid points (N each)] carried to an operator of
/// `dimension` with the same N `modes`: the delayed history interpolated linearly over the grid
/// index (the grid's step count follows the highest natural frequency, which a variant moves);
/// None for another number of modes or a malformed vector.
pub(crate) fn resampled_start(start: &[f64], dimension: usize, modes: usize) -> Option<Vec<f64>> {
    if start.len() == dimension {
        return Some(start.to_vec());
    }
    let head = 2 * modes;
    let grid = |len: usize| {
        (len > head && (len - head).is_multiple_of(modes)).then(|| (len - head) / modes)
    };
    let (from, to) = (grid(start.len())?, grid(dimension)?);
    let mut out = start[..head].to_vec();
    for k in 0..to {
        let x = k as f64 * (from - 1) as f64 / (to - 1).max(1) as f64;
        let (i, t) = (x.floor() as usize, x.fract());
        let j = (i + 1).min(from - 1);
        out.extend(
            (0..modes)
                .map(|c| start[head + i * modes + c] * (1.0 - t) + start[head + j * modes + c] * t),
        );
    }
    Some(out)
}

/// The poles an identification of a stable cut may report: lifted (milling) or physical
/// (turning), and of them the one nearest in frequency to the identified `observed_hz`. For
/// milling it is the dominant multiplier's alone. For turning, where an identification of a
/// multi-mode machine may lock onto a mode's own pole rather than the least-damped root, they are
/// the resonance (dominant root off the spindle harmonics) and each mode's continued pole; the
/// likelihood mixes them with equal weights (a pairing by the nearest alone, a maximum over the
/// candidates, would reward a model for every extra pole it offers: on the proving ground's lathe
/// an extra mode gained 1-3 nats of evidence on campaigns without one); the roots of slow
/// surface regeneration, dominant under process damping at low speed, respond at spindle
/// harmonics, which an identification removes.
pub(crate) fn predict_pole(
    variant: &Variant,
    speed_rpm: f64,
    depth_m: f64,
    immersion: Option<f64>,
    u: f64,
    observed_hz: f64,
    start: Option<&[f64]>,
) -> Option<(PredictedPole, Vec<PredictedPole>)> {
    let model = variant.at(immersion, speed_rpm, u).ok()?;
    let candidates = if milling(&model) {
        let (mu, _) = milling_multiplier(&model, speed_rpm, depth_m, start)?;
        // principal branch of the log: |Im| / 2 pi is the principal frequency in [0, f_tooth / 2]
        vec![observed_pole(multiplier_pole(mu.value, mu.period_s), true)]
    } else {
        let dominant = dominant_resonance_pole(&model, speed_rpm, depth_m).ok()?;
        mode_poles(&model, speed_rpm, depth_m)
            .ok()?
            .into_iter()
            .flatten()
            .chain(std::iter::once(dominant))
            .map(|p| observed_pole(p.lambda, false))
            .filter(|p| p.frequency_hz.is_finite() && p.damping_ratio.is_finite())
            .collect()
    };
    let nearest = candidates.iter().copied().min_by(|a, b| {
        (a.frequency_hz - observed_hz)
            .abs()
            .total_cmp(&(b.frequency_hz - observed_hz).abs())
    })?;
    Some((nearest, candidates))
}

/// A continuous-time pole as it is identified: frequency |Im lambda| / 2 pi for a lifted
/// (milling) pole, |lambda| / 2 pi for a physical one (000 Eq. 6); damping -Re lambda / |lambda|.
pub(crate) fn observed_pole(lambda: Complex64, lifted: bool) -> PredictedPole {
    let (natural_hz, damping_ratio) = chatter_dynamics::pole::pole_frequency_damping(lambda);
    PredictedPole {
        frequency_hz: if lifted {
            lambda.im.abs() / (2.0 * PI)
        } else {
            natural_hz
        },
        damping_ratio,
    }
}

/// Predictions of `variant` for every observation of `data` (in parallel over observations).
pub(crate) fn predict(variant: &Variant, data: &Dataset) -> Prediction {
    let immersion = |g: usize| data.immersions.get(g).copied().flatten();
    let fold = |speed: f64| milling(&variant.model).then(|| 1.0 / variant.delay_s(speed));
    let cuts: Vec<Option<CutPrediction>> = data
        .cuts
        .iter()
        .enumerate()
        .map(|(k, c)| {
            predict_cut(
                variant,
                c.speed_rpm,
                c.depth_m,
                immersion(c.geometry),
                c.u,
                c.chatter_hz.is_some(),
                data.cut_start(k),
            )
        })
        .collect();
    let (poles, pole_candidates): (Vec<Option<PredictedPole>>, Vec<Vec<PredictedPole>>) = data
        .poles
        .iter()
        .enumerate()
        .map(|(k, p)| {
            predict_pole(
                variant,
                p.speed_rpm,
                p.depth_m,
                immersion(p.geometry),
                p.u,
                p.frequency_hz,
                data.pole_start(k),
            )
            .map_or((None, Vec::new()), |(nearest, all)| (Some(nearest), all))
        })
        .unzip();
    let failures =
        cuts.iter().filter(|c| c.is_none()).count() + poles.iter().filter(|p| p.is_none()).count();
    Prediction {
        cut_fold_hz: data.cuts.iter().map(|c| fold(c.speed_rpm)).collect(),
        pole_fold_hz: data.poles.iter().map(|p| fold(p.speed_rpm)).collect(),
        cuts,
        poles,
        pole_candidates,
        failures,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A start keeps y_0 and carries a history linear in the grid index to a finer and a coarser
    /// grid exactly; another number of modes gives none.
    #[test]
    fn starts_are_resampled_over_the_grid() {
        let modes = 2;
        let history = |grid: usize| -> Vec<f64> {
            let mut v = vec![7.0, 8.0, 9.0, 10.0];
            for k in 0..grid {
                let x = k as f64 / (grid - 1) as f64;
                v.extend([x, 2.0 * x]);
            }
            v
        };
        let start = history(11);
        assert_eq!(
            resampled_start(&start, start.len(), modes),
            Some(start.clone())
        );
        for grid in [6, 21] {
            let out = resampled_start(&start, 4 + modes * grid, modes).unwrap();
            let want = history(grid);
            assert_eq!(out.len(), want.len());
            assert!(out.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-12));
        }
        assert_eq!(resampled_start(&start, 4 + 3 * 7, 3), None);
    }

    /// The warm- and the cold-started multiplier of a variant at the inference tolerance equal
    /// the one at the solver's default tolerance to 1e-4 of |mu| (measured: 2e-5).
    #[test]
    fn a_warm_start_gives_the_same_multiplier() {
        let model = crate::generator::nominal_milling().unwrap();
        let (_, start) = milling_multiplier(&model, 9000.0, 2e-3, None).unwrap();
        let variant = crate::variant::recalibrated(&model, 1.04, 1.2, 1.1).unwrap();
        let (warm, _) = milling_multiplier(&variant, 9000.0, 2.2e-3, Some(&start)).unwrap();
        let (cold, _) = milling_multiplier(&variant, 9000.0, 2.2e-3, None).unwrap();
        let exact = Discretization::full()
            .monodromy(&variant, 9000.0, 2.2e-3)
            .unwrap()
            .dominant_eigenpair()
            .unwrap()
            .0;
        // the eigenvalue's error is the residual times its condition number (a monodromy
        // operator is far from normal): 1e-4 of |mu| is 0.3 % of the labels' width in ln|mu|
        for mu in [warm.value, cold.value] {
            assert!(
                (mu - exact).norm() < 1e-4 * exact.norm(),
                "{mu} against {exact}"
            );
        }
    }
}
