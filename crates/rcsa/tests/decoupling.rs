//! Coupling then decoupling (Eq. 3 then Eq. 1) returns the input spindle receptances, directly
//! and through an assembly file whose artifact tap test is written as `chatter frf` CSV files.
#![allow(clippy::unwrap_used)]

use chatter_frf::{Frf, text::to_csv};
use chatter_rcsa::{
    Assembly, Connection, Receptance, SampledReceptance, Segment, Spindle, couple,
    free_free_receptances, frequency_band,
};
use num_complex::Complex64;

/// A spindle-machine receptance independent of the beam code: three modes with shapes
/// [1, theta_r] (m, rad per unit modal displacement), S = sum v v^T / (k_r (1 - r^2 + 2 i zeta r)).
fn spindle(f: f64) -> Receptance {
    let modes = [
        (700.0, 0.04, 4e7, 12.0),
        (1500.0, 0.03, 6e7, -25.0),
        (3100.0, 0.05, 1.5e8, 40.0),
    ];
    modes
        .iter()
        .fold(Receptance::zeros(), |acc, &(fr, z, k, th)| {
            let r = f / fr;
            let d = Complex64::new(k * (1.0 - r * r), k * 2.0 * z * r);
            let c = |x: f64| Complex64::new(x, 0.0) / d;
            acc + Receptance::new(c(1.0), c(th), c(th), c(th * th))
        })
}

/// The standard artifact: a steel cylinder, 19.05 mm diameter, 76.2 mm long (as in Schmitz and
/// Smith's spindle identification).
fn artifact() -> Vec<Segment> {
    vec![Segment::steel(76.2, 19.05, 0.0)]
}

fn rel(a: &Receptance, b: &Receptance) -> f64 {
    (a - b).norm() / b.norm()
}

/// The artifact's tip receptances coupled to the true spindle at frequencies `f` (what a tap
/// test of the artifact measures).
fn artifact_on_spindle(f: &[f64]) -> Vec<Receptance> {
    f.iter()
        .map(|&f| {
            couple(
                &free_free_receptances(&artifact(), f).unwrap(),
                &spindle(f),
                &Receptance::zeros(),
                f,
            )
            .unwrap()
        })
        .collect()
}

#[test]
fn decoupling_returns_the_spindle_within_1e_8() {
    let f = frequency_band(50.0, 5000.0, 991).unwrap();
    let g = artifact_on_spindle(&f);
    let measured = SampledReceptance::new(f.clone(), g).unwrap();
    let Spindle::Sampled(back) = Spindle::from_artifact(&artifact(), &measured).unwrap() else {
        panic!("a sampled spindle")
    };
    let worst = f
        .iter()
        .zip(back.values())
        .map(|(&f, b)| rel(b, &spindle(f)))
        .fold(0.0, f64::max);
    println!("coupling then decoupling: largest relative error {worst:.2e}");
    assert!(worst < 1e-8, "{worst}");
}

#[test]
fn an_assembly_file_with_an_artifact_gives_the_tip_frf_of_the_true_spindle() {
    let dir = tempfile::tempdir().unwrap();
    let f = frequency_band(50.0, 5000.0, 496).unwrap();
    let g = artifact_on_spindle(&f);
    for (name, (i, j)) in [("h", (0, 0)), ("l", (0, 1)), ("p", (1, 1))] {
        let frf = Frf::new(f.clone(), g.iter().map(|g| g[(i, j)]).collect()).unwrap();
        std::fs::write(
            dir.path().join(format!("artifact_{name}.csv")),
            to_csv(&frf),
        )
        .unwrap();
    }
    let carbide = r#"{"length_mm": 65, "outer_diameter_mm": 10.2, "youngs_modulus_gpa": 585,
        "density_kg_per_m3": 14500, "poisson_ratio": 0.22, "loss_factor": 0.002}"#;
    let holder = r#"{"length_mm": 50, "outer_diameter_mm": 32, "inner_diameter_mm": 12.7,
        "youngs_modulus_gpa": 200, "density_kg_per_m3": 7800, "poisson_ratio": 0.29}"#;
    let artifact_json = serde_json::to_string(&artifact()).unwrap();
    let text = format!(
        r#"{{"tool": [{carbide}], "holder": [{holder}],
            "connection": {{"k_n_per_rad": 3e6, "c_n_s_per_rad": 15, "k_n_per_m": 5e8}},
            "spindle": {{"artifact": {{"segments": {artifact_json},
                "tip_frf": {{"h": {{"file": "artifact_h.csv"}}, "l": {{"file": "artifact_l.csv"}},
                             "p": {{"file": "artifact_p.csv"}}}}}}}},
            "fmin_hz": 100, "fmax_hz": 4000, "points": 391}}"#
    );
    let path = dir.path().join("assembly.json");
    std::fs::write(&path, text).unwrap();
    let a = Assembly::from_path(&path).unwrap();
    let truth = Assembly {
        spindle: Spindle::Rigid,
        ..a.clone()
    };
    // the decoupled spindle is linear between the grid points of the tap test, so compare on
    // that grid (every 10 Hz): the predicted tip against the tip on the true spindle
    let mut worst = 0.0f64;
    for &f in a.frequencies_hz.iter() {
        let with_true = {
            let holder = free_free_receptances(&truth.holder, f).unwrap();
            let base = couple(&holder, &spindle(f), &Receptance::zeros(), f).unwrap();
            let tool = free_free_receptances(&truth.tool, f).unwrap();
            let joint = truth.connection.compliance(2.0 * std::f64::consts::PI * f);
            couple(&tool, &base, &joint, f).unwrap()
        };
        worst = worst.max(rel(&a.tool_tip_receptance(f).unwrap(), &with_true));
    }
    println!("tip via the decoupled artifact vs the true spindle: {worst:.2e}");
    assert!(worst < 1e-8, "{worst}");
    assert!(matches!(a.connection, Connection::Flexible(_)));
}
