//! The interchange formats: every malformed input is an error that names the field (never a
//! panic), the examples parse and round-trip, and the FRF obeys its symmetries.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::{ModalModel, ModelFile, Observations, Parameter, ParameterKind};
use proptest::prelude::*;
use std::path::Path;

const GOOD: &str = r#"{
  "name": "test",
  "operation": { "kind": "milling", "teeth": 4, "radial_immersion": 0.2, "direction": "down", "tool_diameter_mm": 19.05 },
  "cutting": { "kt_n_per_mm2": 695.4, "kn_n_per_mm2": 281.0 },
  "modes": [
    { "frequency_hz": 750.0, "damping_ratio": 0.03, "stiffness_n_per_m": 3.0e6, "direction": "x" },
    { "frequency_hz": 750.0, "damping_ratio": 0.03, "stiffness_n_per_m": 3.0e6, "direction": "y" }
  ],
  "process_damping": { "c_n_per_m": 2.5e5 }
}"#;

fn model_error(text: &str) -> String {
    ModalModel::from_json_str(text, Path::new("m.json"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_else(|| panic!("accepted: {text}"))
}

#[test]
fn good_model_parses() {
    let m = ModalModel::from_json_str(GOOD, Path::new("m.json")).unwrap();
    assert_eq!(m.mode_count(), 2);
    assert_eq!(m.process_damping_n_per_m(), Some(2.5e5));
}

#[test]
fn malformed_models_name_the_field() {
    let cases: Vec<(String, &str)> = vec![
        (GOOD.replace("\"teeth\": 4, ", ""), "operation.teeth"),
        (GOOD.replace("frequency_hz\": 750.0, \"damping_ratio\": 0.03, \"stiffness_n_per_m\": 3.0e6, \"direction\": \"x\"", "frequency_khz\": 0.75, \"damping_ratio\": 0.03, \"stiffness_n_per_m\": 3.0e6, \"direction\": \"x\""), "frequency_khz"),
        (GOOD.replacen("\"damping_ratio\": 0.03", "\"damping_ratio\": -0.03", 1), "modes[0].damping_ratio"),
        (GOOD.replacen("\"damping_ratio\": 0.03", "\"damping_ratio\": 1.5", 1), "modes[0].damping_ratio"),
        (GOOD.replace("0.2,", "1.5,"), "operation.radial_immersion"),
        (GOOD.replace("\"radial_immersion\": 0.2", "\"radial_immersion\": 0.0"), "operation.radial_immersion"),
        (GOOD.replace("\"teeth\": 4", "\"teeth\": 0"), "operation.teeth"),
        (GOOD.replace("\"down\"", "\"sideways\""), "operation.direction"),
        (GOOD.replacen("\"direction\": \"x\"", "\"direction\": \"feed\"", 1), "modes[0].direction"),
        (GOOD.replace("\"kn_n_per_mm2\": 281.0", "\"kn_n_per_mm2\": 281.0, \"ks_n_per_mm2\": 750, \"beta_deg\": 68"), "cutting"),
        (GOOD.replace("\"kind\": \"milling\"", "\"kind\": \"drilling\""), "operation.kind"),
        (GOOD.replace("\"stiffness_n_per_m\": 3.0e6, \"direction\": \"y\"", "\"stiffness_n_per_m\": -3.0e6, \"direction\": \"y\""), "modes[1].stiffness_n_per_m"),
        (GOOD.replace("\"frequency_hz\": 750.0, \"damping_ratio\": 0.03, \"stiffness_n_per_m\": 3.0e6, \"direction\": \"y\"", "\"frequency_hz\": 1e400, \"damping_ratio\": 0.03, \"stiffness_n_per_m\": 3.0e6, \"direction\": \"y\""), "number out of range"),
        (GOOD.replace("\"tool_diameter_mm\": 19.05", "\"tool_diameter_mm\": 19.05, \"colour\": \"red\""), "colour"),
        ("".to_string(), "empty"),
        ("{ not json".to_string(), "m.json"),
    ];
    for (text, needle) in cases {
        let err = model_error(&text);
        assert!(
            err.contains(needle),
            "error `{err}` does not mention `{needle}`"
        );
        assert!(
            err.contains("m.json"),
            "error `{err}` does not name the file"
        );
    }
    let empty_modes = r#"{"operation":{"kind":"turning"},"cutting":{"kt_n_per_mm2":635,"kn_n_per_mm2":159},"modes":[]}"#;
    assert!(model_error(empty_modes).contains("modes"));
    let pd_without_diameter = r#"{"operation":{"kind":"turning"},"cutting":{"kt_n_per_mm2":635,"kn_n_per_mm2":159},"modes":[{"frequency_hz":1000,"damping_ratio":0.02,"shape":{"feed":1.0}}],"process_damping":{"c_n_per_m":1e5}}"#;
    assert!(model_error(pd_without_diameter).contains("process_damping"));
}

#[test]
fn malformed_observations_name_the_field() {
    let p = Path::new("o.json");
    let cases = [
        ("{}", "empty"),
        (r#"{"cuts": []}"#, "empty"),
        (
            r#"{"cuts": [{"speed_rpm": 7000, "depth_mm": 1, "stable": true, "chatter_hz": 900}]}"#,
            "cuts[0].chatter_hz",
        ),
        (
            r#"{"cuts": [{"speed_rpm": -7000, "depth_mm": 1, "stable": true}]}"#,
            "cuts[0].speed_rpm",
        ),
        (
            r#"{"cuts": [{"speed_rpm": 7000, "depth_mm": 1, "stable": true, "radial_immersion": 1.5}]}"#,
            "cuts[0].radial_immersion",
        ),
        (
            r#"{"cuts": [{"speed_rpm": 7000, "depth_mm": 1}]}"#,
            "stable",
        ),
        (
            r#"{"poles": [{"speed_rpm": 7000, "depth_mm": 1, "frequency_hz": 900, "damping_ratio": 2}]}"#,
            "poles[0].damping_ratio",
        ),
        (
            r#"{"signals": [{"file": "a.csv", "speed_rpm": 7000, "depth_mm": 1, "quantity": "force"}]}"#,
            "signals[0].quantity",
        ),
        (r#"{"cutz": []}"#, "cutz"),
    ];
    for (text, needle) in cases {
        let err = Observations::from_json_str(text, p)
            .err()
            .map(|e| e.to_string());
        let err = err.unwrap_or_else(|| panic!("accepted {text}"));
        assert!(
            err.contains(needle),
            "error `{err}` does not mention `{needle}`"
        );
    }
}

#[test]
fn cut_tables_as_csv() {
    let p = Path::new("cuts.csv");
    let ok =
        "speed_rpm,depth_mm,stable,chatter_hz,sequence\n7000,1.0,true,,1\n7100,2.0,0,905.5,2\n";
    let obs = Observations::from_cuts_csv(ok, p).unwrap();
    assert_eq!(obs.cuts.len(), 2);
    assert_eq!(obs.cuts[1].chatter_hz, Some(905.5));
    assert_eq!(obs.cuts[1].sequence, Some(2));
    for (text, needle) in [
        (
            "speed_rpm,depth_mm,stable,chatter_hz\n7000,abc,true,\n",
            "line 2",
        ),
        (
            "speed_rpm,depth_mm,stable,chatter_hz\n7000,1.0,maybe,\n",
            "stable",
        ),
        ("rpm,depth_mm,stable,chatter_hz\n7000,1.0,true,\n", "header"),
        ("speed_rpm,depth_mm,stable,chatter_hz\n", "empty"),
        (
            "speed_rpm,depth_mm,stable,chatter_hz\n7000,1.0,true\n",
            "line 2",
        ),
    ] {
        let err = Observations::from_cuts_csv(text, p)
            .err()
            .map(|e| e.to_string());
        let err = err.unwrap_or_else(|| panic!("accepted {text}"));
        assert!(
            err.contains(needle),
            "error `{err}` does not mention `{needle}`"
        );
    }
}

#[test]
fn examples_parse_and_round_trip() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data");
    let mut models = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if name.ends_with("_model.json") {
            let m = ModalModel::from_path(&path).unwrap();
            assert!(
                m.name().is_some_and(|n| n.contains("seed")),
                "{name} does not say its source"
            );
            let back = ModelFile::from_model(&m).validate().unwrap();
            for (a, b) in m.modes().iter().zip(back.modes()) {
                assert!((a.frequency_hz() - b.frequency_hz()).abs() < 1e-9);
                let (pa, pb) = (a.mass_normalized_shape(), b.mass_normalized_shape());
                assert!((pa[0] - pb[0]).abs() < 1e-12 && (pa[1] - pb[1]).abs() < 1e-12);
            }
            models += 1;
        } else if name.ends_with("_observations.json") {
            Observations::from_path(&path).unwrap();
        }
    }
    assert_eq!(models, 5);
}

fn arbitrary_model() -> impl Strategy<Value = ModalModel> {
    proptest::collection::vec((100.0..5000.0f64, 0.001..0.2f64, -3.0..3.0f64, -3.0..3.0f64), 1..4)
        .prop_filter_map("non-zero shapes", |modes| {
            let modes: Vec<String> = modes
                .iter()
                .filter(|m| m.2.abs() + m.3.abs() > 1e-3)
                .map(|(f, z, a, b)| {
                    format!(r#"{{"frequency_hz":{f},"damping_ratio":{z},"shape":{{"x":{a},"y":{b}}}}}"#)
                })
                .collect();
            if modes.is_empty() {
                return None;
            }
            let text = format!(
                r#"{{"operation":{{"kind":"milling","teeth":3,"radial_immersion":0.5,"direction":"up"}},"cutting":{{"kt_n_per_mm2":700,"kn_n_per_mm2":200}},"modes":[{}]}}"#,
                modes.join(",")
            );
            ModalModel::from_json_str(&text, Path::new("prop.json")).ok()
        })
}

proptest! {
    #[test]
    fn frf_reciprocity_and_conjugate_symmetry(model in arbitrary_model(), f in 1.0..8000.0f64) {
        let g01 = model.receptance(f, 0, 1);
        let g10 = model.receptance(f, 1, 0);
        prop_assert!((g01 - g10).norm() <= 1e-12 * (1.0 + g01.norm()));
        let g = model.receptance(f, 0, 0);
        let gm = model.receptance(-f, 0, 0);
        prop_assert!((g.conj() - gm).norm() <= 1e-12 * (1.0 + g.norm()));
    }

    #[test]
    fn zero_theta_is_identity(model in arbitrary_model()) {
        let params: Vec<Parameter> = (0..model.mode_count())
            .flat_map(|n| [
                Parameter::new(ParameterKind::Omega, n),
                Parameter::new(ParameterKind::Zeta, n),
                Parameter::new(ParameterKind::Phi, n),
                Parameter::new(ParameterKind::Stiffness, n),
            ])
            .collect();
        let same = model.perturbed(&params, &vec![0.0; params.len()]).unwrap();
        prop_assert_eq!(same, model);
    }
}

/// The example files of this crate (models and observations; `data/`).
fn example_texts() -> Vec<(String, bool)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data");
    [
        ("schmitz2023_milling_model.json", true),
        ("ahmadi2022_turning_model.json", true),
        ("ebrahimi2025_milling_model.json", true),
        ("ahmadi2022_turning_observations.json", false),
        ("ebrahimi2025_milling_observations.json", false),
    ]
    .iter()
    .map(|(name, model)| (std::fs::read_to_string(dir.join(name)).unwrap(), *model))
    .collect()
}

/// Byte ranges of the JSON numbers in `text`.
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit() || bytes[i] == b'-';
        let after_colon = text[..i].trim_end().ends_with(':')
            || text[..i].trim_end().ends_with(',')
            || text[..i].trim_end().ends_with('[');
        if starts && after_colon {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || b"-+.eE".contains(&bytes[i])) {
                i += 1;
            }
            spans.push((start, i));
        } else {
            i += 1;
        }
    }
    spans
}

