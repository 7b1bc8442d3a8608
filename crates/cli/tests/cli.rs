//! The built `chatter` binary on the example files.
#![allow(clippy::unwrap_used)]

mod browser;

use std::path::{Path, PathBuf};
use std::process::Command;

fn chatter() -> Command {
    Command::new(env!("CARGO_BIN_EXE_chatter"))
}

/// Run, require exit status 0 and return stdout (stderr in the failure message).
fn succeed(command: &mut Command) -> String {
    let out = command.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Run, require exit status 1 (bad input) and return stderr, which must not be a panic.
fn fail(command: &mut Command) -> String {
    let out = command.output().unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// `chatter update --quiet OPTIONS --model MODEL --observations OBSERVATIONS --out OUT`.
fn update(
    options: &[&str],
    model: impl AsRef<std::ffi::OsStr>,
    observations: impl AsRef<std::ffi::OsStr>,
    out: impl AsRef<std::ffi::OsStr>,
) -> Command {
    let mut command = chatter();
    command
        .args(["update", "--quiet"])
        .args(options)
        .arg("--model")
        .arg(model)
        .arg("--observations")
        .arg(observations)
        .arg("--out")
        .arg(out);
    command
}

/// The posterior variables (by name) and the pointwise log-likelihood `y` (flattened) of an
/// ArviZ InferenceData netCDF file, with its `prior` group checked to hold the same variables.
fn inference_data(path: &Path) -> (std::collections::BTreeMap<String, Vec<f64>>, Vec<f64>) {
    let file = netcdf_reader::NcFile::open(path).unwrap();
    let read = |name: &str| -> Vec<f64> {
        file.read_variable_as_f64(name)
            .unwrap()
            .iter()
            .copied()
            .collect()
    };
    let group = file.group("posterior").unwrap();
    let mut posterior = std::collections::BTreeMap::new();
    for v in &group.variables {
        if v.name() != "chain" && v.name() != "draw" {
            posterior.insert(
                v.name().to_string(),
                read(&format!("posterior/{}", v.name())),
            );
            assert!(!read(&format!("prior/{}", v.name())).is_empty());
        }
    }
    (posterior, read("log_likelihood/y"))
}

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
}

#[test]
fn frf_csv_has_header_and_rows() {
    let text = succeed(
        chatter()
            .args(["frf", "--points", "50", "--model"])
            .arg(example("schmitz2023_milling_model.json")),
    );
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
    let text = succeed(
        chatter()
            .args([
                "lobes",
                "--quiet",
                "--method",
                "zoa",
                "--speeds",
                "5000:12000:15",
                "--model",
            ])
            .arg(example("schmitz2023_milling_model.json")),
    );
    assert!(text.starts_with("speed_rpm,depth_mm,chatter_hz\n"));
    assert_eq!(text.lines().count(), 16);
    let out = succeed(
        chatter()
            .args([
                "multiplier",
                "--speed-rpm",
                "7150",
                "--depth-mm",
                "2.286",
                "--model",
            ])
            .arg(example("ahmadi2022_turning_model.json")),
    );
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
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
        succeed(
            chatter()
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
                .arg(&path),
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
    succeed(chatter().args(["demo", "--quiet", "--out"]).arg(dir.path()));
    for f in [
        "papers.csv",
        "turning_lobes.csv",
        "turning_lobes.svg",
        "milling_bands.svg",
        "milling_bands.csv",
        "milling_bands-theta.svg",
        "milling_bands-distance.svg",
        "milling_bands-roots.svg",
        "eq34_covariance.json",
        "turning_credibility.csv",
        "turning_credibility.svg",
        "shopfloor_observations.json",
        "diagnosis/lobes.svg",
        "diagnosis/residuals.svg",
        "summary.json",
        "report.html",
    ] {
        assert!(dir.path().join(f).exists(), "{f} missing");
    }
    // the report page, in a real browser: every plot drawn, the verdicts in words with units
    let page = dir.path().join("report.html");
    let html = std::fs::read_to_string(&page).unwrap();
    assert_eq!(html.matches("<figure>").count(), 8);
    browser::check(
        &page,
        &[
            "Verdict: process_damping",
            "process damping that the model leaves out",
            "the deepest stable pocket reaches",
            "lower credibility bound",
            "lower offset boundary",
            "rpm",
            " mm",
            "N/mm^2",
            "Hz",
            "ln evidence (nats)",
        ],
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["turning_limits"].as_array().unwrap().len(), 4);
    assert_eq!(summary["diagnosis"]["verdict"], "process_damping");
    // 000 Sec. 6.4: credibility bounds on every row, lower <= mean <= upper, and at 7300 rpm
    // they bracket the test cuts (stable at 3.048 mm below, chatter at 3.81 mm above)
    let credibility = std::fs::read_to_string(dir.path().join("turning_credibility.csv")).unwrap();
    for line in credibility.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        assert!(v[2] <= v[1] && v[1] <= v[3], "{line}");
        if v[0] == 7300.0 {
            assert!(v[2] > 3.048 && v[3] < 3.81, "{line}");
        }
    }
    assert!(credibility.lines().any(|l| l.starts_with("7300,")));
    // 000 Table 3 (15), 001 Sec. 4 (15), 003 Table 2 (8); only D's reduction is outside
    // 000 Table 3 15, 001 Sec. 4 15, 002 Table 1 28 (at 194 Hz the 7 frequencies and at 195.3 Hz
    // 5 damping ratios outside: documented), 003 Table 2 8 (D's reduction outside), 004 11,
    // 004 Sec. 6 replayed 8 (the 25 % final MRR, the 75 % test count and the ordering outside:
    // documented in chatter_updating::schmitz2022)
    assert_eq!(summary["papers"]["rows"], 85);
    assert_eq!(summary["papers"]["within_tolerance"], 69);
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
    let err = fail(chatter().args(["check", "--model"]).arg(&bad));
    assert!(
        err.contains("bad.json") && err.contains("radial_immersion"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    assert!(
        fail(
            chatter()
                .args(["lobes", "--speeds", "1:2", "--model"])
                .arg(example("schmitz2023_milling_model.json"))
        )
        .contains("MIN:MAX:N")
    );
    let missing = chatter()
        .args(["check", "--model", "/nonexistent/model.json"])
        .output()
        .unwrap();
    assert_eq!(missing.status.code(), Some(1));
}

/// The Eq. 34 covariance of seed 000 as a covariance file without a mean (formats: README,
/// `bands`), so the bands are around the nominal model.
fn eq34_covariance(dir: &std::path::Path) -> PathBuf {
    let path = dir.join("eq34.json");
    let posterior = chatter_dynamics::examples::ahmadi_2022_posterior();
    let file = serde_json::json!({
        "parameter_names": posterior.parameter_names,
        "covariance": posterior.covariance,
    });
    std::fs::write(&path, file.to_string()).unwrap();
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
    let text = succeed(
        chatter()
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
            .arg(&plot),
    );
    assert!(
        text.starts_with("speed_rpm,depth_mm,lower_mm,upper_mm\n"),
        "{text}"
    );
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
    let text = succeed(
        chatter()
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
            .arg(&map),
    );
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
    let err = fail(
        chatter()
            .args(["bands", "--kind", "montecarlo", "--model"])
            .arg(example("ahmadi2022_turning_model.json")),
    );
    assert!(
        err.contains("--posterior") && err.contains("--covariance"),
        "{err}"
    );
}

/// Proving-ground data with hidden process damping (2x, truth by semi-discretization):
/// `chatter diagnose` names it, reports every class, the regions and the held-out shrinkage,
/// and writes the plots and the diagnosed model, which `chatter lobes` reads.
#[test]
fn diagnose_names_the_hidden_effect_and_writes_plots() {
    use chatter_gap::{EffectClass, HiddenEffect, Scenario, nominal_milling, synthesize};
    let dir = tempfile::tempdir().unwrap();
    let nominal = nominal_milling().unwrap();
    let mut scenario = Scenario::new(HiddenEffect::ParameterError, 5);
    (scenario.effect, _) = chatter_gap::generator::effect_at(
        EffectClass::ProcessDamping,
        2.0,
        &nominal,
        scenario.speed_range_rpm,
    )
    .unwrap();
    let data = synthesize(&nominal, &scenario).unwrap();
    let model_path = dir.path().join("model.json");
    let obs_path = dir.path().join("observations.json");
    std::fs::write(&model_path, nominal.to_json_string()).unwrap();
    std::fs::write(&obs_path, data.to_json_string()).unwrap();
    let out_dir = dir.path().join("gap");
    let out = succeed(
        chatter()
            .args([
                "diagnose", "--quiet", "--seed", "3", "--folds", "3", "--model",
            ])
            .arg(&model_path)
            .arg("--observations")
            .arg(&obs_path)
            .arg("--out")
            .arg(&out_dir)
            .arg("--netcdf"),
    );
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(report["verdict"], "process_damping", "{report}");
    // every class as an ArviZ InferenceData file: posterior, prior and one pointwise
    // log-likelihood column per observation, read back by an independent netCDF decoder
    let observations = data.cuts.len() + data.poles.len();
    for class in EffectClass::ALL {
        let (posterior, log_likelihood) =
            inference_data(&out_dir.join(format!("inference_data/{class}.nc")));
        let draws = posterior["frequency_factor"].len();
        assert!(draws >= 120, "{class}: {draws} draws");
        assert_eq!(log_likelihood.len(), draws * observations, "{class}");
        assert!(
            log_likelihood.iter().all(|v| v.is_finite() && *v <= 10.0),
            "{class}"
        );
    }
    // the five listed classes and the open alternative `speed_band`
    let classes = report["classes"].as_array().unwrap();
    assert_eq!(classes.len(), 6);
    assert_eq!(classes[5]["name"], "speed_band");
    let total: f64 = classes
        .iter()
        .map(|c| c["probability"].as_f64().unwrap())
        .sum();
    assert!((total - 1.0).abs() < 1e-9);
    assert!(classes.iter().all(|c| c["log_evidence"].is_number()
        && c["parameters"]["frequency_factor"]["mean"].is_number()));
    assert!(!report["regions"].as_array().unwrap().is_empty());
    let lpd = &report["shrink"]["log_predictive_density_per_observation"];
    assert!(lpd["after"].as_f64().unwrap() > lpd["before"].as_f64().unwrap());
    assert!(report.get("residuals").is_none());
    for file in [
        "diagnosis.json",
        "lobes.svg",
        "residuals.svg",
        "diagnosed_model.json",
    ] {
        assert!(out_dir.join(file).exists(), "{file}");
    }
    let diagnosed =
        chatter_dynamics::ModalModel::from_path(out_dir.join("diagnosed_model.json")).unwrap();
    assert!(diagnosed.process_damping_n_per_m().is_some());
    succeed(
        chatter()
            .args([
                "lobes",
                "--method",
                "fdm",
                "--speeds",
                "3000:4000:3",
                "--model",
            ])
            .arg(out_dir.join("diagnosed_model.json")),
    );
    let full: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("diagnosis.json")).unwrap())
            .unwrap();
    assert!(
        full["residuals"]["nominal"]["cuts"]
            .as_array()
            .unwrap()
            .len()
            == scenario.cuts
    );
}

/// Clear errors: observations without cuts or poles (a signal record that cannot be read is
/// named with its reason), and invalid options.
#[test]
fn diagnose_rejects_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let obs = dir.path().join("signals_only.json");
    std::fs::write(
        &obs,
        r#"{"signals": [{"file": "s.csv", "speed_rpm": 7000, "depth_mm": 1.0, "sample_rate_hz": 1000}]}"#,
    )
    .unwrap();
    let err = fail(
        chatter()
            .args(["diagnose", "--quiet", "--seed", "1", "--model"])
            .arg(example("schmitz2023_milling_model.json"))
            .arg("--observations")
            .arg(&obs),
    );
    assert!(
        err.contains("signals_only.json")
            && err.contains("no cuts and no poles")
            && err.contains("signals[0]")
            && err.contains("s.csv"),
        "{err}"
    );
    let err = fail(
        chatter()
            .args([
                "diagnose",
                "--quiet",
                "--seed",
                "1",
                "--samples",
                "10",
                "--model",
            ])
            .arg(example("schmitz2023_milling_model.json"))
            .arg("--observations")
            .arg(example("ebrahimi2025_milling_observations.json")),
    );
    assert!(err.contains("samples"), "{err}");
}

