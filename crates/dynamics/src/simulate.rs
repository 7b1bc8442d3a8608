//! Time-domain simulation of regenerative chatter for turning and milling (000 Eq. 1-4,
//! 002 Eq. 1-2, 003 Eq. 1), with loss of contact, process damping and realistic forcing.
//!
//! # Model
//! Each mode obeys q_n'' + 2 zeta_n w_n q_n' + w_n^2 q_n = phi_n^T f(t), x = Phi q. Every cutting
//! edge (the single tool in turning, each tooth in milling) has a chip direction n (feed in
//! turning; (sin phi, cos phi) in milling, as in [`crate::cutting`]) and a force direction
//! u = (k_n, k_t) over (feed, cutting) in turning, u = (k_t cos phi + k_n sin phi,
//! -k_t sin phi + k_n cos phi) in milling, so that the force b h u with h = n . (x(t - tau) - x(t))
//! is exactly -b H(t) (x - x_tau) of [`ModalModel::directional_matrix`].
//!
//! # Surface memory and loss of contact
//! The edge position along n is e(t) = n . (x(t) + feed(t)), with feed(t) the rigid feed motion
//! (f_z per delay). The chip is h = e(t) - S(t - tau), where S is the surface the previous edge
//! left at the same angle (one pitch ago, pitch_j / Omega, on a variable-pitch cutter; the surface
//! is kept per angle of the revolution). When h > 0 the edge cuts, the force is b h u and S(t) = e(t); when
//! h <= 0 the edge is out of contact, the force is zero and the older surface remains,
//! S(t) = S(t - tau). Before the first pass the surface is the nominal one of a rigid tool.
//!
//! # Helix and runout
//! A helical cutter ([`crate::Milling::cutting_edges`]) is cut in axial slices: each slice of
//! each tooth is an edge with its share of the depth, at its tooth's angle less the helix lag
//! z tan(beta_j) / R (rounded to the nearest step), cutting the surface of its own height (one
//! surface per slice), so a variable helix gets its delays along the axis from the surface
//! itself. A tooth's radial runout r_j (`operation.runout_um`) moves its edge out along n:
//! e_j = n . (x + feed) + r_j, so its chip is f + r_j - r_{j+1} in a rigid cut.
//!
//! # Spindle-speed variation
//! Under Omega(t) = Omega_0 (1 + A sin(2 pi r f_0 t)) (`speed_variation`) the tooth angle is
//! Omega_0 s(t) ([`TimeMap`]); the simulator steps uniformly in s, so the angles stay on the
//! grid and the surface one pitch back is where it was (the time-varying delay comes out of the
//! angle grid), and each step lasts t(s + h) - t(s) of true time, with the modal transition of
//! that duration. The outputs are interpolated linearly onto uniform true times before the
//! resampler. The static chip is per tooth (feed proportional to the spindle angle).
//!
//! # Forcing and integration
//! The internal step depends on the dynamics only, never on the output rate
//! ([`internal_step`]): a whole number of steps per delay (so the surface one delay ago lies on
//! the grid, with no interpolation, and the tooth angles repeat exactly every revolution), at
//! least [`MIN_STEPS_PER_TOOTH`] of them in milling ([`MIN_STEPS_PER_DELAY`] in turning) and at
//! least [`STEPS_PER_MODE_PERIOD`] per period of the highest mode. Each mode is advanced with its
//! exact transition for a force that varies linearly over the step (first-order hold),
//! q_{k+1} = Phi(h) q_k + Gamma_0 p_0 + Gamma_1 dp for p(s) = p_0 + dp s, s = (t - t_k) / h in
//! [0, 1].
//!
//! # Switching inside the step
//! The cutting force of an edge is f_j(s) = g_j(s) F_j(s), with F_j = b (h_j u_j - C/V (n_j . v) n_j)
//! the force the edge would exert in contact and g_j the indicator of "in the cut and h_j > 0".
//! F_j and h_j are taken linear over the step: their values at t_k and, at t_{k+1}, the linear
//! extrapolation from t_{k-1} and t_k (second-order accurate where they are smooth). On the
//! first step of an edge in the cut, where the previous step has no chip, the end values are
//! those on the surface the previous edge cut there one delay ago, with x(t_{k+1}) ~ x + v h.
//! The switching is located inside the step instead of on the grid:
//! - entry and exit: the angle of tooth j at step k is 2 pi ((k + o_j) mod R) / R with R the
//!   steps per revolution and o_j the tooth's offset in steps (j steps_per_delay for even pitch;
//!   for a variable-pitch cutter, `operation.pitch_deg`, the steps per delay are raised until
//!   every offset is whole, [`PITCH_GRID_SEARCH`]), so the part [a, z] of the step the tooth spends between
//!   the entry and exit angles of [`crate::Milling::entry_exit_rad`] is known exactly
//!   (a = clamp(entry / dphi - m, 0, 1), z = clamp(exit / dphi - m, 0, 1), m the angle in steps,
//!   dphi = 2 pi / R); a tooth that enters inside the step has no chip at t_k (the surface
//!   before the entry is an older one), so its end values are held over [a, z];
//! - loss and recovery of contact: the chip crosses zero at s* = h_j(0) / (h_j(0) - h_j(1)).
//!
//! The step's force, the sum over edges of the integrals over the part of [0, 1] in contact,
//! is replaced by the linear force with the same first two moments, M0 = int_0^1 f ds and
//! M1 = int_0^1 f s ds: p_0 = 4 M0 - 6 M1, dp = 12 M1 - 6 M0 (exact for a linear force; for a
//! switched one the error of the response over the step is of the order of h^2 times the
//! neglected higher moments, as for a smooth force). The surface memory keeps its values on the
//! grid (the state at t_k decides contact there); the lost-contact fraction is the part of the
//! engaged edge-time (after the first delay) without contact, from the same sub-step intervals.
//!
//! The spindle harmonics, known in closed form, enter with their values at both ends of the
//! step. A seeded Gaussian white force (RMS per coordinate and step, held over the step, so
//! its density is RMS^2 x step up to the internal rate; two draws per step) acts on both
//! coordinates. The outputs (x, v, or the acceleration from the equations of motion with the
//! force at t_k) are low-passed and decimated to the requested rate in one step by a
//! windowed-sinc resampler (module `resample`: cutoff 0.4 of the output rate, stopband below
//! -74 dB from 0.49 of it), so no content above the output's Nyquist frequency folds into the
//! record.