const NASTY: [&str; 16] = [
    "0", "-0", "-1", "1e300", "-1e300", "1e-300", "1e16", "0.5", "2.5", "1", "400", "true", "null",
    "[]", "\"x\"", "{}",
];

proptest! {
    /// Random edits of the example files (a number replaced by a nasty value, or a byte cut)
    /// never panic, and whatever is accepted has finite receptances.
    #[test]
    fn random_edits_of_the_examples_never_panic(
        file in 0usize..5,
        picks in proptest::collection::vec((any::<proptest::sample::Index>(), 0usize..NASTY.len()), 1..4),
        cut in proptest::option::of(any::<proptest::sample::Index>()),
    ) {
        let (mut text, is_model) = example_texts().swap_remove(file);
        for (index, value) in picks {
            let spans = number_spans(&text);
            if spans.is_empty() {
                break;
            }
            let (a, b) = spans[index.index(spans.len())];
            text.replace_range(a..b, NASTY[value]);
        }
        if let Some(at) = cut {
            let at = at.index(text.len());
            if text.is_char_boundary(at) {
                text.remove(at);
            }
        }
        if is_model {
            if let Ok(model) = ModalModel::from_json_str(&text, Path::new("edited.json")) {
                for m in model.modes() {
                    prop_assert!(model.receptance(0.9 * m.frequency_hz(), 0, 0).norm().is_finite());
                }
            }
        } else {
            let _ = Observations::from_json_str(&text, Path::new("edited.json"));
        }
    }
}

