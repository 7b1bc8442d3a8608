//! Reference figures of the time-domain simulator (deterministic cuts: no random force):
//! the dominant Floquet multiplier of stable cuts measured from the start-up transient against
//! the full discretization, and the limit cycle of chattering cuts (RMS, dominant tone, lost
//! contact). The 001 cuts lose contact near the zero-thickness exit, so their fitted multiplier
//! is a figure to compare between steps, not with the full discretization. Run with a temporary
//! `MIN_STEPS_PER_TOOTH` (e.g. 8000) for the converged figures.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::ModalModel;
use chatter_dynamics::examples::{
    ahmadi_2022_turning, ebrahimi_2025_milling, schmitz_2023_milling,
};
use chatter_dynamics::simulate::{Quantity, SimulationSettings, simulate};
use chatter_stability::monodromy::Discretization;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;
use std::time::Instant;

/// Multiplier from samples taken once per delay: d_k = s_{k+1} - s_k obeys
/// d_{k+2} = a d_{k+1} + b d_k for the dominant pair; least squares over every channel.
fn fit_multiplier(seqs: &[Vec<f64>]) -> Complex64 {
    let (mut s11, mut s12, mut s22, mut r1, mut r2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for s in seqs {
        let d: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
        for w in d.windows(3) {
            let (x1, x2, y) = (w[1], w[0], w[2]);
            s11 += x1 * x1;
            s12 += x1 * x2;
            s22 += x2 * x2;
            r1 += x1 * y;
            r2 += x2 * y;
        }
    }
    let det = s11 * s22 - s12 * s12;
    let a = (r1 * s22 - r2 * s12) / det;
    let b = (s11 * r2 - s12 * r1) / det;
    let disc = Complex64::new(a * a + 4.0 * b, 0.0).sqrt();
    let z1 = (Complex64::new(a, 0.0) + disc) / 2.0;
    let z2 = (Complex64::new(a, 0.0) - disc) / 2.0;
    let z = if z1.norm() >= z2.norm() { z1 } else { z2 };
    if z.im < 0.0 { z.conj() } else { z }
}

fn stable(
    name: &str,
    model: &ModalModel,
    rpm: f64,
    depth_mm: f64,
    per_delay: usize,
    k: (usize, usize),
) {
    let tau = model.operation().delay_s(rpm);
    let fs = per_delay as f64 / tau;
    let dur = (k.1 + 3) as f64 * tau;
    let mut s = SimulationSettings::new(rpm, depth_mm * 1e-3, dur, fs, 1);
    s.quantity = Quantity::Displacement;
    s.random_force_rms_n = 0.0;
    let t0 = Instant::now();
    let sim = simulate(model, &s).unwrap();
    let el = t0.elapsed().as_secs_f64();
    let seqs: Vec<Vec<f64>> = sim.channels[..2]
        .iter()
        .filter(|c| c.data.iter().any(|v| *v != 0.0))
        .map(|c| (k.0..k.1).map(|i| c.data[i * per_delay]).collect())
        .collect();
    let mu = fit_multiplier(&seqs);
    let reference = Discretization::full()
        .monodromy(model, rpm, depth_mm * 1e-3)
        .unwrap()
        .dominant_eigenvalue()
        .unwrap();
    let reference = if reference.im < 0.0 {
        reference.conj()
    } else {
        reference
    };
    println!(
        "{name:28} simulated mu |{:.5}| arg {:.5}   monodromy |{:.5}| arg {:.5}   d|mu| {:+.5}  lost {:.5}  ({el:.2} s)",
        mu.norm(),
        mu.arg(),
        reference.norm(),
        reference.arg(),
        mu.norm() - reference.norm(),
        sim.lost_contact_fraction
    );
}

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// Peak of the Hann-windowed spectrum: (frequency by parabolic interpolation, amplitude).
fn peak(x: &[f64], fs: f64) -> (f64, f64) {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let mut buf: Vec<Complex64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
            Complex64::new((v - mean) * w, 0.0)
        })
        .collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let mag: Vec<f64> = buf[..n / 2].iter().map(|c| c.norm()).collect();
    let (i, _) = mag
        .iter()
        .enumerate()
        .skip(2)
        .max_by(|a, b| a.1.total_cmp(b.1))
        .unwrap();
    let (a, b, c) = (mag[i - 1].ln(), mag[i].ln(), mag[i + 1].ln());
    let d = 0.5 * (a - c) / (a - 2.0 * b + c);
    ((i as f64 + d) * fs / n as f64, 4.0 * mag[i] / n as f64)
}

