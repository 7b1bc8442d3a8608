//! The candidate model classes: each is a parameterization of the nominal model with a prior.
//!
//! Every class recalibrates the nominal model with three factors (sampled as logarithms):
//! all natural frequencies by s_f at constant modal stiffness, all damping ratios by s_zeta, and
//! the cutting coefficients over the stiffness by g (the delay equation depends on the cutting
//! coefficients and the stiffness only through this ratio, so g scales the cutting
//! coefficients); and, on a model of several modes, each of up to [`MAX_MODE_OFFSETS`] further
//! modes (the most compliant after the dominant one) its own frequency offset d_j on top of
//! s_f, ln d_j ~ N(0, 0.05^2), sampled after the class's own parameters. A tap test misplaces
//! every mode by its own error (an outside proving ground shifts two modes by -3 % and -1.5 %):
//! with one factor for all, a recalibration at twice that error left 1.5 % in the chatter
//! frequencies, three times their noise, and the check failed on the right class. Each sample becomes a [`Variant`] evaluated exactly ([`crate::predict`]).
//! The classes add:
//!
//! | class | extra parameters | prior |
//! |---|---|---|
//! | `parameter_error` | none | ln s_f ~ N(0, 0.05^2), ln s_zeta ~ N(0, 0.5^2), ln g ~ N(0, 0.3^2) |
//! | `process_damping` | C in F_d = -C b ydot / V (003) | U(0, C_max), C_max: three times the structural damping added to every mode (the least affected one sets it), at the lowest observed speed and the lowest nominal limit |
//! | `speed_dependent_dynamics` | c in f_n(Omega) = f_n0 (1 - c Omega^2), stiffness with f_n^2 | drop c Omega_max^2 ~ U(0, 0.2) |
//! | `extra_mode` | frequency, damping, stiffness, direction of one more mode | ln(f / f_ref) ~ U(ln 0.4, ln 2.5), ln zeta ~ U(ln 0.005, ln 0.1), ln(k / k_ref) ~ U(ln 0.3, ln 30), angle ~ U(0, pi) |
//! | `drift` | r in cutting coefficients x (1 + r u), u the campaign position from `sequence` | N(0, 0.5^2) truncated to [-0.8, 2] |
//!
//! f_ref and k_ref are the frequency and modal stiffness of the nominal mode that dominates
//! regenerative chatter.
//!
//! Besides the listed classes, the open alternative `speed_band` ([`EffectClass::SpeedBand`])
//! asks whether the gap is confined to one region of speeds, in a shape none of the listed
//! effects has: the cutting coefficients over the stiffness times exp(a exp(-x^2 / 2w^2)),
//! x = ln(Omega / Omega_c) ([`crate::variant::CuttingBump`]), with a ~ N(0, 0.7^2) (a factor
//! within 1/4 to 4 at two standard deviations), the centre's position in the observed range of
//! ln speed ~ U(-0.1, 1.1) (just beyond either end: a trend toward that end) and ln w ~
//! U(ln 0.02, ln 0.5) (a band of +-2 % to a trend over a factor 1.6 in speed). A band of
//! changed cutting coefficients or damping, or cutting coefficients that rise toward low
//! cutting speed (built-up edge), all look like this to the labels. It is never a verdict: when
//! it wins ([`crate::diagnose()`]), the verdict is `unexplained` with the band named.

