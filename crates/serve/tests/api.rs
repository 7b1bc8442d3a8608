//! The HTTP API on a real localhost server: the workflow from tap test to detected cuts, bad
//! uploads refused with a message and nothing kept, cross-origin requests refused, and twenty
//! concurrent clients asking for lobes.
#![allow(clippy::unwrap_used)]

mod common;

use chatter_serve::{App, router};
use common::*;
use std::net::SocketAddr;
use std::path::Path;

/// A server on 127.0.0.1 (any free port) over the data folder `dir`, in a thread of its own.
fn start(dir: &Path) -> (SocketAddr, std::sync::Arc<App>) {
    let app = App::open(dir, true).unwrap();
    let served = app.clone();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let runtime = tokio::runtime::Runtime::new().unwrap();
        runtime.block_on(async move {
            let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
            tx.send(listener.local_addr().unwrap()).unwrap();
            axum::serve(listener, router(served)).await.unwrap();
        });
    });
    (rx.recv().unwrap(), app)
}

fn new_setup(addr: SocketAddr, name: &str) -> i64 {
    let r = post_json(addr, "/api/setups", &setup_form(name));
    assert_eq!(r.status, 200, "{}", r.body);
    r.json()["id"].as_i64().unwrap()
}

/// Files under a folder of the data folder.
fn files_in(dir: &Path, sub: &str) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir.join(sub))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn tap_test_fit_lobes_and_detected_cuts() {
    let dir = tempfile::tempdir().unwrap();
    let (addr, _) = start(dir.path());
    assert!(get(addr, "/").body.contains("Machine &amp; tool"));
    assert!(get(addr, "/assets/app.js").body.contains("function chart"));
    let id = new_setup(addr, "tap test mill");

    // the fit recovers the mode the tap test was written from: noise-free data, so LSCF and
    // the least-squares refinement should land within 0.5 % in frequency and 5 % in stiffness
    // and damping (the real-mode refit's stiffness over a band that cuts the mode's tails)
    for (name, text) in [("tap.csv", tap_test_csv()), ("tap.uff", tap_test_uff())] {
        let r = post_form(
            addr,
            &format!("/api/setups/{id}/frf"),
            &[("direction", "xy")],
            Some((name, text.as_bytes())),
        );
        assert_eq!(r.status, 200, "{name}: {}", r.body);
        let fit = &r.json()["fit"];
        let modes = fit["modes"].as_array().unwrap();
        assert_eq!(modes.len(), 1, "{name}: {modes:?}");
        let (fn_hz, zeta, k) = TAP_MODE;
        let f = modes[0]["frequency_hz"].as_f64().unwrap();
        let z = modes[0]["damping_ratio"].as_f64().unwrap();
        let s = modes[0]["stiffness_n_per_m"].as_f64().unwrap();
        assert!((f / fn_hz - 1.0).abs() < 0.005, "{name}: {f} Hz");
        assert!((z / zeta - 1.0).abs() < 0.05, "{name}: zeta {z}");
        assert!((s / k - 1.0).abs() < 0.05, "{name}: k {s}");
        assert!(fit["overlay_um_per_n"].as_array().unwrap().len() > 100);
        assert!(!fit["stabilization"].as_array().unwrap().is_empty());
    }
    let detail = get(addr, &format!("/api/setups/{id}")).json();
    assert_eq!(detail["model_versions"], 2);
    let modes = detail["model"]["model"]["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 2, "x and y of the symmetric tool: {modes:?}");

    // lobes: the diagram, the bands, the recommendation below its own limit
    let r = get(
        addr,
        &format!("/api/setups/{id}/lobes?max_depth_mm=20&risk=0.05"),
    );
    assert_eq!(r.status, 200, "{}", r.body);
    let d = &r.json()["diagram"];
    let lobes = d["lobes"].as_array().unwrap();
    assert!(lobes.len() >= 200, "{} speeds", lobes.len());
    let rec = &d["recommended"];
    let depth = rec["depth_mm"].as_f64().unwrap();
    assert!(depth > 0.0 && depth <= rec["limiting_depth_mm"].as_f64().unwrap());
    // the limit at the recommended speed is the diagram's at that speed
    let speed = rec["speed_rpm"].as_f64().unwrap();
    let at = lobes
        .iter()
        .find(|p| p[0].as_f64() == Some(speed))
        .expect("the recommended speed is a speed of the diagram");
    assert_eq!(at[1].as_f64(), rec["limiting_depth_mm"].as_f64());
    assert!(!d["upper"].as_array().unwrap().is_empty());

    // a cut entered by hand, then two recordings whose truth is known by construction
    let r = post_json(
        addr,
        &format!("/api/setups/{id}/cuts"),
        &serde_json::json!({"speed_rpm": 6000, "depth_mm": 1.5, "stable": true}),
    );
    assert_eq!(r.status, 200, "{}", r.body);
    let stable = recording_wav(6000.0, None);
    let chatter = recording_wav(6000.0, Some(812.5));
    let judge = |name: &str, bytes: &[u8]| {
        let r = post_form(
            addr,
            &format!("/api/setups/{id}/recordings"),
            &[("speed_rpm", "6000"), ("depth_mm", "2")],
            Some((name, bytes)),
        );
        assert_eq!(r.status, 200, "{name}: {}", r.body);
        r.json()["detection"].clone()
    };
    let d = judge("quiet cut.wav", &stable);
    assert_eq!(d["verdict"], "stable", "{d}");
    let d = judge("loud cut.wav", &chatter);
    assert_eq!(d["verdict"], "chatter", "{d}");
    // within two frequency bins of the sine written into the record
    let resolution = d["evidence"]["resolution_hz"].as_f64().unwrap();
    assert!(
        (d["chatter_hz"].as_f64().unwrap() - 812.5).abs() <= 2.0 * resolution,
        "{d}"
    );
    assert!(d["note"].as_str().unwrap().contains("loud cut.wav"));

    // the user overrules the stable verdict
    let detail = get(addr, &format!("/api/setups/{id}")).json();
    let cuts = detail["cuts"].as_array().unwrap();
    assert_eq!(cuts.len(), 3);
    assert_eq!(cuts[1]["origin"], "detected");
    assert_eq!(cuts[1]["recording"], "quiet cut.wav");
    let r = post_json(
        addr,
        &format!("/api/cuts/{}/result", cuts[1]["id"]),
        &serde_json::json!({"stable": false}),
    );
    assert_eq!(r.status, 200, "{}", r.body);
    let cut = &get(addr, &format!("/api/setups/{id}")).json()["cuts"][1];
    assert_eq!(cut["stable"], false);
    assert_eq!(cut["overruled"], true);
    // exports
    let r = get(addr, &format!("/api/setups/{id}/export/observations.json"));
    let o = chatter_dynamics::Observations::from_json_str(&r.body, Path::new("export")).unwrap();
    assert_eq!(o.cuts.len(), 3);
    let r = get(addr, &format!("/api/setups/{id}/export/model.json"));
    chatter_dynamics::ModalModel::from_json_str(&r.body, Path::new("export")).unwrap();
    // every upload kept (2 tap tests, 2 recordings), nothing left in tmp/
    assert_eq!(files_in(dir.path(), "files").len(), 4);
    assert!(files_in(dir.path(), "tmp").is_empty());
}

#[test]
fn bad_uploads_give_a_message_and_store_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (addr, app) = start(dir.path());
    let id = new_setup(addr, "bad uploads");
    let good_model = chatter_dynamics::examples::SCHMITZ_2023_MILLING_MODEL;
    let r = post_form(
        addr,
        &format!("/api/setups/{id}/model"),
        &[],
        Some(("model.json", good_model.as_bytes())),
    );
    assert_eq!(r.status, 200, "{}", r.body);
    let counts = app.db().counts().unwrap();
    let files = files_in(dir.path(), "files");

    let csv = tap_test_csv();
    let uff = tap_test_uff();
    let wav = recording_wav(6000.0, None);
    let huge = "frequency_hz,real_m_per_n,imag_m_per_n\n".to_string()
        + &"100,1e-7,1e-7\n".repeat(9 * 1024 * 1024 / 14 + 1);
    let nan_csv: String = csv
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 40 {
                "339,NaN,NaN,NaN\n".to_string()
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let mut nan_rows = String::from("frequency_hz,real_m_per_n,imag_m_per_n\n");
    for f in 300..400 {
        nan_rows += &format!("{f},NaN,1e-7\n");
    }
    let negative_model = good_model.replace("3.0e6", "-3.0e6");
    let measured_only = r#"{"operation": {"kind": "milling", "teeth": 4, "radial_immersion": 0.2, "direction": "down"},
        "cutting": {"ks_n_per_mm2": 750, "beta_deg": 68},
        "measured_frf": [{"file": "../../etc/passwd", "direction": "x"}]}"#;
    let frf = format!("/api/setups/{id}/frf");
    let model = format!("/api/setups/{id}/model");
    let recording = format!("/api/setups/{id}/recordings");
    let observations = format!("/api/setups/{id}/observations");
    let at_speed = [("speed_rpm", "6000"), ("depth_mm", "2")];
    let garbage: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 24) as u8)
        .collect();
    // (what, route, fields, file, a word the message must hold)
    type Case<'a> = (
        &'a str,
        &'a str,
        &'a [(&'a str, &'a str)],
        Option<(&'a str, Vec<u8>)>,
        &'a str,
    );
    let cases: Vec<Case> = vec![
        ("empty FRF", &frf, &[], Some(("tap.csv", vec![])), "empty"),
        ("no file", &frf, &[], None, "no file"),
        (
            "wrong type",
            &frf,
            &[],
            Some(("tap.exe", csv.clone().into_bytes())),
            ".uff",
        ),
        (
            "no extension",
            &frf,
            &[],
            Some(("tap", csv.clone().into_bytes())),
            "must end in",
        ),
        (
            "parent path",
            &frf,
            &[],
            Some(("../../etc/passwd.csv", csv.clone().into_bytes())),
            "plain file name",
        ),
        (
            "absolute path",
            &frf,
            &[],
            Some(("/etc/tap.csv", csv.clone().into_bytes())),
            "plain file name",
        ),
        (
            "windows path",
            &frf,
            &[],
            Some(("C:\\data\\tap.csv", csv.clone().into_bytes())),
            "plain file name",
        ),
        (
            "hidden name",
            &frf,
            &[],
            Some((".tap.csv", csv.clone().into_bytes())),
            "plain file name",
        ),
        (
            "huge",
            &frf,
            &[],
            Some(("tap.csv", huge.into_bytes())),
            "MiB",
        ),
        (
            "NaN column",
            &frf,
            &[],
            Some(("tap.csv", nan_rows.into_bytes())),
            "tap.csv",
        ),
        (
            "NaN cells",
            &frf,
            &[],
            Some(("tap.csv", nan_csv.into_bytes())),
            "tap.csv",
        ),
        (
            "truncated UFF",
            &frf,
            &[],
            Some(("tap.uff", uff.as_bytes()[..uff.len() / 2].to_vec())),
            "tap.uff",
        ),
        (
            "binary as CSV",
            &frf,
            &[],
            Some(("tap.csv", garbage.clone())),
            "UTF-8",
        ),
        (
            "header only",
            &frf,
            &[],
            Some((
                "tap.csv",
                b"frequency_hz,real_m_per_n,imag_m_per_n\n".to_vec(),
            )),
            "tap.csv",
        ),
        (
            "text in numbers",
            &frf,
            &[],
            Some(("tap.txt", b"100 abc 1e-7\n200 1e-7 xyz\n".to_vec())),
            "tap.txt",
        ),
        (
            "bad band",
            &frf,
            &[("fmin_hz", "900"), ("fmax_hz", "800")],
            Some(("tap.csv", csv.clone().into_bytes())),
            "fmax_hz",
        ),
        (
            "broken JSON",
            &model,
            &[],
            Some(("model.json", b"{\"operation\": ".to_vec())),
            "model.json",
        ),
        (
            "negative stiffness",
            &model,
            &[],
            Some(("model.json", negative_model.into_bytes())),
            "stiffness",
        ),
        (
            "model pointing at files",
            &model,
            &[],
            Some(("model.json", measured_only.as_bytes().to_vec())),
            "model.json",
        ),
        (
            "text as WAV",
            &recording,
            &at_speed,
            Some(("cut.wav", csv.clone().into_bytes())),
            "RIFF",
        ),
        (
            "truncated WAV",
            &recording,
            &at_speed,
            Some(("cut.wav", wav[..44].to_vec())),
            "cut.wav",
        ),
        (
            "MP3 garbage",
            &recording,
            &at_speed,
            Some(("cut.mp3", garbage.clone())),
            "MP3",
        ),
        (
            "CSV without rate",
            &recording,
            &at_speed,
            Some(("cut.csv", b"x\n0.1\n0.2\n".to_vec())),
            "sample rate",
        ),
        (
            "recording without speed",
            &recording,
            &[("depth_mm", "2")],
            Some(("cut.wav", wav.clone())),
            "speed_rpm",
        ),
        (
            "negative depth",
            &observations,
            &[],
            Some((
                "cuts.json",
                br#"{"cuts": [{"speed_rpm": 5000, "depth_mm": -1, "stable": true}]}"#.to_vec(),
            )),
            "depth_mm",
        ),
    ];
    assert!(cases.len() >= 20);
    for (what, route, fields, file, word) in &cases {
        let file = file.as_ref().map(|(n, b)| (*n, b.as_slice()));
        let r = post_form(addr, route, fields, file);
        assert!(
            r.status == 400 || r.status == 413,
            "{what}: status {} {}",
            r.status,
            r.body
        );
        let message = r.error();
        assert!(
            message.contains(word),
            "{what}: the message `{message}` does not name `{word}`"
        );
        assert_eq!(app.db().counts().unwrap(), counts, "{what}: rows stored");
        assert_eq!(files_in(dir.path(), "files"), files, "{what}: a file kept");
        assert!(files_in(dir.path(), "tmp").is_empty(), "{what}: tmp/");
    }
}

