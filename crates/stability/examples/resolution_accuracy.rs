//! Limiting-depth error (%) of FDM and SDM against a converged reference over the single-DOF
//! benchmark (full immersion, 5000-21 000 rpm) and the process-damping flexure (300-1000 rpm):
//! at the automatic resolution m, at 2m, and the prepared solvers ([`Method::prepare`], which
//! extrapolate from m and 2m). The reference is the semi-discretization (full discretization with
//! process damping) at max(1600, 240 steps per vibration cycle), scanned from zero depth to 1e-6
//! (at 5500 and 8500 rpm, 400 steps were still 0.3 % and 0.14 % off).
//!
//! `cargo run --release -p chatter-stability --example resolution_accuracy`

use chatter_dynamics::{ModalModel, Operation, examples};
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::monodromy::{AUTO_MIN_STEPS, Discretization, steps, steps_at_least};
use chatter_stability::prepared::Method;
use std::f64::consts::PI;

fn depth(d: Discretization, model: &ModalModel, rpm: f64, tol: f64) -> f64 {
    let options = BoundaryOptions {
        relative_tolerance: tol,
        ..Default::default()
    };
    limiting_depth(&d, model, rpm, &options).map_or(f64::NAN, |p| p.depth_m)
}

fn main() {
    let cases: Vec<(&str, ModalModel, Vec<f64>)> = vec![
        (
            "single-DOF benchmark, full immersion",
            examples::insperger_benchmark(1.0),
            (0..=32).map(|i| 5000.0 + 500.0 * i as f64).collect(),
        ),
        (
            "flexure, C = 2.5e5 N/m",
            examples::process_damping_flexure(Some(2.5e5)),
            vec![300.0, 400.0, 600.0, 1000.0],
        ),
    ];
    for (name, model, speeds) in cases {
        let Operation::Milling(op) = model.operation() else {
            continue;
        };
        let f_max = model
            .modes()
            .iter()
            .map(|m| m.frequency_hz())
            .fold(0.0, f64::max);
        println!("{name}");
        println!(
            "| rpm | m | reference (mm) | FDM m | FDM 2m | FDM prepared | SDM m | SDM 2m | SDM prepared |"
        );
        let (mut worst_fdm, mut worst_sdm) = ([0.0f64; 3], [0.0f64; 3]);
        for rpm in speeds {
            let (entry, exit) = op.entry_exit_rad();
            let cutting_s = (exit - entry) / (2.0 * PI) * 60.0 / rpm;
            let m_ref =
                steps_at_least((240.0 * f_max * cutting_s).ceil() as usize, steps::<1600>());
            let reference_scheme = if model.process_damping_n_per_m().is_some() {
                Discretization::full()
            } else {
                Discretization::semi()
            };
            let reference = depth(reference_scheme.with_steps(m_ref), &model, rpm, 1e-6);
            let mut line = String::new();
            let mut m_auto = AUTO_MIN_STEPS;
            for (method, worst) in [(Method::Fdm, &mut worst_fdm), (Method::Sdm, &mut worst_sdm)] {
                let scheme = method.discretization().unwrap_or_else(Discretization::full);
                m_auto = scheme.steps_at(&model, rpm);
                let b1 = depth(scheme.with_steps(m_auto), &model, rpm, 1e-4);
                let b2 = depth(
                    scheme.with_steps(m_auto.saturating_mul(steps::<2>())),
                    &model,
                    rpm,
                    1e-4,
                );
                let prepared = method
                    .prepare(&model, &BoundaryOptions::default())
                    .and_then(|p| p.limiting_depth(rpm))
                    .map_or(f64::NAN, |p| p.depth_m);
                for (k, b) in [b1, b2, prepared].into_iter().enumerate() {
                    let e = 100.0 * (b - reference) / reference;
                    worst[k] = worst[k].max(e.abs());
                    line += &format!(" {e:+.3} |");
                }
            }
            println!("| {rpm:.0} | {m_auto} | {:.5} |{line}", reference * 1e3);
        }
        println!("worst |error| %: FDM {worst_fdm:.3?}, SDM {worst_sdm:.3?}");
    }
}