use crate::data::Dataset;
use crate::error::{GapError, Result};
use crate::variant::{CuttingBump, Variant, recalibrated_per_mode};
use chatter_bayes::prior::{IndependentPrior, Marginal, Prior};
use chatter_dynamics::{ModalModel, Mode, ModeShape};
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::boundary::dominant_mode_frequency_hz;
use chatter_stability::prepared::Method;
use chatter_stability::process_damping::{average_normal_projector, damping_ratio_slope_per_m};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// C_max: the process damping that adds this many times a mode's structural damping at the
/// lowest observed speed and the lowest nominal limiting depth, for every mode (the one it acts
/// on least sets the bound: which mode limits stability is not known before the fit).
const PROCESS_DAMPING_SPAN: f64 = 3.0;
/// Slices of the extra mode's log-frequency prior, ln 0.4 to ln 2.5 of the reference: each a
/// factor 6.25^(1/4) = 1.58 wide. On the four seed-1 extra-mode campaigns of the xy and
/// low-immersion machines (1x, 2x) the verdict was right on 4 of 4 with four slices of 120 and
/// two or three steps ([`EffectClass::steps`]), on 1 of 4 with one population of 300 samples,
/// 2 of 4 with four slices and one step, 3 of 4 with four slices of 100 and two steps, 3 of 4
/// with two slices of 300, 2 of 3 with one population of 180 and three steps. Half the samples
/// per slice (60) would save a third of a campaign's time but lost the extra mode at 2x on the
/// xy and low-immersion machines of the proving ground (xy: ln Z -236 against -110 with 120;
/// the verdict `unexplained`).
const EXTRA_MODE_STRATA: usize = 4;
/// Gap along a stratified coordinate (ln of the extra mode's frequency: 5 %) that separates two
/// posterior modes in [`ClassModel::posterior_mean`]; a polished mode of the proving ground
/// spreads its samples over a few per cent with gaps of a few tenths of a per cent.
const MODE_GAP: f64 = 0.05;
/// Modes beyond the dominant one that get their own frequency offset (the most compliant first):
/// each offset is one more sampled dimension in every class.
pub const MAX_MODE_OFFSETS: usize = 3;
/// Prior standard deviation of a mode's ln frequency offset.
const MODE_OFFSET_SD: f64 = 0.05;
/// Report names of the modes' frequency offsets (by mode index; the last stands for the rest).
const MODE_OFFSET_NAMES: [&str; 8] = [
    "mode_1_frequency_offset",
    "mode_2_frequency_offset",
    "mode_3_frequency_offset",
    "mode_4_frequency_offset",
    "mode_5_frequency_offset",
    "mode_6_frequency_offset",
    "mode_7_frequency_offset",
    "mode_8_or_later_frequency_offset",
];
/// Largest relative frequency drop at the highest observed speed.
const MAX_SOFTENING: f64 = 0.2;

/// Where each parameter sits in a class's vector: the recalibration (ln s_f, ln s_zeta, ln g)
/// first, then the class's own parameters (the table in the module docs).
mod slot {
    /// ln s_f, the natural-frequency factor.
    pub const FREQUENCY_SCALE: usize = 0;
    /// ln s_zeta, the damping factor.
    pub const DAMPING_SCALE: usize = 1;
    /// ln g, the cutting-over-stiffness factor.
    pub const CUTTING_OVER_STIFFNESS: usize = 2;
    /// The one parameter of `process_damping` (C / C_max), `speed_dependent_dynamics` (the drop
    /// at the highest speed) and `drift` (r).
    pub const EFFECT: usize = 3;
    /// `extra_mode`: ln(f / f_ref).
    pub const EXTRA_FREQUENCY: usize = 3;
    /// `extra_mode`: ln zeta.
    pub const EXTRA_DAMPING: usize = 4;
    /// `extra_mode`: ln(k / k_ref).
    pub const EXTRA_STIFFNESS: usize = 5;
    /// `extra_mode`: the direction's angle from x (rad, an axis: period pi).
    pub const EXTRA_DIRECTION: usize = 6;
    /// `speed_band`: a, the log of the factor at the band's centre.
    pub const BAND_LN_FACTOR: usize = 3;
    /// `speed_band`: the centre's position in the observed range of ln speed (0 lowest, 1
    /// highest).
    pub const BAND_CENTER: usize = 4;
    /// `speed_band`: ln w, w the half-width in ln speed.
    pub const BAND_LN_WIDTH: usize = 5;
}

/// The extra mode of `extra_mode` at parameters theta, in physical units.
struct ExtraMode {
    frequency_hz: f64,
    damping_ratio: f64,
    stiffness_n_per_m: f64,
    direction_rad: f64,
}

