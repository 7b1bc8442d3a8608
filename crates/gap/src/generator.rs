//! Synthetic shop-floor data from a "true" machine that hides one effect: the proving ground of
//! the diagnosis (and the data of `chatter demo`).
//!
//! The true machine is the nominal model with a recalibration error (frequencies, damping,
//! cutting coefficients over stiffness) and one hidden effect: process damping, speed-dependent
//! modes, an extra mode, drift of the cutting coefficients over the campaign, or an effect outside
//! the candidate list, runout so strong that only some teeth cut (the delay becomes several
//! tooth periods and the force average drops). Its boundary is the fast zero-order form at four
//! times the inference grid density.
//!
//! The campaign is a designed experiment: at every test speed, depths at fixed ratios of the
//! nominal limiting depth, run in random order (`sequence`). A cut chatters with probability
//! Phi(ln(b / b_true) / w) (label noise near the boundary); a chattering cut reports the true
//! chatter frequency plus Gaussian jitter. Poles are the exact dominant poles of the true
//! machine at stable depths (fractions of the true limit) plus Gaussian noise with the
//! standard deviations written to the file, as repeated operational modal analysis would give.
//!
//! ```
//! use chatter_gap::{HiddenEffect, Scenario, nominal_milling, synthesize};
//! let nominal = nominal_milling()?;
//! let scenario = Scenario::new(HiddenEffect::Drift { cutting_change_over_campaign: 0.5 }, 7);
//! let data = synthesize(&nominal, &scenario)?;
//! assert_eq!(data.cuts.len(), 18 * 7);
//! assert_eq!(data.poles.len(), 8);
//! assert!(data.cuts.iter().all(|c| c.sequence.is_some()));
//! # Ok::<(), chatter_gap::GapError>(())
//! ```

use crate::classes::EffectClass;
use crate::error::{GapError, Result, positive};
use crate::machine::{FastMode, Machine, geometries};
use chatter_dynamics::{
    Cut, CuttingCoefficients, Milling, MillingDirection, ModalModel, Mode, ModeShape, Observations,
    Operation, PoleObservation,
};
use rand::rngs::StdRng;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use serde::Serialize;
use std::f64::consts::PI;

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
}

impl HiddenEffect {
    /// The class a correct diagnosis names, or None for an effect outside the list.
    pub fn expected_class(&self) -> Option<EffectClass> {
        match self {
            HiddenEffect::ParameterError => Some(EffectClass::ParameterError),
            HiddenEffect::ProcessDamping { .. } => Some(EffectClass::ProcessDamping),
            HiddenEffect::SpeedDependentDynamics { .. } => {
                Some(EffectClass::SpeedDependentDynamics)
            }
            HiddenEffect::ExtraMode { .. } => Some(EffectClass::ExtraMode),
            HiddenEffect::Drift { .. } => Some(EffectClass::Drift),
            HiddenEffect::Runout { .. } => None,
        }
    }

    /// The expected verdict's name (`unexplained` outside the list).
    pub fn expected_verdict(&self) -> &'static str {
        self.expected_class()
            .map_or("unexplained", EffectClass::name)
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
    /// Test speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// Depths of every test speed as multiples of the nominal limiting depth there.
    pub depth_ratios: Vec<f64>,
    /// Speeds at which poles are identified (rpm).
    pub pole_speeds_rpm: Vec<f64>,
    /// Depths of the pole cuts as fractions of the true limiting depth.
    pub pole_depth_fractions: Vec<f64>,
    /// Probit width of the label noise in ln depth.
    pub label_width_log_depth: f64,
    /// Standard deviation of the chatter-frequency jitter (Hz).
    pub chatter_jitter_hz: f64,
    /// Standard deviation of identified pole frequencies (Hz).
    pub pole_frequency_std_hz: f64,
    /// Standard deviation of identified pole damping ratios, relative.
    pub pole_damping_std_relative: f64,
    /// Whether `sequence` is recorded.
    pub run_order: RunOrder,
    /// Seed of the run order and every noise draw.
    pub seed: u64,
}

impl Scenario {
    /// A campaign with `effect` and the defaults: no recalibration error; 6 low speeds from 1200
    /// to 3450 rpm and 12 from 4500 to 13000 rpm; depths 0.5 to 4 times the nominal limit in
    /// steps of sqrt(2); poles at 2100, 6000, 9000 and 12000 rpm at 0.25 and 0.55 of the true
    /// limit; label width 0.04; jitter 2 Hz; pole noise 1.5 Hz and 8 %; sequence recorded.
    pub fn new(effect: HiddenEffect, seed: u64) -> Self {
        let low = (0..6).map(|i| 1200.0 + 450.0 * i as f64);
        let high = (0..12).map(|i| 4500.0 + 8500.0 * i as f64 / 11.0);
        Self {
            effect,
            error: Recalibration::default(),
            speeds_rpm: low.chain(high).collect(),
            depth_ratios: (0..7).map(|i| 0.5 * 2f64.sqrt().powi(i)).collect(),
            pole_speeds_rpm: vec![2100.0, 6000.0, 9000.0, 12000.0],
            pole_depth_fractions: vec![0.25, 0.55],
            label_width_log_depth: 0.04,
            chatter_jitter_hz: 2.0,
            pole_frequency_std_hz: 1.5,
            pole_damping_std_relative: 0.08,
            run_order: RunOrder::Recorded,
            seed,
        }
    }

