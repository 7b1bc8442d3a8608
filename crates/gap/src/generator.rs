//! The proving ground: synthetic shop-floor campaigns from a "true" machine that hides one
//! effect, computed by a different and more faithful solver than the one inside the diagnosis.
//!
//! # Truth
//! The true machine is a [`Variant`] of the nominal model (a recalibration error and one hidden
//! effect). Every true quantity comes from the **semi-discretization** (Insperger and Stépán)
//! at four times the automatic resolution of the true model (at least 160 steps per delay),
//! while the diagnosis uses the first-order **full discretization** at the automatic
//! resolution (turning: the characteristic roots): another scheme at a converged resolution,
//! so the inference's approximation error shows in the data as it would against a real
//! machine. Where the truth's eigen-solver stalls, the truth is recomputed on a finer grid and
//! then with the full discretization at four times the resolution. `tests/proving_ground.rs`
//! checks the truth against an independent computation written in the test.
//!
//! # Campaign
//! As a shop would run it: `cuts` cuts at `speeds` test speeds drawn uniformly over the
//! machine's range and depths log-uniform between 0.5 and 2 times the **nominal** limiting depth
//! there, in random order (`sequence`). A cut is labelled chatter when |mu| > 1 at its depth
//! jittered by exp(w e), e ~ N(0, 1): a probit in ln(b / b_lim) with width w (label noise near
//! the boundary). A chattering cut reports the frequency of the dominant multiplier at its own
//! depth with relative jitter. Poles are the dominant closed-loop poles of stable cuts (fractions
//! of the true limit at the pole speeds), lifted for milling, with relative frequency and
//! damping noise, as repeated operational modal analysis would give; in turning the resonance
//! (`chatter_stability::resonance`), since the dominant roots of slow surface regeneration under
//! process damping at low speed respond at spindle harmonics, which the analysis removes.
//!
//! ```no_run
//! use chatter_gap::{HiddenEffect, Scenario, nominal_milling, synthesize};
//! let nominal = nominal_milling()?;
//! let scenario = Scenario::new(HiddenEffect::Drift { cutting_change_over_campaign: 0.5 }, 7);
//! let data = synthesize(&nominal, &scenario)?;
//! assert_eq!(data.cuts.len(), scenario.cuts);
//! assert!(data.cuts.iter().all(|c| c.sequence.is_some()));
//! # Ok::<(), chatter_gap::GapError>(())
//! ```

use crate::classes::{EffectClass, dominant_mode};
use crate::error::{GapError, Result, positive};
use crate::predict::observed_pole;
use crate::variant::{CuttingBand, Variant, recalibrated};
use chatter_dynamics::{
    Cut, CuttingCoefficients, Milling, MillingDirection, ModalModel, Mode, ModeShape, Observations,
    Operation, PoleObservation, Turning,
};
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::monodromy::{Discretization, steps, steps_at_least};
use num_complex::Complex64;
use rand::rngs::StdRng;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use serde::Serialize;
use std::f64::consts::PI;
use std::num::NonZeroUsize;

/// Resolution of the truth relative to the automatic one, and its floor.
const TRUTH_REFINEMENT: usize = 4;
const TRUTH_MIN_STEPS: NonZeroUsize = steps::<160>();