impl ExtraMode {
    fn new(nominal: &Nominal, theta: &[f64]) -> Self {
        Self {
            frequency_hz: nominal.reference_hz * theta[slot::EXTRA_FREQUENCY].exp(),
            damping_ratio: theta[slot::EXTRA_DAMPING].exp(),
            stiffness_n_per_m: nominal.reference_stiffness_n_per_m
                * theta[slot::EXTRA_STIFFNESS].exp(),
            direction_rad: theta[slot::EXTRA_DIRECTION],
        }
    }

    /// The mode with a mass-normalized shape of modulus omega / sqrt(k) along its direction.
    fn mode(&self) -> Option<Mode> {
        let amplitude = 2.0 * PI * self.frequency_hz / self.stiffness_n_per_m.sqrt();
        Mode::new(
            self.frequency_hz,
            self.damping_ratio,
            ModeShape::MassNormalized([
                amplitude * self.direction_rad.cos(),
                amplitude * self.direction_rad.sin(),
            ]),
        )
        .ok()
    }
}

/// A candidate explanation of the gap.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EffectClass {
    /// The nominal model recalibrated (frequencies, damping, cutting coefficients over stiffness).
    ParameterError,
    /// Recalibration plus process damping C (seed 003).
    ProcessDamping,
    /// Recalibration plus natural frequencies (and stiffness) falling with spindle speed.
    SpeedDependentDynamics,
    /// Recalibration plus one unmodelled mode.
    ExtraMode,
    /// Recalibration plus cutting coefficients changing linearly with `sequence`.
    Drift,
    /// The open alternative (module docs): recalibration plus cutting coefficients changed in
    /// one band of speeds. Never named as the verdict.
    SpeedBand,
}

impl EffectClass {
    /// The prior coordinate split into equal slices, each sampled by its own run
    /// (`chatter_bayes::strata`), and the number of slices; None for one plain run.
    /// `extra_mode`'s posterior has several modes in the extra mode's frequency (wherever the
    /// mode adds a lobe or a pole the data show, with the other parameters compensating); one
    /// population of 300 locked onto a wrong one on the proving ground (xy milling machine,
    /// seed 1: 1515 Hz, and 902 Hz with the damping x0.7, for a truth at 972 Hz; the check then
    /// failed and the verdict was `unexplained`).
    pub fn strata(self) -> Option<(usize, usize)> {
        match self {
            EffectClass::ExtraMode => Some((slot::EXTRA_FREQUENCY, EXTRA_MODE_STRATA)),
            _ => None,
        }
    }

    /// Metropolis-Hastings steps per chain and stage for this class, from the options' `steps`.
    /// `extra_mode` takes twice as many: inside a stratum its seven parameters trade off
    /// (stiffness, damping and direction of the extra mode against the recalibration), and with
    /// one step the chains stayed on a ridge beside the optimum (xy machine, seed 1, extra mode
    /// at 1x: ln Z -114.5 with 1 step, -100.8 with 2, -83.1 with 3; the check failed with 1 and
    /// passed with 2 and 3). Three steps cost a third more for no verdict gained on the four
    /// test campaigns, and pushed a 40-cut turning campaign from 60 s towards 80 s.
    pub fn steps(self, steps: usize) -> usize {
        match self {
            EffectClass::ExtraMode | EffectClass::SpeedBand => 2 * steps,
            _ => steps,
        }
    }

    /// Every class, in report order.
    pub const ALL: [EffectClass; 5] = [
        EffectClass::ParameterError,
        EffectClass::ProcessDamping,
        EffectClass::SpeedDependentDynamics,
        EffectClass::ExtraMode,
        EffectClass::Drift,
    ];

    /// The name used in reports (`parameter_error`, ...).
    pub fn name(self) -> &'static str {
        match self {
            EffectClass::ParameterError => "parameter_error",
            EffectClass::ProcessDamping => "process_damping",
            EffectClass::SpeedDependentDynamics => "speed_dependent_dynamics",
            EffectClass::ExtraMode => "extra_mode",
            EffectClass::Drift => "drift",
            EffectClass::SpeedBand => "speed_band",
        }
    }

    /// Whether the class is one of the listed effects a verdict may name ([`EffectClass::ALL`]);
    /// false for the open alternative.
    pub fn is_listed(self) -> bool {
        self != EffectClass::SpeedBand
    }

    /// The coordinate along which the posterior may have separate modes, which
    /// [`ClassModel::posterior_mean`] keeps apart: the extra mode's frequency, the band's centre.
    fn mode_coordinate(self) -> Option<usize> {
        match self {
            EffectClass::ExtraMode => Some(slot::EXTRA_FREQUENCY),
            EffectClass::SpeedBand => Some(slot::BAND_CENTER),
            _ => None,
        }
    }
}

