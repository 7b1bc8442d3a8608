//! `chatter sle` and `chatter recommend` on the seed-001 example, and their bad input.
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

fn run(args: &[&str]) -> (Option<i32>, String, String) {
    let out = chatter().args(args).output().unwrap();
    (
        out.status.code(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

#[test]
fn sle_writes_one_row_per_speed() {
    let model = example("schmitz2023_milling_model.json");
    let dir = tempfile::tempdir().unwrap();
    let plot = dir.path().join("sle.svg");
    let (code, csv, err) = run(&[
        "sle",
        "--model",
        model.to_str().unwrap(),
        "--speeds",
        "6000:12000:7",
        "--depth-mm",
        "0.4",
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0],
        "speed_rpm,sle_um,peak_to_valley_um,modulus,stable"
    );
    assert_eq!(lines.len(), 8);
    for line in &lines[1..] {
        let v: Vec<&str> = line.split(',').collect();
        assert_eq!(v.len(), 5, "{line}");
        assert!(v[1].parse::<f64>().unwrap().is_finite());
        assert!(v[2].parse::<f64>().unwrap() >= 0.0);
    }
    assert!(std::fs::read_to_string(&plot).unwrap().contains("<svg"));
}

#[test]
fn recommend_proposes_the_pocket_and_the_harmonizer_speeds() {
    let model = example("schmitz2023_milling_model.json");
    let (code, json, err) = run(&[
        "recommend",
        "--model",
        model.to_str().unwrap(),
        "--max-depth-mm",
        "20",
        "--sle-tolerance-um",
        "50",
        "--chatter-speed-rpm",
        "7000",
        "--chatter-hz",
        "772",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let speed = v["cut"]["speed_rpm"].as_f64().unwrap();
    assert!((speed / 11_300.0 - 1.0).abs() < 0.03, "{json}");
    assert!(!v["cut"]["reasons"].as_array().unwrap().is_empty());
    let speeds = v["harmonizer"]["speeds"].as_array().unwrap();
    // 772 Hz / (4 x 7000 / 60 Hz) = 1.65: harmonics 1 and 2, 11 580 and 5790 rpm
    assert_eq!(speeds.len(), 2);
    assert!((speeds[0]["speed_rpm"].as_f64().unwrap() - 11_580.0).abs() < 1e-6);
    assert!((speeds[1]["speed_rpm"].as_f64().unwrap() - 5790.0).abs() < 1e-6);
}

#[test]
fn bad_input_names_the_option() {
    let model = example("schmitz2023_milling_model.json");
    let m = model.to_str().unwrap();
    for (args, expected) in [
        (
            vec![
                "sle",
                "--model",
                m,
                "--speeds",
                "6000:12000:7",
                "--depth-mm",
                "-1",
            ],
            "--depth-mm",
        ),
        (
            vec![
                "recommend",
                "--model",
                m,
                "--max-depth-mm",
                "5",
                "--risk",
                "0.9",
            ],
            "--risk 0.9",
        ),
        (
            vec![
                "recommend",
                "--model",
                m,
                "--max-depth-mm",
                "5",
                "--chatter-hz",
                "700",
            ],
            "--chatter-hz needs --chatter-speed-rpm",
        ),
        (
            vec![
                "recommend",
                "--model",
                m,
                "--max-depth-mm",
                "5",
                "--sle-tolerance-um",
                "0",
            ],
            "--sle-tolerance-um 0",
        ),
    ] {
        let (code, _, err) = run(&args);
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// A variable-pitch model file runs through `lobes` with fdm, sdm (one delay per tooth) and zoa
/// (the pitch-averaged regeneration) and is refused by name by `sle`.
#[test]
fn variable_pitch_model_file() {
    let model = example("variable_pitch_milling_model.json");
    let m = model.to_str().unwrap();
    for method in ["fdm", "sdm"] {
        let (code, csv, err) = run(&[
            "lobes",
            "--quiet",
            "--model",
            m,
            "--method",
            method,
            "--speeds",
            "9000:11000:3",
        ]);
        assert_eq!(code, Some(0), "{err}");
        assert_eq!(csv.lines().count(), 4, "{csv}");
    }
    // the zero-order method searches the variable pitch (Altintas, Engin & Budak 1999)
    let (code, csv, err) = run(&[
        "lobes",
        "--quiet",
        "--model",
        m,
        "--method",
        "zoa",
        "--speeds",
        "9000:11000:3",
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(csv.lines().count(), 4, "{csv}");
    let (code, _, err) = run(&[
        "sle",
        "--model",
        m,
        "--speeds",
        "9000:11000:3",
        "--depth-mm",
        "1",
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("operation.pitch_deg"), "{err}");
}

/// `multiplier` with a spindle-speed variation: the multiplier over the modulation period; at
/// zero amplitude the constant-speed one; an amplitude of 1 is refused by name.
#[test]
fn multiplier_with_speed_variation() {
    let model = example("ahmadi2022_turning_model.json");
    let m = model.to_str().unwrap();
    let base = [
        "multiplier",
        "--model",
        m,
        "--speed-rpm",
        "7000",
        "--depth-mm",
        "3",
    ];
    let (code, plain, err) = run(&base);
    assert_eq!(code, Some(0), "{err}");
    let plain: serde_json::Value = serde_json::from_str(&plain).unwrap();
    let with = |a: &str| {
        let mut args = base.to_vec();
        args.extend(["--ssv-amplitude-ratio", a, "--ssv-frequency-ratio", "0.2"]);
        run(&args)
    };
    let (code, zero, err) = with("0");
    assert_eq!(code, Some(0), "{err}");
    let zero: serde_json::Value = serde_json::from_str(&zero).unwrap();
    assert_eq!(zero["modulus"], plain["modulus"]);
    let (code, varied, err) = with("0.1");
    assert_eq!(code, Some(0), "{err}");
    let varied: serde_json::Value = serde_json::from_str(&varied).unwrap();
    assert!(varied["period_s"].as_f64().unwrap() > 4.9 * 60.0 / 7000.0);
    let (code, _, err) = with("1");
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("ssv_amplitude_ratio"), "{err}");
}