#[test]
fn update_writes_posterior_summary_model_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("posterior");
    succeed(&mut update(
        &[
            "--classes",
            "0.5,1",
            "--samples",
            "200",
            "--seed",
            "3",
            "--netcdf",
        ],
        example("ahmadi2022_turning_model.json"),
        example("ahmadi2022_turning_observations.json"),
        &out_dir,
    ));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    let names: Vec<&str> = summary["parameter_names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        ["theta_omega_2", "theta_zeta_2", "theta_phi_2", "sigma_r2"]
    );
    assert_eq!(summary["posterior_mean"].as_array().unwrap().len(), 4);
    assert_eq!(summary["posterior_covariance"].as_array().unwrap().len(), 4);
    let classes = summary["classes"].as_array().unwrap();
    assert_eq!(classes.len(), 2);
    let total: f64 = classes
        .iter()
        .map(|c| c["probability"].as_f64().unwrap())
        .sum();
    assert!((total - 1.0).abs() < 1e-9);
    let selected = summary["selected_alpha"].as_f64().unwrap();
    assert!(selected == 0.5 || selected == 1.0);
    let theta_omega = summary["posterior_mean"][0].as_f64().unwrap();
    assert!(theta_omega > 0.002 && theta_omega < 0.01, "{theta_omega}");
    let csv = std::fs::read_to_string(out_dir.join("posterior.csv")).unwrap();
    assert!(csv.starts_with("theta_omega_2,theta_zeta_2,theta_phi_2,sigma_r2,weight\n"));
    assert_eq!(csv.lines().count(), 201);
    // --netcdf: the same samples as an ArviZ InferenceData file, read back by an independent
    // netCDF decoder; one pointwise log-likelihood column per identified pole repetition
    let (posterior, log_likelihood) = inference_data(&out_dir.join("inference_data.nc"));
    for (k, name) in names.iter().enumerate() {
        let column: Vec<f64> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
            .collect();
        assert_eq!(posterior[*name], column, "{name}");
    }
    assert_eq!(log_likelihood.len() % 200, 0);
    assert!(log_likelihood.len() >= 200 && log_likelihood.iter().all(|v| v.is_finite()));
    for plot in ["evidence.svg", "corner.svg"] {
        let svg = std::fs::read_to_string(out_dir.join(plot)).unwrap();
        assert!(svg.contains("<svg"), "{plot}");
    }
    // the updated model is a valid model file with the mode-2 frequency raised
    let updated = out_dir.join("updated_model.json");
    succeed(chatter().args(["check", "--model"]).arg(&updated));
    let model: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&updated).unwrap()).unwrap();
    let f2 = model["modes"][1]["frequency_hz"].as_f64().unwrap();
    assert!((f2 - 2445.0 * (1.0 + theta_omega)).abs() < 1e-6);
}

