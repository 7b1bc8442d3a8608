//! `chatter rcsa` on the example assembly, and a bad assembly file.
#![allow(clippy::unwrap_used)]

use std::process::Command;

fn example() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/schmitz2022_rcsa_assembly.json")
}

#[test]
fn rcsa_writes_the_tip_frf_csv_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, svg) = (dir.path().join("tip.csv"), dir.path().join("tip.svg"));
    let out = Command::new(env!("CARGO_BIN_EXE_chatter"))
        .args(["rcsa", "--assembly"])
        .arg(example())
        .arg("--out")
        .arg(&csv)
        .arg("--plot")
        .arg(&svg)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("frequency_hz,real_m_per_n,imag_m_per_n,magnitude_m_per_n")
    );
    assert_eq!(lines.count(), 300);
    assert!(std::fs::metadata(&svg).unwrap().len() > 1000);
}

#[test]
fn rcsa_names_the_bad_field() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.json");
    let text = std::fs::read_to_string(example()).unwrap().replacen(
        "\"length_mm\": 26.0",
        "\"length_mm\": -26.0",
        1,
    );
    std::fs::write(&path, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_chatter"))
        .args(["rcsa", "--assembly"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.json") && err.contains("tool[0].length_mm") && err.contains("-26"),
        "{err}"
    );
}
