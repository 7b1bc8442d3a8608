//! The built `chatter` binary on the example files.
#![allow(clippy::unwrap_used)]

use std::path::PathBuf;
use std::process::Command;

fn chatter() -> Command {
    Command::new(env!("CARGO_BIN_EXE_chatter"))
}

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
}

#[test]
fn frf_csv_has_header_and_rows() {
    let out = chatter()
        .args(["frf", "--points", "50", "--model"])
        .arg(example("schmitz2023_milling_model.json"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "frequency_hz,real_m_per_n,imag_m_per_n,magnitude_m_per_n"
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 50);
    // static compliance 1/k at 0 Hz
    let first: Vec<f64> = rows[0].split(',').map(|v| v.parse().unwrap()).collect();
    assert!((first[1] - 1.0 / 3.0e6).abs() < 1e-15);
}

#[test]
fn lobes_and_multiplier() {
    let out = chatter()
        .args([
            "lobes",
            "--quiet",
            "--method",
            "zoa",
            "--speeds",
            "5000:12000:15",
            "--model",
        ])
        .arg(example("schmitz2023_milling_model.json"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("speed_rpm,depth_mm,chatter_hz\n"));
    assert_eq!(text.lines().count(), 16);
    let out = chatter()
        .args([
            "multiplier",
            "--speed-rpm",
            "7150",
            "--depth-mm",
            "2.286",
            "--model",
        ])
        .arg(example("ahmadi2022_turning_model.json"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let modulus = json["modulus"].as_f64().unwrap();
    assert!(
        modulus > 0.0 && modulus < 1.0,
        "P1 of seed 000 is a stable cut: {modulus}"
    );
    assert_eq!(json["kind"], "hopf");
    let chatter_hz = json["chatter_hz"].as_f64().unwrap();
    assert!((chatter_hz - 2473.0).abs() < 0.03 * 2473.0);
}

#[test]
fn simulate_writes_csv_and_wav() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["sig.csv", "sig.wav"] {
        let path = dir.path().join(name);
        let out = chatter()
            .args([
                "simulate",
                "--quiet",
                "--speed-rpm",
                "7150",
                "--depth-mm",
                "1",
                "--duration-s",
                "0.2",
            ])
            .args(["--sample-rate-hz", "10000", "--seed", "3", "--model"])
            .arg(example("ahmadi2022_turning_model.json"))
            .arg("--out")
            .arg(&path)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        if name.ends_with(".wav") {
            let reader = hound::WavReader::open(&path).unwrap();
            assert_eq!(reader.spec().channels, 3);
            assert_eq!(reader.spec().sample_rate, 10000);
            assert_eq!(reader.len(), 3 * 2000);
        } else {
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(text.starts_with("feed,cutting,once_per_rev\n"));
            assert_eq!(text.lines().count(), 2001);
        }
    }
}

#[test]
fn demo_writes_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = chatter()
        .args(["demo", "--quiet", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "turning_lobes.csv",
        "turning_lobes.svg",
        "milling_bands.svg",
        "eq34_covariance.json",
        "turning_credibility.csv",
        "turning_credibility.svg",
        "summary.json",
    ] {
        assert!(dir.path().join(f).exists(), "{f} missing");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["turning_limits"].as_array().unwrap().len(), 4);
}

#[test]
fn bad_input_is_a_clear_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json");
    std::fs::write(
        &bad,
        r#"{"operation":{"kind":"milling","teeth":4,"radial_immersion":1.5,"direction":"down"},"cutting":{"kt_n_per_mm2":1,"kn_n_per_mm2":1},"modes":[{"frequency_hz":1,"damping_ratio":0.1,"stiffness_n_per_m":1,"direction":"x"}]}"#,
    )
    .unwrap();
    let out = chatter()
        .args(["check", "--model"])
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("bad.json") && err.contains("radial_immersion"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    let out = chatter()
        .args(["lobes", "--speeds", "1:2", "--model"])
        .arg(example("schmitz2023_milling_model.json"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8(out.stderr).unwrap().contains("MIN:MAX:N"));
    let missing = chatter()
        .args(["check", "--model", "/nonexistent/model.json"])
        .output()
        .unwrap();
    assert_eq!(missing.status.code(), Some(1));
}

/// The Eq. 34 covariance of seed 000 as a covariance file (formats: README, `bands`).
fn eq34_covariance(dir: &std::path::Path) -> PathBuf {
    let path = dir.join("eq34.json");
    std::fs::write(
        &path,
        r#"{"parameter_names": ["theta_omega_2", "theta_zeta_2", "theta_phi_2"],
            "covariance": [[3.5e-7, -2.9e-5, -1.5e-5], [-2.9e-5, 0.0042, 0.0019], [-1.5e-5, 0.0019, 9.4e-4]]}"#,
    )
    .unwrap();
    path
}

fn csv_rows(text: &str) -> Vec<Vec<Option<f64>>> {
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().ok()).collect())
        .collect()
}

/// Perturbation bands of the turning case: lower <= mean <= upper where all exist, and the
/// stable cut 7150 rpm / 2.286 mm lies below the lower bound (seed 000, Eq. 34).
#[test]
fn perturbation_bands_bracket_the_mean() {
    let dir = tempfile::tempdir().unwrap();
    let cov = eq34_covariance(dir.path());
    let plot = dir.path().join("bands.svg");
    let out = chatter()
        .args([
            "bands",
            "--quiet",
            "--kind",
            "perturbation",
            "--speeds",
            "7150:7500:3",
            "--depths",
            "1.5:4:26",
            "--covariance",
        ])
        .arg(&cov)
        .arg("--model")
        .arg(example("ahmadi2022_turning_model.json"))
        .arg("--plot")
        .arg(&plot)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("speed_rpm,depth_mm,lower_mm,upper_mm\n"), "{text}");
    let rows = csv_rows(&text);
    assert_eq!(rows.len(), 3);
    for r in &rows {
        if let (Some(lo), Some(mean), Some(up)) = (r[2], r[1], r[3]) {
            assert!(lo < mean && mean < up, "{r:?}");
        }
    }
    assert!(rows[0][2].unwrap() > 2.286, "{:?}", rows[0]);
    assert!(plot.exists());
}