/// The effect hidden in the true machine.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum HiddenEffect {
    /// Nothing beyond the recalibration error.
    ParameterError,
    /// Process damping F_d = -C b ydot / V.
    ProcessDamping {
        /// C (N/m).
        c_n_per_m: f64,
    },
    /// Natural frequencies falling with speed, f_n (1 - c Omega^2), stiffness with f_n^2.
    SpeedDependentDynamics {
        /// Relative frequency drop c Omega^2 at the highest test speed.
        frequency_drop_at_max_speed: f64,
    },
    /// One more mode.
    ExtraMode {
        /// Natural frequency (Hz).
        frequency_hz: f64,
        /// Damping ratio.
        damping_ratio: f64,
        /// Modal stiffness along its direction (N/m).
        stiffness_n_per_m: f64,
        /// Direction from the first coordinate towards the second (degrees).
        direction_deg: f64,
    },
    /// Cutting coefficients changing by this fraction from the first to the last entry.
    Drift {
        /// Relative change over the campaign.
        cutting_change_over_campaign: f64,
    },
    /// Outside the candidate list: only `cutting_teeth` evenly spaced teeth of a milling cutter
    /// cut (extreme runout).
    Runout {
        /// Teeth that cut (a divisor of the cutter's teeth).
        cutting_teeth: usize,
    },
    /// Outside the candidate list: the cutting coefficients change by a factor inside a band of
    /// speeds (e.g. built-up edge).
    CuttingBand {
        /// Lowest speed of the band (rpm).
        from_rpm: f64,
        /// Highest speed of the band (rpm).
        to_rpm: f64,
        /// Factor on the cutting coefficients.
        factor: f64,
    },
}

impl HiddenEffect {
    /// The class a correct diagnosis names (`None` for `consistent` or an effect outside the
    /// list).
    pub fn expected_class(&self) -> Option<EffectClass> {
        match self {
            HiddenEffect::ParameterError => Some(EffectClass::ParameterError),
            HiddenEffect::ProcessDamping { .. } => Some(EffectClass::ProcessDamping),
            HiddenEffect::SpeedDependentDynamics { .. } => {
                Some(EffectClass::SpeedDependentDynamics)
            }
            HiddenEffect::ExtraMode { .. } => Some(EffectClass::ExtraMode),
            HiddenEffect::Drift { .. } => Some(EffectClass::Drift),
            HiddenEffect::Runout { .. } | HiddenEffect::CuttingBand { .. } => None,
        }
    }

    /// The expected verdict's name for a true machine with recalibration `error`: `consistent`
    /// when there is neither an effect nor an error, `unexplained` outside the list.
    pub fn expected_verdict(&self, error: &Recalibration) -> &'static str {
        match self {
            HiddenEffect::ParameterError if *error == Recalibration::default() => "consistent",
            _ => self
                .expected_class()
                .map_or("unexplained", EffectClass::name),
        }
    }
}

/// The recalibration error of the true machine against the nominal model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Recalibration {
    /// Natural frequencies (at constant modal stiffness).
    pub frequency_factor: f64,
    /// Damping ratios.
    pub damping_factor: f64,
    /// Cutting coefficients over stiffness.
    pub cutting_over_stiffness_factor: f64,
}

impl Default for Recalibration {
    /// No error.
    fn default() -> Self {
        Self {
            frequency_factor: 1.0,
            damping_factor: 1.0,
            cutting_over_stiffness_factor: 1.0,
        }
    }
}

/// Whether the campaign records the run order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RunOrder {
    /// Every cut and pole carries `sequence`.
    Recorded,
    /// No `sequence`.
    Omitted,
}

/// A synthetic campaign. Defaults in [`Scenario::new`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scenario {
    /// The hidden effect.
    pub effect: HiddenEffect,
    /// The recalibration error.
    pub error: Recalibration,
    /// Speed range of the cuts (rpm).
    pub speed_range_rpm: (f64, f64),
    /// Number of test cuts.
    pub cuts: usize,
    /// Number of distinct test speeds the cuts share (drawn uniformly over the range).
    pub speeds: usize,
    /// Range of the cut depths as multiples of the nominal limiting depth (log-uniform).
    pub depth_ratio_range: (f64, f64),
    /// Speeds at which poles are identified (rpm); two poles each.
    pub pole_speeds_rpm: Vec<f64>,
    /// Depths of the pole cuts as fractions of the true limiting depth.
    pub pole_depth_fractions: Vec<f64>,
    /// Probit width of the label noise in ln depth.
    pub label_width_log_depth: f64,
    /// Relative standard deviation of the chatter-frequency jitter.
    pub chatter_jitter_relative: f64,
    /// Relative standard deviation of identified pole frequencies.
    pub pole_frequency_std_relative: f64,
    /// Relative standard deviation of identified pole damping ratios.
    pub pole_damping_std_relative: f64,
    /// Whether `sequence` is recorded.
    pub run_order: RunOrder,
    /// Seed of the speeds, depths, run order and every noise draw.
    pub seed: u64,
}