#[test]
fn update_milling_poles_with_each_sampler_and_rejects_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    // identified milling poles with TMCMC (002)
    let out_dir = dir.path().join("tmcmc");
    succeed(&mut update(
        &[
            "--sampler",
            "tmcmc",
            "--classes",
            "0.01",
            "--samples",
            "40",
            "--seed",
            "1",
            "--parameters",
            "theta_omega_1,theta_zeta_1",
        ],
        example("ebrahimi2025_milling_model.json"),
        example("ebrahimi2025_milling_observations.json"),
        &out_dir,
    ));
    let summary = std::fs::read_to_string(out_dir.join("summary.json")).unwrap();
    assert!(summary.contains("sigma_w2_hz2"), "{summary}");
    // the GP surrogate is the default for milling poles and reports its errors
    let summary: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert!(summary["surrogate"]["held_out"]["rms_frequency_error_hz"].is_f64());
    let poles = std::fs::read_to_string(out_dir.join("poles.csv")).unwrap();
    assert_eq!(poles.lines().count(), 8, "{poles}");
    // cut results with rejection sampling + adaptive MCMC (004): one class, no alpha
    let cuts = dir.path().join("cuts.csv");
    std::fs::write(
        &cuts,
        "speed_rpm,depth_mm,stable,chatter_hz\n2100,0.3,true,\n2100,0.9,false,196\n",
    )
    .unwrap();
    let out_dir = dir.path().join("amcmc");
    succeed(&mut update(
        &[
            "--sampler",
            "amcmc",
            "--samples",
            "60",
            "--seed",
            "1",
            "--parameters",
            "kn_n_per_mm2",
        ],
        example("ebrahimi2025_milling_model.json"),
        &cuts,
        &out_dir,
    ));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    assert!(summary["selected_alpha"].is_null());
    assert_eq!(summary["parameter_names"][0], "kn_n_per_mm2");
    let priors = dir.path().join("priors.json");
    std::fs::write(
        &priors,
        r#"{"theta_k_7": {"kind": "uniform", "low": 0, "high": 1}}"#,
    )
    .unwrap();
    for extra in [
        vec!["--classes".to_string(), "abc".to_string()],
        vec!["--priors".to_string(), priors.display().to_string()],
        vec!["--parameters".to_string(), "theta_bogus_1".to_string()],
    ] {
        let err = fail(
            update(
                &["--samples", "20", "--seed", "1"],
                example("ahmadi2022_turning_model.json"),
                example("ahmadi2022_turning_observations.json"),
                dir.path().join("never"),
            )
            .args(&extra),
        );
        assert!(
            err.contains("abc") || err.contains("theta_k_7") || err.contains("theta_bogus_1"),
            "{err}"
        );
        assert!(!dir.path().join("never").exists());
    }
}

#[test]
fn plan_prints_the_next_cut() {
    for strategy in ["voi", "mrr"] {
        let out = succeed(
            chatter()
                .args([
                    "plan",
                    "--quiet",
                    "--paths",
                    "40",
                    "--strategy",
                    strategy,
                    "--model",
                ])
                .arg(example("ebrahimi2025_milling_model.json"))
                .arg("--observations")
                .arg(example("ebrahimi2025_milling_observations.json")),
        );
        let plan: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(plan["strategy"], strategy);
        let speed = plan["next_cut"]["speed_rpm"].as_f64().unwrap();
        assert!((1575.0..=3000.0).contains(&speed), "{speed}");
        assert!(plan["next_cut"]["depth_mm"].as_f64().unwrap() > 0.0);
        assert!(plan["stop"].is_boolean());
    }
    assert!(
        fail(
            chatter()
                .args([
                    "plan",
                    "--quiet",
                    "--strategy",
                    "mrr",
                    "--p-test",
                    "1.5",
                    "--model",
                ])
                .arg(example("ebrahimi2025_milling_model.json"))
                .arg("--observations")
                .arg(example("ebrahimi2025_milling_observations.json"))
        )
        .contains("--p-test 1.5")
    );
}

/// 004 from its example files: `plan --strategy mrr` with the correlated RCSA prior file samples
/// the prior's eight parameters and proposes a first cut on the P_test contour (P_s within 0.05
/// of P_test); a prior file naming a parameter that is not sampled is refused by name.
#[test]
fn plan_takes_the_004_correlated_prior() {
    let plan = |extra: &[&str]| {
        let mut c = chatter();
        c.args([
            "plan",
            "--quiet",
            "--strategy",
            "mrr",
            "--method",
            "zoa",
            "--paths",
            "60",
        ])
        .args([
            "--speeds",
            "8000:16000:21",
            "--depths",
            "0.1:6:60",
            "--p-test",
            "0.25",
        ])
        .arg("--model")
        .arg(example("schmitz2022_rcsa_model.json"))
        .arg("--priors")
        .arg(example("schmitz2022_rcsa_prior.json"))
        .args(extra);
        c
    };
    let plan_json: serde_json::Value = serde_json::from_str(&succeed(&mut plan(&[]))).unwrap();
    assert_eq!(plan_json["parameter_names"][2], "fn1_hz");
    assert_eq!(plan_json["parameter_names"].as_array().unwrap().len(), 8);
    let p = plan_json["next_cut"]["p_stable"].as_f64().unwrap();
    assert!((p - 0.25).abs() <= 0.05, "{p}");
    let err = fail(&mut plan(&["--parameters", "kt_n_per_mm2,kn_n_per_mm2"]));
    assert!(
        err.contains("ks_n_per_mm2") && err.contains("not a sampled parameter"),
        "{err}"
    );
}