impl std::fmt::Display for EffectClass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for EffectClass {
    type Err = GapError;
    /// A class from its report name.
    fn from_str(s: &str) -> Result<Self> {
        EffectClass::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| GapError::UnknownClass(s.to_string()))
    }
}

/// The nominal model with the references the priors are scaled by.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Nominal {
    /// The nominal model as given.
    pub model: ModalModel,
    /// Natural frequency of the dominant mode (Hz).
    pub reference_hz: f64,
    /// Modal stiffness of the dominant mode, omega^2 / |phi|^2 (N/m).
    pub reference_stiffness_n_per_m: f64,
    /// Highest observed speed (rpm).
    pub max_speed_rpm: f64,
    /// Lowest observed speed (rpm).
    pub min_speed_rpm: f64,
    /// C_max of the process-damping prior; None without a cutting diameter.
    pub process_damping_scale_n_per_m: Option<f64>,
    /// The modes (indices into the model's) with their own frequency offset (module docs).
    pub offset_modes: Vec<usize>,
}

impl Nominal {
    /// The nominal model; `speeds` are the observed speeds (rpm) that scale the priors.
    pub fn new(model: &ModalModel, speeds: &[f64]) -> Result<Self> {
        let (dominant, reference_stiffness_n_per_m) = dominant_mode(model)?;
        let reference_hz = dominant.frequency_hz();
        let offset_modes = offset_modes(model, dominant);
        let max_speed_rpm = speeds.iter().copied().fold(0.0, f64::max);
        let min_speed_rpm = speeds.iter().copied().fold(f64::INFINITY, f64::min);
        if !(max_speed_rpm > 0.0 && min_speed_rpm.is_finite()) {
            return Err(GapError::Observations("no spindle speeds".into()));
        }
        let process_damping_scale_n_per_m = match model.operation().cutting_diameter_m() {
            Some(d) => {
                // the lowest zero-order limit over the observed speeds (a prior scale only)
                let bare = model.with_process_damping(None)?;
                let zero_order = Method::Zoa.prepare(&bare, &BoundaryOptions::default()).ok();
                let b_min = speeds
                    .iter()
                    .filter_map(|&s| zero_order.as_ref()?.limiting_depth(s).ok())
                    .map(|p| p.depth_m)
                    .fold(f64::INFINITY, f64::min);
                // every mode gets up to SPAN times its own damping: the least affected sets C_max
                let v = PI * d * min_speed_rpm / 60.0;
                let projector = average_normal_projector(model.operation());
                let c = model
                    .modes()
                    .iter()
                    .map(|m| {
                        // damping-ratio slope per m of depth at C / V = 1
                        let q = damping_ratio_slope_per_m(
                            m.mass_normalized_shape(),
                            m.omega_rad_s(),
                            &projector,
                        );
                        PROCESS_DAMPING_SPAN * m.damping_ratio() * v / (b_min * q)
                    })
                    .filter(|c| c.is_finite())
                    .fold(0.0, f64::max);
                (c.is_finite() && c > 0.0).then_some(c)
            }
            None => None,
        };
        Ok(Self {
            model: model.clone(),
            reference_hz,
            reference_stiffness_n_per_m,
            max_speed_rpm,
            min_speed_rpm,
            process_damping_scale_n_per_m,
            offset_modes,
        })
    }
}

/// The modes other than `dominant` with their own frequency offset: the [`MAX_MODE_OFFSETS`]
/// most compliant (largest |phi|^2 / omega^2), in the model's order.
fn offset_modes(model: &ModalModel, dominant: &Mode) -> Vec<usize> {
    let compliance = |m: &Mode| {
        let phi = m.mass_normalized_shape();
        (phi[0].powi(2) + phi[1].powi(2)) / m.omega_rad_s().powi(2)
    };
    let mut others: Vec<usize> = (0..model.modes().len())
        .filter(|&j| !std::ptr::eq(&model.modes()[j], dominant))
        .collect();
    others
        .sort_by(|&a, &b| compliance(&model.modes()[b]).total_cmp(&compliance(&model.modes()[a])));
    others.truncate(MAX_MODE_OFFSETS);
    others.sort_unstable();
    others
}