#[test]
fn cross_origin_requests_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (addr, app) = start(dir.path());
    let before = app.db().counts().unwrap();
    let body = setup_form("from elsewhere").to_string();
    for headers in [
        vec![("Origin", "http://evil.example")],
        vec![("Sec-Fetch-Site", "cross-site")],
        vec![("Host", "evil.example:8080")],
    ] {
        let mut h = headers.clone();
        h.push(("Content-Type", "application/json"));
        let r = send(addr, "POST", "/api/setups", &h, body.as_bytes());
        assert_eq!(r.status, 403, "{headers:?}: {}", r.body);
        assert!(r.error().contains("cross-origin"), "{}", r.body);
    }
    // a page of another site cannot read through a rebound name either
    let r = send(addr, "GET", "/api/setups", &[("Host", "evil.example")], &[]);
    assert_eq!(r.status, 403);
    assert_eq!(app.db().counts().unwrap(), before);
    // this server's own page may
    let origin = format!("http://{addr}");
    let r = send(
        addr,
        "POST",
        "/api/setups",
        &[("Origin", &origin), ("Content-Type", "application/json")],
        body.as_bytes(),
    );
    assert_eq!(r.status, 200, "{}", r.body);
}

#[test]
fn twenty_concurrent_clients_get_their_lobes() {
    let dir = tempfile::tempdir().unwrap();
    let (addr, _) = start(dir.path());
    // two setups, so the clients ask for two diagrams at once
    let ids: Vec<i64> = ["a", "b"].iter().map(|n| new_setup(addr, n)).collect();
    for (k, id) in ids.iter().enumerate() {
        let model = if k == 0 {
            chatter_dynamics::examples::SCHMITZ_2023_MILLING_MODEL.to_string()
        } else {
            chatter_dynamics::examples::SCHMITZ_2023_MILLING_MODEL
                .replace("750.0, \"damping", "800.0, \"damping")
        };
        let r = post_form(
            addr,
            &format!("/api/setups/{id}/model"),
            &[],
            Some(("m.json", model.as_bytes())),
        );
        assert_eq!(r.status, 200, "{}", r.body);
    }
    let started = std::time::Instant::now();
    let clients: Vec<_> = (0..20)
        .map(|c| {
            let id = ids[c % 2];
            // every fourth client asks for another risk: a diagram of its own
            let risk = if c % 4 == 3 { 0.1 } else { 0.05 };
            std::thread::spawn(move || {
                let t = std::time::Instant::now();
                let r = get(addr, &format!("/api/setups/{id}/lobes?risk={risk}"));
                (r, t.elapsed())
            })
        })
        .collect();
    let mut slowest = std::time::Duration::ZERO;
    for c in clients {
        let (r, took) = c.join().unwrap();
        assert_eq!(r.status, 200, "{}", r.body);
        assert!(r.json()["diagram"]["lobes"].as_array().unwrap().len() >= 200);
        slowest = slowest.max(took);
    }
    eprintln!(
        "20 concurrent lobe requests answered; slowest {:.2} s, all in {:.2} s",
        slowest.as_secs_f64(),
        started.elapsed().as_secs_f64()
    );
}
