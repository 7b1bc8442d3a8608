//! Closed-loop poles of turning from the characteristic equation (Ahmadi 2022, seed 000,
//! Section 2.1, Eq. 5-6; the equation and its Newton step are in [`crate::characteristic`],
//! with process damping).
//!
//! Each structural pole lambda_n = -zeta_n w_n + i w_n sqrt(1 - zeta_n^2) (the root at a = 0) is
//! continued in the width a by Newton's method. The dominant pole is the root with the largest
//! real part from a grid of starts ([`dominant_pole`]); its frequency is |lambda| and its damping
//! -Re(lambda) / |lambda| (Eq. 6).

use crate::StabilitySolver;
use crate::characteristic::Characteristic;
use crate::error::{Result, StabilityError, check_condition};
use crate::multiplier::DominantMultiplier;
use crate::resonance::{near_harmonic, resonance_floor_hz};
use chatter_dynamics::ModalModel;
use chatter_dynamics::pole::pole_frequency_damping;
use num_complex::Complex64;
use std::f64::consts::PI;

/// Width steps of the continuation from a = 0.
const CONTINUATION_STEPS: usize = 24;
/// Newton iterations per continuation step.
const NEWTON_ITERATIONS: usize = 30;
/// Newton iterations from a grid start: a start a quarter of the root spacing from a root
/// converges quadratically within a few; one that wanders is abandoned.
const GRID_NEWTON_ITERATIONS: usize = 12;
/// Starts -x / tau on the negative real axis of the dominant-root search.
const REAL_STARTS: [f64; 4] = [0.05, 0.3, 1.0, 3.0];

/// A closed-loop pole with its frequency and damping (000 Eq. 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosedLoopPole {
    /// lambda (rad/s).
    pub lambda: Complex64,
    /// |lambda| / 2 pi.
    pub frequency_hz: f64,
    /// -Re(lambda) / |lambda|.
    pub damping_ratio: f64,
}

impl ClosedLoopPole {
    fn new(lambda: Complex64) -> Self {
        let (frequency_hz, damping_ratio) = pole_frequency_damping(lambda);
        Self {
            lambda,
            frequency_hz,
            damping_ratio,
        }
    }
}

/// The structural pole `lambda` continued in the width from a = 0 to `width_m` in
/// [`CONTINUATION_STEPS`] steps, Newton at each.
fn continue_pole(ch: &Characteristic, mut lambda: Complex64, width_m: f64) -> Result<Complex64> {
    for k in 1..=CONTINUATION_STEPS {
        let a = width_m * k as f64 / CONTINUATION_STEPS as f64;
        lambda = ch.newton(lambda, a, NEWTON_ITERATIONS).ok_or_else(|| {
            StabilityError::NoConvergence {
                solver: "characteristic-equation Newton",
                detail: format!("width {a} m"),
            }
        })?;
    }
    Ok(lambda)
}