use crate::error::{DynamicsError, Result, positive};
use crate::model::ModalModel;
use crate::operation::Operation;
use crate::resample::Resampler;
use chatter_progress::{Observer, Silent};
use nalgebra::Matrix4;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::f64::consts::PI;

/// Tooth angles under a sinusoidal spindle-speed variation, Omega(t) = Omega_0 (1 + A sin(w_m t))
/// (Insperger & Stépán 2004; Sastry, Kapoor & DeVor 2002): the angle is Omega_0 s(t) with the
/// equivalent constant-speed time s(t) = t - (A / w_m) (cos(w_m t) - 1), increasing for A < 1
/// and equal to t at every whole modulation period. The simulator steps uniformly in s (so the
/// tooth angles stay on its grid) and the discretizations sample the coefficients at s(t).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeMap {
    amplitude: f64,
    omega_m: f64,
}

impl TimeMap {
    /// The map of relative amplitude `amplitude` A in [0, 1) at modulation frequency
    /// `omega_m_rad_s` w_m > 0 (callers validate both).
    pub fn new(amplitude: f64, omega_m_rad_s: f64) -> Self {
        Self {
            amplitude,
            omega_m: omega_m_rad_s,
        }
    }

    /// s(t).
    pub fn equivalent(&self, t: f64) -> f64 {
        t - self.amplitude / self.omega_m * ((self.omega_m * t).cos() - 1.0)
    }

    /// The t with s(t) = `s` (Newton from t = s; s' = 1 + A sin(w_m t) >= 1 - A > 0).
    pub fn inverse(&self, s: f64) -> f64 {
        let mut t = s;
        for _ in 0..100 {
            let step = (self.equivalent(t) - s) / (1.0 + self.amplitude * (self.omega_m * t).sin());
            t -= step;
            if step.abs() <= 1e-15 * (1.0 + t.abs()) {
                break;
            }
        }
        t
    }
}

/// Which kinematic quantity the output channels hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Displacement (m).
    Displacement,
    /// Velocity (m/s).
    Velocity,
    /// Acceleration (m/s^2).
    Acceleration,
}

/// Settings of one simulated cut.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulationSettings {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Axial depth (milling) or width (turning) of cut (m).
    pub depth_m: f64,
    /// Signal length (s).
    pub duration_s: f64,
    /// Output sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Seed of the random force.
    pub seed: u64,
    /// Output quantity.
    pub quantity: Quantity,
    /// Static chip: feed per tooth (milling) or per revolution (turning), m. Default 0.05 mm.
    pub feed_per_tooth_m: f64,
    /// RMS of the broadband random force on each coordinate (N). Default 1 N.
    pub random_force_rms_n: f64,
    /// Amplitude of explicit spindle-harmonic forcing (N), harmonics 1-4 with amplitude 1/k.
    /// Default 0.
    pub harmonic_force_n: f64,
    /// Radial immersion override for milling.
    pub radial_immersion: Option<f64>,
    /// Spindle-speed variation (amplitude ratio A in [0, 1), frequency ratio r > 0): the speed
    /// is Omega_0 (1 + A sin(2 pi r f_0 t)) about `speed_rpm` = 60 f_0 ([`TimeMap`]). Default
    /// none.
    pub speed_variation: Option<(f64, f64)>,
}

impl SimulationSettings {
    /// Settings with the documented defaults for the forcing.
    pub fn new(
        speed_rpm: f64,
        depth_m: f64,
        duration_s: f64,
        sample_rate_hz: f64,
        seed: u64,
    ) -> Self {
        Self {
            speed_rpm,
            depth_m,
            duration_s,
            sample_rate_hz,
            seed,
            quantity: Quantity::Acceleration,
            feed_per_tooth_m: 0.05e-3,
            random_force_rms_n: 1.0,
            harmonic_force_n: 0.0,
            radial_immersion: None,
            speed_variation: None,
        }
    }

    /// Check every field.
    pub fn validate(&self) -> Result<()> {
        positive("speed_rpm", self.speed_rpm)?;
        positive("duration_s", self.duration_s)?;
        positive("sample_rate_hz", self.sample_rate_hz)?;
        for (field, v) in [
            ("depth_m", self.depth_m),
            ("feed_per_tooth_m", self.feed_per_tooth_m),
            ("random_force_rms_n", self.random_force_rms_n),
            ("harmonic_force_n", self.harmonic_force_n),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(DynamicsError::value(field, v, "a finite value >= 0"));
            }
        }
        if let Some((a, r)) = self.speed_variation {
            if !(a.is_finite() && (0.0..1.0).contains(&a)) {
                return Err(DynamicsError::value(
                    "ssv_amplitude_ratio",
                    a,
                    "an amplitude ratio in [0, 1): the speed must stay positive",
                ));
            }
            if !(r.is_finite() && r > 0.0) {
                return Err(DynamicsError::value(
                    "ssv_frequency_ratio",
                    r,
                    "a modulation frequency over the spindle frequency > 0",
                ));
            }
        }
        let samples = self.duration_s * self.sample_rate_hz;
        if !(2.0..=1e9).contains(&samples) {
            return Err(DynamicsError::value(
                "duration_s",
                self.duration_s,
                "between 2 samples and 1e9 samples at the sample rate",
            ));
        }
        Ok(())
    }
}