impl Nominal {
    /// The nominal model as a variant.
    pub fn variant(&self) -> Variant {
        Variant::new(self.model.clone())
    }
}

/// The mode that dominates regenerative chatter (the one whose frequency
/// [`dominant_mode_frequency_hz`] picks) with its modal stiffness omega^2 / |phi|^2 (N/m).
pub(crate) fn dominant_mode(model: &ModalModel) -> Result<(&Mode, f64)> {
    let f_ref = dominant_mode_frequency_hz(model);
    let mode = model
        .modes()
        .iter()
        .min_by(|a, b| {
            (a.frequency_hz() - f_ref)
                .abs()
                .total_cmp(&(b.frequency_hz() - f_ref).abs())
        })
        .ok_or_else(|| GapError::Model("no modes".into()))?;
    let phi = mode.mass_normalized_shape();
    Ok((
        mode,
        mode.omega_rad_s().powi(2) / (phi[0].powi(2) + phi[1].powi(2)),
    ))
}

/// A class ready for the sampler: prior and the map from parameters to a machine.
#[derive(Debug, Clone)]
pub(crate) struct ClassModel<'a> {
    pub class: EffectClass,
    pub nominal: &'a Nominal,
    pub prior: IndependentPrior,
}

/// Why a class cannot be tried on these data, or None.
pub(crate) fn unavailable(class: EffectClass, nominal: &Nominal, data: &Dataset) -> Option<String> {
    match class {
        EffectClass::ProcessDamping if nominal.process_damping_scale_n_per_m.is_none() => Some(
            "process_damping needs the cutting speed: give operation.tool_diameter_mm \
             (milling) or operation.workpiece_diameter_mm (turning)"
                .into(),
        ),
        EffectClass::Drift if !data.has_sequence => {
            Some("drift needs `sequence` on every cut and pole (more than one value)".into())
        }
        _ => None,
    }
}

impl<'a> ClassModel<'a> {
    /// The class over `nominal`.
    pub fn new(class: EffectClass, nominal: &'a Nominal) -> Result<Self> {
        let mut m = vec![
            Marginal::Normal {
                mean: 0.0,
                sd: 0.05,
            },
            Marginal::Normal { mean: 0.0, sd: 0.5 },
            Marginal::Normal { mean: 0.0, sd: 0.3 },
        ];
        match class {
            EffectClass::ParameterError => {}
            EffectClass::ProcessDamping | EffectClass::SpeedDependentDynamics => {
                m.push(Marginal::Uniform {
                    low: 0.0,
                    high: if class == EffectClass::ProcessDamping {
                        1.0
                    } else {
                        MAX_SOFTENING
                    },
                });
            }
            EffectClass::ExtraMode => {
                m.extend([
                    Marginal::Uniform {
                        low: 0.4f64.ln(),
                        high: 2.5f64.ln(),
                    },
                    Marginal::Uniform {
                        low: 0.005f64.ln(),
                        high: 0.1f64.ln(),
                    },
                    Marginal::Uniform {
                        low: 0.3f64.ln(),
                        high: 30f64.ln(),
                    },
                    Marginal::Uniform { low: 0.0, high: PI },
                ]);
            }
            EffectClass::Drift => m.push(Marginal::TruncatedNormal {
                mean: 0.0,
                sd: 0.5,
                low: -0.8,
                high: 2.0,
            }),
            EffectClass::SpeedBand => m.extend([
                Marginal::Normal { mean: 0.0, sd: 0.7 },
                Marginal::Uniform {
                    low: -0.1,
                    high: 1.1,
                },
                Marginal::Uniform {
                    low: 0.02f64.ln(),
                    high: 0.5f64.ln(),
                },
            ]),
        }
        m.extend(nominal.offset_modes.iter().map(|_| Marginal::Normal {
            mean: 0.0,
            sd: MODE_OFFSET_SD,
        }));
        let prior = IndependentPrior::new(m).map_err(|source| GapError::Sampler {
            class: class.name(),
            source,
        })?;
        Ok(Self {
            class,
            nominal,
            prior,
        })
    }

