//! A signal-level campaign diagnosed end to end in one call
//! (`chatter_jobs::diagnose::diagnose_recordings`): recordings only, made with the time-domain
//! simulator (`chatter_dynamics::simulate`, a different computation from the characteristic
//! equation and from the identification) on a one-mode lathe, written as CSV with an
//! observations file listing them.
//!
//! Truth. The limiting width at each speed is the full discretization's
//! (`chatter_stability::boundary::limiting_depth`); records at 0.4-0.55 of it are stable, at
//! 1.6-2 of it they chatter. The pole of a stable record is the rightmost root of the
//! characteristic equation at the cut (000 Eq. 5-6,
//! `chatter_stability::frequency_domain::dominant_pole`).
//!
//! Checks: every judged verdict against the truth; the chatter frequency near the mode; the
//! identified pole within [`FREQUENCY_TOLERANCE`] (relative) of the root's frequency and
//! [`DAMPING_TOLERANCE`] (relative) of its damping ratio; a malformed record listed as not
//! judged with its reason; the hand-labelled cut of the file kept; the diagnosis made on all
//! of them, `consistent` (the model is the one the records were simulated with).
#![allow(clippy::unwrap_used)]

use chatter_dynamics::simulate::SimulationSettings;
use chatter_dynamics::{
    Cut, CuttingCoefficients, ModalModel, Mode, ModeShape, Observations, Operation, SignalRecord,
    Turning,
};
use chatter_jobs::diagnose::{DiagnoseRequest, diagnose_recordings};
use chatter_jobs::recordings::{RecordVerdict, RecordsRequest, write_simulated_records};
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::frequency_domain::dominant_pole;
use chatter_stability::monodromy::Discretization;

/// Identified pole frequency against the rightmost root, relative (measured: +0.13 to +0.43 %).
const FREQUENCY_TOLERANCE: f64 = 0.01;
/// Identified pole damping ratio against the rightmost root, relative (3 s records: the
/// identification's damping scatter is about 1.4 / sqrt(zeta omega T), 10-15 % here; measured
/// -28 to +20 %).
const DAMPING_TOLERANCE: f64 = 0.4;
/// Record length (s) and output rate (Hz).
const DURATION_S: f64 = 3.0;
const SAMPLE_RATE_HZ: f64 = 5000.0;

/// A lathe with one 700 Hz mode (damping ratio 0.03, 3e7 N/m) at 30 degrees between feed and
/// cutting directions, kt 1500 and kn 600 N/mm^2: both channels move.
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

/// Speeds (rpm) and width ratios of the campaign: four stable records, two chattering ones.
const CUTS: [(f64, f64); 6] = [
    (4200.0, 0.4),
    (4200.0, 1.8),
    (5000.0, 0.55),
    (5000.0, 0.4),
    (6000.0, 0.5),
    (6000.0, 1.6),
];

/// Write the campaign to `dir`: the simulated records, a malformed record and a cut labelled by
/// hand; returns the model, the observations file and the limiting widths (mm) of `CUTS`.
pub fn campaign(dir: &std::path::Path) -> (ModalModel, std::path::PathBuf, Vec<f64>) {
    let model = lathe();
    let limits: Vec<f64> = CUTS
        .iter()
        .map(|(s, _)| {
            1e3 * limiting_depth(
                &Discretization::full(),
                &model,
                *s,
                &BoundaryOptions::default(),
            )
            .unwrap()
            .depth_m
        })
        .collect();
    let cuts: Vec<(f64, f64)> = CUTS
        .iter()
        .zip(&limits)
        .map(|((s, r), b)| (*s, r * b))
        .collect();
    let settings = SimulationSettings::new(0.0, 0.0, DURATION_S, SAMPLE_RATE_HZ, 11);
    let path = write_simulated_records(&model, &cuts, &settings, dir).unwrap();
    let mut observations = Observations::from_path(&path).unwrap();
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "feed,cutting\n0.1,0.2\n0.3,oops\n").unwrap();
    observations.signals.push(SignalRecord {
        file: bad,
        speed_rpm: 5000.0,
        depth_mm: 1.0,
        sample_rate_hz: Some(SAMPLE_RATE_HZ),
        once_per_rev_channel: None,
        quantity: None,
        sequence: None,
        radial_immersion: None,
        note: None,
    });
    let mut by_hand = Cut::labelled(5000.0, 0.3 * limits[2], true);
    by_hand.note = Some("labelled by hand".into());
    observations.cuts.push(by_hand);
    std::fs::write(&path, observations.to_json_string()).unwrap();
    (model, path, limits)
}

