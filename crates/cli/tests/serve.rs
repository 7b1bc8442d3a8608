//! `chatter serve` as a user runs it: the built binary as a child process on a free localhost
//! port. A kill -9 during a learning job, then a restart on the same data folder: the database
//! opens, the job is marked failed, no setup, model or cut is lost. And the whole workflow in
//! real headless Chromium driven by Playwright for Python (skipped with a message when chromium
//! or the `playwright` Python package is missing), with screenshots of every screen.
#![allow(clippy::unwrap_used)]

#[path = "../../serve/tests/common/mod.rs"]
mod common;

use common::*;
use std::io::{BufRead, BufReader};
use std::net::SocketAddr;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Start `chatter serve --port 0` on `data` and read the address it prints.
fn serve(data: &Path, example: bool) -> (Child, SocketAddr) {
    let mut command = Command::new(env!("CARGO_BIN_EXE_chatter"));
    command
        .args(["serve", "--port", "0", "--data"])
        .arg(data)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit());
    if example {
        command.arg("--example");
    }
    let mut child = command.spawn().unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|rest| rest.split('/').next())
        .unwrap_or_else(|| panic!("no address in `{line}`"))
        .parse()
        .unwrap();
    (child, addr)
}

fn wait_for(what: &str, limit: Duration, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(start.elapsed() < limit, "{what}: not within {limit:?}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn kill_9_during_learning_loses_nothing_and_fails_the_job() {
    let dir = tempfile::tempdir().unwrap();
    let (mut child, addr) = serve(dir.path(), true);
    let setups = get(addr, "/api/setups").json()["setups"].clone();
    let id = setups[0]["id"].as_i64().unwrap();
    // a setup of the user's own, with a cut, beside the example
    let own = post_json(addr, "/api/setups", &setup_form("own mill")).json()["id"]
        .as_i64()
        .unwrap();
    let r = post_json(
        addr,
        &format!("/api/setups/{own}/cuts"),
        &serde_json::json!({"speed_rpm": 7000, "depth_mm": 1.0, "stable": true}),
    );
    assert_eq!(r.status, 200, "{}", r.body);
    let before: Vec<serde_json::Value> = [id, own]
        .iter()
        .map(|s| get(addr, &format!("/api/setups/{s}")).json())
        .collect();
    assert_eq!(before[0]["cuts"].as_array().unwrap().len(), 32);
    assert_eq!(before[0]["poles"], 8);
    let r = post_json(
        addr,
        &format!("/api/setups/{id}/learn"),
        &serde_json::json!({"seed": 3, "update_samples": 200, "diagnose_samples": 120}),
    );
    assert_eq!(r.status, 200, "{}", r.body);
    let job = r.json()["job"].as_i64().unwrap();
    // the job is under way: its progress reports a stage
    wait_for("the job's progress", Duration::from_secs(60), || {
        let s = get(addr, &format!("/api/jobs/{job}")).json();
        s["job"]["status"] == "running"
            && s["progress"]["stage"]
                .as_str()
                .is_some_and(|t| !t.is_empty())
    });
    std::thread::sleep(Duration::from_millis(500));
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();

    let (mut child, addr) = serve(dir.path(), true);
    let j = get(addr, &format!("/api/jobs/{job}")).json();
    assert_eq!(j["job"]["status"], "failed", "{j}");
    assert!(
        j["job"]["error"]
            .as_str()
            .unwrap()
            .contains("server stopped"),
        "{j}"
    );
    assert!(j["job"]["result"].is_null());
    assert_eq!(
        get(addr, "/api/setups").json()["setups"]
            .as_array()
            .unwrap()
            .len(),
        2,
        "the example is not seeded twice, the own setup is kept"
    );
    for (s, b) in [id, own].iter().zip(&before) {
        let after = get(addr, &format!("/api/setups/{s}")).json();
        for key in ["setup", "model", "cuts", "poles", "files", "model_versions"] {
            assert_eq!(after[key], b[key], "setup {s}: {key}");
        }
    }
    child.kill().unwrap();
    child.wait().unwrap();
}

/// Whether Playwright for Python can be imported.
fn playwright() -> bool {
    Command::new("python3")
        .args(["-c", "import playwright.sync_api"])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

#[test]
fn whole_workflow_in_headless_chromium() {
    if !Path::new("/usr/bin/chromium").exists() {
        eprintln!("skipping the browser workflow: no /usr/bin/chromium (apt-get install chromium)");
        return;
    }
    if !playwright() {
        eprintln!(
            "skipping the browser workflow: the Python package `playwright` is missing \
             (python3 -m pip install playwright; no `playwright install`, Debian's chromium is used)"
        );
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let shots = std::env::var_os("CHATTER_SCREENSHOTS")
        .map_or_else(|| dir.path().join("screenshots"), Into::into);
    std::fs::create_dir_all(&shots).unwrap();
    let tap = dir.path().join("tap_x.uff");
    std::fs::write(&tap, tap_test_uff()).unwrap();
    let recording = dir.path().join("cut_6000rpm.wav");
    std::fs::write(&recording, recording_wav(6000.0, Some(812.5))).unwrap();
    let bad = dir.path().join("photo.exe");
    std::fs::write(&bad, b"MZ not a tap test").unwrap();
    let data = dir.path().join("data");
    let (mut child, addr) = serve(&data, true);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../serve/tests/browser/workflow.py");
    let out = Command::new("python3")
        .arg(&script)
        .arg(format!("http://{addr}/"))
        .arg(&shots)
        .arg(&tap)
        .arg(&recording)
        .arg(&bad)
        .output()
        .unwrap();
    child.kill().unwrap();
    child.wait().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    eprintln!("{stdout}");
    assert!(
        out.status.success() && stdout.trim_end().ends_with("ok"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // lobes on screen within 1 s of the click, the first (computing) time included
    for line in stdout.lines().filter(|l| l.starts_with("lobes_ms")) {
        let wall: f64 = line.split(' ').nth(1).unwrap().parse().unwrap();
        assert!(wall <= 1000.0, "{line}");
    }
    for name in [
        "01-machine-and-tool",
        "03-lobes-hover",
        "04-cut-log",
        "06-learn-diagnosis",
    ] {
        assert!(shots.join(format!("{name}.png")).exists(), "{name}");
    }
}