/// `chatter update` on a few cuts with 004's correlated prior file and the zero-order cut
/// likelihood: the eight prior names are the updated parameters, and the posterior keeps the
/// modal block's correlation (corr(f_n1, k_1) = 0.9999977 in the prior, where the cuts say
/// nothing); `--method` with identified poles is refused naming it.
#[test]
fn update_takes_the_004_correlated_prior() {
    let dir = tempfile::tempdir().unwrap();
    let cuts = dir.path().join("cuts.json");
    std::fs::write(
        &cuts,
        r#"{"cuts": [{"speed_rpm": 10985, "depth_mm": 2.8, "stable": true},
                     {"speed_rpm": 10985, "depth_mm": 3.2, "stable": false},
                     {"speed_rpm": 10000, "depth_mm": 1.2, "stable": false}]}"#,
    )
    .unwrap();
    let out_dir = dir.path().join("posterior");
    let priors = example("schmitz2022_rcsa_prior.json");
    let options = |method: &'static str| {
        vec![
            "--samples".to_string(),
            "300".into(),
            "--seed".into(),
            "2".into(),
            "--method".into(),
            method.into(),
            "--priors".into(),
            priors.to_str().unwrap().into(),
        ]
    };
    let zoa = options("zoa");
    let zoa: Vec<&str> = zoa.iter().map(String::as_str).collect();
    succeed(&mut update(
        &zoa,
        example("schmitz2022_rcsa_model.json"),
        &cuts,
        &out_dir,
    ));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    let names = summary["parameter_names"].as_array().unwrap();
    assert_eq!(names.len(), 8);
    assert_eq!(names[2], "fn1_hz");
    assert_eq!(names[3], "k1_n_per_m");
    let correlation = |cov: &serde_json::Value| {
        let c = |i: usize, j: usize| cov[i][j].as_f64().unwrap();
        c(2, 3) / (c(2, 2) * c(3, 3)).sqrt()
    };
    let r = correlation(&summary["posterior_covariance"]);
    let prior: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&priors).unwrap()).unwrap();
    let r_prior = correlation(&prior["covariance"]);
    // Fisher z of the prior's 0.9999977 is 6.84; 300 samples (effective 100 or more) put the
    // posterior's within 0.4 (measured 6.857)
    assert!(
        (r.atanh() - r_prior.atanh()).abs() < 0.4,
        "{r} vs {r_prior}"
    );
    let err = fail(&mut update(
        &["--method", "zoa", "--seed", "1"],
        example("ahmadi2022_turning_model.json"),
        example("ahmadi2022_turning_observations.json"),
        dir.path().join("poles"),
    ));
    assert!(
        err.contains("method") && err.contains("cut results only"),
        "{err}"
    );
}

/// `chatter oma` on a small signal file: a seeded 800 Hz mode (zeta 2 %) on two channels plus a
/// once-per-revolution tachometer at 7150 rpm, 4 s at 10 kHz. The pole comes back in the
/// observations schema (frequency within 0.4 %, damping within 20 %, ten repetitions), the
/// stabilization diagram is drawn, and bad entries name the file and the field.
#[test]
fn oma_identifies_the_signals_of_an_observations_file() {
    use chatter_oma::synthetic::{SyntheticMode, SyntheticRecord};
    let dir = tempfile::tempdir().unwrap();
    let fs = 10_000.0;
    let record = SyntheticRecord {
        channels: vec!["a1".into(), "a2".into()],
        modes: vec![SyntheticMode {
            pole: chatter_dynamics::ModalPole::new(800.0, 0.02),
            shape: vec![1.0, 0.5],
        }],
        harmonics: Vec::new(),
        noise_fraction: 0.1,
        sample_rate_hz: fs,
        duration_s: 4.0,
        seed: 3,
    };
    let signals = record.generate().unwrap();
    let samples_per_rev = fs * 60.0 / 7150.0;
    let mut csv = String::from("a1,a2,tach\n");
    for k in 0..signals.data[0].len() {
        let tach = if (k as f64 % samples_per_rev) < 3.0 {
            1
        } else {
            0
        };
        csv.push_str(&format!(
            "{:e},{:e},{tach}\n",
            signals.data[0][k], signals.data[1][k]
        ));
    }
    std::fs::write(dir.path().join("rec.csv"), csv).unwrap();
    let write_obs = |entry: &str| {
        let path = dir.path().join("obs.json");
        std::fs::write(
            &path,
            format!(
                r#"{{ "cuts": [{{ "speed_rpm": 7150, "depth_mm": 2.0, "stable": true }}],
                     "signals": [{entry}] }}"#
            ),
        )
        .unwrap();
        path
    };
    let obs = write_obs(
        r#"{ "file": "rec.csv", "speed_rpm": 7150, "depth_mm": 2.0, "sample_rate_hz": 10000,
             "once_per_rev_channel": "tach", "quantity": "acceleration" }"#,
    );
    let svg = dir.path().join("diagram.svg");
    let out = succeed(
        chatter()
            .args(["oma", "--observations"])
            .arg(&obs)
            .arg("--plot")
            .arg(&svg),
    );
    let result: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(result["cuts"].as_array().unwrap().len(), 1);
    let pole = &result["poles"][0];
    assert_eq!(pole["speed_rpm"], 7150.0);
    let f = pole["frequency_hz"].as_f64().unwrap();
    let zeta = pole["damping_ratio"].as_f64().unwrap();
    assert!((f - 800.0).abs() < 0.004 * 800.0, "{pole}");
    assert!((zeta - 0.02).abs() < 0.2 * 0.02, "{pole}");
    assert_eq!(pole["repetitions"], 10);
    assert!(pole["frequency_std_hz"].as_f64().unwrap() > 0.0);
    assert!(pole["note"].as_str().unwrap().contains("modified LSCE"));
    // the output is itself a valid observations file
    let reread = dir.path().join("poles.json");
    std::fs::write(&reread, &out).unwrap();
    chatter_dynamics::Observations::from_path(&reread).unwrap();
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));

    for (entry, expected) in [
        (
            r#"{ "file": "rec.csv", "speed_rpm": 7150, "depth_mm": 2.0 }"#,
            "sample_rate_hz",
        ),
        (
            r#"{ "file": "rec.csv", "speed_rpm": 7150, "depth_mm": 2.0, "sample_rate_hz": 10000,
                 "once_per_rev_channel": "tacho" }"#,
            "once_per_rev_channel",
        ),
        (
            r#"{ "file": "missing.csv", "speed_rpm": 7150, "depth_mm": 2.0,
                 "sample_rate_hz": 10000 }"#,
            "missing.csv",
        ),
    ] {
        let obs = write_obs(entry);
        let err = fail(chatter().args(["oma", "--observations"]).arg(&obs));
        assert!(
            err.contains("obs.json") && err.contains("signals[0]") && err.contains(expected),
            "{err}"
        );
    }
}

/// `dir/obs.json`: observations with one signal record, `file` plus the JSON `fields`.
fn one_signal_observations(dir: &Path, file: &Path, fields: &str) -> PathBuf {
    let obs = dir.join("obs.json");
    std::fs::write(
        &obs,
        format!(
            r#"{{ "signals": [ {{ "file": {:?}, {fields} }} ] }}"#,
            file.to_str().unwrap()
        ),
    )
    .unwrap();
    obs
}

