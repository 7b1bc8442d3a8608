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
//! left at the same angle. When h > 0 the edge cuts, the force is b h u and S(t) = e(t); when
//! h <= 0 the edge is out of contact, the force is zero and the older surface remains,
//! S(t) = S(t - tau). Before the first pass the surface is the nominal one of a rigid tool.
//!
//! # Forcing and integration
//! The internal step depends on the dynamics only, never on the output rate
//! ([`internal_step`]): a whole number of steps per delay (so the surface one delay ago lies on
//! the grid, with no interpolation), at least [`MIN_STEPS_PER_TOOTH`] of them in milling
//! ([`MIN_STEPS_PER_DELAY`] in turning) and at least
//! [`STEPS_PER_MODE_PERIOD`] per period of the highest mode. Each mode is advanced with its exact
//! transition for a force that varies linearly over the step (first-order hold): the cutting and
//! harmonic force ramps with the slope of the previous step, except on steps where an edge
//! entered, left or lost the cut, where it is held. A seeded Gaussian white force (RMS per
//! coordinate and step, held over the step, so its density is RMS^2 x step up to the internal
//! rate) plus optional spindle harmonics acts on both coordinates. The outputs are low-passed
//! and decimated to the requested rate in one step by a windowed-sinc resampler (cutoff 0.4 of
//! the output rate, stopband below -74 dB from 0.49 of it), so no content above the output's
//! Nyquist frequency folds into the record.

use crate::error::{DynamicsError, Result, positive};
use crate::model::ModalModel;
use crate::operation::Operation;
use crate::resample::Resampler;
use chatter_progress::{Observer, Silent};
use nalgebra::Matrix4;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::f64::consts::PI;

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
    /// Fraction of engaged edge-steps (after the first delay) without contact.
    pub lost_contact_fraction: f64,
}