/// Monte Carlo bands: quantile bounds ordered, the probability map written and within [0, 1];
/// without a distribution the command fails with a message naming both options.
#[test]
fn montecarlo_bands_and_map() {
    let dir = tempfile::tempdir().unwrap();
    let cov = eq34_covariance(dir.path());
    let map = dir.path().join("map.csv");
    let out = chatter()
        .args([
            "bands",
            "--quiet",
            "--kind",
            "montecarlo",
            "--samples",
            "24",
            "--seed",
            "3",
            "--speeds",
            "7150:7500:2",
            "--depths",
            "1:4:7",
            "--covariance",
        ])
        .arg(&cov)
        .arg("--model")
        .arg(example("ahmadi2022_turning_model.json"))
        .arg("--map-out")
        .arg(&map)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("speed_rpm,depth_mm,lower_mm,upper_mm,chatter_hz_q05"));
    for r in csv_rows(&text) {
        let (q50, q05, q95) = (r[1].unwrap(), r[2].unwrap(), r[3].unwrap());
        assert!(q05 <= q50 && q50 <= q95, "{r:?}");
    }
    let grid = std::fs::read_to_string(&map).unwrap();
    assert!(grid.starts_with("speed_rpm,depth_mm,p_stable\n"));
    let rows = csv_rows(&grid);
    assert_eq!(rows.len(), 2 * 7);
    assert!(rows.iter().all(|r| (0.0..=1.0).contains(&r[2].unwrap())));
    let out = chatter()
        .args(["bands", "--kind", "montecarlo", "--model"])
        .arg(example("ahmadi2022_turning_model.json"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("--posterior") && err.contains("--covariance"), "{err}");
}
