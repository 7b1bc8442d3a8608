//! Zero-order lobes straight from measured FRFs: a sampled modal FRF gives the modal lobes, and
//! the same FRF through a UFF 58 file and a `measured_frf` model file gives identical lobes (the
//! CutPro files' lobes are in `cutpro_lobes.rs`).

#![allow(clippy::unwrap_used)]

use chatter_dynamics::{ModalModel, ModelFile, examples};
use chatter_frf::uff::{Uff58Record, write_uff58};
use chatter_frf::{Frf, MeasuredModel};
use chatter_stability::zero_order::{ZeroOrderOptions, measured_limiting_depths, zoa_lobes};

use std::path::{Path, PathBuf};

/// Write the model's xx, yy and xy FRFs as one UFF 58 file and a model file naming them.
fn write_measured(model: &ModalModel, dir: &Path, grid: &[f64]) -> PathBuf {
    let records: Vec<Uff58Record> = [(0, 0), (1, 1), (0, 1)]
        .iter()
        .map(|&(i, j)| {
            let frf = Frf::from_model(model, i, j, grid.to_vec()).unwrap();
            Uff58Record::receptance(&frf, "synthesized", (1, i as i64 + 1), (1, j as i64 + 1))
        })
        .collect();
    write_uff58(&dir.join("tip.uff"), &records).unwrap();
    let mut file = ModelFile::from_model(model);
    file.modes.clear();
    file.measured_frf = Some(
        serde_json::from_str(
            r#"[{"file": "tip.uff", "direction": "x", "dataset": 0},
            {"file": "tip.uff", "direction": "y", "dataset": 1},
            {"file": "tip.uff", "directions": ["x", "y"], "dataset": 2}]"#,
        )
        .unwrap(),
    );
    let path = dir.join("measured.json");
    std::fs::write(&path, serde_json::to_string_pretty(&file).unwrap()).unwrap();
    path
}

#[test]
fn uff58_round_trip_gives_identical_lobes_and_the_modal_lobes() {
    for model in [
        examples::schmitz_2023_milling(),
        examples::ebrahimi_2025_milling(),
    ] {
        let f_max = model
            .modes()
            .iter()
            .map(|m| m.frequency_hz())
            .fold(0.0, f64::max);
        // twenty points per half-power bandwidth 2 zeta f_n of the sharpest mode, at most 1 Hz
        let step = model
            .modes()
            .iter()
            .map(|m| 0.1 * m.damping_ratio() * m.frequency_hz())
            .fold(1.0, f64::min);
        let grid: Vec<f64> = (0..=(3.0 * f_max / step) as usize)
            .map(|k| k as f64 * step)
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let path = write_measured(&model, dir.path(), &grid);
        // a measured-only model is not a modal model, and says what to do
        let e = ModalModel::from_path(&path).unwrap_err().to_string();
        assert!(e.contains("measured_frf") && e.contains("fit-frf"), "{e}");
        let measured = MeasuredModel::from_path(&path).unwrap();
        let direct = model.sampled_receptance(grid.clone()).unwrap();
        let f_dom = chatter_stability::boundary::dominant_mode_frequency_hz(&model);
        let n = model.operation().delays_per_revolution() as f64;
        let speeds: Vec<f64> = (0..200)
            .map(|i| 60.0 * f_dom / n * (0.1 + 1.1 * i as f64 / 199.0))
            .collect();
        let opts = ZeroOrderOptions::unbounded();
        let from_file = measured_limiting_depths(
            &measured.operation,
            measured.cutting,
            &measured.receptance,
            &speeds,
            &opts,
        )
        .unwrap();
        let from_grid =
            measured_limiting_depths(model.operation(), model.cutting(), &direct, &speeds, &opts)
                .unwrap();
        let modal = zoa_lobes(&model, &speeds).unwrap();
        let mut worst_file: f64 = 0.0;
        let mut worst_modal: f64 = 0.0;
        for ((a, b), m) in from_file.iter().zip(&from_grid).zip(&modal) {
            worst_file = worst_file.max((a.depth_m / b.depth_m - 1.0).abs());
            let e = (a.depth_m / m.depth_m - 1.0).abs();
            if e > 5e-3 {
                eprintln!(
                    "{} rpm: measured {} mm {} Hz, modal {} mm {} Hz",
                    a.speed_rpm,
                    a.depth_mm(),
                    a.chatter_hz,
                    m.depth_mm(),
                    m.chatter_hz
                );
            }
            worst_modal = worst_modal.max(e);
        }
        eprintln!(
            "{:?}: UFF vs direct {worst_file:e}, measured vs modal {worst_modal:e}",
            model.name()
        );
        assert!(
            worst_file < 1e-9,
            "UFF round trip changed the lobes by {worst_file}"
        );
        assert!(
            worst_modal < 5e-3,
            "measured vs modal zero-order lobes: {worst_modal}"
        );
    }
}
