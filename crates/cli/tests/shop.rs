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

/// The vertices of the longest `<polyline>` drawn in `stroke` (plotters writes integer pixels).
fn polyline(svg: &str, stroke: &str) -> Vec<(f64, f64)> {
    svg.split("<polyline")
        .skip(1)
        .filter(|p| p.split("/>").next().unwrap().contains(stroke))
        .map(|p| {
            let points = p
                .split("points=\"")
                .nth(1)
                .unwrap()
                .split('"')
                .next()
                .unwrap();
            points
                .split_whitespace()
                .map(|xy| {
                    let (x, y) = xy.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect::<Vec<(f64, f64)>>()
        })
        .max_by_key(|v| v.len())
        .unwrap_or_default()
}

/// The largest residual (pixels) of the least-squares line through (value, pixel).
fn affine_residual(values: &[f64], pixels: &[f64]) -> f64 {
    let n = values.len() as f64;
    let (mv, mp) = (
        values.iter().sum::<f64>() / n,
        pixels.iter().sum::<f64>() / n,
    );
    let sxy: f64 = values
        .iter()
        .zip(pixels)
        .map(|(v, p)| (v - mv) * (p - mp))
        .sum();
    let sxx: f64 = values.iter().map(|v| (v - mv).powi(2)).sum();
    let slope = sxy / sxx;
    values
        .iter()
        .zip(pixels)
        .map(|(v, p)| (p - (mp + slope * (v - mv))).abs())
        .fold(0.0, f64::max)
}

/// `lobes --plot --sle`: the SVG holds the lobe panel and under it the SLE panel, whose line is
/// the `chatter sle` CSV at the same speeds and depth. The SVG has pixels, not values: the
/// plotted x must be affine in the CSV's speeds and y affine in its SLE, within 1 pixel (plotters
/// rounds each vertex to a whole pixel, +-0.5), over a line spanning more than 100 pixels
/// vertically (so a 1-pixel residual is under 1 % of the SLE range).
#[test]
fn lobes_plot_with_the_sle_panel() {
    let model = example("schmitz2023_milling_model.json");
    let m = model.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let plot = dir.path().join("lobes.svg");
    let speeds = "6000:12000:25";
    let (code, _, err) = run(&[
        "lobes",
        "--quiet",
        "--model",
        m,
        "--speeds",
        speeds,
        "--plot",
        plot.to_str().unwrap(),
        "--sle",
        "--sle-depth-mm",
        "0.3",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.contains("Stability lobes (fdm)"), "no lobe panel");
    assert!(
        svg.contains("Surface location error at 0.3 mm"),
        "no SLE panel"
    );
    // the SLE panel lies under the lobe panel: the SVG is two 560-pixel panels high
    assert!(svg.contains("height=\"1120\""), "{}", &svg[..200]);
    let (code, csv, err) = run(&["sle", "--model", m, "--speeds", speeds, "--depth-mm", "0.3"]);
    assert_eq!(code, Some(0), "{err}");
    let rows: Vec<Vec<String>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    assert!(
        rows.iter().all(|r| r[4] == "true"),
        "every speed stable at 0.3 mm: {csv}"
    );
    let line = polyline(&svg, "#1F77B4");
    assert_eq!(line.len(), rows.len(), "one vertex per speed");
    let speed: Vec<f64> = rows.iter().map(|r| r[0].parse().unwrap()).collect();
    let sle: Vec<f64> = rows.iter().map(|r| r[1].parse().unwrap()).collect();
    let (px, py): (Vec<f64>, Vec<f64>) = line.into_iter().unzip();
    let span =
        py.iter().cloned().fold(f64::MIN, f64::max) - py.iter().cloned().fold(f64::MAX, f64::min);
    assert!(span > 100.0, "the SLE line spans {span} pixels");
    let (rx, ry) = (affine_residual(&speed, &px), affine_residual(&sle, &py));
    eprintln!("residuals: x {rx} px, y {ry} px over {span} px");
    assert!(rx <= 1.0 && ry <= 1.0, "x {rx} px, y {ry} px");

    // the default depth: half the shallowest limiting depth of the lobes
    let (code, lobes, err) = run(&[
        "lobes",
        "--quiet",
        "--model",
        m,
        "--speeds",
        speeds,
        "--plot",
        plot.to_str().unwrap(),
        "--sle",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let shallowest = lobes
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').nth(1)?.parse::<f64>().ok())
        .fold(f64::INFINITY, f64::min);
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(
        svg.contains(&format!(
            "Surface location error at {} mm",
            0.5 * shallowest
        )),
        "default depth {}",
        0.5 * shallowest
    );
    // --sle draws on the plot
    let (code, _, err) = run(&["lobes", "--model", m, "--speeds", speeds, "--sle"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("--sle is not used without --plot"), "{err}");
}

/// A probability-of-stability map as `chatter bands --map-out` writes it, made by hand: at the
/// risk P the depth at a speed is the deepest grid depth up to which P_s >= 1 - P, and the cut
/// the one with the largest depth x speed (worked out by hand below).
#[test]
fn recommend_from_a_stability_map_and_bad_evidence() {
    let model = example("schmitz2023_milling_model.json");
    let m = model.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("map.csv");
    let rows = [
        (10_000.0, [1.0, 0.97, 0.90, 0.50]),
        (11_000.0, [1.0, 0.99, 0.96, 0.60]),
    ];
    let mut text = String::from("speed_rpm,depth_mm,p_stable\n");
    for (s, ps) in rows {
        for (d, p) in ps.iter().enumerate() {
            text += &format!("{s},{d},{p}\n");
        }
    }
    std::fs::write(&map, text).unwrap();
    // (risk, speed, depth): 0.05 -> 1 mm at 10 000, 2 mm at 11 000; 0.45 -> 2 and 3 mm
    for (risk, speed, depth, p) in [("0.05", 11_000.0, 2.0, 0.96), ("0.45", 11_000.0, 3.0, 0.60)] {
        let (code, json, err) = run(&[
            "recommend",
            "--model",
            m,
            "--max-depth-mm",
            "20",
            "--bands",
            map.to_str().unwrap(),
            "--risk",
            risk,
        ]);
        assert_eq!(code, Some(0), "{err}");
        let v: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert_eq!(v["cut"]["speed_rpm"].as_f64().unwrap(), speed, "{json}");
        assert!(
            (v["cut"]["depth_mm"].as_f64().unwrap() - depth).abs() < 1e-12,
            "{json}"
        );
        assert_eq!(v["probability_of_stability"].as_f64().unwrap(), p, "{json}");
        assert_eq!(v["basis"], "Monte Carlo probability map");
    }
    // a Type B band table has no risk of its own to trade
    let type_b = dir.path().join("bands.csv");
    std::fs::write(
        &type_b,
        "speed_rpm,depth_mm,lower_mm,upper_mm,theta_deg,distance,upper_speed_rpm,upper_depth_mm,\
         lower_speed_rpm,lower_depth_mm\n10000,3,2.5,3.5,0,0,0,0,0,0\n11000,4,3.2,4.6,0,0,0,0,0,0\n",
    )
    .unwrap();
    let posterior = dir.path().join("posterior");
    std::fs::create_dir(&posterior).unwrap();
    let base = ["recommend", "--model", m, "--max-depth-mm", "20"];
    for (extra, expected) in [
        (
            vec!["--bands", type_b.to_str().unwrap(), "--risk", "0.1"],
            "--risk 0.1: the lower curve of a band table has its own risk",
        ),
        (
            vec!["--bands", map.to_str().unwrap(), "--risk", "1.5"],
            "--risk 1.5: expected a probability of chatter in (0, 1)",
        ),
        (
            vec!["--bands", map.to_str().unwrap(), "--limit-sd-percent", "5"],
            "--limit-sd-percent is not used with bands",
        ),
        (
            vec!["--posterior", posterior.to_str().unwrap()],
            "summary.json: not found",
        ),
        (
            vec![
                "--posterior",
                posterior.to_str().unwrap(),
                "--bands",
                map.to_str().unwrap(),
            ],
            "give either --posterior DIR or --bands FILE, not both",
        ),
    ] {
        let mut args = base.to_vec();
        args.extend(extra.iter().copied());
        let (code, _, err) = run(&args);
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // Type B lower boundary without a risk: the lower curve is the depth
    let (code, json, err) = run(&[
        "recommend",
        "--model",
        m,
        "--max-depth-mm",
        "20",
        "--bands",
        type_b.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert!(
        (v["cut"]["depth_mm"].as_f64().unwrap() - 3.2).abs() < 1e-12,
        "{json}"
    );
    assert!(v["risk"].is_null(), "{json}");
}