/// The closed-loop poles continued from every structural pole, at `speed_rpm` and width
/// `width_m`.
pub fn closed_loop_poles(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<Vec<ClosedLoopPole>> {
    continued_poles(model, speed_rpm, width_m)?
        .into_iter()
        .collect()
}

/// Every structural pole continued in the width, each with its own outcome.
fn continued_poles(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<Vec<Result<ClosedLoopPole>>> {
    check_condition(speed_rpm, width_m)?;
    let ch = Characteristic::new(model, speed_rpm)?;
    Ok(model
        .modes()
        .iter()
        .map(|m| {
            let (w, z) = (m.omega_rad_s(), m.damping_ratio());
            let start = Complex64::new(-z * w, w * (1.0 - z * z).sqrt());
            continue_pole(&ch, start, width_m).map(ClosedLoopPole::new)
        })
        .collect())
}

/// The dominant (largest real part) closed-loop pole. Delay equations have infinitely many
/// roots; near each mode they form a chain spaced about 2 pi / tau in frequency. Continuing
/// the structural pole in the width does not always end on the dominant root, nor always
/// succeed (at long delays e^{-lambda tau} is large at a damped pole and Newton's basin
/// small), so Newton is started on the imaginary axis, where stability is decided, on a grid
/// around every mode (spacing a quarter of the spindle frequency, from 15 % below the lower to
/// 15 % above the higher of the natural frequency and the frequency with the cut's mean
/// stiffness sqrt(omega^2 + b W_ii), which deep cuts reach, at most 12 iterations each) and on the negative real axis at -x / tau
/// (x = 0.05, 0.3, 1, 3: the real root of slow surface regeneration, which dominates with
/// process damping at low speed), and the root with the largest real part wins; an error only
/// when no start converges. Checked against the first-order full discretization at
/// 4000 steps (tests here) and against the semi-discretization at 4x resolution on the gap
/// proving ground's turning machine (|mu| within 4e-4 from 0.3x to 2x the limiting depth).
pub fn dominant_pole(model: &ModalModel, speed_rpm: f64, width_m: f64) -> Result<ClosedLoopPole> {
    grid_roots(model, speed_rpm, width_m)?
        .into_iter()
        .max_by(|a, b| a.re.total_cmp(&b.re))
        .map(ClosedLoopPole::new)
        .ok_or_else(|| no_root(speed_rpm, width_m))
}

/// The resonance of a cut: the closed-loop pole with the largest real part whose multiplier
/// e^{lambda tau} keeps clear of the spindle harmonics and whose frequency is structural
/// ([`crate::resonance`]), from the starts of [`dominant_pole`]. It is what an identification of a stable cut sees when the dominant
/// roots are the real one of slow surface regeneration and its chain at spindle harmonics
/// (process damping at low speed).
pub fn dominant_resonance_pole(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<ClosedLoopPole> {
    let tau = model.operation().delay_s(speed_rpm);
    let floor_rad_s = 2.0 * PI * resonance_floor_hz(model);
    grid_roots(model, speed_rpm, width_m)?
        .into_iter()
        .filter(|r| !near_harmonic((r * tau).exp()) && r.im >= floor_rad_s)
        .max_by(|a, b| a.re.total_cmp(&b.re))
        .map(ClosedLoopPole::new)
        .ok_or_else(|| no_root(speed_rpm, width_m))
}

/// The dominant pole ([`dominant_pole`]) and every other distinct unstable (Re lambda > 0)
/// closed-loop pole that the same starts reach, by decreasing real part (none when the cut is
/// stable), from one Newton pass. Past the boundary several roots of a chain can be unstable; a
/// nonlinear limit cycle (loss of contact) may grow from any of them, not always the most
/// unstable (on the gap proving ground's lathe at 1.4-1.6 |mu| the simulated chatter settles
/// 25-50 Hz from the dominant root, on the root that crossed the axis first).
pub fn dominant_and_unstable_poles(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<(ClosedLoopPole, Vec<ClosedLoopPole>)> {
    let mut roots = grid_roots(model, speed_rpm, width_m)?;
    roots.sort_by(|a, b| b.re.total_cmp(&a.re));
    let Some(&dominant) = roots.first() else {
        return Err(no_root(speed_rpm, width_m));
    };
    let mut distinct = vec![dominant];
    for r in roots.into_iter().filter(|r| r.re > 0.0) {
        if distinct.iter().all(|d| (d - r).norm() > 1e-6 * r.norm()) {
            distinct.push(r);
        }
    }
    Ok((
        ClosedLoopPole::new(dominant),
        distinct[1..]
            .iter()
            .map(|&r| ClosedLoopPole::new(r))
            .collect(),
    ))
}

/// Every distinct closed-loop pole (upper half plane) that the starts of [`dominant_pole`]
/// reach, by decreasing real part, so the first is the dominant pole: near each mode the chain
/// of delay roots spaced about 1 / tau in frequency, and the real root of slow surface
/// regeneration. Roots closer than 1e-6 |lambda| are one. The chain is listed only within the
/// grid's span (15 % around each mode and its cut-stiffness frequency); a root far down the
/// chain that no start converges to is missing. An error only when no start converges.
///
/// ```
/// use chatter_dynamics::examples;
/// use chatter_stability::frequency_domain::{characteristic_roots, dominant_pole};
/// let model = examples::ahmadi_2022_turning();
/// let roots = characteristic_roots(&model, 3000.0, 1e-3).unwrap();
/// let dominant = dominant_pole(&model, 3000.0, 1e-3).unwrap();
/// assert!(roots.len() > 1);
/// assert!((roots[0].lambda - dominant.lambda).norm() < 1e-6 * dominant.lambda.norm());
/// assert!(roots.windows(2).all(|w| w[0].lambda.re >= w[1].lambda.re));
/// ```
pub fn characteristic_roots(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<Vec<ClosedLoopPole>> {
    let mut roots = grid_roots(model, speed_rpm, width_m)?;
    if roots.is_empty() {
        return Err(no_root(speed_rpm, width_m));
    }
    roots.sort_by(|a, b| b.re.total_cmp(&a.re));
    let mut distinct: Vec<Complex64> = Vec::with_capacity(roots.len());
    for r in roots {
        if distinct.iter().all(|d| (d - r).norm() > 1e-6 * r.norm()) {
            distinct.push(r);
        }
    }
    Ok(distinct.into_iter().map(ClosedLoopPole::new).collect())
}

/// Where the branch of each of `poles` (closed-loop poles at `speed_rpm` and width `width_m`,
/// e.g. the unstable ones of [`dominant_and_unstable_poles`]) crosses the imaginary axis as the
/// width is lowered: the width (m) and the pole there, `None` for a pole that is not unstable
/// or whose branch is lost ([`Characteristic::axis_crossing`]). A chattering cut with loss of
/// contact settles near one of these frequencies (the describing-function limit cycle).
pub fn axis_crossings(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
    poles: &[ClosedLoopPole],
) -> Result<Vec<Option<(f64, ClosedLoopPole)>>> {
    check_condition(speed_rpm, width_m)?;
    let ch = Characteristic::new(model, speed_rpm)?;
    Ok(poles
        .iter()
        .map(|p| {
            ch.axis_crossing(p.lambda, width_m)
                .map(|(a, l)| (a, ClosedLoopPole::new(l)))
        })
        .collect())
}

/// A root branch a chattering cut may vibrate on ([`chatter_branches`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChatterBranch {
    /// The branch's root at the cut's width.
    pub at_width: ClosedLoopPole,
    /// Where the branch crosses the imaginary axis as the width is lowered: the width (m) and
    /// the pole there (`None` when not found).
    pub crossing: Option<(f64, ClosedLoopPole)>,
    /// How often a chattering cut settles on it (sums to 1 over the branches).
    pub weight: f64,
}

impl ChatterBranch {
    /// Im lambda / 2 pi at the cut's width (Hz).
    pub fn at_width_hz(&self) -> f64 {
        self.at_width.lambda.im / (2.0 * PI)
    }

    /// Im lambda / 2 pi at the axis crossing (Hz), or at the cut's width when not found.
    pub fn crossing_hz(&self) -> f64 {
        self.crossing
            .map_or(self.at_width.lambda, |(_, p)| p.lambda)
            .im
            / (2.0 * PI)
    }
}

/// Branches a chattering cut is mixed over ([`chatter_branches`]).
pub const CHATTER_BRANCHES: usize = 4;
/// Weight of the dominant branch and of the first-crossed branch when they differ.
const MAIN_WEIGHT: f64 = 0.45;
/// Weight shared by the other unstable branches.
const OTHER_WEIGHT: f64 = 0.1;

/// Where a chattering turning cut at `speed_rpm` and width `width_m` vibrates, as a mixture
/// over root branches, each between its axis crossing ([`axis_crossings`]: the limit cycle with
/// loss of contact) and its root at the cut's width (the linear growth), with the dominant root
/// first. Past the boundary several branches are unstable; time-domain simulations with loss of
/// contact (`chatter_dynamics::simulate`, detected by `chatter_oma::detection`; the gap crate's
/// example `chatter_frequency` and test `chatter_frequency`: a two-mode lathe at 1.5x and 2.5x
/// the limit, 10 speeds) settle on the dominant branch or on the branch that crossed first
/// (the boundary's) about equally often, now and then on another, 60-70 % of the way from the
/// crossing to the root at the width. Weights: 0.45 each (0.9 when they are one branch), 0.1
/// shared by the next two unstable branches, renormalized when there are fewer. A stable cut
/// has the dominant root alone.
pub fn chatter_branches(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<Vec<ChatterBranch>> {
    let (dominant, others) = dominant_and_unstable_poles(model, speed_rpm, width_m)?;
    let mut roots = vec![dominant];
    roots.extend(others);
    let crossings = axis_crossings(model, speed_rpm, width_m, &roots)?;
    let first_crossed = crossings
        .iter()
        .enumerate()
        .filter_map(|(i, c)| c.map(|(width, _)| (i, width)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(0, |(i, _)| i);
    let mut chosen = vec![(0, MAIN_WEIGHT)];
    if first_crossed == 0 {
        chosen[0].1 += MAIN_WEIGHT;
    } else {
        chosen.push((first_crossed, MAIN_WEIGHT));
    }
    let others: Vec<usize> = (1..roots.len())
        .filter(|&i| i != first_crossed)
        .take(CHATTER_BRANCHES - chosen.len())
        .collect();
    for &i in &others {
        chosen.push((i, OTHER_WEIGHT / others.len() as f64));
    }
    let total: f64 = chosen.iter().map(|c| c.1).sum();
    Ok(chosen
        .into_iter()
        .map(|(i, w)| ChatterBranch {
            at_width: roots[i],
            crossing: crossings[i],
            weight: w / total,
        })
        .collect())
}

/// The error when no Newton start converges.
fn no_root(speed_rpm: f64, width_m: f64) -> StabilityError {
    StabilityError::NoConvergence {
        solver: "characteristic-equation Newton",
        detail: format!("no root found at {speed_rpm} rpm, width {width_m} m"),
    }
}

/// The roots (upper half plane) that Newton reaches from the starts of [`dominant_pole`].
fn grid_roots(model: &ModalModel, speed_rpm: f64, width_m: f64) -> Result<Vec<Complex64>> {
    check_condition(speed_rpm, width_m)?;
    let ch = Characteristic::new(model, speed_rpm)?;
    let tau = ch.delay_s();
    let spacing = 2.0 * PI / tau / 4.0;
    // the real (non-oscillating) root of the slow surface regeneration, which dominates with
    // process damping at low speed: |lambda| ~ 1 / tau
    let real_starts = REAL_STARTS.iter().map(|x| Complex64::new(-x / tau, 0.0));
    // the cutting stiffness moves the roots of a deep cut away from the structural frequency:
    // the grid also covers sqrt(omega^2 + b W_ii), the frequency with the cut's mean stiffness
    let shifted = |i: usize| {
        let w = ch.omegas_rad_s()[i];
        (w * w + width_m * ch.coupling_diagonal(i))
            .max(0.01 * w * w)
            .sqrt()
    };
    Ok((0..ch.omegas_rad_s().len())
        .flat_map(|i| {
            let (w, w_cut) = (ch.omegas_rad_s()[i], shifted(i));
            let below = ((w - w.min(w_cut) + 0.15 * w) / spacing).ceil() as i64;
            let above = ((w.max(w_cut) - w + 0.15 * w) / spacing).ceil() as i64;
            (-below..=above).map(move |j| Complex64::new(0.0, w + j as f64 * spacing))
        })
        .chain(real_starts)
        .filter_map(|start| ch.newton(start, width_m, GRID_NEWTON_ITERATIONS))
        .filter(|root| root.im >= 0.0)
        .collect())
}

/// Each mode's own closed-loop pole, continued in the width from its structural pole as
/// [`closed_loop_poles`] does, `None` where the continuation fails: the pole an identification
/// sees near that mode, which need not be the dominant one.
pub fn mode_poles(
    model: &ModalModel,
    speed_rpm: f64,
    width_m: f64,
) -> Result<Vec<Option<ClosedLoopPole>>> {
    Ok(continued_poles(model, speed_rpm, width_m)?
        .into_iter()
        .map(Result::ok)
        .collect())
}

/// The frequency-domain method as a [`StabilitySolver`]: mu = e^{lambda tau} of the dominant pole.
#[derive(Debug, Clone, Copy, Default)]
pub struct FrequencyDomain;

impl StabilitySolver for FrequencyDomain {
    fn name(&self) -> &'static str {
        "frequency-domain"
    }

    fn dominant_multiplier(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<DominantMultiplier> {
        let p = dominant_pole(model, speed_rpm, depth_m)?;
        let tau = model.operation().delay_s(speed_rpm);
        Ok(DominantMultiplier::new((p.lambda * tau).exp(), tau))
    }

    fn chatter_frequency_hz(
        &self,
        model: &ModalModel,
        speed_rpm: f64,
        depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)> {
        let p = dominant_pole(model, speed_rpm, depth_m)?;
        let tau = model.operation().delay_s(speed_rpm);
        Ok((
            DominantMultiplier::new((p.lambda * tau).exp(), tau),
            p.lambda.im / (2.0 * PI),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    #[test]
    fn zero_width_gives_structural_poles() {
        let model = examples::ahmadi_2022_turning();
        let poles = closed_loop_poles(&model, 7150.0, 0.0).unwrap();
        for (p, m) in poles.iter().zip(model.modes()) {
            assert!((p.frequency_hz - m.frequency_hz()).abs() < 1e-9 * m.frequency_hz());
            assert!((p.damping_ratio - m.damping_ratio()).abs() < 1e-12);
        }
    }

    /// The one-pass dominant pole is [`dominant_pole`]'s; the other poles are unstable, slower
    /// than it and distinct; a stable cut has none and a cut far past the boundary several.
    #[test]
    fn unstable_poles_follow_the_dominant_one() {
        let model = examples::ahmadi_2022_turning();
        let options = crate::boundary::BoundaryOptions::default();
        let limit = crate::boundary::limiting_depth(&FrequencyDomain, &model, 7150.0, &options)
            .unwrap()
            .depth_m;
        let (_, none) = dominant_and_unstable_poles(&model, 7150.0, 0.5 * limit).unwrap();
        assert!(none.is_empty());
        let mut seen_others = false;
        for factor in [1.5, 3.0, 6.0] {
            let b = factor * limit;
            let (dominant, others) = dominant_and_unstable_poles(&model, 7150.0, b).unwrap();
            assert_eq!(dominant, dominant_pole(&model, 7150.0, b).unwrap());
            for p in &others {
                assert!(p.lambda.re > 0.0 && p.lambda.re <= dominant.lambda.re);
                assert!((p.lambda - dominant.lambda).norm() > 1e-6 * dominant.lambda.norm());
            }
            seen_others |= !others.is_empty();
        }
        assert!(seen_others, "no second unstable root up to 6x the limit");
    }

    /// The branches of a chattering cut: at 1.5x, 3x and 6x the limit (seed-000 lathe, and with
    /// process damping C = 2e4 N/m at 2000 rpm) the first-crossed branch crosses the axis at
    /// the limiting depth of the boundary search (within its tolerance, 1e-6 relative here
    /// with the tighter search below) and at its chatter frequency (the dominant root there,
    /// within 1e-4 Hz), the crossing is a root of the characteristic equation with Re = 0, the
    /// dominant branch comes first, and the weights sum to 1.
    #[test]
    fn the_first_crossed_branch_crosses_at_the_boundary() {
        use crate::boundary::{BoundaryOptions, limiting_depth};
        let bare = examples::ahmadi_2022_turning();
        let options = BoundaryOptions {
            relative_tolerance: 1e-9,
            ..BoundaryOptions::default()
        };
        for (model, speed) in [
            (bare.clone(), 7150.0),
            (bare.with_process_damping(Some(2e4)).unwrap(), 2000.0),
        ] {
            let limit = limiting_depth(&FrequencyDomain, &model, speed, &options)
                .unwrap()
                .depth_m;
            let boundary = dominant_pole(&model, speed, limit).unwrap();
            let ch = Characteristic::new(&model, speed).unwrap();
            for factor in [1.5, 3.0, 6.0] {
                let branches = chatter_branches(&model, speed, factor * limit).unwrap();
                let dominant = dominant_pole(&model, speed, factor * limit).unwrap();
                assert_eq!(branches[0].at_width, dominant);
                let total: f64 = branches.iter().map(|b| b.weight).sum();
                assert!((total - 1.0).abs() < 1e-12);
                let (width, pole) = branches
                    .iter()
                    .filter_map(|b| b.crossing)
                    .min_by(|a, b| a.0.total_cmp(&b.0))
                    .unwrap();
                assert!((width / limit - 1.0).abs() < 1e-6, "{width} vs {limit}");
                assert!(
                    (pole.lambda.im - boundary.lambda.im).abs() / (2.0 * PI) < 1e-4,
                    "{} vs {}",
                    pole.frequency_hz,
                    boundary.frequency_hz
                );
                for (w, p) in branches.iter().filter_map(|b| b.crossing) {
                    assert!(p.lambda.re.abs() <= 1e-9 * p.lambda.norm());
                    let step = ch.newton_step(p.lambda, w).unwrap();
                    assert!(step.norm() <= 1e-8 * p.lambda.norm(), "{step}");
                }
            }
        }
    }

    /// Turning with process damping (seed-000 lathe, C = 2e4 N/m, 38 mm workpiece): the poles
    /// include it as the discretization does, so the limiting depths agree to 0.2 % with FDM at
    /// 4000 steps (measured 0.11 % at 2000 rpm, 0.01 % at 7150 rpm: FDM's first-order error at
    /// 30 steps per vibration cycle), and process damping raises the limit at 2000 rpm (V = 4 m/s)
    /// from 2.880 to 3.130 mm.
    #[test]
    fn process_damping_agrees_with_discretization() {
        use crate::boundary::{BoundaryOptions, limiting_depth};
        use crate::monodromy::{Discretization, steps};
        let bare = examples::ahmadi_2022_turning();
        let model = bare.with_process_damping(Some(2e4)).unwrap();
        let options = BoundaryOptions::default();
        for speed in [2000.0, 7150.0] {
            let poles = limiting_depth(&FrequencyDomain, &model, speed, &options).unwrap();
            let fdm = limiting_depth(
                &Discretization::full().with_steps(steps::<4000>()),
                &model,
                speed,
                &options,
            )
            .unwrap();
            assert!(
                (poles.depth_m - fdm.depth_m).abs() < 2e-3 * fdm.depth_m,
                "{speed} rpm: poles {} mm, fdm {} mm",
                poles.depth_mm(),
                fdm.depth_mm()
            );
        }
        let without = limiting_depth(&FrequencyDomain, &bare, 2000.0, &options).unwrap();
        let with = limiting_depth(&FrequencyDomain, &model, 2000.0, &options).unwrap();
        assert!(
            with.depth_m > 1.05 * without.depth_m,
            "{with:?} vs {without:?}"
        );
    }

    #[test]
    fn milling_is_rejected() {
        let model = examples::schmitz_2023_milling();
        assert!(closed_loop_poles(&model, 7000.0, 1e-3).is_err());
    }
}