/// One output channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Coordinate name (`x`, `y`, `feed`, `cutting`) or `once_per_rev`.
    pub name: String,
    /// Samples.
    pub data: Vec<f64>,
}

/// A simulated record.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// The two coordinates by name, then the `once_per_rev` pulse channel.
    pub channels: Vec<Channel>,
    /// Fraction of the engaged edge-time (after the first delay) without contact, resolved inside
    /// the step (module docs).
    pub lost_contact_fraction: f64,
}

/// Fewest internal steps per period of the highest mode. With the cutting force interpolated
/// linearly over each step (first-order hold, the slope extrapolated from the previous step) the
/// local error of the regenerative loop is of second order in the step: 100 steps per period
/// keep the closed-loop damping of seed 000's P3 pole (zeta 0.0038) within about 1 %, where a
/// force held constant over 20 steps per period lowered it by a third.
pub const STEPS_PER_MODE_PERIOD: f64 = 100.0;
/// Fewest internal steps per tooth period in milling. With the entry, exit and loss of contact
/// located inside the step (module docs) the error is of second order in the step. Against a
/// converged run (8000 steps per tooth), with no random force: seed 001's chattering cut at
/// 7000 rpm / 2 mm (27 % lost contact) has its limit-cycle RMS within +0.62 % at the mode rule
/// alone (161 steps per tooth), +0.077 % at 500 and +0.020 % at 1000 (the former scheme, with
/// the switching on the grid, +0.46 % at 250 and -0.01 % at 2000); the dominant multiplier of
/// seed 002's slotting cut at 2500 rpm / 1 mm, measured from the start-up transient, is within
/// 2.4e-4, 6e-5 and 1e-5 (former scheme at 2000: 1e-5). 1000 keeps the figures of the former
/// 2000 (see `tests/sim_accuracy.rs` of chatter-integration).
pub const MIN_STEPS_PER_TOOTH: usize = 1000;
/// Fewest internal steps per delay in turning (continuous cutting).
pub const MIN_STEPS_PER_DELAY: usize = 50;
/// Most surface samples (internal steps per delay times cutting edges) the simulator keeps: the
/// surface of the previous pass is a ring buffer of this length (8 bytes each, 400 MB at most).
pub const MAX_SURFACE_SAMPLES: usize = 50_000_000;
/// How many more steps per delay than the dynamics ask for a variable-pitch cutter may get so
/// that every tooth offset is a whole number of steps (then the surface each tooth cuts lies on
/// the grid, one pitch back, without interpolation); beyond it the offsets are rounded to the
/// nearest step (an error of at most half a step in each pitch).
pub const PITCH_GRID_SEARCH: usize = 1000;

/// One cutting edge element of the simulation: a tooth, or one axial slice of a helical tooth.
struct Element {
    /// The tooth (its runout and static chip).
    tooth: usize,
    /// The surface ring it cuts (its axial slice; 0 for a straight cutter).
    ring: usize,
    /// Its angle at step 0 in steps of the revolution.
    offset: usize,
    /// The fraction of the depth it cuts.
    weight: f64,
}

/// The elements of `model` at `depth_m` on a revolution of `steps_per_rev` steps: each tooth at
/// `offset_steps` with the whole depth, or for a helical cutter each of its axial slices
/// ([`crate::Milling::cutting_edges`]) with its own surface ring, its tooth's offset less the
/// slice's helix lag z tan(beta_j) / R rounded to the nearest step (an angle error of at most
/// half a step, 1 / (2 R) of a turn) and its share of the depth.
fn edge_elements(
    model: &ModalModel,
    depth_m: f64,
    offset_steps: &[usize],
    steps_per_rev: usize,
) -> Vec<Element> {
    let straight = || {
        offset_steps
            .iter()
            .enumerate()
            .map(|(j, &offset)| Element {
                tooth: j,
                ring: 0,
                offset,
                weight: 1.0,
            })
            .collect()
    };
    let Operation::Milling(m) = model.operation() else {
        return straight();
    };
    if !m.is_helical() {
        return straight();
    }
    let edges = m.cutting_edges(depth_m);
    let slices = edges.len() / m.teeth();
    let r = steps_per_rev as f64;
    edges
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let lag = m.tooth_offset_rad(e.tooth) - e.lead_rad;
            let lag_steps = ((lag / (2.0 * PI) * r).round() as usize) % steps_per_rev;
            Element {
                tooth: e.tooth,
                ring: i % slices,
                offset: (offset_steps[e.tooth] + steps_per_rev - lag_steps) % steps_per_rev,
                weight: e.weight,
            }
        })
        .collect()
}

/// Per mode: transition (row-major 2x2), input vector of the held force, input vector of the
/// force's change over the step, shape, omega_n, zeta_n.
struct ModeStep {
    phi: [f64; 4],
    held: [f64; 2],
    ramp: [f64; 2],
    shape: [f64; 2],
    omega: f64,
    zeta: f64,
}

/// Simulate a cut.
pub fn simulate(model: &ModalModel, settings: &SimulationSettings) -> Result<Simulation> {
    simulate_with_observer(model, settings, &Silent)
}