impl Scenario {
    /// A campaign with `effect` on [`nominal_milling`] and the defaults: no recalibration error;
    /// 32 cuts at 10 speeds between 2000 and 13000 rpm at 0.5-2 times the nominal limit; poles at 3000, 6000,
    /// 9000 and 12000 rpm at 0.3 and 0.6 of the true limit; label width 0.05; chatter jitter
    /// 0.3 %; pole noise 1 % in frequency and 20 % in damping; sequence recorded.
    pub fn new(effect: HiddenEffect, seed: u64) -> Self {
        Self {
            effect,
            error: Recalibration::default(),
            speed_range_rpm: (2000.0, 13000.0),
            cuts: 32,
            speeds: 10,
            depth_ratio_range: (0.5, 2.0),
            pole_speeds_rpm: vec![3000.0, 6000.0, 9000.0, 12000.0],
            pole_depth_fractions: vec![0.3, 0.6],
            label_width_log_depth: 0.05,
            chatter_jitter_relative: 0.003,
            pole_frequency_std_relative: 0.01,
            pole_damping_std_relative: 0.2,
            run_order: RunOrder::Recorded,
            seed,
        }
    }

    /// The same campaign over another speed range, with the pole speeds spread over it.
    pub fn with_speed_range(mut self, min_rpm: f64, max_rpm: f64, pole_speeds: usize) -> Self {
        self.speed_range_rpm = (min_rpm, max_rpm);
        self.pole_speeds_rpm = (0..pole_speeds)
            .map(|i| min_rpm + (max_rpm - min_rpm) * (i as f64 + 0.5) / pole_speeds as f64)
            .collect();
        self
    }
}

/// The nominal model of the synthetic shop: the milling case of seed 001 (4 teeth, 20 % down
/// milling, Ks 750 N/mm^2, beta 68 deg) on a 19.05 mm cutter, with an x mode of 750 Hz, 3 %,
/// 3e6 N/m and a y mode of 810 Hz, 3.5 %, 3.6e6 N/m.
pub fn nominal_milling() -> Result<ModalModel> {
    let op = Milling::new(4, 0.2, MillingDirection::Down, Some(0.01905), None)?;
    Ok(ModalModel::new(
        Some("synthetic shop: seed 001 cutter with two distinct modes".into()),
        Operation::Milling(op),
        CuttingCoefficients::from_ks_beta(750e6, 68f64.to_radians())?,
        vec![mode(750.0, 0.03, 3.0e6, 0)?, mode(810.0, 0.035, 3.6e6, 1)?],
        None,
    )?)
}

fn mode(f: f64, z: f64, k: f64, coordinate: usize) -> Result<Mode> {
    Ok(Mode::new(
        f,
        z,
        ModeShape::Directional {
            coordinate,
            stiffness_n_per_m: k,
        },
    )?)
}

/// A mode of stiffness `k` along a direction `angle_deg` from the first coordinate.
fn oblique(f: f64, z: f64, k: f64, angle_deg: f64) -> Result<Mode> {
    let a = 2.0 * PI * f / k.sqrt();
    let t = angle_deg.to_radians();
    Ok(Mode::new(
        f,
        z,
        ModeShape::MassNormalized([a * t.cos(), a * t.sin()]),
    )?)
}

/// A machine of the proving ground: its nominal model and test speed range.
#[derive(Debug, Clone)]
pub struct ProvingMachine {
    /// Short name.
    pub name: &'static str,
    /// The nominal model.
    pub model: ModalModel,
    /// Speed range of the campaigns (rpm).
    pub speed_range_rpm: (f64, f64),
}

/// A case of the proving ground: its name, magnitude label ("control" or "2x"), the hidden
/// effect and the recalibration error of the true machine.
pub type ProvingCase = (String, String, HiddenEffect, Recalibration);