/// A model file in `dir` whose dynamics are the CutPro tool-tip FRFs (`measured_frf`, x and
/// y) with the files' cutting coefficients, and the two FRF paths; None (test skipped) when the
/// real data are absent.
fn cutpro_measured_model(dir: &Path) -> Option<(PathBuf, PathBuf, PathBuf)> {
    let x = real_data("cutpro_frf/General_FRFX.frf")?;
    let y = real_data("cutpro_frf/General_FRFY.frf")?;
    let path = dir.join("cutpro.json");
    let model = serde_json::json!({
        "operation": {"kind": "milling", "teeth": 2, "radial_immersion": 0.5,
                      "direction": "down", "tool_diameter_mm": 31.75},
        "cutting": {"kt_n_per_mm2": 1319.4, "kn_n_per_mm2": 788.8},
        "measured_frf": [{"file": x, "direction": "x"}, {"file": y, "direction": "y"}]
    });
    std::fs::write(&path, model.to_string()).unwrap();
    Some((path, x, y))
}

fn real_data(path: &str) -> Option<PathBuf> {
    let p = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/real"
    ))
    .join(path);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("skipped: {} is absent", p.display());
        None
    }
}

#[test]
fn lobes_zoa_from_measured_frf_and_clear_error_for_other_methods() {
    let dir = tempfile::tempdir().unwrap();
    let csv = succeed(
        chatter()
            .arg("frf")
            .arg("--model")
            .arg(example("schmitz2023_milling_model.json"))
            .args(["--fmin-hz", "0", "--fmax-hz", "2500", "--points", "2501"]),
    );
    std::fs::write(dir.path().join("xx.csv"), &csv).unwrap();
    let model = dir.path().join("measured.json");
    std::fs::write(
        &model,
        r#"{"operation": {"kind": "milling", "teeth": 4, "radial_immersion": 0.2, "direction": "down"},
            "cutting": {"ks_n_per_mm2": 750, "beta_deg": 68},
            "measured_frf": [{"file": "xx.csv", "direction": "x"}, {"file": "xx.csv", "direction": "y"}]}"#,
    )
    .unwrap();
    let zoa_lobes = |model: &Path| {
        succeed(
            chatter()
                .args([
                    "lobes",
                    "--method",
                    "zoa",
                    "--speeds",
                    "4000:12000:5",
                    "--model",
                ])
                .arg(model),
        )
    };
    let measured = zoa_lobes(&model);
    let modal = zoa_lobes(&example("schmitz2023_milling_model.json"));
    let depths = |t: &str| -> Vec<f64> {
        t.lines()
            .skip(1)
            .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
            .collect()
    };
    for (a, b) in depths(&measured).iter().zip(depths(&modal)) {
        assert!((a / b - 1.0).abs() < 5e-3, "{a} vs {b}");
    }
    let err = fail(
        chatter()
            .args(["lobes", "--method", "fdm", "--model"])
            .arg(&model),
    );
    assert!(
        err.contains("--method zoa") && err.contains("fit-frf"),
        "{err}"
    );
}

#[test]
fn fit_frf_writes_a_model_and_a_plot_for_the_real_tap_test() {
    let Some(frf) =
        real_data("tap_test_tool_holder/ExperimentalModalAnalysis_Point_1_Channel_1_CH1.txt")
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (out, plot) = (dir.path().join("fitted.json"), dir.path().join("fit.svg"));
    let report = succeed(
        chatter()
            .arg("fit-frf")
            .arg("--frf")
            .arg(&frf)
            .args(["--fmin-hz", "300", "--fmax-hz", "3500", "--model"])
            .arg(example("schmitz2023_milling_model.json"))
            .arg("--out")
            .arg(&out)
            .arg("--plot")
            .arg(&plot),
    );
    let r: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert!(
        r["nrmse_complex_modes_with_residuals"].as_f64().unwrap() < 0.08,
        "{report}"
    );
    succeed(chatter().arg("check").arg("--model").arg(&out));
    assert!(std::fs::read_to_string(&plot).unwrap().contains("<svg"));
    let err = fail(
        chatter()
            .arg("fit-frf")
            .arg("--frf")
            .arg(&frf)
            .args(["--fmin-hz", "3500", "--fmax-hz", "300", "--out"])
            .arg(&out),
    );
    assert!(err.contains("--fmax-hz 300"), "{err}");
}

/// Depth (mm) per row of a `speed_rpm,depth_mm,chatter_hz` lobes CSV.
fn lobe_depths(csv: &str) -> Vec<f64> {
    csv.lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .nth(1)
                .unwrap()
                .parse()
                .unwrap_or(f64::INFINITY)
        })
        .collect()
}

/// The CutPro tool-tip FRFs (x, y) fitted one after the other by `chatter fit-frf` into one
/// model file (the fit picks complex modes: the files' residues are non-proportional), then the
/// zero-order lobes of that FILE against the lobes straight from the FRFs (`measured_frf`):
/// within 3 % at every speed and in the minimum (the issue's must-show; measured 1.8e-3 in the
/// library test). The same file refuses FDM with the method and mode named.
#[test]
fn fit_frf_complex_modes_reproduce_the_cutpro_lobes() {
    let dir = tempfile::tempdir().unwrap();
    let Some((base, x, y)) = cutpro_measured_model(dir.path()) else {
        return;
    };
    let (fit_x, fit_xy) = (dir.path().join("x.json"), dir.path().join("xy.json"));
    for (frf, direction, from, to) in [(&x, "x", &base, &fit_x), (&y, "y", &fit_x, &fit_xy)] {
        let report = succeed(
            chatter()
                .arg("fit-frf")
                .arg("--frf")
                .arg(frf)
                .args([
                    "--fmin-hz",
                    "100",
                    "--fmax-hz",
                    "3000",
                    "--direction",
                    direction,
                ])
                .arg("--model")
                .arg(from)
                .arg("--out")
                .arg(to)
                // y also writes its residual terms, which only the zero-order method takes
                .args((direction == "y").then_some("--with-residuals")),
        );
        let r: serde_json::Value = serde_json::from_str(&report).unwrap();
        assert_eq!(r["modes_in_model"], "complex", "{report}");
        assert_eq!(r["residuals_in_model"], direction == "y", "{report}");
        assert!(
            r["nrmse_complex_modes"].as_f64().unwrap() < 1e-3,
            "{report}"
        );
    }
    let text = std::fs::read_to_string(&fit_xy).unwrap();
    let file: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(file["modes"].as_array().unwrap().len(), 4, "{text}");
    assert_eq!(file["residuals"][0]["direction"], "y", "{text}");
    let lobes = |m: &PathBuf| {
        lobe_depths(&succeed(
            chatter()
                .args([
                    "lobes",
                    "--method",
                    "zoa",
                    "--speeds",
                    "3000:22950:400",
                    "--model",
                ])
                .arg(m),
        ))
    };
    let (direct, fitted) = (lobes(&base), lobes(&fit_xy));
    assert_eq!(direct.len(), 400);
    let mut worst: f64 = 0.0;
    for (d, f) in direct.iter().zip(&fitted) {
        assert_eq!(d.is_finite(), f.is_finite(), "{d} vs {f}");
        if d.is_finite() {
            worst = worst.max((f / d - 1.0).abs());
        }
    }
    let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let minimum = (min(&fitted) / min(&direct) - 1.0).abs();
    eprintln!(
        "CutPro lobes from the fitted file vs direct: {worst:.2e} at each speed, {minimum:.2e} in the minimum"
    );
    assert!(worst < 0.03 && minimum < 0.03, "{worst} {minimum}");
    let err = fail(
        chatter()
            .args([
                "lobes",
                "--method",
                "fdm",
                "--speeds",
                "5000:6000:3",
                "--model",
            ])
            .arg(&fit_xy),
    );
    assert!(err.contains("fdm") && err.contains("residuals[y]"), "{err}");
    // residual terms come with the complex modes they were fitted with
    let err = fail(
        chatter()
            .arg("fit-frf")
            .arg("--frf")
            .arg(&x)
            .args([
                "--fmin-hz",
                "100",
                "--fmax-hz",
                "3000",
                "--mode-form",
                "real",
            ])
            .arg("--with-residuals")
            .arg("--out")
            .arg(dir.path().join("never.json")),
    );
    assert!(err.contains("--with-residuals"), "{err}");
}