/// Exact transition of one mode over `h` with a force that varies linearly over the step,
/// p(t) = p_k + (p_{k+1} - p_k) t / h: (Phi 2x2 as [a, b, c, d], input of p_k, input of
/// p_{k+1} - p_k), from the exponential of the 4x4 augmented matrix.
fn mode_transition(omega: f64, zeta: f64, h: f64) -> ([f64; 4], [f64; 2], [f64; 2]) {
    let mut m = Matrix4::zeros();
    m[(0, 1)] = h;
    m[(1, 0)] = -omega * omega * h;
    m[(1, 1)] = -2.0 * zeta * omega * h;
    m[(1, 2)] = h;
    m[(2, 3)] = 1.0;
    let e = m.exp();
    (
        [e[(0, 0)], e[(0, 1)], e[(1, 0)], e[(1, 1)]],
        [e[(0, 2)], e[(1, 2)]],
        [e[(0, 3)], e[(1, 3)]],
    )
}

/// The internal step (s) and the number of steps per delay for a model whose highest natural
/// frequency is `f_max_hz` at delay `tau_s`: a whole number of steps per delay, at least
/// `min_steps` ([`MIN_STEPS_PER_TOOTH`] in milling, [`MIN_STEPS_PER_DELAY`] in turning), each at
/// most 1 / ([`STEPS_PER_MODE_PERIOD`] f_max). Independent of the output rate.
pub fn internal_step(f_max_hz: f64, tau_s: f64, min_steps: usize) -> (f64, usize) {
    let h_target = 1.0 / (STEPS_PER_MODE_PERIOD * f_max_hz);
    let steps = ((tau_s / h_target).ceil() as usize).max(min_steps.max(1));
    (tau_s / steps as f64, steps)
}