impl ProvingMachine {
    /// The control (the nominal model is right) and every class of `classes` at every
    /// magnitude of `magnitudes` ([`effect_at`]); process damping only where the model has a
    /// cutting diameter.
    pub fn cases(&self, classes: &[EffectClass], magnitudes: &[f64]) -> Result<Vec<ProvingCase>> {
        let mut cases = vec![(
            "control".to_string(),
            "control".to_string(),
            HiddenEffect::ParameterError,
            Recalibration::default(),
        )];
        for &class in classes {
            if class == EffectClass::ProcessDamping
                && self.model.operation().cutting_diameter_m().is_none()
            {
                continue;
            }
            for &m in magnitudes {
                let (effect, error) = effect_at(class, m, &self.model, self.speed_range_rpm)?;
                cases.push((class.name().into(), format!("{m}x"), effect, error));
            }
        }
        Ok(cases)
    }
}

/// The machines of the proving ground: two-direction milling at 30 % (x 650 Hz, y 720 Hz,
/// 4 teeth, down), low radial immersion (7 %, 2 teeth, up milling), two modes in one direction
/// (3 teeth, 50 %), and turning (a feed mode and one at 30 degrees).
pub fn proving_machines() -> Result<Vec<ProvingMachine>> {
    let milling = |teeth, immersion, direction, modes: Vec<Mode>| -> Result<ModalModel> {
        Ok(ModalModel::new(
            None,
            Operation::Milling(Milling::new(
                teeth,
                immersion,
                direction,
                Some(0.0127),
                None,
            )?),
            CuttingCoefficients::new(700e6, 210e6)?,
            modes,
            None,
        )?)
    };
    Ok(vec![
        ProvingMachine {
            name: "xy milling 30 %",
            model: milling(
                4,
                0.3,
                MillingDirection::Down,
                vec![mode(650.0, 0.025, 8e6, 0)?, mode(720.0, 0.03, 1.1e7, 1)?],
            )?,
            speed_range_rpm: (3000.0, 12000.0),
        },
        ProvingMachine {
            name: "low immersion 7 %",
            model: milling(
                2,
                0.07,
                MillingDirection::Up,
                vec![mode(900.0, 0.02, 2e6, 0)?, mode(960.0, 0.025, 2.4e6, 1)?],
            )?,
            speed_range_rpm: (8000.0, 24000.0),
        },
        ProvingMachine {
            name: "two modes in x",
            model: milling(
                3,
                0.5,
                MillingDirection::Down,
                vec![mode(600.0, 0.03, 1.2e7, 0)?, mode(1100.0, 0.025, 1.5e7, 0)?],
            )?,
            speed_range_rpm: (4000.0, 16000.0),
        },
        ProvingMachine {
            name: "turning",
            model: ModalModel::new(
                None,
                Operation::Turning(Turning::new(Some(0.05))?),
                CuttingCoefficients::new(1500e6, 600e6)?,
                vec![
                    mode(640.0, 0.03, 2.5e7, 0)?,
                    oblique(700.0, 0.035, 3e7, 30.0)?,
                ],
                None,
            )?,
            speed_range_rpm: (800.0, 4000.0),
        },
    ])
}

/// The truth's solver for `model` at `speed_rpm` (see the module docs).
pub fn truth_solver(model: &ModalModel, speed_rpm: f64) -> Discretization {
    truth_solver_refined(model, speed_rpm, TRUTH_REFINEMENT)
}

fn truth_solver_refined(model: &ModalModel, speed_rpm: f64, refinement: usize) -> Discretization {
    let auto = Discretization::semi().steps_at(model, speed_rpm);
    Discretization::semi().with_steps(steps_at_least(
        refinement.saturating_mul(auto.get()),
        TRUTH_MIN_STEPS,
    ))
}