    /// The same campaign without the speeds below `min_rpm` (tie-breaking data withheld).
    pub fn without_speeds_below(mut self, min_rpm: f64) -> Self {
        self.speeds_rpm.retain(|s| *s >= min_rpm);
        self.pole_speeds_rpm.retain(|s| *s >= min_rpm);
        self
    }
}

/// The nominal model of the synthetic shop: the milling case of seed 001 (4 teeth, 20 % down
/// milling, Ks 750 N/mm^2, beta 68 deg) on a 19.05 mm cutter, with an x mode of 750 Hz, 3 %,
/// 3e6 N/m and a y mode of 810 Hz, 3.5 %, 3.6e6 N/m.
pub fn nominal_milling() -> Result<ModalModel> {
    let op = Milling::new(4, 0.2, MillingDirection::Down, Some(0.01905), None)?;
    let mode = |f: f64, z: f64, k: f64, coordinate: usize| {
        Mode::new(
            f,
            z,
            ModeShape::Directional {
                coordinate,
                stiffness_n_per_m: k,
            },
        )
    };
    Ok(ModalModel::new(
        Some("synthetic shop: seed 001 cutter with two distinct modes".into()),
        Operation::Milling(op),
        CuttingCoefficients::from_ks_beta(750e6, 68f64.to_radians())?,
        vec![mode(750.0, 0.03, 3.0e6, 0)?, mode(810.0, 0.035, 3.6e6, 1)?],
        None,
    )?)
}