/// `chatter bands --kind geometric` on the CutPro `measured_frf` model: with stated offsets
/// (the zero-order lobes straight from the FRFs), and with `--gain-sd 0.05 --frequency-sd 0.01`
/// (40 draws, seed 17): the offsets printed are 2 sd of the pocket over the FRF draws, checked
/// against the exact map of each draw, (Omega, b) -> ((1 + e) Omega, b / (1 + g)) of the
/// pocket of `chatter lobes` (within 2 %: the pocket's speed grid of 25 rpm and the printed
/// digits); bad uses are refused.
#[test]
fn bands_on_measured_frf_with_offsets_from_the_frf_uncertainty() {
    let dir = tempfile::tempdir().unwrap();
    let Some((model, _, _)) = cutpro_measured_model(dir.path()) else {
        return;
    };
    let speeds = ["--speeds", "4500:7500:121"];
    let stated = succeed(
        chatter()
            .args([
                "bands",
                "--kind",
                "geometric",
                "--offset-rpm",
                "100",
                "--model",
            ])
            .arg(&model)
            .args(speeds),
    );
    assert!(
        stated.starts_with("speed_rpm,depth_mm,lower_mm,upper_mm"),
        "{stated}"
    );
    let lobes = succeed(
        chatter()
            .args(["lobes", "--method", "zoa", "--model"])
            .arg(&model)
            .args(speeds),
    );
    let depths = lobe_depths(&lobes);
    let i = (0..depths.len())
        .min_by(|&a, &b| depths[a].total_cmp(&depths[b]))
        .unwrap();
    let (speed, depth) = (4500.0 + 25.0 * i as f64, depths[i]);
    let out = chatter()
        .args([
            "bands",
            "--kind",
            "geometric",
            "--gain-sd",
            "0.05",
            "--frequency-sd",
            "0.01",
        ])
        .args(["--samples", "40", "--seed", "17", "--model"])
        .arg(&model)
        .args(speeds)
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("offsets from the FRF"))
        .unwrap();
    let numbers: Vec<f64> = line
        .rsplit("): ")
        .next()
        .unwrap()
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|t| t.parse().ok())
        .collect();
    let (offset_rpm, offset_mm) = (numbers[0], numbers[1]);
    let draws = chatter_uncertainty::measured::FrfUncertainty::new(0.05, 0.01)
        .unwrap()
        .draws(40, 17);
    let sd = |v: Vec<f64>| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
    };
    let exact_rpm = 2.0 * sd(draws.iter().map(|(_, e)| (1.0 + e) * speed).collect());
    let exact_mm = 2.0 * sd(draws.iter().map(|(g, _)| depth / (1.0 + g)).collect());
    eprintln!(
        "FRF bands: {offset_rpm} rpm / {offset_mm} mm vs exact map {exact_rpm:.1} / {exact_mm:.4}"
    );
    assert!(
        (offset_rpm / exact_rpm - 1.0).abs() < 0.02,
        "{line} vs {exact_rpm}"
    );
    assert!(
        (offset_mm / exact_mm - 1.0).abs() < 0.02,
        "{line} vs {exact_mm}"
    );
    for (args, expected) in [
        (vec!["--gain-sd", "0.5"], "gain_sd"),
        (
            vec!["--gain-sd", "0.05", "--offset-rpm", "100"],
            "give one of the two",
        ),
        (
            vec!["--gain-sd", "0.05", "--kind", "montecarlo"],
            "--gain-sd",
        ),
    ] {
        let e = fail(
            chatter()
                .arg("bands")
                .arg("--model")
                .arg(&model)
                .args(speeds)
                .args(args),
        );
        assert!(e.contains(expected), "{e}");
    }
    let e = fail(
        chatter()
            .args(["bands", "--gain-sd", "0.05", "--model"])
            .arg(example("schmitz2023_milling_model.json")),
    );
    assert!(e.contains("no measured_frf"), "{e}");
}

/// `chatter detect` on two records written by `chatter simulate` (seed 001's milling example at
/// 7000 rpm, where the full-discretization limit is 0.97 mm): 0.5 mm is stable, 1.5 mm chatters
/// near the 760 Hz the lobe diagram gives; the plots are written; a CSV record without its
/// sample rate is a clear error.
#[test]
fn detect_labels_simulated_cuts() {
    let dir = tempfile::tempdir().unwrap();
    for (name, depth) in [("stable.csv", "0.5"), ("chatter.csv", "1.5")] {
        succeed(chatter().args([
            "simulate",
            "--model",
            example("schmitz2023_milling_model.json").to_str().unwrap(),
            "--speed-rpm",
            "7000",
            "--depth-mm",
            depth,
            "--duration-s",
            "4",
            "--sample-rate-hz",
            "10000",
            "--seed",
            "1",
            "--out",
            dir.path().join(name).to_str().unwrap(),
        ]));
    }
    let obs = dir.path().join("obs.json");
    std::fs::write(
        &obs,
        r#"{ "signals": [
            { "file": "stable.csv", "speed_rpm": 7000, "depth_mm": 0.5, "sample_rate_hz": 10000,
              "once_per_rev_channel": "once_per_rev" },
            { "file": "chatter.csv", "speed_rpm": 7000, "depth_mm": 1.5, "sample_rate_hz": 10000 }
        ] }"#,
    )
    .unwrap();
    let plots = dir.path().join("plots");
    let out = succeed(chatter().args([
        "detect",
        "--observations",
        obs.to_str().unwrap(),
        "--model",
        example("schmitz2023_milling_model.json").to_str().unwrap(),
        "--plot",
        plots.to_str().unwrap(),
    ]));
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let cuts = json["cuts"].as_array().unwrap();
    assert_eq!(cuts.len(), 2);
    assert_eq!(cuts[0]["stable"], true, "{out}");
    assert!(cuts[0].get("chatter_hz").is_none());
    assert_eq!(cuts[1]["stable"], false, "{out}");
    let f = cuts[1]["chatter_hz"].as_f64().unwrap();
    assert!((740.0..790.0).contains(&f), "{f}");
    // the simulator adds no mains hum: the note says none was found; the model's 4 teeth make
    // the flip lines judged, and the note says how the windows judged the record
    let note = cuts[1]["note"].as_str().unwrap();
    assert!(
        note.starts_with("detect chatter.csv; no interference comb found in 45-65 Hz; "),
        "{note}"
    );
    assert!(
        note.contains("flip line") && note.contains("window"),
        "{note}"
    );
    let evidence = &cuts[1]["evidence"];
    assert!(
        (evidence["line_hz"].as_f64().unwrap() - f).abs() < 1e-9,
        "{evidence}"
    );
    assert!(evidence["margin"].as_f64().unwrap() >= 0.0, "{evidence}");
    assert!(
        cuts[0]["evidence"]["margin"].as_f64().unwrap() < 0.0,
        "{out}"
    );
    assert!(plots.join("detect-1.svg").exists() && plots.join("detect-2.svg").exists());
    // the output is an observations file again
    std::fs::write(dir.path().join("labels.json"), &out).unwrap();
    succeed(chatter().args([
        "check",
        "--model",
        example("schmitz2023_milling_model.json").to_str().unwrap(),
        "--observations",
        dir.path().join("labels.json").to_str().unwrap(),
    ]));
    std::fs::write(
        &obs,
        r#"{ "signals": [ { "file": "stable.csv", "speed_rpm": 7000, "depth_mm": 0.5 } ] }"#,
    )
    .unwrap();
    let err = fail(chatter().args(["detect", "--observations", obs.to_str().unwrap()]));
    assert!(err.contains("sample_rate_hz"), "{err}");
}