/// `f` with the truth's solver; when its eigen-solver fails (Arnoldi can stall on clustered
/// multipliers of a large operator, seen on turning with process damping at long delays), once
/// more at five times the automatic resolution, then with the first-order full discretization
/// at four times: equally converged grids with other operators.
fn with_truth<T>(
    model: &ModalModel,
    speed_rpm: f64,
    f: impl Fn(&Discretization) -> chatter_stability::Result<T>,
) -> Result<T> {
    let semi = truth_solver(model, speed_rpm);
    let first = match f(&semi) {
        Ok(v) => return Ok(v),
        Err(e) => e,
    };
    if let Ok(v) = f(&truth_solver_refined(
        model,
        speed_rpm,
        TRUTH_REFINEMENT + 1,
    )) {
        return Ok(v);
    }
    let full = Discretization::full().with_steps(semi.steps_at(model, speed_rpm));
    f(&full).map_err(|e| GapError::Model(format!("{first}; on finer and other grids: {e}")))
}

/// The true limiting depth (m) of `model` at a speed; infinite where no lobe is below 1 m.
pub fn true_limiting_depth(model: &ModalModel, speed_rpm: f64) -> Result<f64> {
    let options = BoundaryOptions {
        relative_tolerance: 1e-3,
        start_depth_m: 1e-4,
        ..BoundaryOptions::default()
    };
    with_truth(model, speed_rpm, |solver| {
        limiting_depth(solver, model, speed_rpm, &options).map(|p| p.depth_m)
    })
    .map_err(|e| GapError::Model(format!("true limiting depth at {speed_rpm} rpm: {e}")))
}

/// The true machine of `scenario` over `nominal`.
pub fn true_variant(nominal: &ModalModel, scenario: &Scenario) -> Result<Variant> {
    let e = scenario.error;
    positive("error.frequency_factor", e.frequency_factor)?;
    positive("error.damping_factor", e.damping_factor)?;
    positive(
        "error.cutting_over_stiffness_factor",
        e.cutting_over_stiffness_factor,
    )?;
    let mut model = recalibrated(
        nominal,
        e.frequency_factor,
        e.damping_factor,
        e.cutting_over_stiffness_factor,
    )?;
    let mut v = Variant::new(model.clone());
    match scenario.effect {
        HiddenEffect::ParameterError => {}
        HiddenEffect::Runout { cutting_teeth } => {
            let Operation::Milling(op) = model.operation() else {
                return Err(GapError::Model("runout needs a milling model".into()));
            };
            if cutting_teeth == 0 || op.teeth() % cutting_teeth != 0 {
                return Err(GapError::InvalidInput {
                    field: "runout.cutting_teeth".into(),
                    value: cutting_teeth as f64,
                    expected: "a divisor of the cutter's teeth",
                });
            }
            let fewer = Milling::new(
                cutting_teeth,
                op.radial_immersion(),
                op.direction(),
                op.tool_diameter_m(),
                op.helix_rad(),
            )?;
            model = model.with_operation(Operation::Milling(fewer))?;
            v.model = model;
        }
        HiddenEffect::ProcessDamping { c_n_per_m } => {
            v.model = model.with_process_damping(Some(positive("c_n_per_m", c_n_per_m)?))?;
        }
        HiddenEffect::SpeedDependentDynamics {
            frequency_drop_at_max_speed,
        } => {
            v.softening_per_rpm2 = frequency_drop_at_max_speed / scenario.speed_range_rpm.1.powi(2);
        }
        HiddenEffect::ExtraMode {
            frequency_hz,
            damping_ratio,
            stiffness_n_per_m,
            direction_deg,
        } => {
            let omega = 2.0 * PI * positive("extra_mode.frequency_hz", frequency_hz)?;
            let a = omega / positive("extra_mode.stiffness_n_per_m", stiffness_n_per_m)?.sqrt();
            let angle = direction_deg.to_radians();
            let mut modes = model.modes().to_vec();
            modes.push(Mode::new(
                frequency_hz,
                damping_ratio,
                ModeShape::MassNormalized([a * angle.cos(), a * angle.sin()]),
            )?);
            v.model = model.with_modes(modes)?;
        }
        HiddenEffect::Drift {
            cutting_change_over_campaign,
        } => v.drift_rate = cutting_change_over_campaign,
        HiddenEffect::CuttingBand {
            from_rpm,
            to_rpm,
            factor,
        } => {
            v.cutting_band = Some(CuttingBand {
                from_rpm,
                to_rpm,
                factor: positive("cutting_band.factor", factor)?,
            });
        }
    }
    Ok(v)
}