/// `operation.pitch_deg`: absent is even pitch; a list must have one positive angle per tooth
/// summing to 360, and errors name the field and echo the values.
#[test]
fn pitch_deg_is_checked_by_name() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/schmitz2023_milling_model.json"
    ))
    .unwrap();
    let with = |pitch: &str| {
        text.replacen(
            "\"kind\": \"milling\"",
            &format!("\"kind\": \"milling\", \"pitch_deg\": {pitch}"),
            1,
        )
    };
    let origin = std::path::Path::new("model.json");
    let parse = |t: &str| chatter_dynamics::ModalModel::from_json_str(t, origin);
    assert!(
        with("[]").contains("pitch_deg"),
        "the example's milling kind"
    );
    let ok = parse(&with("[70, 110, 70, 110]")).unwrap();
    assert!(ok.operation().is_variable_pitch());
    let round_trip = chatter_dynamics::model_file::ModelFile::from_model(&ok);
    assert_eq!(
        round_trip.operation.pitch_deg.as_deref().map(|p| p.len()),
        Some(4)
    );
    for (pitch, expected) in [
        ("[70, 110, 70, 100]", "sums to 350"),
        ("[70, 110, 180]", "one per tooth (4)"),
        ("[-70, 110, 210, 110]", "pitch_deg[0]"),
        ("[0, 110, 140, 110]", "> 0"),
    ] {
        let err = parse(&with(pitch)).err().unwrap().to_string();
        assert!(err.contains("operation.pitch_deg"), "{pitch}: {err}");
        assert!(err.contains(expected), "{pitch}: {err}");
    }
}