/// `lobes --method zoa` honours the model's process damping (issue 14): on the 003-like flexure
/// (228 Hz in x, 1 tooth, 50 % up milling, C = 2.5e5 N/m) the zero-order limit at 300 rpm is
/// 1.698 mm with it (`chatter_stability::zero_order::limiting_depths`) against 0.780 mm without;
/// at 3000 rpm, where V is ten times higher, process damping adds less (0.863 against 0.821 mm).
#[test]
fn zoa_lobes_include_process_damping() {
    let dir = tempfile::tempdir().unwrap();
    let model = |c: Option<f64>| {
        let pd = c.map_or(String::new(), |c| {
            format!(r#", "process_damping": {{"c_n_per_m": {c}}}"#)
        });
        format!(
            r#"{{"operation": {{"kind": "milling", "teeth": 1, "radial_immersion": 0.5, "direction": "up", "tool_diameter_mm": 18.54}}, "cutting": {{"kt_n_per_mm2": 2111.2, "kn_n_per_mm2": 1052.6}}, "modes": [{{"frequency_hz": 228.0, "damping_ratio": 0.02, "stiffness_n_per_m": 5.6e6, "direction": "x"}}]{pd}}}"#
        )
    };
    let mut depths = Vec::new();
    for (name, c) in [("damped.json", Some(2.5e5)), ("bare.json", None)] {
        let path = dir.path().join(name);
        std::fs::write(&path, model(c)).unwrap();
        let csv = succeed(
            chatter()
                .args([
                    "lobes",
                    "--quiet",
                    "--method",
                    "zoa",
                    "--speeds",
                    "300:3000:2",
                ])
                .arg("--model")
                .arg(&path),
        );
        let row: Vec<f64> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
            .collect();
        depths.push(row);
    }
    for (got, expected) in depths.iter().flatten().zip([1.698, 0.863, 0.780, 0.821]) {
        assert!((got - expected).abs() < 2e-3, "{got} vs {expected}");
    }
}

/// `chatter detect` and `chatter oma` on the real chatter record `test255_accelY.csv` (shared
/// data folder; slot milling at 5000 rpm, labelled chatter by its authors), without the mains
/// frequency given: detection finds the 50 Hz mains comb, reports it in the cut's note, and
/// calls the record chatter (near 684 Hz, off every multiple of 50 Hz and of the spindle
/// frequency); the OMA refuses the record, naming the comb and the option that overrides the
/// refusal, and still does with the mains given (`--interference-hz 50`); with
/// `--allow-chatter` the pole is flagged in its note and is no forced line (at least 1 Hz from
/// every multiple of 50 Hz and of the spindle frequency: before issue 16 it was 150.01 Hz).
/// `--interference-hz none` turns the search off (detection then says stable: the 150 Hz mains
/// line wins); a bad value is a clear error. Skipped with a message when the data are absent.
#[test]
fn oma_refuses_the_real_chatter_record() {
    let Some(record) = real_data("milling_chatter_record/test255_accelY.csv") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let obs = one_signal_observations(
        dir.path(),
        &record,
        r#""speed_rpm": 5000, "depth_mm": 2.6, "sample_rate_hz": 10000"#,
    );
    let off = |f: f64, base: f64| (f - (f / base).round().max(1.0) * base).abs();
    let detect = ["detect", "--observations", obs.to_str().unwrap()];
    let out = succeed(chatter().args(detect));
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let cut = &json["cuts"][0];
    assert_eq!(cut["stable"], false, "{cut}");
    let f = cut["chatter_hz"].as_f64().unwrap();
    assert!(off(f, 50.0) > 2.0 && off(f, 5000.0 / 60.0) > 2.0, "{cut}");
    let note = cut["note"].as_str().unwrap();
    assert!(
        note.contains("interference comb found and left out: 50.0"),
        "{note}"
    );
    let out = succeed(chatter().args(detect).args(["--interference-hz", "none"]));
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(json["cuts"][0]["stable"], true, "{out}");
    let err = fail(chatter().args(detect).args(["--interference-hz", "50,x"]));
    assert!(err.contains("--interference-hz `x`"), "{err}");

    let args = ["oma", "--observations", obs.to_str().unwrap()];
    let err = fail(chatter().args(args));
    assert!(
        err.contains("chatter detection calls this record chatter")
            && err.contains("interference comb found and left out: 50.0")
            && err.contains("--allow-chatter"),
        "{err}"
    );
    let err = fail(chatter().args(args).args(["--interference-hz", "50"]));
    assert!(
        err.contains("chatter detection calls this record chatter")
            && err.contains("interference given"),
        "{err}"
    );
    let out = succeed(chatter().args(args).args(["--allow-chatter"]));
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let pole = &json["poles"][0];
    assert!(pole["note"].as_str().unwrap().contains("FLAGGED"), "{pole}");
    let f = pole["frequency_hz"].as_f64().unwrap();
    assert!(off(f, 50.0) > 1.0 && off(f, 5000.0 / 60.0) > 1.0, "{pole}");
}

/// `chatter detect --estimate-speed` on the no-chatter sound clip of the shared data folder
/// (cutting conditions not recorded): the spindle speed is estimated from the clip's harmonic
/// comb at 5496 rpm (91.6 Hz; its lines 91.5, 366.7, 732.8, 1007.4, 1099.5 Hz are multiples 1, 4,
/// 8, 11, 12, checked with a separate Welch spectrum), written as the cut's `speed_rpm` and named
/// in its note, and the cut is stable, as labelled. The chatter clip is chatter at 1067.6 Hz
/// (the cut's dominant line; the background tone at 2329.9 Hz before and after the cut is a
/// reference stretch). Skipped with a message when the data are absent.
#[test]
fn detect_estimates_the_speed_of_a_sound_clip() {
    let Some(clip) = real_data("milling_chatter_record/metalcutting_nochatter8058.mp3") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let obs = one_signal_observations(
        dir.path(),
        &clip,
        r#""speed_rpm": 1000, "depth_mm": 1, "quantity": "sound""#,
    );
    let out = succeed(chatter().args([
        "detect",
        "--estimate-speed",
        "--observations",
        obs.to_str().unwrap(),
    ]));
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let cut = &json["cuts"][0];
    assert_eq!(cut["stable"], true, "{cut}");
    let rpm = cut["speed_rpm"].as_f64().unwrap();
    assert!((rpm - 5496.0).abs() < 6.0, "{cut}");
    let note = cut["note"].as_str().unwrap();
    assert!(
        note.contains("speed estimated from the harmonic comb"),
        "{note}"
    );
    // the chatter clip: its background before and after the cut is a reference stretch, and
    // the cut's dominant line is the chatter (tests/oma_detection.rs)
    let Some(clip) = real_data("milling_chatter_record/combined_chatter6567.mp3") else {
        return;
    };
    let obs = one_signal_observations(
        dir.path(),
        &clip,
        r#""speed_rpm": 1000, "depth_mm": 1, "quantity": "sound""#,
    );
    let out = succeed(chatter().args([
        "detect",
        "--estimate-speed",
        "--observations",
        obs.to_str().unwrap(),
    ]));
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let cut = &json["cuts"][0];
    assert_eq!(cut["stable"], false, "{cut}");
    let f = cut["chatter_hz"].as_f64().unwrap();
    assert!((1062.0..=1072.0).contains(&f), "{cut}");
    let note = cut["note"].as_str().unwrap();
    assert!(
        note.contains("reference stretch without the cut")
            && note.contains("carrying over half of the cut's power"),
        "{note}"
    );
}

/// `chatter oma` overrides: a model order range, the segment count, an explicit harmonic list
/// and no decimation reach the identification (the note reports the order and the imposed
/// harmonics); bad values are clear errors naming the option or field.
#[test]
fn oma_overrides_reach_the_identification() {
    let dir = tempfile::tempdir().unwrap();
    let signals =
        chatter_oma::synthetic::SyntheticRecord::single_mode(800.0, 0.02, 0.1, 10_000.0, 4.0, 2)
            .generate()
            .unwrap();
    let mut csv = String::from("a\n");
    for v in &signals.data[0] {
        csv.push_str(&format!("{v:e}\n"));
    }
    std::fs::write(dir.path().join("rec.csv"), csv).unwrap();
    let obs = dir.path().join("obs.json");
    std::fs::write(
        &obs,
        r#"{ "signals": [ { "file": "rec.csv", "speed_rpm": 6000, "depth_mm": 1.0,
             "sample_rate_hz": 10000 } ] }"#,
    )
    .unwrap();
    let base = ["oma", "--observations", obs.to_str().unwrap()];
    let svg = dir.path().join("d.svg");
    let out = succeed(chatter().args(base).args([
        "--min-order",
        "2",
        "--max-order",
        "12",
        "--segments",
        "4",
        "--harmonics-hz",
        "1234.5",
        "--decimation",
        "1",
        "--plot",
        svg.to_str().unwrap(),
    ]));
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let pole = &json["poles"][0];
    assert_eq!(pole["repetitions"], 4, "{pole}");
    assert!(
        pole["note"].as_str().unwrap().contains("[1234.5]"),
        "{pole}"
    );
    let f = pole["frequency_hz"].as_f64().unwrap();
    assert!((f - 800.0).abs() < 0.005 * 800.0, "{pole}");
    let orders = std::fs::read_to_string(dir.path().join("d-orders.svg")).unwrap();
    assert!(orders.contains("<svg") && orders.contains("model order"));
    let err = fail(chatter().args(base).args(["--harmonics-hz", "abc"]));
    assert!(err.contains("--harmonics-hz"), "{err}");
    let err = fail(
        chatter()
            .args(base)
            .args(["--min-order", "9", "--max-order", "3"]),
    );
    assert!(err.contains("min_order"), "{err}");
    let err = fail(chatter().args(base).args(["--segments", "0"]));
    assert!(err.contains("segments"), "{err}");
}