/// The effect of `class` at `magnitude` (1 = a clear but realistic gap) on `nominal` over
/// `speed_range_rpm`, with its recalibration error: parameter error 1x = frequencies -3 %,
/// damping +15 %, cutting over stiffness x1.36 (log factors scaled by the magnitude); process
/// damping 1x = C adding the structural damping of the dominant mode at the lowest speed and
/// the lowest nominal limit; speed-dependent dynamics 1x = 4 % frequency drop at the top speed;
/// extra mode 1x = a 45-degree mode at 1.35 f_ref, 3 %, 1.5 k_ref (2x: k / 2, 0.5x: k x 2);
/// drift 1x = +40 % over the campaign; the open alternative `speed_band` 1x = cutting
/// coefficients x2 between 0.4 and 0.7 of the speed range (an effect outside the list).
pub fn effect_at(
    class: EffectClass,
    magnitude: f64,
    nominal: &ModalModel,
    speed_range_rpm: (f64, f64),
) -> Result<(HiddenEffect, Recalibration)> {
    let none = Recalibration::default();
    let (dominant, k_ref) = dominant_mode(nominal)?;
    let f_ref = dominant.frequency_hz();
    let phi = dominant.mass_normalized_shape();
    Ok(match class {
        EffectClass::ParameterError => (
            HiddenEffect::ParameterError,
            Recalibration {
                frequency_factor: 0.97f64.powf(magnitude),
                damping_factor: 1.15f64.powf(magnitude),
                cutting_over_stiffness_factor: 1.36f64.powf(magnitude),
            },
        ),
        EffectClass::ProcessDamping => {
            let d = nominal.operation().cutting_diameter_m().ok_or_else(|| {
                GapError::Model("process damping needs the cutting diameter".into())
            })?;
            let b_min = (0..8)
                .map(|i| {
                    let s = speed_range_rpm.0
                        + (speed_range_rpm.1 - speed_range_rpm.0) * i as f64 / 7.0;
                    true_limiting_depth(nominal, s)
                })
                .collect::<Result<Vec<f64>>>()?
                .into_iter()
                .fold(f64::INFINITY, f64::min);
            let v = PI * d * speed_range_rpm.0 / 60.0;
            let projector =
                chatter_stability::process_damping::average_normal_projector(nominal.operation());
            let slope = chatter_stability::process_damping::damping_ratio_slope_per_m(
                phi,
                dominant.omega_rad_s(),
                &projector,
            );
            let c = magnitude * dominant.damping_ratio() * v / (b_min * slope);
            (HiddenEffect::ProcessDamping { c_n_per_m: c }, none)
        }
        EffectClass::SpeedDependentDynamics => (
            HiddenEffect::SpeedDependentDynamics {
                frequency_drop_at_max_speed: 0.04 * magnitude,
            },
            none,
        ),
        EffectClass::ExtraMode => (
            HiddenEffect::ExtraMode {
                frequency_hz: 1.35 * f_ref,
                damping_ratio: 0.03,
                stiffness_n_per_m: 1.5 * k_ref / magnitude,
                direction_deg: 45.0,
            },
            none,
        ),
        EffectClass::Drift => (
            HiddenEffect::Drift {
                cutting_change_over_campaign: 0.4 * magnitude,
            },
            none,
        ),
        EffectClass::SpeedBand => {
            let (lo, hi) = speed_range_rpm;
            (
                HiddenEffect::CuttingBand {
                    from_rpm: lo + 0.4 * (hi - lo),
                    to_rpm: lo + 0.7 * (hi - lo),
                    factor: 1.0 + magnitude,
                },
                none,
            )
        }
    })
}

/// What a test of the run order measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlannedKind {
    /// A test cut, labelled stable or chatter (with its chatter frequency).
    Cut,
    /// A stable cut whose dominant pole is identified; its depth is a fraction of the true
    /// limiting depth at its speed and campaign position.
    Pole {
        /// Depth as a fraction of the true limiting depth.
        fraction: f64,
    },
}

