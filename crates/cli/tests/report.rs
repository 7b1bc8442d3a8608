//! `--report FILE.html`: the page of `bands`, `plan`, `update` and `diagnose`, rendered in
//! headless Chromium where one is installed (the demo's page is checked beside the demo run in
//! `cli.rs`), and a bad `--report` refused before the work.
#![allow(clippy::unwrap_used)]

mod browser;

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

/// Run and require success.
fn succeed(command: &mut Command) {
    let out = command.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Every section heading of the page builder is on the page, and nothing loads from elsewhere.
fn check_sections(page: &std::path::Path) -> String {
    let html = std::fs::read_to_string(page).unwrap();
    for s in [
        "Verdict", "Warnings", "Inputs", "Model", "Results", "Figures",
    ] {
        assert!(html.contains(&format!("<h2>{s}</h2>")), "{s}");
    }
    for forbidden in ["<script", "<link", "src=", "href="] {
        assert!(!html.contains(forbidden), "{forbidden}");
    }
    html
}

#[test]
fn bands_and_plan_pages_render_with_their_figures() {
    let dir = tempfile::tempdir().unwrap();
    let bands = dir.path().join("bands.html");
    succeed(
        chatter()
            .args([
                "bands",
                "--quiet",
                "--kind",
                "geometric",
                "--speeds",
                "4000:14000:400",
                "--out",
            ])
            .arg(dir.path().join("bands.csv"))
            .arg("--model")
            .arg(example("schmitz2023_milling_model.json"))
            .arg("--report")
            .arg(&bands),
    );
    let html = check_sections(&bands);
    assert_eq!(
        html.matches("<figure>").count(),
        4,
        "band, theta, distance, raw roots"
    );
    browser::check(
        &bands,
        &[
            "the deepest stable pocket reaches",
            "lower offset boundary",
            "rpm",
            " mm",
            "N/mm^2",
            "--speeds",
            "Hz",
        ],
    );

    let plan = dir.path().join("plan.html");
    succeed(
        chatter()
            .args(["plan", "--quiet", "--paths", "40", "--strategy", "mrr"])
            .arg("--model")
            .arg(example("ebrahimi2025_milling_model.json"))
            .arg("--observations")
            .arg(example("ebrahimi2025_milling_observations.json"))
            .arg("--report")
            .arg(&plan),
    );
    check_sections(&plan);
    browser::check(
        &plan,
        &[
            "Next test: cut at",
            "rpm",
            "mm deep",
            "probability of stability",
            "cm^3/min",
            "kt_n_per_mm2",
        ],
    );
}

#[test]
fn update_and_diagnose_pages_hold_their_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let update = dir.path().join("update.html");
    succeed(
        chatter()
            .args([
                "update",
                "--quiet",
                "--classes",
                "0.5,1",
                "--samples",
                "60",
                "--seed",
                "3",
                "--model",
            ])
            .arg(example("ahmadi2022_turning_model.json"))
            .arg("--observations")
            .arg(example("ahmadi2022_turning_observations.json"))
            .arg("--out")
            .arg(dir.path().join("posterior"))
            .arg("--report")
            .arg(&update),
    );
    let html = check_sections(&update);
    assert_eq!(html.matches("<figure>").count(), 2, "evidence, corner");
    for needed in [
        "The data select the model class alpha = ",
        "theta_omega_2",
        "1 (relative change)",
        "ln p(D | M) (nats)",
        "identified (Hz)",
        "--samples</th><td>60</td>",
    ] {
        assert!(html.contains(needed), "{needed}");
    }

    let diagnose = dir.path().join("diagnose.html");
    succeed(
        chatter()
            .args([
                "diagnose",
                "--quiet",
                "--seed",
                "1",
                "--samples",
                "40",
                "--validation",
                "off",
                "--model",
            ])
            .arg(example("ebrahimi2025_milling_model.json"))
            .arg("--observations")
            .arg(example("ebrahimi2025_milling_observations.json"))
            .arg("--report")
            .arg(&diagnose),
    );
    let html = check_sections(&diagnose);
    assert_eq!(html.matches("<figure>").count(), 2, "lobes, residuals");
    for needed in [
        "Verdict: ",
        "ln evidence (nats)",
        "solver failures / evaluations",
        "Posterior predictive check",
    ] {
        assert!(html.contains(needed), "{needed}");
    }
    // without --out nothing but the page is written
    let mut names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["diagnose.html", "posterior", "update.html"]);
}

#[test]
fn a_bad_report_path_is_refused_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no/such/page.html");
    let model = example("ebrahimi2025_milling_model.json");
    let obs = example("ebrahimi2025_milling_observations.json");
    let commands: [Vec<std::ffi::OsString>; 4] = [
        vec!["bands".into(), "--model".into(), model.clone().into()],
        vec![
            "plan".into(),
            "--strategy".into(),
            "mrr".into(),
            "--model".into(),
            model.clone().into(),
            "--observations".into(),
            obs.clone().into(),
        ],
        vec![
            "diagnose".into(),
            "--seed".into(),
            "1".into(),
            "--model".into(),
            model.clone().into(),
            "--observations".into(),
            obs.clone().into(),
        ],
        vec![
            "update".into(),
            "--seed".into(),
            "1".into(),
            "--out".into(),
            dir.path().join("posterior").into(),
            "--model".into(),
            model.into(),
            "--observations".into(),
            obs.into(),
        ],
    ];
    for args in commands {
        for report in [missing.clone(), dir.path().to_path_buf()] {
            let out = chatter()
                .arg(&args[0])
                .arg("--quiet")
                .args(&args[1..])
                .arg("--report")
                .arg(&report)
                .output()
                .unwrap();
            let err = String::from_utf8(out.stderr).unwrap();
            assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
            assert!(
                err.contains("--report") && !err.contains("panicked"),
                "{args:?}: {err}"
            );
        }
    }
    assert!(!dir.path().join("posterior").exists());
}