/// Simulate a cut, reporting progress to `observer`, which is polled every hundredth of the
/// record ([`DynamicsError::Cancelled`]).
pub fn simulate_with_observer(
    model: &ModalModel,
    settings: &SimulationSettings,
    observer: &dyn Observer,
) -> Result<Simulation> {
    settings.validate()?;
    model.require_proportional("the time-domain simulation")?;
    let model = match (model.operation(), settings.radial_immersion) {
        (Operation::Milling(m), Some(r)) => {
            model.with_operation(Operation::Milling(m.with_radial_immersion(r)?))?
        }
        _ => model.clone(),
    };
    let tau = model.operation().delay_s(settings.speed_rpm);
    let f_max = model
        .modes()
        .iter()
        .map(|m| m.frequency_hz())
        .fold(0.0, f64::max);
    let min_steps = match model.operation() {
        Operation::Turning(_) => MIN_STEPS_PER_DELAY,
        Operation::Milling(_) => MIN_STEPS_PER_TOOTH,
    };
    let (mut h, mut steps_per_delay) = internal_step(f_max, tau, min_steps);
    let edges = match model.operation() {
        Operation::Turning(_) => 1,
        Operation::Milling(m) => m.teeth(),
    };
    // each tooth's angular offset in steps (tooth j at step k is at angle index
    // (k + offset_j) mod R): j steps_per_delay for even pitch; for a variable-pitch cutter the
    // steps per delay are raised (by at most PITCH_GRID_SEARCH) until every offset is a whole
    // number of steps, else the offsets are rounded to the nearest step
    let mut offset_steps: Vec<usize> = (0..edges).map(|j| j * steps_per_delay).collect();
    if let Operation::Milling(m) = model.operation()
        && m.is_variable_pitch()
    {
        let fractions: Vec<f64> = (0..edges)
            .map(|j| m.tooth_offset_rad(j) / (2.0 * PI))
            .collect();
        let misfit = |spd: usize| {
            let r = (spd * edges) as f64;
            fractions
                .iter()
                .map(|f| (f * r - (f * r).round()).abs())
                .fold(0.0, f64::max)
        };
        let spd = (steps_per_delay..steps_per_delay + PITCH_GRID_SEARCH)
            .find(|&spd| misfit(spd) < 1e-6)
            .unwrap_or(steps_per_delay);
        steps_per_delay = spd;
        h = tau / spd as f64;
        let r = spd * edges;
        offset_steps = fractions
            .iter()
            .map(|f| ((f * r as f64).round() as usize) % r)
            .collect();
    }
    // the static chip of each edge in units of the feed per tooth: its pitch over the mean pitch
    let chip_scale: Vec<f64> = match model.operation() {
        Operation::Milling(m) if m.is_variable_pitch() => (0..edges)
            .map(|j| m.tooth_pitch_rad(j) * edges as f64 / (2.0 * PI))
            .collect(),
        _ => vec![1.0; edges],
    };
    let elements = edge_elements(
        &model,
        settings.depth_m,
        &offset_steps,
        steps_per_delay * edges,
    );
    let rings = elements.iter().map(|e| e.ring + 1).max().unwrap_or(1);
    let runout: Vec<f64> = match model.operation() {
        Operation::Milling(m) => (0..edges).map(|j| m.tooth_runout_m(j)).collect(),
        Operation::Turning(_) => vec![0.0],
    };
    let surface_samples = steps_per_delay.saturating_mul(edges).saturating_mul(rings);
    if surface_samples > MAX_SURFACE_SAMPLES {
        // steps per delay grow as 1 / speed: the speed at which the surface fits the cap
        let lowest = settings.speed_rpm * surface_samples as f64 / MAX_SURFACE_SAMPLES as f64;
        return Err(DynamicsError::value(
            "speed_rpm",
            settings.speed_rpm,
            format!(
                "a speed whose delay the simulator resolves in at most {MAX_SURFACE_SAMPLES} \
                 surface samples (one delay needs {surface_samples} here at {STEPS_PER_MODE_PERIOD} \
                 steps per period of the {} Hz mode); a speed above {} rpm",
                crate::limits::written(f_max),
                crate::limits::written(lowest.ceil())
            ),
        ));
    }
    let n_out = (settings.duration_s * settings.sample_rate_hz).floor() as usize;
    let mut resampler = Resampler::<2>::new(h, settings.sample_rate_hz);
    let last_out_s = (n_out.max(1) - 1) as f64 / settings.sample_rate_hz;
    let end_s = last_out_s + resampler.half_width_s();
    let end_s = match settings.speed_variation {
        Some((a, r)) if a > 0.0 => {
            TimeMap::new(a, 2.0 * PI * r * settings.speed_rpm / 60.0).equivalent(end_s)
        }
        _ => end_s,
    };
    let total_steps = (end_s / h).ceil() as usize + 2;
    if total_steps > 2_000_000_000 {
        return Err(DynamicsError::value(
            "duration_s",
            settings.duration_s,
            "at most 2e9 internal steps",
        ));
    }

    let modes: Vec<ModeStep> = model
        .modes()
        .iter()
        .map(|m| {
            let (phi, held, ramp) = mode_transition(m.omega_rad_s(), m.damping_ratio(), h);
            ModeStep {
                phi,
                held,
                ramp,
                shape: m.mass_normalized_shape(),
                omega: m.omega_rad_s(),
                zeta: m.damping_ratio(),
            }
        })
        .collect();
    let nm = modes.len();
    let mut q = vec![0.0; nm];
    let mut qd = vec![0.0; nm];

    // edges: turning has one (chip along feed), milling one per tooth
    let cutting = model.cutting();
    let (kt, kn) = (cutting.kt_n_per_m2(), cutting.kn_n_per_m2());
    let milling = match model.operation() {
        Operation::Turning(_) => None,
        Operation::Milling(m) => Some(m.entry_exit_rad()),
    };
    // tooth angles: tooth j at step k is at 2 pi ((k + offset_steps[j]) mod R) / R, with R the
    // steps per revolution (a whole number: the delay is a whole number of steps)
    let steps_per_rev = steps_per_delay * edges;
    let step_angle = 2.0 * PI / steps_per_rev as f64;
    let (step_sin, step_cos) = step_angle.sin_cos();
    // (sin, cos) of an angle advanced by one step
    let rotated = |[s, c]: [f64; 2]| [s * step_cos + c * step_sin, c * step_cos - s * step_sin];
    let (entry_steps, exit_steps) = match milling {
        Some((entry, exit)) => (entry / step_angle, exit / step_angle),
        None => (0.0, 0.0),
    };
    // each tooth's angle in steps, (k + offset_steps[j]) mod steps_per_rev
    let mut tooth_index = vec![0usize; elements.len()];
    // (sin, cos) of each tooth angle, rotated by the step angle and recomputed every delay
    let mut tooth_sc = vec![[0.0f64, 1.0f64]; elements.len()];
    // force direction u of a milling edge whose chip direction is (sin phi, cos phi)
    let milling_force_direction = |[s, c]: [f64; 2]| [kt * c + kn * s, -kt * s + kn * c];
    let omega_spindle = 2.0 * PI * settings.speed_rpm / 60.0;
    let feed_speed = settings.feed_per_tooth_m / tau; // m/s along x (milling) or feed (turning)
    let b = settings.depth_m;
    let cv = model.process_damping_per_width(settings.speed_rpm);
    // spindle-speed variation: the steps are uniform in the equivalent time s (tooth angles on
    // the grid), each lasting t(s + h) - t(s) of true time
    let map = match settings.speed_variation {
        Some((a, r)) if a > 0.0 => {
            if cv > 0.0 {
                return Err(DynamicsError::invalid(
                    "process_damping",
                    "with a spindle-speed variation (the cutting speed varies along the cut) \
                     is not simulated",
                ));
            }
            Some(TimeMap::new(a, 2.0 * PI * r * settings.speed_rpm / 60.0))
        }
        _ => None,
    };
    let true_time = |s: f64| map.map_or(s, |m| m.inverse(s));
    let mut modes = modes;
    // the output at uniform true times, interpolated between the steps of a varied speed
    let mut last_output: Option<(f64, [f64; 2])> = None;
    let mut next_output = 0usize;
    // surface ring buffer: the surface last left at each angle index of one revolution (steps
    // per delay times edges values; in turning the revolution is the delay)
    let mut surface = vec![f64::NAN; steps_per_rev * rings];
    // each edge's angle index at this step, and the surface there as the edge ahead left it,
    // read before any edge overwrites it
    let mut angle_index = vec![0usize; elements.len()];
    let mut previous_slot = vec![f64::NAN; elements.len()];
    // per edge, the chip and the ungated force of the previous step (for the extrapolation)
    let mut previous_chip = vec![0.0f64; elements.len()];
    let mut previous_edge_force = vec![[0.0f64; 2]; elements.len()];
    let mut previous_in_cut = vec![false; elements.len()];
    let harmonic = |t: f64| -> f64 {
        (1..=4)
            .map(|k| (k as f64 * omega_spindle * t + 0.7 * k as f64).cos() / k as f64)
            .sum()
    };
    let mut harmonic_now = if settings.harmonic_force_n > 0.0 {
        harmonic(0.0)
    } else {
        0.0
    };

    let mut rng = rand::rngs::StdRng::seed_from_u64(settings.seed);
    let mut out = [vec![0.0; n_out], vec![0.0; n_out]];
    // engaged edge-time and the part of it without contact, in steps
    let (mut engaged, mut lost) = (0.0f64, 0.0f64);
    let report_every = (total_steps / 100).max(1);

    for step in 0..total_steps {
        let t = step as f64 * h;
        // the step's true duration under a speed variation (h at constant speed)
        let dt = match map {
            Some(_) => {
                let dt = true_time(t + h) - true_time(t);
                for md in modes.iter_mut() {
                    (md.phi, md.held, md.ramp) = mode_transition(md.omega, md.zeta, dt);
                }
                dt
            }
            None => h,
        };
        let (mut x, mut v) = ([0.0f64; 2], [0.0f64; 2]);
        for (n, md) in modes.iter().enumerate() {
            x[0] += md.shape[0] * q[n];
            x[1] += md.shape[1] * q[n];
            v[0] += md.shape[0] * qd[n];
            v[1] += md.shape[1] * qd[n];
        }
        // cutting forces from every edge: the force at t (for the output) and the first two
        // moments over the step, int_0^1 f(s) ds and int_0^1 f(s) s ds (s = time / h)
        let mut f = [0.0f64; 2];
        let (mut m0, mut m1) = ([0.0f64; 2], [0.0f64; 2]);
        let slot = step % steps_per_delay;
        let has_previous_step = step > 0;
        let after_first_delay = step >= steps_per_delay;
        if milling.is_some() {
            if step % steps_per_delay == 0 {
                for (j, (sc, index)) in tooth_sc.iter_mut().zip(&mut tooth_index).enumerate() {
                    *index = (step + elements[j].offset) % steps_per_rev;
                    let (s, c) = (*index as f64 * step_angle).sin_cos();
                    *sc = [s, c];
                }
            } else {
                for (sc, index) in tooth_sc.iter_mut().zip(&mut tooth_index) {
                    *sc = rotated(*sc);
                    *index = if *index + 1 == steps_per_rev {
                        0
                    } else {
                        *index + 1
                    };
                }
            }
            angle_index.copy_from_slice(&tooth_index);
        } else {
            angle_index[0] = slot;
        }
        for ((previous, &index), element) in
            previous_slot.iter_mut().zip(&angle_index).zip(&elements)
        {
            *previous = surface[element.ring * steps_per_rev + index];
        }
        for (j, element) in elements.iter().enumerate() {
            let b = b * element.weight;
            let ring = element.ring * steps_per_rev;
            // chip direction n, force direction u and the part [a, z] of the step in the cut
            let (n_dir, u, in_cut, (a, z)) = match milling {
                None => ([1.0, 0.0], [kn, kt], true, (0.0, 1.0)),
                Some((entry, exit)) => {
                    let index = tooth_index[j] as f64;
                    let p = index * step_angle;
                    (
                        tooth_sc[j],
                        milling_force_direction(tooth_sc[j]),
                        p >= entry && p <= exit,
                        (
                            (entry_steps - index).clamp(0.0, 1.0),
                            (exit_steps - index).clamp(0.0, 1.0),
                        ),
                    )
                }
            };
            // edge position along n including the rigid feed motion
            // (and the tooth's runout, how far it stands out along n)
            let e = n_dir[0] * (feed_speed * t - x[0]) - n_dir[1] * x[1] + runout[element.tooth];
            // the surface at this angle was left one pitch ago by the next edge (milling) or one
            // revolution ago by the same edge (turning)
            let previous = previous_slot[j];
            let s_prev = if previous.is_nan() {
                e - settings.feed_per_tooth_m * chip_scale[element.tooth] * n_dir[0] // rigid first pass
            } else {
                previous
            };
            let chip = e - s_prev;
            let mut new_surface = e;
            if b > 0.0 && (in_cut || z > a) {
                // the force the edge would exert in contact, b h u - b C/V (n . v) n
                let vn = n_dir[0] * v[0] + n_dir[1] * v[1];
                let force = [
                    b * (chip * u[0] - cv * vn * n_dir[0]),
                    b * (chip * u[1] - cv * vn * n_dir[1]),
                ];
                let entering = a > 0.0 && z > a;
                let extrapolated = has_previous_step && previous_in_cut[j];
                // chip and force at the end of the step
                let (chip_end, force_end) = if extrapolated || z <= a {
                    // extrapolated linearly from the previous step
                    let pf = previous_edge_force[j];
                    (
                        2.0 * chip - previous_chip[j],
                        [2.0 * force[0] - pf[0], 2.0 * force[1] - pf[1]],
                    )
                } else {
                    // first step in the cut (the previous step has no chip to extrapolate
                    // from): the chip at the end of the step on the surface the previous edge
                    // cut there one delay ago, with the displacement extrapolated by the velocity
                    let (n_end, u_end) = match milling {
                        None => (n_dir, u),
                        Some(_) => {
                            let n_end = rotated(tooth_sc[j]);
                            (n_end, milling_force_direction(n_end))
                        }
                    };
                    let x_end = [x[0] + v[0] * dt, x[1] + v[1] * dt];
                    let e_end = n_end[0] * (feed_speed * (t + h) - x_end[0]) - n_end[1] * x_end[1]
                        + runout[element.tooth];
                    let s_next = surface[ring + (angle_index[j] + 1) % steps_per_rev];
                    let chip_end = if s_next.is_nan() {
                        settings.feed_per_tooth_m * chip_scale[element.tooth] * n_end[0]
                    } else {
                        e_end - s_next
                    };
                    let vn_end = n_end[0] * v[0] + n_end[1] * v[1];
                    (
                        chip_end,
                        [
                            b * (chip_end * u_end[0] - cv * vn_end * n_end[0]),
                            b * (chip_end * u_end[1] - cv * vn_end * n_end[1]),
                        ],
                    )
                };
                if entering {
                    // the edge enters the cut inside the step, where its chip at the start of
                    // the step is not one (the surface there is older): the end values are
                    // held over the part of the step in the cut
                    let contact = if chip_end > 0.0 { z - a } else { 0.0 };
                    if after_first_delay {
                        engaged += z - a;
                        lost += (z - a) - contact;
                    }
                    let (w0, w1) = (contact, 0.5 * (z * z - (z - contact) * (z - contact)));
                    for i in 0..2 {
                        m0[i] += force_end[i] * w0;
                        m1[i] += force_end[i] * w1;
                    }
                }
                let slope = [force_end[0] - force[0], force_end[1] - force[1]];
                previous_chip[j] = chip;
                previous_edge_force[j] = force;
                previous_in_cut[j] = in_cut;
                if z > a && !entering {
                    // the part of [a, z] with a positive chip (chip linear over the step)
                    let (ca, cz) = if chip > 0.0 && chip_end > 0.0 {
                        (a, z)
                    } else if chip <= 0.0 && chip_end <= 0.0 {
                        (z, z)
                    } else {
                        let cross = chip / (chip - chip_end);
                        if chip > 0.0 {
                            (a, z.min(cross))
                        } else {
                            (a.max(cross), z)
                        }
                    };
                    if after_first_delay {
                        engaged += z - a;
                        lost += (z - a) - (cz - ca).max(0.0);
                    }
                    if cz > ca {
                        let w0 = cz - ca;
                        let w1 = 0.5 * (cz * cz - ca * ca);
                        let w2 = (cz * cz * cz - ca * ca * ca) / 3.0;
                        for i in 0..2 {
                            m0[i] += force[i] * w0 + slope[i] * w1;
                            m1[i] += force[i] * w1 + slope[i] * w2;
                        }
                    }
                }
                if in_cut {
                    if chip > 0.0 {
                        f[0] += force[0];
                        f[1] += force[1];
                    } else {
                        new_surface = s_prev;
                    }
                } else if !previous.is_nan() {
                    new_surface = s_prev.min(e);
                }
            } else {
                previous_in_cut[j] = false;
                if !previous.is_nan() {
                    new_surface = s_prev.min(e);
                }
            }
            surface[ring + angle_index[j]] = new_surface;
        }
        if settings.harmonic_force_n > 0.0 {
            // known in closed form: its values at both ends of the step
            let harmonic_end = harmonic(t + h);
            let (h0, dh) = (harmonic_now, harmonic_end - harmonic_now);
            for (i, scale) in [1.0, 0.5].into_iter().enumerate() {
                let amplitude = settings.harmonic_force_n * scale;
                f[i] += amplitude * h0;
                m0[i] += amplitude * (h0 + 0.5 * dh);
                m1[i] += amplitude * (0.5 * h0 + dh / 3.0);
            }
            harmonic_now = harmonic_end;
        }
        // random force, held over the step (white up to the internal rate)
        let mut r = [0.0f64; 2];
        for rc in r.iter_mut() {
            let z: f64 = StandardNormal.sample(&mut rng);
            *rc = settings.random_force_rms_n * z;
        }
        // output at this instant
        let value = match settings.quantity {
            Quantity::Displacement => x,
            Quantity::Velocity => v,
            Quantity::Acceleration => {
                let total = [f[0] + r[0], f[1] + r[1]];
                let mut acc = [0.0; 2];
                for (n, md) in modes.iter().enumerate() {
                    let p = md.shape[0] * total[0] + md.shape[1] * total[1];
                    let qdd = p - 2.0 * md.zeta * md.omega * qd[n] - md.omega * md.omega * q[n];
                    acc[0] += md.shape[0] * qdd;
                    acc[1] += md.shape[1] * qdd;
                }
                acc
            }
        };
        match map {
            None => resampler.push(value, &mut out),
            Some(_) => {
                // linear interpolation onto the uniform true times n h
                let now = true_time(t);
                if let Some((before, previous)) = last_output {
                    while (next_output as f64) * h <= now {
                        let at = next_output as f64 * h;
                        let w = (at - before) / (now - before);
                        resampler.push(
                            [
                                previous[0] + w * (value[0] - previous[0]),
                                previous[1] + w * (value[1] - previous[1]),
                            ],
                            &mut out,
                        );
                        next_output += 1;
                    }
                } else {
                    resampler.push(value, &mut out);
                    next_output = 1;
                }
                last_output = Some((now, value));
            }
        }
        // the linear force p0 + dp s with the same two moments as the cutting and harmonic
        // forces over the step (p0 = 4 M0 - 6 M1, dp = 12 M1 - 6 M0), plus the held random force
        let held = [
            4.0 * m0[0] - 6.0 * m1[0] + r[0],
            4.0 * m0[1] - 6.0 * m1[1] + r[1],
        ];
        let ramp = [12.0 * m1[0] - 6.0 * m0[0], 12.0 * m1[1] - 6.0 * m0[1]];
        for (n, md) in modes.iter().enumerate() {
            let p = md.shape[0] * held[0] + md.shape[1] * held[1];
            let dp = md.shape[0] * ramp[0] + md.shape[1] * ramp[1];
            let (a, g, s) = (md.phi, md.held, md.ramp);
            let (q0, v0) = (q[n], qd[n]);
            q[n] = a[0] * q0 + a[1] * v0 + g[0] * p + s[0] * dp;
            qd[n] = a[2] * q0 + a[3] * v0 + g[1] * p + s[1] * dp;
        }
        if !(q.iter().all(|v| v.is_finite())) {
            return Err(DynamicsError::invalid(
                "simulation",
                format!("the response diverged at t = {t:.4} s"),
            ));
        }
        if step % report_every == 0 {
            chatter_progress::check(observer)?;
            observer.fraction_done(step as f64 / total_steps as f64);
        }
    }
    observer.fraction_done(1.0);
    // once-per-revolution pulses at the output samples nearest each revolution start
    let rev_s = 60.0 / settings.speed_rpm;
    let mut pulse = vec![0.0; n_out];
    let mut revolutions = 0.0;
    let mut next_rev = 0.0;
    for (k, p) in pulse.iter_mut().enumerate() {
        let ts = k as f64 / settings.sample_rate_hz;
        if ts >= next_rev - 0.5 / settings.sample_rate_hz {
            *p = 1.0;
            revolutions += 1.0;
            next_rev = match map {
                None => next_rev + rev_s,
                Some(m) => m.inverse(revolutions * rev_s),
            };
        }
    }
    let names = model.operation().coordinates();
    let [c0, c1] = out;
    Ok(Simulation {
        sample_rate_hz: settings.sample_rate_hz,
        channels: vec![
            Channel {
                name: names[0].name().into(),
                data: c0,
            },
            Channel {
                name: names[1].name().into(),
                data: c1,
            },
            Channel {
                name: "once_per_rev".into(),
                data: pulse,
            },
        ],
        lost_contact_fraction: if engaged > 0.0 { lost / engaged } else { 0.0 },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::examples;

    #[test]
    fn runout_sets_each_tooths_chip() {
        // tooth j cuts the surface tooth j + 1 left, so in a rigid cut its chip is
        // f sin(phi) + r_j - r_{j+1}: with the runout [r, 0] of a 2-tooth cutter in 50 % down
        // milling (phi from pi/2 to pi), tooth 1's chip f sin(phi) - r is gone where
        // sin(phi) < r / f. At r = f / 2 that is the last third of its arc (1/6 of the engaged
        // edge-time of both teeth); at r = 2 f tooth 1 never touches the part (1/2). A light cut
        // (0.01 mm, about 0.2 um of deflection against the 25 um offset) stays within 0.005 of
        // the rigid fractions.
        let model = examples::insperger_benchmark(0.5);
        let Operation::Milling(m) = model.operation() else {
            unreachable!("a milling model")
        };
        let feed_um = 50.0;
        let lost = |runout_um: f64| {
            let milling = m.clone().with_runout_um(Some(&[runout_um, 0.0])).unwrap();
            let model = model.with_operation(Operation::Milling(milling)).unwrap();
            let mut s = SimulationSettings::new(10_000.0, 0.01e-3, 0.12, 5000.0, 1);
            s.random_force_rms_n = 0.0;
            s.feed_per_tooth_m = feed_um * 1e-6;
            simulate(&model, &s).unwrap().lost_contact_fraction
        };
        let (below, above) = (lost(0.5 * feed_um), lost(2.0 * feed_um));
        assert!((below - 1.0 / 6.0).abs() < 0.005, "{below}");
        assert!((above - 0.5).abs() < 0.005, "{above}");
        assert!(lost(0.0) < 1e-3);
    }

    #[test]
    fn linear_force_matches_directional_matrix() {
        // b h u summed over teeth in the cut equals -b H (x - x_tau) for any displacement step.
        let model = examples::schmitz_2023_milling();
        let cutting = model.cutting();
        let (kt, kn) = (cutting.kt_n_per_m2(), cutting.kn_n_per_m2());
        let rpm = 7000.0;
        let dx = [1.3e-6, -0.4e-6]; // x - x_tau
        for k in 0..50 {
            let t = k as f64 * 1.7e-4;
            let h = model.directional_matrix(t, rpm);
            let expected = [
                -(h[(0, 0)] * dx[0] + h[(0, 1)] * dx[1]),
                -(h[(1, 0)] * dx[0] + h[(1, 1)] * dx[1]),
            ];
            let mut f = [0.0; 2];
            if let Operation::Milling(m) = model.operation() {
                for j in 0..m.teeth() {
                    let phi = 2.0 * PI * rpm / 60.0 * t + 2.0 * PI * j as f64 / 4.0;
                    if crate::cutting::tooth_in_cut(m, phi) {
                        let (s, c) = phi.sin_cos();
                        let chip = -(s * dx[0] + c * dx[1]);
                        f[0] += chip * (kt * c + kn * s);
                        f[1] += chip * (-kt * s + kn * c);
                    }
                }
            }
            for i in 0..2 {
                assert!((f[i] - expected[i]).abs() < 1e-9 * (1.0 + expected[i].abs()));
            }
        }
    }

    #[test]
    fn bad_settings_are_errors() {
        let model = examples::ahmadi_2022_turning();
        for s in [
            SimulationSettings::new(0.0, 1e-3, 1.0, 1e4, 1),
            SimulationSettings::new(7000.0, -1e-3, 1.0, 1e4, 1),
            SimulationSettings::new(7000.0, 1e-3, f64::NAN, 1e4, 1),
            SimulationSettings::new(7000.0, 1e-3, 1.0, 0.0, 1),
            SimulationSettings::new(7000.0, 1e-3, 1e-6, 1e4, 1),
        ] {
            assert!(simulate(&model, &s).is_err(), "{s:?}");
        }
    }

    #[test]
    fn a_cancelled_simulation_stops_at_its_first_step() {
        // 100 s of milling would take about a minute
        let model = examples::schmitz_2023_milling();
        let settings = SimulationSettings::new(7000.0, 1e-3, 100.0, 1e4, 1);
        let r = simulate_with_observer(&model, &settings, &chatter_progress::AlreadyCancelled);
        assert!(matches!(r, Err(DynamicsError::Cancelled(_))), "{r:?}");
    }
}