/// One test of a campaign's run order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannedTest {
    /// What it measures.
    pub kind: PlannedKind,
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Depth (m): the cut's depth, or for a pole the fraction times the true limit.
    pub depth_m: f64,
    /// Campaign position in [0, 1] (drift).
    pub position: f64,
    /// Run-order number when the scenario records it.
    pub sequence: Option<i64>,
}

/// Which multiplier of the truth an observation reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TruthRoot {
    /// The dominant one: cut labels and chatter frequencies, milling poles.
    Dominant,
    /// The resonance ([`Discretization::resonance_frequency_hz`]): what an identification of a
    /// stable turning cut sees, not a dominant multiplier at the spindle harmonics (slow surface
    /// regeneration under process damping at low speed, whose response an identification
    /// removes as forced lines).
    Resonance,
}

/// ln|mu| and the frequency of the truth's `root` multiplier at a cut, with the continuous-time
/// pole lambda it implies (physical frequency).
fn truth_at(
    model: &ModalModel,
    speed_rpm: f64,
    depth_m: f64,
    root: TruthRoot,
) -> Result<(f64, f64, Complex64)> {
    let (mu, f) = with_truth(model, speed_rpm, |solver| match root {
        TruthRoot::Dominant => solver.chatter_frequency_hz(model, speed_rpm, depth_m),
        TruthRoot::Resonance => solver.resonance_frequency_hz(model, speed_rpm, depth_m),
    })
    .map_err(|e| {
        GapError::Model(format!(
            "truth ({root:?} multiplier) at {speed_rpm} rpm, {depth_m} m: {e}"
        ))
    })?;
    let lambda = Complex64::new(mu.modulus().ln() / mu.period_s, 2.0 * PI * f);
    Ok((mu.modulus().ln(), f, lambda))
}

/// The run order of `scenario` on the machine `nominal`: cuts at `scenario.speeds` random
/// speeds with depths log-uniform in `depth_ratio_range` times the nominal limit (capped at
/// 50 mm), pole tests at `pole_speeds_rpm` x `pole_depth_fractions` of the true limit, shuffled.
/// The same plan whoever observes it: [`synthesize`] from the exact truth, or a test that
/// simulates every cut and reads it as a shop would.
pub fn campaign_plan(nominal: &ModalModel, scenario: &Scenario) -> Result<Vec<PlannedTest>> {
    let mut rng = StdRng::seed_from_u64(scenario.seed);
    plan(nominal, scenario, &mut rng)
}

fn plan(nominal: &ModalModel, scenario: &Scenario, rng: &mut StdRng) -> Result<Vec<PlannedTest>> {
    let truth = true_variant(nominal, scenario)?;
    let (lo, hi) = scenario.speed_range_rpm;
    positive("speed_range_rpm.0", lo)?;
    if hi.is_nan() || hi < lo {
        return Err(GapError::InvalidInput {
            field: "speed_range_rpm.1".into(),
            value: hi,
            expected: "at least the lowest speed",
        });
    }
    let (r_lo, r_hi) = scenario.depth_ratio_range;
    positive("depth_ratio_range.0", r_lo)?;
    positive("depth_ratio_range.1", r_hi)?;
    let speeds: Vec<f64> = (0..scenario.speeds.max(1))
        .map(|_| lo + (hi - lo) * rng.random::<f64>())
        .collect();
    let limits = speeds
        .iter()
        .map(|&s| Ok(true_limiting_depth(nominal, s)?.min(0.05)))
        .collect::<Result<Vec<f64>>>()?;
    let mut tests = Vec::new();
    for k in 0..scenario.cuts {
        let i = k % speeds.len();
        let ratio = (r_lo.ln() + (r_hi / r_lo).ln() * rng.random::<f64>()).exp();
        tests.push((PlannedKind::Cut, speeds[i], ratio * limits[i]));
    }
    for &speed_rpm in &scenario.pole_speeds_rpm {
        positive("pole_speeds_rpm", speed_rpm)?;
        for &fraction in &scenario.pole_depth_fractions {
            let fraction = positive("pole_depth_fractions", fraction)?;
            tests.push((PlannedKind::Pole { fraction }, speed_rpm, f64::NAN));
        }
    }
    tests.shuffle(rng);
    let n = tests.len().max(2);
    tests
        .into_iter()
        .enumerate()
        .map(|(k, (kind, speed_rpm, depth_m))| {
            let position = k as f64 / (n - 1) as f64;
            let depth_m = match kind {
                PlannedKind::Cut => depth_m,
                PlannedKind::Pole { fraction } => {
                    let model = truth.at(None, speed_rpm, position)?;
                    fraction * true_limiting_depth(&model, speed_rpm)?.min(0.05)
                }
            };
            Ok(PlannedTest {
                kind,
                speed_rpm,
                depth_m,
                position,
                sequence: (scenario.run_order == RunOrder::Recorded).then_some(k as i64 + 1),
            })
        })
        .collect()
}