#[test]
fn a_recorded_campaign_is_diagnosed_in_one_call() {
    let dir = tempfile::tempdir().unwrap();
    let (model, path, limits) = campaign(dir.path());
    let observations = Observations::from_path(&path).unwrap();
    let request = DiagnoseRequest {
        samples: 40,
        validation: chatter_gap::Validation::Off,
        ..DiagnoseRequest::new(1)
    };
    let start = std::time::Instant::now();
    let d = diagnose_recordings(
        &model,
        &observations,
        &request,
        &RecordsRequest::default(),
        &chatter_progress::Silent,
    )
    .unwrap();
    eprintln!(
        "diagnosed in {:.1} s: verdict {}",
        start.elapsed().as_secs_f64(),
        d.diagnosis.verdict.name()
    );
    assert_eq!(d.records.len(), CUTS.len() + 1);
    for (row, ((speed, ratio), limit)) in d.records.iter().zip(CUTS.iter().zip(&limits)) {
        let root = dominant_pole(&model, *speed, row.depth_mm * 1e-3).unwrap();
        eprintln!(
            "{speed} rpm, {:.3} mm ({ratio} x {limit:.3}): {:?}, chatter {:?}, pole {:?}, root \
             {:.2} Hz zeta {:.5}, V {:?}; {:?}",
            row.depth_mm,
            row.verdict,
            row.chatter_hz,
            row.pole
                .as_ref()
                .map(|p| (p.frequency_hz, p.damping_ratio, p.frequency_std_hz)),
            root.frequency_hz,
            root.damping_ratio,
            row.evidence.as_ref().map(|e| (e.line_variation, e.margin)),
            row.reason
        );
        assert!(row.evidence.is_some() && row.detection_note.is_some());
        if *ratio < 0.6 {
            assert_eq!(row.verdict, RecordVerdict::Stable, "{row:?}");
            let pole = row.pole.as_ref().unwrap_or_else(|| panic!("{row:?}"));
            assert!(
                (pole.frequency_hz - root.frequency_hz).abs()
                    < FREQUENCY_TOLERANCE * root.frequency_hz,
                "{pole:?} vs {root:?}"
            );
            assert!(
                (pole.damping_ratio - root.damping_ratio).abs()
                    < DAMPING_TOLERANCE * root.damping_ratio,
                "{pole:?} vs {root:?}"
            );
        } else {
            assert_eq!(row.verdict, RecordVerdict::Chatter, "{row:?}");
            let f = row.chatter_hz.unwrap();
            assert!((600.0..800.0).contains(&f), "{f}");
            assert!(row.pole.is_none());
            assert!(row.reason.as_ref().unwrap().contains("limit cycle"));
        }
    }
    let bad = d.records.last().unwrap();
    assert_eq!(bad.verdict, RecordVerdict::NotJudged);
    assert!(bad.pole.is_none() && bad.evidence.is_none());
    let reason = bad.reason.as_deref().unwrap();
    assert!(
        reason.starts_with("not judged") && reason.contains("bad.csv") && reason.contains("oops"),
        "{reason}"
    );
    // the hand-labelled cut first, then one cut per judged record and one pole per stable one
    let counts = d.record_counts();
    assert_eq!(
        (counts.stable, counts.chatter, counts.not_judged),
        (4, 2, 1)
    );
    assert_eq!(counts.poles, 4);
    assert_eq!(d.observations.cuts.len(), 1 + 6);
    assert_eq!(
        d.observations.cuts[0].note.as_deref(),
        Some("labelled by hand")
    );
    assert_eq!(d.observations.poles.len(), 4);
    assert_eq!(d.diagnosis.residuals.nominal.cuts.len(), 7);
    assert_eq!(d.diagnosis.residuals.nominal.poles.len(), 4);
    assert!(
        d.diagnosis
            .notes
            .iter()
            .all(|n| !n.contains("signal records not used")),
        "{:?}",
        d.diagnosis.notes
    );
    // the table is in the JSON beside the diagnosis's own fields
    let json: serde_json::Value = serde_json::to_value(&d).unwrap();
    assert_eq!(json["verdict"], "consistent");
    let rows = json["records"].as_array().unwrap();
    assert_eq!(rows.len(), 7);
    assert_eq!(rows[6]["verdict"], "not_judged");
    assert!(rows[0]["pole"]["frequency_hz"].is_f64());
}

#[test]
fn a_campaign_without_a_judged_record_names_every_reason() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.csv");
    let observations = Observations {
        signals: vec![SignalRecord {
            file: missing,
            speed_rpm: 5000.0,
            depth_mm: 1.0,
            sample_rate_hz: Some(SAMPLE_RATE_HZ),
            once_per_rev_channel: None,
            quantity: None,
            sequence: None,
            radial_immersion: None,
            note: None,
        }],
        ..Observations::default()
    };
    let e = diagnose_recordings(
        &lathe(),
        &observations,
        &DiagnoseRequest::new(1),
        &RecordsRequest::default(),
        &chatter_progress::Silent,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("signals[0]") && e.contains("missing.csv"), "{e}");
}