    /// The variant at parameters `theta`; None where they make no physical model.
    pub fn variant(&self, theta: &[f64]) -> Option<Variant> {
        let (sz, g) = (
            theta[slot::DAMPING_SCALE].exp(),
            theta[slot::CUTTING_OVER_STIFFNESS].exp(),
        );
        let model =
            recalibrated_per_mode(&self.nominal.model, &self.frequency_factors(theta), sz, g)
                .ok()?;
        let mut v = Variant::new(model);
        match self.class {
            EffectClass::ParameterError => {}
            EffectClass::ProcessDamping => {
                let c = self.process_damping_n_per_m(theta);
                v.model = v.model.with_process_damping((c > 0.0).then_some(c)).ok()?;
            }
            EffectClass::SpeedDependentDynamics => {
                v.softening_per_rpm2 = self.softening_per_rpm2(theta);
            }
            EffectClass::ExtraMode => {
                let mut modes = v.model.modes().to_vec();
                modes.push(ExtraMode::new(self.nominal, theta).mode()?);
                v.model = v.model.with_modes(modes).ok()?;
            }
            EffectClass::Drift => v.drift_rate = theta[slot::EFFECT],
            EffectClass::SpeedBand => v.cutting_bump = Some(self.bump(theta)),
        }
        Some(v)
    }

    /// The posterior mean of `samples` (equally weighted, with their log-likelihoods
    /// `ln_likelihoods`) in the posterior mode of the highest-density sample. For a class with
    /// strata ([`EffectClass::strata`]) the samples are sorted along the stratified coordinate
    /// and cut where neighbours are more than [`MODE_GAP`] apart; only the cut holding the sample
    /// of largest ln L + ln p(theta) is averaged (a mean over modes at 900 and 1500 Hz would be
    /// a mode where the data have none). The extra mode's direction is an axis (period pi): its
    /// mean is the axial circular mean, arg(sum e^{2 i angle}) / 2.
    pub fn posterior_mean(&self, samples: &[Vec<f64>], ln_likelihoods: &[f64]) -> Option<Vec<f64>> {
        let best = (0..samples.len()).max_by(|&a, &b| {
            let density = |i: usize| ln_likelihoods[i] + self.prior.ln_pdf(&samples[i]);
            density(a).total_cmp(&density(b))
        })?;
        let members: Vec<&Vec<f64>> = match self.class.mode_coordinate() {
            None => samples.iter().collect(),
            Some(coordinate) => {
                let mut order: Vec<usize> = (0..samples.len()).collect();
                order.sort_by(|&a, &b| samples[a][coordinate].total_cmp(&samples[b][coordinate]));
                let at = order.iter().position(|&i| i == best)?;
                let gap = |k: usize| {
                    samples[order[k + 1]][coordinate] - samples[order[k]][coordinate] > MODE_GAP
                };
                let first = (0..at).rev().find(|&k| gap(k)).map_or(0, |k| k + 1);
                let last = (at..order.len() - 1)
                    .find(|&k| gap(k))
                    .unwrap_or(order.len() - 1);
                order[first..=last].iter().map(|&i| &samples[i]).collect()
            }
        };
        let n = members.len() as f64;
        let mut mean: Vec<f64> = (0..samples[best].len())
            .map(|k| members.iter().map(|t| t[k]).sum::<f64>() / n)
            .collect();
        if self.class == EffectClass::ExtraMode {
            let (s, c) = members.iter().fold((0.0, 0.0), |(s, c), t| {
                let doubled = 2.0 * t[slot::EXTRA_DIRECTION];
                (s + doubled.sin(), c + doubled.cos())
            });
            mean[slot::EXTRA_DIRECTION] = (0.5 * s.atan2(c)).rem_euclid(PI);
        }
        Some(mean)
    }

