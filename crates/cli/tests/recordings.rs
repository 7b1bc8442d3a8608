//! `chatter diagnose` on recordings only, in one command: records simulated in the time domain
//! (`chatter_jobs::recordings::write_simulated_records`) on a one-mode lathe, two stable (0.4
//! and 0.5 of the full discretization's limiting width), one chattering (1.8 of it) and one
//! malformed file. The report JSON, `diagnosis.json` and the `--report` page hold the table of
//! records: verdicts against the truth, the poles of the stable records within 1 % in
//! frequency of the rightmost characteristic root (000 Eq. 5-6), and the malformed record with
//! its reason. The library test `crates/jobs/tests/recordings.rs` checks a larger campaign.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::simulate::SimulationSettings;
use chatter_dynamics::{
    CuttingCoefficients, ModalModel, Mode, ModeShape, ModelFile, Observations, Operation,
    SignalRecord, Turning,
};
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::frequency_domain::dominant_pole;
use chatter_stability::monodromy::Discretization;
use std::process::Command;

/// A lathe with one 700 Hz mode (damping ratio 0.03, 3e7 N/m) at 30 degrees between feed and
/// cutting directions, kt 1500 and kn 600 N/mm^2.
fn lathe() -> ModalModel {
    let a = 2.0 * std::f64::consts::PI * 700.0 / 3e7f64.sqrt();
    let t = 30f64.to_radians();
    ModalModel::new(
        Some("one-mode lathe".into()),
        Operation::Turning(Turning::new(Some(0.05)).unwrap()),
        CuttingCoefficients::new(1500e6, 600e6).unwrap(),
        vec![
            Mode::new(
                700.0,
                0.03,
                ModeShape::MassNormalized([a * t.cos(), a * t.sin()]),
            )
            .unwrap(),
        ],
        None,
    )
    .unwrap()
}

#[test]
fn diagnose_reads_recordings_and_reports_every_record() {
    let dir = tempfile::tempdir().unwrap();
    let model = lathe();
    let model_path = dir.path().join("model.json");
    std::fs::write(
        &model_path,
        serde_json::to_string_pretty(&ModelFile::from_model(&model)).unwrap(),
    )
    .unwrap();
    let ratios = [(5000.0, 0.4), (5000.0, 1.8), (6000.0, 0.5)];
    let cuts: Vec<(f64, f64)> = ratios
        .iter()
        .map(|&(s, r)| {
            let limit = limiting_depth(
                &Discretization::full(),
                &model,
                s,
                &BoundaryOptions::default(),
            )
            .unwrap()
            .depth_m;
            (s, r * limit * 1e3)
        })
        .collect();
    let settings = SimulationSettings::new(0.0, 0.0, 3.0, 5000.0, 21);
    let obs_path =
        chatter_jobs::recordings::write_simulated_records(&model, &cuts, &settings, dir.path())
            .unwrap();
    let mut observations = Observations::from_path(&obs_path).unwrap();
    std::fs::write(
        dir.path().join("bad.csv"),
        "feed,cutting\n0.1,0.2\n0.3,oops\n",
    )
    .unwrap();
    observations.signals.push(SignalRecord {
        file: dir.path().join("bad.csv"),
        speed_rpm: 5000.0,
        depth_mm: 1.0,
        sample_rate_hz: Some(5000.0),
        once_per_rev_channel: None,
        quantity: None,
        sequence: None,
        radial_immersion: None,
        note: None,
    });
    std::fs::write(&obs_path, observations.to_json_string()).unwrap();
    let out = dir.path().join("out");
    let page = dir.path().join("report.html");
    let run = Command::new(env!("CARGO_BIN_EXE_chatter"))
        .args([
            "diagnose",
            "--quiet",
            "--seed",
            "1",
            "--samples",
            "40",
            "--validation",
            "off",
        ])
        .arg("--model")
        .arg(&model_path)
        .arg("--observations")
        .arg(&obs_path)
        .arg("--out")
        .arg(&out)
        .arg("--report")
        .arg(&page)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    let full: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("diagnosis.json")).unwrap())
            .unwrap();
    assert_eq!(report["records"], full["records"]);
    assert!(full["verdict"].is_string(), "{}", full["verdict"]);
    let rows = report["records"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    for (row, (&(speed, ratio), &(_, depth))) in rows.iter().zip(ratios.iter().zip(&cuts)) {
        assert_eq!(row["speed_rpm"].as_f64().unwrap(), speed);
        assert!(row["evidence"]["line_variation"].is_f64(), "{row}");
        if ratio < 0.6 {
            assert_eq!(row["verdict"], "stable", "{row}");
            let root = dominant_pole(&model, speed, depth * 1e-3).unwrap();
            let f = row["pole"]["frequency_hz"].as_f64().unwrap();
            assert!(
                (f - root.frequency_hz).abs() < 0.01 * root.frequency_hz,
                "{f} vs {root:?}"
            );
            assert!(row["pole"]["damping_ratio"].as_f64().unwrap() > 0.0);
        } else {
            assert_eq!(row["verdict"], "chatter", "{row}");
            assert!((600.0..800.0).contains(&row["chatter_hz"].as_f64().unwrap()));
            assert!(row.get("pole").is_none());
            assert!(row["reason"].as_str().unwrap().contains("limit cycle"));
        }
    }
    assert_eq!(rows[3]["verdict"], "not_judged");
    let reason = rows[3]["reason"].as_str().unwrap();
    assert!(
        reason.contains("bad.csv") && reason.contains("oops"),
        "{reason}"
    );
    let html = std::fs::read_to_string(&page).unwrap();
    let text = html.split("<section id=\"figures\">").next().unwrap();
    for needed in [
        "Signal records: chatter detection and OMA",
        "<td>signals[3]</td><td>bad.csv</td>",
        "<td>not judged</td>",
        "<td>record-2.csv</td>",
        "<td>chatter</td>",
        "The diagnosis is made from 4 signal records: chatter detection judged 2 stable and 1 \
         chatter (1 not judged); OMA identified a pole from 2 of the 2 stable records.",
        "Verdict: ",
    ] {
        assert!(html.contains(needed), "{needed}\n{text}");
    }
    assert!(!html.contains("signal records not used"));
}
