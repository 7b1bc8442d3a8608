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
use std::time::Instant;

#[path = "../transient.rs"]
mod transient;
use transient::{deterministic, fit_multiplier, peak, rms, upper};

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
    let s = deterministic(rpm, depth_mm * 1e-3, dur, fs);
    let t0 = Instant::now();
    let sim = simulate(model, &s).unwrap();
    let el = t0.elapsed().as_secs_f64();
    let seqs: Vec<Vec<f64>> = sim.channels[..2]
        .iter()
        .filter(|c| c.data.iter().any(|v| *v != 0.0))
        .map(|c| (k.0..k.1).map(|i| c.data[i * per_delay]).collect())
        .collect();
    let mu = fit_multiplier(&seqs);
    let reference = upper(
        Discretization::full()
            .monodromy(model, rpm, depth_mm * 1e-3)
            .unwrap()
            .dominant_eigenvalue()
            .unwrap(),
    );
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

fn chatter(name: &str, model: &ModalModel, rpm: f64, depth_mm: f64, fs: f64, dur: f64) {
    let s = deterministic(rpm, depth_mm * 1e-3, dur, fs);
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