/// `operation.helix_deg` (one value or one per tooth, in [0, 90)), `operation.axial_slices`
/// (>= 1) and `operation.runout_um` (one per tooth, each >= 0): errors name the field and echo
/// the value; a helix needs the tool diameter.
#[test]
fn helix_slices_and_runout_are_checked_by_name() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/schmitz2023_milling_model.json"
    ))
    .unwrap();
    let with = |fields: &str| {
        text.replacen(
            "\"kind\": \"milling\"",
            &format!("\"kind\": \"milling\", {fields}"),
            1,
        )
    };
    let origin = std::path::Path::new("model.json");
    let parse = |t: &str| chatter_dynamics::ModalModel::from_json_str(t, origin);
    let ok = parse(&with(
        r#""tool_diameter_mm": 12, "helix_deg": [30, 35, 30, 35], "axial_slices": 8, "runout_um": [5, 0, 0, 0]"#,
    ))
    .unwrap();
    assert!(ok.operation().is_helical() && ok.operation().has_uneven_teeth());
    let round_trip = chatter_dynamics::model_file::ModelFile::from_model(&ok);
    let again = parse(&serde_json::to_string(&round_trip).unwrap()).unwrap();
    assert_eq!(again.operation(), ok.operation());
    let uniform = parse(&with(r#""tool_diameter_mm": 12, "helix_deg": 30"#)).unwrap();
    assert!(uniform.operation().is_helical() && !uniform.operation().has_uneven_teeth());
    for (fields, field, expected) in [
        (
            r#""tool_diameter_mm": 12, "helix_deg": 95"#,
            "operation.helix_deg",
            "95",
        ),
        (
            r#""tool_diameter_mm": 12, "helix_deg": [30, 30, -5, 30]"#,
            "operation.helix_deg[2]",
            "-5",
        ),
        (
            r#""tool_diameter_mm": 12, "helix_deg": [30, 30]"#,
            "operation.helix_deg",
            "one per tooth (4)",
        ),
        (
            r#""helix_deg": 30"#,
            "operation.tool_diameter_mm",
            "helical",
        ),
        (
            r#""tool_diameter_mm": 12, "helix_deg": 30, "axial_slices": 0"#,
            "operation.axial_slices",
            "0",
        ),
        (
            r#""runout_um": [5, -2, 0, 0]"#,
            "operation.runout_um[1]",
            "-2",
        ),
        (
            r#""runout_um": [5, 0]"#,
            "operation.runout_um",
            "one radial offset per tooth",
        ),
    ] {
        let err = parse(&with(fields)).err().unwrap().to_string();
        assert!(err.contains(field), "{fields}: {err}");
        assert!(err.contains(expected), "{fields}: {err}");
    }
}