fn chatter(name: &str, model: &ModalModel, rpm: f64, depth_mm: f64, fs: f64, dur: f64) {
    let mut s = SimulationSettings::new(rpm, depth_mm * 1e-3, dur, fs, 1);
    s.quantity = Quantity::Displacement;
    s.random_force_rms_n = 0.0;
    let t0 = Instant::now();
    let sim = simulate(model, &s).unwrap();
    let el = t0.elapsed().as_secs_f64();
    let x = &sim.channels[0].data;
    let tail = &x[x.len() / 2..];
    let (f, a) = peak(tail, fs);
    println!(
        "{name:28} rms(x) {:.5e}  peak {f:.2} Hz amp {a:.5e}  lost {:.5}  ({el:.2} s)",
        rms(tail),
        sim.lost_contact_fraction
    );
}

fn noisy(name: &str, model: &ModalModel, rpm: f64, depth_mm: f64, random: f64, quantity: Quantity) {
    let mut s = SimulationSettings::new(rpm, depth_mm * 1e-3, 1.0, 50_000.0, 1);
    s.random_force_rms_n = random;
    s.quantity = quantity;
    let t0 = Instant::now();
    let sim = simulate(model, &s).unwrap();
    let el = t0.elapsed().as_secs_f64();
    let x = &sim.channels[0].data;
    let scale = if quantity == Quantity::Displacement {
        1e6
    } else {
        1.0
    };
    println!(
        "{name:28} rms x {:.5e} rms y {:.5e}  lost {:.5}  ({el:.3} s)",
        rms(&x[x.len() / 5..]) * scale,
        rms(&sim.channels[1].data[x.len() / 5..]) * scale,
        sim.lost_contact_fraction
    );
}

fn main() {
    let m001 = schmitz_2023_milling();
    let m002 = ebrahimi_2025_milling();
    let m000 = ahmadi_2022_turning();
    stable("002 2500 rpm 1.0 mm", &m002, 2500.0, 1.0, 50, (8, 90));
    stable("002 2500 rpm 0.5 mm", &m002, 2500.0, 0.5, 50, (8, 90));
    stable("001 7000 rpm 0.5 mm", &m001, 7000.0, 0.5, 20, (3, 60));
    stable("001 7000 rpm 1.0 mm", &m001, 7000.0, 1.0, 20, (3, 60));
    chatter(
        "001 7000 rpm 2.0 mm chatter",
        &m001,
        7000.0,
        2.0,
        20_000.0,
        1.0,
    );
    chatter(
        "000 7150 rpm 5.0 mm chatter",
        &m000,
        7150.0,
        5.0,
        20_000.0,
        1.0,
    );
    noisy(
        "bench 001 7000 rpm 0.5 mm",
        &m001,
        7000.0,
        0.5,
        1.0,
        Quantity::Acceleration,
    );
    noisy(
        "bench 000 7150 rpm 2 mm",
        &m000,
        7150.0,
        2.0,
        1.0,
        Quantity::Acceleration,
    );
    noisy(
        "001 0.5 mm acc no random",
        &m001,
        7000.0,
        0.5,
        0.0,
        Quantity::Acceleration,
    );
    noisy(
        "001 0.5 mm disp (x1e6)",
        &m001,
        7000.0,
        0.5,
        1.0,
        Quantity::Displacement,
    );
}