/// `chatter sensitivity` reproduces 000 Table 3 at P1 (7150 rpm, 2.286 mm) within 3 % on the
/// one-step map; the period map's derivative is m |mu|^((m-1)/m) times larger.
#[test]
fn sensitivity_reproduces_table3_at_p1() {
    let run = |map: &str| -> serde_json::Value {
        let text = succeed(
            chatter()
                .args(["sensitivity", "--model"])
                .arg(example("ahmadi2022_turning_model.json"))
                .args(["--speed-rpm", "7150", "--depth-mm", "2.286", "--map", map])
                .args(["--parameters", "theta_omega_2,theta_zeta_2,theta_phi_2"]),
        );
        serde_json::from_str(&text).unwrap()
    };
    let one = run("one-step");
    assert_eq!(one["steps_per_delay"], 200);
    let s = one["sensitivities"].as_array().unwrap();
    for (e, paper) in s.iter().zip([0.3105, 0.0028, 0.0078]) {
        let m = e["modulus"].as_f64().unwrap();
        assert!((m - paper).abs() < 0.03 * paper, "{e}");
    }
    let period = run("period");
    let mu = period["eigenvalue"]["modulus"].as_f64().unwrap();
    let ratio =
        period["sensitivities"][0]["modulus"].as_f64().unwrap() / s[0]["modulus"].as_f64().unwrap();
    assert!(
        (ratio - 200.0 * mu.powf(199.0 / 200.0)).abs() < 1e-6 * ratio,
        "{ratio}"
    );
    let err = fail(
        chatter()
            .args(["sensitivity", "--model"])
            .arg(example("schmitz2023_milling_model.json"))
            .args(["--speed-rpm", "6000", "--depth-mm", "1"]),
    );
    assert!(err.contains("period"), "{err}");
}

/// Geometric bands carry the raw Eq. 10-11 roots and write the theta and d plots (001 Figs.
/// 7-10).
#[test]
fn geometric_bands_export_raw_roots_and_theta_distance_plots() {
    let dir = tempfile::tempdir().unwrap();
    let plot = dir.path().join("b.svg");
    let text = succeed(
        chatter()
            .args(["bands", "--quiet", "--kind", "geometric", "--model"])
            .arg(example("schmitz2023_milling_model.json"))
            .args(["--speeds", "5000:7000:41", "--plot"])
            .arg(&plot),
    );
    assert!(text.starts_with(
        "speed_rpm,depth_mm,lower_mm,upper_mm,theta_deg,distance,upper_speed_rpm,\
         upper_depth_mm,lower_speed_rpm,lower_depth_mm\n"
    ));
    for f in ["b.svg", "b-theta.svg", "b-distance.svg", "b-roots.svg"] {
        assert!(dir.path().join(f).exists(), "{f}");
    }
}