/// Fewest internal steps per period of the highest mode. With the cutting force interpolated
/// linearly over each step (first-order hold, the slope extrapolated from the previous step) the
/// local error of the regenerative loop is of second order in the step: 100 steps per period
/// keep the closed-loop damping of seed 000's P3 pole (zeta 0.0038) within about 1 %, where a
/// force held constant over 20 steps per period lowered it by a third.
pub const STEPS_PER_MODE_PERIOD: f64 = 100.0;
/// Fewest internal steps per tooth period in milling: the tooth angles, the
/// entry and exit of the cut and the loss of contact at zero chip thickness are resolved on this
/// grid. With 235 steps per tooth period (the mode rule alone) the lifted identification of
/// seed 002's slotting cut at 2500 rpm / 1 mm gave the multiplier 0.95 for 0.874; with 2000 it
/// gives 0.866.
pub const MIN_STEPS_PER_TOOTH: usize = 2000;
/// Fewest internal steps per delay in turning (continuous cutting).
pub const MIN_STEPS_PER_DELAY: usize = 50;
/// Most surface samples (internal steps per delay times cutting edges) the simulator keeps: the
/// surface of the previous pass is a ring buffer of this length (8 bytes each, 400 MB at most).
pub const MAX_SURFACE_SAMPLES: usize = 50_000_000;

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
    let (h, steps_per_delay) = internal_step(f_max, tau, min_steps);
    let edges = match model.operation() {
        Operation::Turning(_) => 1,
        Operation::Milling(m) => m.teeth(),
    };
    let surface_samples = steps_per_delay.saturating_mul(edges);
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
    let total_steps = ((last_out_s + resampler.half_width_s()) / h).ceil() as usize + 2;
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
    let (edges, milling) = match model.operation() {
        Operation::Turning(_) => (1usize, None),
        Operation::Milling(m) => (m.teeth(), Some(m.clone())),
    };
    let omega_spindle = 2.0 * PI * settings.speed_rpm / 60.0;
    let feed_speed = settings.feed_per_tooth_m / tau; // m/s along x (milling) or feed (turning)
    let b = settings.depth_m;
    let cv = model.process_damping_per_width(settings.speed_rpm);
    // surface ring buffer: one value per edge per step over one delay
    let mut surface = vec![f64::NAN; steps_per_delay * edges];
    // the slot's surfaces as they were one delay ago, read before any edge overwrites them
    let mut previous_slot = vec![f64::NAN; edges];

    let mut rng = rand::rngs::StdRng::seed_from_u64(settings.seed);
    let mut out = [vec![0.0; n_out], vec![0.0; n_out]];
    let (mut engaged, mut lost) = (0usize, 0usize);
    // deterministic (cutting and harmonic) modal forces of the previous step and its contact set
    let mut previous_force = vec![0.0; nm];
    let mut previous_contact: Option<u64> = None;
    let mut modal_force = vec![0.0; nm];
    let report_every = (total_steps / 100).max(1);

    for step in 0..total_steps {
        let t = step as f64 * h;
        let x = [
            (0..nm).map(|n| modes[n].shape[0] * q[n]).sum::<f64>(),
            (0..nm).map(|n| modes[n].shape[1] * q[n]).sum::<f64>(),
        ];
        let v = [
            (0..nm).map(|n| modes[n].shape[0] * qd[n]).sum::<f64>(),
            (0..nm).map(|n| modes[n].shape[1] * qd[n]).sum::<f64>(),
        ];
        // cutting forces from every edge
        let mut f = [0.0f64; 2];
        let mut contact = 0u64;
        let slot = step % steps_per_delay;
        previous_slot.copy_from_slice(&surface[slot * edges..(slot + 1) * edges]);
        for j in 0..edges {
            let (n_dir, u, in_cut) = match &milling {
                None => ([1.0, 0.0], [kn, kt], true),
                Some(m) => {
                    let phi = omega_spindle * t + 2.0 * PI * j as f64 / edges as f64;
                    let (s, c) = phi.sin_cos();
                    (
                        [s, c],
                        [kt * c + kn * s, -kt * s + kn * c],
                        crate::cutting::tooth_in_cut(m, phi),
                    )
                }
            };
            // edge position along n including the rigid feed motion
            let e = n_dir[0] * (feed_speed * t - x[0]) - n_dir[1] * x[1];
            // the surface at this angle was left one delay ago by the next edge (milling) or the
            // same edge (turning)
            let prev_edge = (j + 1) % edges;
            let previous = previous_slot[prev_edge];
            let s_prev = if previous.is_nan() {
                e - settings.feed_per_tooth_m * n_dir[0] // rigid first pass
            } else {
                previous
            };
            let mut new_surface = e;
            if in_cut && b > 0.0 {
                let chip = e - s_prev;
                if step >= steps_per_delay {
                    engaged += 1;
                }
                if chip > 0.0 {
                    contact |= 1 << (j % 64);
                    f[0] += b * chip * u[0];
                    f[1] += b * chip * u[1];
                    if cv > 0.0 {
                        let vn = n_dir[0] * v[0] + n_dir[1] * v[1];
                        f[0] -= b * cv * vn * n_dir[0];
                        f[1] -= b * cv * vn * n_dir[1];
                    }
                } else {
                    if step >= steps_per_delay {
                        lost += 1;
                    }
                    new_surface = s_prev;
                }
            } else if !previous.is_nan() {
                new_surface = s_prev.min(e);
            }
            surface[slot * edges + j] = new_surface;
        }
        if settings.harmonic_force_n > 0.0 {
            let harmonic: f64 = (1..=4)
                .map(|k| (k as f64 * omega_spindle * t + 0.7 * k as f64).cos() / k as f64)
                .sum();
            f[0] += settings.harmonic_force_n * harmonic;
            f[1] += settings.harmonic_force_n * harmonic * 0.5;
        }
        // random force, held over the step (white up to the internal rate)
        let mut r = [0.0f64; 2];
        for rc in r.iter_mut() {
            let z: f64 = StandardNormal.sample(&mut rng);
            *rc = settings.random_force_rms_n * z;
        }
        let total = [f[0] + r[0], f[1] + r[1]];
        // output at this instant
        let value = match settings.quantity {
            Quantity::Displacement => x,
            Quantity::Velocity => v,
            Quantity::Acceleration => {
                let mut a = [0.0; 2];
                for (n, md) in modes.iter().enumerate() {
                    let p = md.shape[0] * total[0] + md.shape[1] * total[1];
                    let qdd = p - 2.0 * md.zeta * md.omega * qd[n] - md.omega * md.omega * q[n];
                    a[0] += md.shape[0] * qdd;
                    a[1] += md.shape[1] * qdd;
                }
                a
            }
        };
        resampler.push(value, &mut out);
        // advance every mode exactly: the cutting and harmonic force ramps over the step with
        // the slope of the previous step (held when an edge entered, left or lost the cut), the
        // random force is held
        let smooth = previous_contact == Some(contact);
        for (n, md) in modes.iter().enumerate() {
            let p_det = md.shape[0] * f[0] + md.shape[1] * f[1];
            let p_rand = md.shape[0] * r[0] + md.shape[1] * r[1];
            let ramp = if smooth {
                p_det - previous_force[n]
            } else {
                0.0
            };
            modal_force[n] = p_det;
            let (a, g, s) = (md.phi, md.held, md.ramp);
            let (q0, v0) = (q[n], qd[n]);
            let p = p_det + p_rand;
            q[n] = a[0] * q0 + a[1] * v0 + g[0] * p + s[0] * ramp;
            qd[n] = a[2] * q0 + a[3] * v0 + g[1] * p + s[1] * ramp;
        }
        previous_force.copy_from_slice(&modal_force);
        previous_contact = Some(contact);
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
    let mut next_rev = 0.0;
    for (k, p) in pulse.iter_mut().enumerate() {
        let ts = k as f64 / settings.sample_rate_hz;
        if ts >= next_rev - 0.5 / settings.sample_rate_hz {
            *p = 1.0;
            next_rev += rev_s;
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
        lost_contact_fraction: if engaged > 0 {
            lost as f64 / engaged as f64
        } else {
            0.0
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::examples;

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