/// The true machine of `scenario` over `nominal`.
fn true_machine(nominal: &ModalModel, scenario: &Scenario) -> Result<Machine> {
    let mut model = nominal.clone();
    if let HiddenEffect::Runout { cutting_teeth } = scenario.effect {
        let Operation::Milling(op) = nominal.operation() else {
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
    }
    let mut m = Machine::from_model(&model, geometries(&model, &[None])?)?;
    let e = scenario.error;
    positive("error.frequency_factor", e.frequency_factor)?;
    positive("error.damping_factor", e.damping_factor)?;
    positive(
        "error.cutting_over_stiffness_factor",
        e.cutting_over_stiffness_factor,
    )?;
    for mode in &mut m.modes {
        mode.omega *= e.frequency_factor;
        mode.phi = [
            mode.phi[0] * e.frequency_factor,
            mode.phi[1] * e.frequency_factor,
        ];
        mode.zeta *= e.damping_factor;
    }
    m.gain = e.cutting_over_stiffness_factor;
    let max_speed = scenario.speeds_rpm.iter().copied().fold(0.0, f64::max);
    match scenario.effect {
        HiddenEffect::ParameterError | HiddenEffect::Runout { .. } => {}
        HiddenEffect::ProcessDamping { c_n_per_m } => {
            if m.diameter_m.is_none() {
                return Err(GapError::Model(
                    "process damping needs the model's cutting diameter".into(),
                ));
            }
            m.process_damping_n_per_m = c_n_per_m;
        }
        HiddenEffect::SpeedDependentDynamics {
            frequency_drop_at_max_speed,
        } => m.softening_per_rpm2 = frequency_drop_at_max_speed / max_speed.powi(2),
        HiddenEffect::ExtraMode {
            frequency_hz,
            damping_ratio,
            stiffness_n_per_m,
            direction_deg,
        } => {
            let omega = 2.0 * PI * positive("extra_mode.frequency_hz", frequency_hz)?;
            let a = omega / positive("extra_mode.stiffness_n_per_m", stiffness_n_per_m)?.sqrt();
            let angle = direction_deg.to_radians();
            m.modes.push(FastMode {
                omega,
                zeta: damping_ratio,
                phi: [a * angle.cos(), a * angle.sin()],
            });
        }
        HiddenEffect::Drift {
            cutting_change_over_campaign,
        } => m.drift_rate = cutting_change_over_campaign,
    }
    if m.modes.iter().any(|x| !(x.zeta > 0.0 && x.zeta < 1.0)) {
        return Err(GapError::InvalidInput {
            field: "damping".into(),
            value: m.modes.iter().map(|x| x.zeta).fold(0.0, f64::max),
            expected: "true damping ratios in (0, 1)",
        });
    }
    Ok(m)
}

/// One entry of the run order: a test cut or a pole identification.
enum Entry {
    Cut { speed_rpm: f64, depth_m: f64 },
    Pole { speed_rpm: f64, fraction: f64 },
}

/// Synthetic observations of `scenario` on the machine whose nominal model is `nominal`.
pub fn synthesize(nominal: &ModalModel, scenario: &Scenario) -> Result<Observations> {
    let truth = true_machine(nominal, scenario)?;
    let nominal_fast = Machine::from_model(nominal, geometries(nominal, &[None])?)?;
    for &s in scenario.speeds_rpm.iter().chain(&scenario.pole_speeds_rpm) {
        positive("speeds_rpm", s)?;
    }
    let requests: Vec<(f64, usize)> = scenario.speeds_rpm.iter().map(|&s| (s, 0)).collect();
    let nominal_limits = nominal_fast.boundary(&requests);
    let mut entries = Vec::new();
    for (&speed_rpm, limit) in scenario.speeds_rpm.iter().zip(&nominal_limits) {
        if !limit.depth_m.is_finite() {
            continue;
        }
        for &r in &scenario.depth_ratios {
            entries.push(Entry::Cut {
                speed_rpm,
                depth_m: positive("depth_ratios", r)? * limit.depth_m,
            });
        }
    }
    for &speed_rpm in &scenario.pole_speeds_rpm {
        for &fraction in &scenario.pole_depth_fractions {
            entries.push(Entry::Pole {
                speed_rpm,
                fraction: positive("pole_depth_fractions", fraction)?,
            });
        }
    }
    let mut speeds: Vec<f64> = scenario
        .speeds_rpm
        .iter()
        .chain(&scenario.pole_speeds_rpm)
        .copied()
        .collect();
    speeds.sort_by(f64::total_cmp);
    speeds.dedup();
    let true_requests: Vec<(f64, usize)> = speeds.iter().map(|&s| (s, 0)).collect();
    let true_limits = truth.boundary(&true_requests);
    let true_limit = |s: f64| {
        speeds
            .iter()
            .position(|x| *x == s)
            .map_or(f64::INFINITY, |i| true_limits[i].depth_m)
    };
    let true_chatter = |s: f64| {
        speeds
            .iter()
            .position(|x| *x == s)
            .map_or(f64::NAN, |i| true_limits[i].chatter_hz)
    };
    let mut rng = StdRng::seed_from_u64(scenario.seed);
    entries.shuffle(&mut rng);
    let n = entries.len().max(2);
    let jitter = Normal::new(0.0, scenario.chatter_jitter_hz.max(0.0)).map_err(|_| {
        GapError::InvalidInput {
            field: "chatter_jitter_hz".into(),
            value: scenario.chatter_jitter_hz,
            expected: "a standard deviation >= 0",
        }
    })?;
    let tau_nominal = |s: f64| nominal_fast.delay_s(s);
    let mut obs = Observations::default();
    for (k, entry) in entries.iter().enumerate() {
        let u = k as f64 / (n - 1) as f64;
        let sequence = (scenario.run_order == RunOrder::Recorded).then_some(k as i64 + 1);
        match *entry {
            Entry::Cut { speed_rpm, depth_m } => {
                let b_true = true_limit(speed_rpm) / truth.drift_factor(u);
                let z = (depth_m / b_true).ln() / scenario.label_width_log_depth;
                let p = 0.5 * chatter_bayes::prior::erfc(-z / std::f64::consts::SQRT_2);
                let stable = rng.random::<f64>() >= p;
                let f_true = true_chatter(speed_rpm);
                let chatter_hz =
                    (!stable && f_true.is_finite()).then(|| f_true + jitter.sample(&mut rng));
                obs.cuts.push(Cut {
                    speed_rpm,
                    depth_mm: depth_m * 1e3,
                    stable,
                    chatter_hz,
                    sequence,
                    radial_immersion: None,
                    note: None,
                });
            }
            Entry::Pole {
                speed_rpm,
                fraction,
            } => {
                let limit = true_limit(speed_rpm) / truth.drift_factor(u);
                let depth_m = fraction * limit.min(0.05);
                let Some(lambda) = truth.dominant_pole(speed_rpm, depth_m, 0, u) else {
                    continue;
                };
                let pole = truth.observed_pole(lambda, tau_nominal(speed_rpm));
                let f_std = scenario.pole_frequency_std_hz;
                let z_std = scenario.pole_damping_std_relative * pole.damping_ratio.abs();
                let draw = |rng: &mut StdRng, sd: f64| -> f64 {
                    Normal::new(0.0, sd).map_or(0.0, |d| d.sample(rng))
                };
                let frequency_hz = (pole.frequency_hz + draw(&mut rng, f_std)).abs();
                let damping_ratio = pole.damping_ratio + draw(&mut rng, z_std);
                obs.poles.push(PoleObservation {
                    speed_rpm,
                    depth_mm: depth_m * 1e3,
                    frequency_hz: frequency_hz.max(1e-3),
                    damping_ratio: damping_ratio.clamp(-0.99, 0.99),
                    frequency_std_hz: Some(f_std),
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