/// Synthetic observations of `scenario` on the machine whose nominal model is `nominal`: the
/// [`campaign_plan`] observed through the exact truth with the scenario's noise.
pub fn synthesize(nominal: &ModalModel, scenario: &Scenario) -> Result<Observations> {
    let truth = true_variant(nominal, scenario)?;
    let mut rng = StdRng::seed_from_u64(scenario.seed);
    let tests = plan(nominal, scenario, &mut rng)?;
    let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
    let milling = matches!(nominal.operation(), Operation::Milling(_));
    let mut obs = Observations::default();
    for test in &tests {
        let (speed_rpm, depth_m, sequence) = (test.speed_rpm, test.depth_m, test.sequence);
        let model = truth.at(None, speed_rpm, test.position)?;
        match test.kind {
            PlannedKind::Cut => {
                let jittered = depth_m * (scenario.label_width_log_depth * normal()).exp();
                let (ln_mu, _, _) = truth_at(&model, speed_rpm, jittered, TruthRoot::Dominant)?;
                let stable = ln_mu < 0.0;
                let chatter_hz = if stable {
                    None
                } else {
                    let (_, f, _) = truth_at(&model, speed_rpm, depth_m, TruthRoot::Dominant)?;
                    Some(f * (1.0 + scenario.chatter_jitter_relative * normal()))
                };
                obs.cuts.push(Cut {
                    speed_rpm,
                    depth_mm: depth_m * 1e3,
                    stable,
                    chatter_hz,
                    sequence,
                    radial_immersion: None,
                    note: None,
                    evidence: None,
                });
            }
            PlannedKind::Pole { .. } => {
                let root = if milling {
                    TruthRoot::Dominant
                } else {
                    TruthRoot::Resonance
                };
                let (_, _, lambda) = truth_at(&model, speed_rpm, depth_m, root)?;
                let tau = model.operation().delay_s(speed_rpm);
                // a lifted pole: the principal value of ln(mu) / tau
                let lambda = if milling {
                    (lambda * tau).exp().ln() / tau
                } else {
                    lambda
                };
                let pole = observed_pole(lambda, milling);
                let f_std = scenario.pole_frequency_std_relative * pole.frequency_hz;
                let z_std = scenario.pole_damping_std_relative * pole.damping_ratio.abs();
                let frequency_hz = (pole.frequency_hz + f_std * normal()).abs();
                let damping_ratio = pole.damping_ratio + z_std * normal();
                obs.poles.push(PoleObservation {
                    speed_rpm,
                    depth_mm: depth_m * 1e3,
                    frequency_hz: frequency_hz.max(1e-3),
                    damping_ratio: damping_ratio.clamp(-0.99, 0.99),
                    frequency_std_hz: Some(f_std.max(1e-3)),
                    damping_std: Some(z_std.max(1e-4)),
                    repetitions: Some(10),
                    sequence,
                    radial_immersion: None,
                    note: None,
                });
            }
        }
    }
    obs.validate()?;
    Ok(obs)
}
