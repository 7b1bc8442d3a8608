//! `chatter lobes` with a fixed resolution and the |mu| map, and `chatter plan` before the
//! first cut and with the likelihood widths set.
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

fn run(command: &mut Command) -> (bool, String, String) {
    let out = command.output().unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// The map's |mu| crosses 1 where the lobes say (between the map depths that bracket the
/// limit), at every speed; the heat map is written; the option errors are clear.
#[test]
fn lobes_write_a_modulus_map_consistent_with_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let (map, svg) = (dir.path().join("map.csv"), dir.path().join("map.svg"));
    let (ok, lobes, err) = run(chatter()
        .args(["lobes", "--quiet", "--method", "fdm", "--model"])
        .arg(example("schmitz2023_milling_model.json"))
        .args([
            "--speeds",
            "5000:6000:5",
            "--cutting-steps",
            "40",
            "--depths",
            "0.25:5:20",
        ])
        .arg("--map-out")
        .arg(&map)
        .arg("--map-plot")
        .arg(&svg));
    assert!(ok, "{err}");
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    let text = std::fs::read_to_string(&map).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 5 * 20);
    for line in lobes.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        let (speed, limit): (f64, f64) = (cells[0].parse().unwrap(), cells[1].parse().unwrap());
        for r in rows.iter().filter(|r| r[0] == speed) {
            if r[1] < 0.99 * limit {
                assert!(r[2] < 1.0, "{r:?} below the limit {limit}");
            } else if r[1] > 1.01 * limit {
                assert!(r[2] > 1.0, "{r:?} above the limit {limit}");
            }
        }
    }
    let (ok, _, err) = run(chatter()
        .args([
            "lobes",
            "--quiet",
            "--method",
            "zoa",
            "--cutting-steps",
            "40",
            "--model",
        ])
        .arg(example("schmitz2023_milling_model.json")));
    assert!(!ok && err.contains("--cutting-steps"), "{err}");
    // zero steps is refused where the option is read, by its name
    let (ok, _, err) = run(chatter()
        .args([
            "lobes",
            "--quiet",
            "--method",
            "fdm",
            "--cutting-steps",
            "0",
            "--model",
        ])
        .arg(example("schmitz2023_milling_model.json")));
    assert!(
        !ok && err.contains("--cutting-steps") && err.contains("'0'"),
        "{err}"
    );
    let (ok, _, err) = run(chatter()
        .args(["lobes", "--quiet", "--depths", "1:2:3", "--model"])
        .arg(example("schmitz2023_milling_model.json")));
    assert!(!ok && err.contains("--depths"), "{err}");
}

/// Before any cut, value of information plans from the prior paths of 003's flexure and writes
/// the P_s map and the sampled boundaries; a frequency width is refused with value of information (003's likelihood has none).
#[test]
fn plan_the_first_cut_from_the_prior() {
    let dir = tempfile::tempdir().unwrap();
    let (map_path, boundaries_path) = (dir.path().join("map.csv"), dir.path().join("paths.csv"));
    let (ok, out, err) = run(chatter()
        .args([
            "plan",
            "--quiet",
            "--strategy",
            "voi",
            "--paths",
            "30",
            "--model",
        ])
        .arg(example("karandikar_flexure_model.json"))
        .args([
            "--speeds",
            "400:2000:5",
            "--depths",
            "0.5:7.5:15",
            "--sigma-depth-mm",
            "0.25",
            "--map-out",
        ])
        .arg(&map_path)
        .arg("--boundaries-out")
        .arg(&boundaries_path));
    assert!(ok, "{err}");
    let plan: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(plan["cuts_used"], 0);
    // the P_s map, recomputed from the exported boundaries: the probability of the paths whose
    // limit lies above the depth (empty depth: no boundary below the ceiling), non-increasing
    // in depth, on the 5 speeds x 15 depths asked
    let rows = |path: &std::path::Path| -> Vec<Vec<String>> {
        std::fs::read_to_string(path)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect()
    };
    let number = |s: &str| -> f64 { s.parse().unwrap_or(f64::INFINITY) };
    let boundaries = rows(&boundaries_path);
    assert_eq!(boundaries.len(), 30 * 5);
    let total: f64 = boundaries
        .iter()
        .filter(|r| r[2] == boundaries[0][2])
        .map(|r| number(&r[1]))
        .sum();
    assert!((total - 1.0).abs() < 1e-9, "{total}");
    let map = rows(&map_path);
    assert_eq!(map.len(), 5 * 15);
    let mut last = (String::new(), f64::INFINITY);
    for r in &map {
        let (depth_mm, p) = (number(&r[1]), number(&r[2]));
        let recomputed: f64 = boundaries
            .iter()
            .filter(|b| b[2] == r[0] && depth_mm < number(&b[3]))
            .map(|b| number(&b[1]))
            .sum();
        assert!((p - recomputed).abs() < 1e-9, "{r:?}: {recomputed}");
        if r[0] == last.0 {
            assert!(p <= last.1 + 1e-12, "P_s rises with depth at {r:?}");
        }
        last = (r[0].clone(), p);
    }
    assert!(
        plan["next_cut"]["expected_reduction_percent"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    let (ok, _, err) = run(chatter()
        .args([
            "plan",
            "--quiet",
            "--strategy",
            "voi",
            "--sigma-chatter-hz",
            "20",
            "--model",
        ])
        .arg(example("karandikar_flexure_model.json")));
    assert!(!ok && err.contains("--sigma-chatter-hz"), "{err}");
}