    /// Reported parameters at `theta`: names with units and values.
    pub fn physical(&self, theta: &[f64]) -> Vec<(&'static str, f64)> {
        let mut out = vec![
            ("frequency_factor", theta[slot::FREQUENCY_SCALE].exp()),
            ("damping_factor", theta[slot::DAMPING_SCALE].exp()),
            (
                "cutting_over_stiffness_factor",
                theta[slot::CUTTING_OVER_STIFFNESS].exp(),
            ),
        ];
        match self.class {
            EffectClass::ParameterError => {}
            EffectClass::ProcessDamping => {
                out.push(("c_n_per_m", self.process_damping_n_per_m(theta)))
            }
            EffectClass::SpeedDependentDynamics => {
                out.push(("frequency_drop_at_max_speed", theta[slot::EFFECT]));
                out.push(("softening_per_rpm2", self.softening_per_rpm2(theta)));
            }
            EffectClass::ExtraMode => {
                let extra = ExtraMode::new(self.nominal, theta);
                out.push(("frequency_hz", extra.frequency_hz));
                out.push(("damping_ratio", extra.damping_ratio));
                out.push(("stiffness_n_per_m", extra.stiffness_n_per_m));
                out.push(("direction_deg", extra.direction_rad.to_degrees()));
            }
            EffectClass::Drift => out.push(("cutting_change_over_campaign", theta[slot::EFFECT])),
            EffectClass::SpeedBand => {
                let b = self.bump(theta);
                out.push(("band_cutting_factor", b.ln_factor.exp()));
                out.push(("band_center_rpm", b.center_rpm));
                out.push(("band_from_rpm", b.center_rpm * (-b.width_ln).exp()));
                out.push(("band_to_rpm", b.center_rpm * b.width_ln.exp()));
            }
        }
        let start = self.offsets_start();
        for (k, &j) in self.nominal.offset_modes.iter().enumerate() {
            out.push((
                MODE_OFFSET_NAMES[j.min(MODE_OFFSET_NAMES.len() - 1)],
                theta[start + k].exp(),
            ));
        }
        out
    }

    /// Where the mode offsets start in theta: after the class's own parameters.
    fn offsets_start(&self) -> usize {
        self.prior.dimension() - self.nominal.offset_modes.len()
    }

    /// Each mode's frequency factor at theta: s_f, times its offset for the offset modes.
    fn frequency_factors(&self, theta: &[f64]) -> Vec<f64> {
        let mut ln = vec![theta[slot::FREQUENCY_SCALE]; self.nominal.model.modes().len()];
        let start = self.offsets_start();
        for (k, &j) in self.nominal.offset_modes.iter().enumerate() {
            ln[j] += theta[start + k];
        }
        ln.into_iter().map(f64::exp).collect()
    }

    /// `process_damping`'s C (N/m) at theta.
    fn process_damping_n_per_m(&self, theta: &[f64]) -> f64 {
        theta[slot::EFFECT] * self.nominal.process_damping_scale_n_per_m.unwrap_or(0.0)
    }

    /// `speed_band`'s bump at theta.
    pub(crate) fn bump(&self, theta: &[f64]) -> CuttingBump {
        let (lo, hi) = (
            self.nominal.min_speed_rpm.ln(),
            self.nominal.max_speed_rpm.ln(),
        );
        CuttingBump {
            center_rpm: (lo + theta[slot::BAND_CENTER] * (hi - lo)).exp(),
            width_ln: theta[slot::BAND_LN_WIDTH].exp(),
            ln_factor: theta[slot::BAND_LN_FACTOR],
        }
    }

    /// `speed_dependent_dynamics`'s c in f_n(Omega) = f_n0 (1 - c Omega^2) at theta (1/rpm^2).
    fn softening_per_rpm2(&self, theta: &[f64]) -> f64 {
        theta[slot::EFFECT] / self.nominal.max_speed_rpm.powi(2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for c in EffectClass::ALL {
            assert_eq!(c.name().parse::<EffectClass>().unwrap(), c);
            assert_eq!(
                serde_json::to_string(&c).unwrap(),
                format!("\"{}\"", c.name())
            );
        }
        assert!("runout".parse::<EffectClass>().is_err());
    }
}
