//! A table of bad inputs run against the built binary (issue 19): every case must exit non-zero
//! by validation (well before the hang guard of [`HANG_LIMIT`]), print no panic, name the option
//! or field and echo the value as the user wrote it, and write nothing. A second table of valid
//! edge cases must keep working.
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A case that runs this long is a hang: killed and failed. Validation answers in well under a
/// second, so the cases never get near it.
const HANG_LIMIT: Duration = Duration::from_secs(20);

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
}

/// Run `chatter ARGS`; (exit code, stderr), or an error text on a hang.
fn run(args: &[String]) -> Result<(Option<i32>, String), String> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_chatter"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
            return Ok((status.code(), err));
        }
        if start.elapsed() > HANG_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("still running after {HANG_LIMIT:?}: killed"));
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// One bad input: its class, the command line and what stderr must contain.
struct Case {
    class: &'static str,
    args: Vec<String>,
    expect: Vec<String>,
}

/// Files shared by the cases, in a scratch folder.
struct Files {
    dir: tempfile::TempDir,
}

impl Files {
    fn path(&self, name: &str) -> String {
        self.dir.path().join(name).display().to_string()
    }
    fn write(&self, name: &str, text: &str) -> String {
        std::fs::write(self.dir.path().join(name), text).unwrap();
        self.path(name)
    }
}

/// A milling model file with `field` replaced by `value` (the text as written).
fn milling(field: &str, value: &str) -> String {
    let mut v = [
        ("teeth", "4"),
        ("radial_immersion", "0.2"),
        ("extra_operation", ""),
        ("ks_n_per_mm2", "750"),
        ("beta_deg", "68"),
        ("frequency_hz", "750"),
        ("damping_ratio", "0.03"),
        ("stiffness_n_per_m", "3e6"),
    ];
    for entry in &mut v {
        if entry.0 == field {
            entry.1 = value;
        }
    }
    let get = |k: &str| v.iter().find(|e| e.0 == k).unwrap().1;
    format!(
        r#"{{"operation": {{"kind": "milling", "teeth": {}, "radial_immersion": {}, "direction": "down"{}}},
 "cutting": {{"ks_n_per_mm2": {}, "beta_deg": {}}},
 "modes": [{{"frequency_hz": {}, "damping_ratio": {}, "stiffness_n_per_m": {}, "direction": "x"}},
           {{"frequency_hz": 750, "damping_ratio": 0.03, "stiffness_n_per_m": 3e6, "direction": "y"}}]}}"#,
        get("teeth"),
        get("radial_immersion"),
        get("extra_operation"),
        get("ks_n_per_mm2"),
        get("beta_deg"),
        get("frequency_hz"),
        get("damping_ratio"),
        get("stiffness_n_per_m"),
    )
}

/// A turning model file with `field` replaced by `value`.
fn turning(field: &str, value: &str) -> String {
    let mut v = [
        ("workpiece_diameter_mm", "38"),
        ("kt_n_per_mm2", "635"),
        ("kn_n_per_mm2", "159"),
        ("feed", "2.8"),
        ("process_damping", ""),
    ];
    for entry in &mut v {
        if entry.0 == field {
            entry.1 = value;
        }
    }
    let get = |k: &str| v.iter().find(|e| e.0 == k).unwrap().1;
    format!(
        r#"{{"operation": {{"kind": "turning", "workpiece_diameter_mm": {}}},
 "cutting": {{"kt_n_per_mm2": {}, "kn_n_per_mm2": {}}},
 "modes": [{{"frequency_hz": 1842, "damping_ratio": 0.021, "shape": {{"feed": {}, "cutting": -0.9}}}},
           {{"frequency_hz": 2445, "damping_ratio": 0.009, "shape": {{"feed": 0.9, "cutting": 2.6}}}}]{}}}"#,
        get("workpiece_diameter_mm"),
        get("kt_n_per_mm2"),
        get("kn_n_per_mm2"),
        get("feed"),
        get("process_damping"),
    )
}

/// Turning observations with one pole whose `field` is `value`.
fn pole(field: &str, value: &str) -> String {
    let mut v = [
        ("speed_rpm", "7150"),
        ("depth_mm", "2.286"),
        ("frequency_hz", "2473"),
        ("damping_ratio", "0.0012"),
        ("frequency_std_hz", "0.56"),
        ("damping_std", "0.00014"),
        ("repetitions", "10"),
    ];
    for entry in &mut v {
        if entry.0 == field {
            entry.1 = value;
        }
    }
    let fields: Vec<String> = v.iter().map(|(k, x)| format!("\"{k}\": {x}")).collect();
    format!(r#"{{"poles": [{{{}}}]}}"#, fields.join(", "))
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

fn case(class: &'static str, args: Vec<String>, expect: &[&str]) -> Case {
    Case {
        class,
        args,
        expect: strings(expect),
    }
}

/// `check --model FILE` on a model text.
fn model_case(f: &Files, class: &'static str, name: &str, text: &str, expect: &[&str]) -> Case {
    let path = f.write(name, text);
    case(class, strings(&["check", "--model", &path]), expect)
}

#[allow(clippy::too_many_lines)]
fn cases(f: &Files) -> Vec<Case> {
    let m = example("schmitz2023_milling_model.json")
        .display()
        .to_string();
    let t = example("ahmadi2022_turning_model.json")
        .display()
        .to_string();
    let turning_obs = example("ahmadi2022_turning_observations.json")
        .display()
        .to_string();
    let milling_obs = example("ebrahimi2025_milling_observations.json")
        .display()
        .to_string();
    let mut c = Vec::new();

    // model files: every number outside its plausible range, echoed as written
    for (field, value) in [
        ("frequency_hz", "0"),
        ("frequency_hz", "-1"),
        ("frequency_hz", "1e300"),
        ("frequency_hz", "1e6"),
        ("damping_ratio", "-0.1"),
        ("damping_ratio", "1"),
        ("damping_ratio", "1.5"),
        ("stiffness_n_per_m", "0"),
        ("stiffness_n_per_m", "-3e6"),
        ("stiffness_n_per_m", "1e-300"),
        ("stiffness_n_per_m", "1e20"),
        ("radial_immersion", "0"),
        ("radial_immersion", "1.5"),
        ("radial_immersion", "-0.2"),
        ("ks_n_per_mm2", "-750"),
        ("ks_n_per_mm2", "0"),
        ("ks_n_per_mm2", "1e9"),
        ("beta_deg", "400"),
        ("beta_deg", "0"),
        ("beta_deg", "-68"),
        ("beta_deg", "180"),
    ] {
        let name = format!("m-{field}-{value}.json");
        c.push(model_case(
            f,
            "model range",
            &name,
            &milling(field, value),
            &[field, &format!(": {value} (expected")],
        ));
    }
    for (value, field) in [
        ("0", "operation.teeth"),
        ("-4", "operation.teeth"),
        ("100000", "operation.teeth"),
        ("2.5", "operation.teeth"),
    ] {
        let name = format!("m-teeth-{value}.json");
        let expect = [field, value];
        c.push(model_case(
            f,
            "model range",
            &name,
            &milling("teeth", value),
            &expect,
        ));
    }
    // type errors name the field's path, not only the line and column
    for (field, value, path) in [
        ("damping_ratio", r#""0.03""#, "modes[0].damping_ratio"),
        ("frequency_hz", "true", "modes[0].frequency_hz"),
        ("radial_immersion", "[0.2]", "operation.radial_immersion"),
    ] {
        let name = format!("m-type-{field}.json");
        c.push(model_case(
            f,
            "model type",
            &name,
            &milling(field, value),
            &[path, "invalid type"],
        ));
    }
    for (extra, field, value) in [
        (r#", "helix_deg": 90"#, "helix_deg", "90"),
        (r#", "helix_deg": -5"#, "helix_deg", "-5"),
        (r#", "tool_diameter_mm": 0"#, "tool_diameter_mm", "0"),
        (r#", "tool_diameter_mm": -10"#, "tool_diameter_mm", "-10"),
        (r#", "tool_diameter_mm": 1e9"#, "tool_diameter_mm", "1e9"),
    ] {
        let name = format!("m-{field}-{value}.json");
        c.push(model_case(
            f,
            "model range",
            &name,
            &milling("extra_operation", extra),
            &[field, &format!(": {value} (expected")],
        ));
    }
    for (field, value, shown) in [
        ("kt_n_per_mm2", "-635", "-635"),
        ("kt_n_per_mm2", "0", "0"),
        ("kn_n_per_mm2", "1e9", "1e9"),
        ("workpiece_diameter_mm", "-38", "-38"),
        ("workpiece_diameter_mm", "0", "0"),
        ("feed", "1e-200", "1e-200"),
        ("feed", "1e200", "1e200"),
    ] {
        let name = format!("t-{field}-{value}.json");
        c.push(model_case(
            f,
            "model range",
            &name,
            &turning(field, value),
            &[field, shown],
        ));
    }
    for (value, shown) in [("-1", "-1"), ("1e15", "1e15")] {
        let text = turning(
            "process_damping",
            &format!(r#", "process_damping": {{"c_n_per_m": {value}}}"#),
        );
        c.push(model_case(
            f,
            "model range",
            &format!("t-c-{value}.json"),
            &text,
            &["process_damping.c_n_per_m", shown],
        ));
    }
    // model files: structure
    let dup = milling("frequency_hz", "750").replace(
        r#"{"frequency_hz": 750, "damping_ratio": 0.03, "stiffness_n_per_m": 3e6, "direction": "y"}"#,
        r#"{"frequency_hz": 750, "damping_ratio": 0.03, "stiffness_n_per_m": 3e6, "direction": "x"}"#,
    );
    c.push(model_case(
        f,
        "model structure",
        "dup.json",
        &dup,
        &["modes[1]", "repeats modes[0]"],
    ));
    let example_text = std::fs::read_to_string(example("schmitz2023_milling_model.json")).unwrap();
    for (name, text, expect) in [
        ("array.json", format!("[{example_text}]"), "JSON array"),
        ("string.json", "\"model\"".to_string(), "JSON string"),
        ("number.json", "42".to_string(), "JSON number"),
        ("null.json", "null".to_string(), "JSON null"),
        ("empty.json", String::new(), "empty file"),
        ("syntax.json", "{\"operation\": ".to_string(), "EOF"),
        (
            "unknown.json",
            example_text.replace("\"teeth\"", "\"teeth\": 4, \"flutes\""),
            "flutes",
        ),
        (
            "direction.json",
            example_text.replace("\"direction\": \"x\"", "\"direction\": \"z\""),
            "`z`",
        ),
        (
            "kind.json",
            example_text.replace("\"milling\"", "\"drilling\""),
            "drilling",
        ),
        (
            "updown.json",
            example_text.replace("\"down\"", "\"sideways\""),
            "sideways",
        ),
    ] {
        c.push(model_case(
            f,
            "model structure",
            name,
            &text,
            &[name, expect],
        ));
    }
    c.push(case(
        "model structure",
        strings(&["check", "--model", &f.path("missing.json")]),
        &["missing.json", "No such file"],
    ));

    // observations files
    for (field, value) in [
        ("damping_ratio", "-0.1"),
        ("damping_ratio", "1"),
        ("frequency_std_hz", "0"),
        ("damping_std", "0"),
        ("damping_std", "-0.001"),
        ("depth_mm", "1e300"),
        ("depth_mm", "0"),
        ("depth_mm", "-1"),
        ("speed_rpm", "0"),
        ("speed_rpm", "-7150"),
        ("speed_rpm", "1e-6"),
        ("speed_rpm", "1e9"),
        ("frequency_hz", "0"),
        ("frequency_hz", "1e300"),
    ] {
        let path = f.write(&format!("p-{field}-{value}.json"), &pole(field, value));
        c.push(case(
            "observations range",
            strings(&["check", "--model", &t, "--observations", &path]),
            &[
                &format!("poles[0].{field}"),
                &format!(": {value} (expected"),
            ],
        ));
    }
    let repetitions = f.write("p-rep.json", &pole("repetitions", "0"));
    c.push(case(
        "observations range",
        strings(&["check", "--model", &t, "--observations", &repetitions]),
        &["poles[0].repetitions", "0"],
    ));
    let p = pole("speed_rpm", "7150");
    let twice = p.replace("}]}", &format!("}}, {}]}}", &p[11..p.len() - 2]));
    let twice = f.write("p-twice.json", &twice);
    c.push(case(
        "observations structure",
        strings(&["check", "--model", &t, "--observations", &twice]),
        &["poles[1]", "repeats poles[0]"],
    ));
    for (name, text, expect) in [
        (
            "o-type-stable.json",
            r#"{"cuts": [{"speed_rpm": 7000, "depth_mm": 1, "stable": "yes"}]}"#,
            "cuts[0].stable",
        ),
        (
            "o-type-speed.json",
            r#"{"cuts": [{"speed_rpm": 7000, "depth_mm": 1, "stable": true}, {"speed_rpm": "fast", "depth_mm": 1, "stable": true}]}"#,
            "cuts[1].speed_rpm",
        ),
        (
            "o-stable-chatter.json",
            r#"{"cuts": [{"speed_rpm": 7000, "depth_mm": 1, "stable": true, "chatter_hz": 800}]}"#,
            "cuts[0].chatter_hz",
        ),
        (
            "o-chatter-hz.json",
            r#"{"cuts": [{"speed_rpm": 7000, "depth_mm": 1, "stable": false, "chatter_hz": -800}]}"#,
            "-800",
        ),
        (
            "o-immersion.json",
            r#"{"cuts": [{"speed_rpm": 7000, "depth_mm": 1, "stable": true, "radial_immersion": 1.5}]}"#,
            "cuts[0].radial_immersion",
        ),
        (
            "o-rate.json",
            r#"{"signals": [{"file": "s.csv", "speed_rpm": 7000, "depth_mm": 1, "sample_rate_hz": 0}]}"#,
            "signals[0].sample_rate_hz",
        ),
        (
            "o-quantity.json",
            r#"{"signals": [{"file": "s.csv", "speed_rpm": 7000, "depth_mm": 1, "quantity": "jerk"}]}"#,
            "jerk",
        ),
        ("o-empty.json", "{}", "empty"),
        ("o-array.json", "[]", "JSON array"),
        ("o-unknown.json", r#"{"cutz": []}"#, "cutz"),
    ] {
        let path = f.write(name, text);
        c.push(case(
            "observations structure",
            strings(&["check", "--model", &m, "--observations", &path]),
            &[name, expect],
        ));
    }
    for (name, text, expect) in [
        (
            "c-header.csv",
            "rpm,depth,stable,hz\n7000,1,true,\n",
            "header",
        ),
        (
            "c-number.csv",
            "speed_rpm,depth_mm,stable,chatter_hz\nfast,1,true,\n",
            "`fast`",
        ),
        (
            "c-stable.csv",
            "speed_rpm,depth_mm,stable,chatter_hz\n7000,1,maybe,\n",
            "`maybe`",
        ),
        (
            "c-depth.csv",
            "speed_rpm,depth_mm,stable,chatter_hz\n7000,1,true,\n7000,-2,true,\n",
            "line 3, cuts[1].depth_mm`: -2",
        ),
    ] {
        let path = f.write(name, text);
        c.push(case(
            "observations structure",
            strings(&["check", "--model", &m, "--observations", &path]),
            &[name, expect],
        ));
    }

    // mismatches between files
    for command in ["check", "update", "diagnose", "plan"] {
        let mut args = strings(&[command, "--model", &m, "--observations", &turning_obs]);
        match command {
            "update" => args.extend(strings(&["--seed", "1", "--out", &f.path("u-mismatch")])),
            "diagnose" => args.extend(strings(&["--seed", "1"])),
            "plan" => args.extend(strings(&["--strategy", "voi"])),
            _ => {}
        }
        c.push(Case {
            class: "mismatch",
            args,
            expect: strings(&["poles[0].frequency_hz", "2473", "tooth-passing"]),
        });
    }
    let immersion_cut = f.write(
        "o-milling-cut.json",
        r#"{"cuts": [{"speed_rpm": 7000, "depth_mm": 1, "stable": true, "radial_immersion": 0.5}]}"#,
    );
    c.push(case(
        "mismatch",
        strings(&["check", "--model", &t, "--observations", &immersion_cut]),
        &["cuts[0].radial_immersion", "turning"],
    ));
    let posterior = f.dir.path().join("turning-posterior");
    std::fs::create_dir_all(&posterior).unwrap();
    std::fs::copy(
        example("ahmadi2022_turning_model.json"),
        posterior.join("updated_model.json"),
    )
    .unwrap();
    c.push(case(
        "mismatch",
        strings(&[
            "bands",
            "--model",
            &m,
            "--kind",
            "perturbation",
            "--posterior",
            &posterior.display().to_string(),
        ]),
        &["--posterior", "turning model", "milling model"],
    ));
    let signal = f.write(
        "turning-signal.csv",
        &(0..64)
            .map(|k| format!("{},{}\n", (k as f64 * 0.3).sin(), (k as f64 * 0.7).cos()))
            .fold("feed,cutting\n".to_string(), |a, r| a + &r),
    );
    let signal_obs = f.write(
        "turning-signal.json",
        &format!(
            r#"{{"signals": [{{"file": "{signal}", "speed_rpm": 7000, "depth_mm": 1, "sample_rate_hz": 10000}}]}}"#
        ),
    );
    for (flag, value) in [
        ("--segments", "100000000"),
        ("--segments", "0"),
        ("--max-order", "100000"),
        ("--min-order", "0"),
        ("--decimation", "0"),
    ] {
        c.push(case(
            "option range",
            strings(&["oma", "--observations", &signal_obs, flag, value]),
            &[&format!("{flag} {value}")],
        ));
    }
    for command in ["oma", "detect"] {
        c.push(case(
            "mismatch",
            strings(&[command, "--model", &m, "--observations", &signal_obs]),
            &["channel `feed`", "milling"],
        ));
    }
    for (name, text, expect) in [
        (
            "asymmetric.json",
            r#"{"parameter_names": ["theta_omega_2", "theta_zeta_2"], "covariance": [[1e-6, 1e-7], [-1e-7, 1e-4]]}"#,
            "symmetric",
        ),
        (
            "not-square.json",
            r#"{"parameter_names": ["theta_omega_2", "theta_zeta_2"], "covariance": [[1e-6, 0], [0]]}"#,
            "2 x 2",
        ),
    ] {
        let path = f.write(name, text);
        c.push(case(
            "covariance",
            strings(&[
                "bands",
                "--model",
                &t,
                "--kind",
                "perturbation",
                "--covariance",
                &path,
            ]),
            &[name, expect],
        ));
    }

    // options: ranges, echoed as typed (negative numbers parse)
    for (flag, value) in [
        ("--speed-rpm", "1e-6"),
        ("--speed-rpm", "0.5"),
        ("--speed-rpm", "-1"),
        ("--speed-rpm", "2e6"),
        ("--depth-mm", "-1"),
        ("--depth-mm", "0"),
        ("--depth-mm", "1e300"),
    ] {
        let mut args = strings(&[
            "multiplier",
            "--model",
            &m,
            "--speed-rpm",
            "5000",
            "--depth-mm",
            "1",
        ]);
        let at = args.iter().position(|a| a == flag).unwrap();
        args[at + 1] = value.into();
        c.push(Case {
            class: "option range",
            args,
            expect: strings(&[&format!("{flag} {value}: expected")]),
        });
    }
    for (flag, value) in [
        ("--speed-rpm", "1e-6"),
        ("--speed-rpm", "0"),
        ("--depth-mm", "-1"),
        ("--duration-s", "0"),
        ("--duration-s", "1e9"),
        ("--sample-rate-hz", "-1"),
        ("--random-force-n", "-1"),
        ("--harmonic-force-n", "-2"),
        ("--feed-per-tooth-mm", "0"),
        ("--feed-per-tooth-mm", "-0.05"),
    ] {
        let mut args = strings(&[
            "simulate",
            "--model",
            &m,
            "--speed-rpm",
            "5000",
            "--depth-mm",
            "1",
            "--duration-s",
            "0.1",
            "--sample-rate-hz",
            "1000",
            "--seed",
            "1",
            "--out",
            &f.path("sim.csv"),
        ]);
        if let Some(at) = args.iter().position(|a| a == flag) {
            args[at + 1] = value.into();
        } else {
            args.extend(strings(&[flag, value]));
        }
        c.push(Case {
            class: "option range",
            args,
            expect: strings(&[&format!("{flag} {value}")]),
        });
    }
    c.push(case(
        "work size",
        strings(&[
            "simulate",
            "--model",
            &m,
            "--speed-rpm",
            "5000",
            "--depth-mm",
            "1",
            "--duration-s",
            "3600",
            "--sample-rate-hz",
            "1000000",
            "--seed",
            "1",
            "--out",
            &f.path("sim.csv"),
        ]),
        &["--duration-s 3600", "samples"],
    ));
    for spec in [
        "0.001:0.01:2",
        "1e9:2e9:5",
        "a:b:c",
        "1000:500:10",
        "1000:2000:1",
        "1000:2000:1e9",
        "1000:2000:100000",
        "-1:5:3",
        "1000:2000",
    ] {
        c.push(case(
            "option range",
            strings(&["lobes", "--model", &m, "--speeds", spec]),
            &[&format!("--speeds {spec}")],
        ));
    }
    for method in ["fdm", "sdm"] {
        c.push(case(
            "work size",
            strings(&[
                "lobes",
                "--model",
                &t,
                "--method",
                method,
                "--speeds",
                "100:200:2",
            ]),
            &["--speeds", "at 100 rpm", "steps"],
        ));
    }
    c.push(case(
        "work size",
        strings(&[
            "multiplier",
            "--model",
            &t,
            "--speed-rpm",
            "100",
            "--depth-mm",
            "1",
        ]),
        &["--speed-rpm", "at 100 rpm", "steps"],
    ));
    for (args, expect) in [
        (vec!["--points", "100000000"], "--points 100000000"),
        (vec!["--points", "1"], "--points 1"),
        (vec!["--fmin-hz", "-5", "--fmax-hz", "100"], "--fmin-hz -5"),
        (vec!["--fmax-hz", "1e9"], "--fmax-hz 1e9"),
        (vec!["--fmin-hz", "10"], "--fmin-hz 10"),
        (vec!["--from", "z"], "`z`"),
    ] {
        let mut a = strings(&["frf", "--model", &m]);
        a.extend(strings(&args));
        c.push(case("option range", a, &[expect]));
    }
    for (args, expect) in [
        (vec!["--offset-rpm", "1e9"], "--offset-rpm 1e9"),
        (vec!["--offset-rpm", "-100"], "--offset-rpm -100"),
        (vec!["--offset-mm", "-1"], "--offset-mm -1"),
        (vec!["--offset-mm", "1e6"], "--offset-mm 1e6"),
        (
            vec!["--offset-rpm", "5000", "--speeds", "3000:4000:50"],
            "--offset-rpm 5000",
        ),
    ] {
        let mut a = strings(&["bands", "--model", &m, "--kind", "geometric"]);
        a.extend(strings(&args));
        c.push(case("option range", a, &[expect]));
    }

    // options the chosen kind ignores
    let covariance = f.write(
        "cov.json",
        r#"{"parameter_names": ["theta_omega_2"], "covariance": [[1e-6]]}"#,
    );
    for (kind, args, expect) in [
        (
            "geometric",
            vec!["--covariance", covariance.as_str()],
            "--covariance",
        ),
        (
            "geometric",
            vec!["--posterior", posterior.to_str().unwrap()],
            "--posterior",
        ),
        ("geometric", vec!["--samples", "100"], "--samples"),
        ("geometric", vec!["--seed", "3"], "--seed"),
        ("geometric", vec!["--depths", "0:2:10"], "--depths"),
        ("geometric", vec!["--map-out", "x.csv"], "--map-out"),
        ("perturbation", vec!["--offset-rpm", "50"], "--offset-rpm"),
        ("perturbation", vec!["--samples", "100"], "--samples"),
        ("montecarlo", vec!["--offset-mm", "0.1"], "--offset-mm"),
        ("montecarlo", vec!["--depths", "0:2:10"], "--depths"),
    ] {
        let mut a = strings(&["bands", "--model", &t, "--kind", kind]);
        a.extend(strings(&args));
        c.push(case(
            "ignored option",
            a,
            &[expect, &format!("--kind {kind}")],
        ));
    }
    c.push(case(
        "ignored option",
        strings(&["bands", "--model", &t, "--kind", "perturbation"]),
        &["--kind perturbation needs"],
    ));
    c.push(case(
        "ignored option",
        strings(&["lobes", "--model", &m, "--observations", &milling_obs]),
        &["--observations", "--plot"],
    ));
    c.push(case(
        "ignored option",
        strings(&[
            "diagnose",
            "--model",
            &m,
            "--observations",
            &milling_obs,
            "--seed",
            "1",
            "--validation",
            "off",
            "--folds",
            "4",
        ]),
        &["--folds", "--validation off"],
    ));
    for (args, expect) in [
        (vec!["--strategy", "voi", "--p-test", "0.3"], "--p-test"),
        (
            vec!["--strategy", "mrr", "--target", "kt_n_per_mm2"],
            "--target",
        ),
        (vec!["--strategy", "mrr", "--p-test", "1.5"], "--p-test 1.5"),
        (
            vec!["--strategy", "mrr", "--p-test", "-0.5"],
            "--p-test -0.5",
        ),
        (vec!["--strategy", "mrr", "--paths", "0"], "--paths 0"),
        (
            vec!["--strategy", "mrr", "--feed-per-tooth-mm", "0"],
            "--feed-per-tooth-mm 0",
        ),
        (
            vec!["--strategy", "mrr", "--depths", "0:1e9:5"],
            "--depths 0:1e9:5",
        ),
    ] {
        let mut a = strings(&["plan", "--model", &m, "--observations", &milling_obs]);
        a.extend(strings(&args));
        c.push(case("ignored option", a, &[expect]));
    }
    for (args, expect) in [
        (vec!["--classes", "1,1"], "--classes 1,1"),
        (vec!["--classes", "0,1"], "`0`"),
        (vec!["--classes", "abc"], "`abc`"),
        (vec!["--classes", "-1"], "`-1`"),
        (vec!["--samples", "0"], "--samples 0"),
        (vec!["--samples", "100000000"], "--samples 100000000"),
    ] {
        let mut a = strings(&[
            "update",
            "--model",
            &t,
            "--observations",
            &turning_obs,
            "--seed",
            "1",
            "--out",
            &f.path("u-options"),
        ]);
        a.extend(strings(&args));
        c.push(case("option range", a, &[expect]));
    }
    let cuts_only = f.write(
        "cuts-only.json",
        r#"{"cuts": [{"speed_rpm": 7000, "depth_mm": 1, "stable": true}, {"speed_rpm": 7200, "depth_mm": 3, "stable": false}]}"#,
    );
    c.push(case(
        "ignored option",
        strings(&[
            "update",
            "--model",
            &t,
            "--observations",
            &cuts_only,
            "--seed",
            "1",
            "--classes",
            "0.5,1",
            "--out",
            &f.path("u-cuts"),
        ]),
        &["--classes"],
    ));
    for (args, expect) in [
        (vec!["--folds", "100"], "--folds 100"),
        (
            vec!["--validation", "speed-bands", "--folds", "4"],
            "3 distinct speeds",
        ),
        (vec!["--samples", "5"], "--samples 5"),
    ] {
        let mut a = strings(&[
            "diagnose",
            "--model",
            &m,
            "--observations",
            &milling_obs,
            "--seed",
            "1",
        ]);
        a.extend(strings(&args));
        c.push(case("option range", a, &[expect]));
    }

    // outputs: checked before the work, never created silently
    let existing_dir = f.dir.path().join("a-folder");
    std::fs::create_dir_all(&existing_dir).unwrap();
    let existing_dir = existing_dir.display().to_string();
    let foreign = f.dir.path().join("foreign");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("thesis.tex"), "mine").unwrap();
    let foreign = foreign.display().to_string();
    let missing = f.path("no/such/folder/x.csv");
    let a_file = f.write("a-file.txt", "text");
    for (args, expect) in [
        (vec!["lobes", "--model", &m, "--out", &missing], "--out"),
        (
            vec!["lobes", "--model", &m, "--out", &existing_dir],
            "is a folder",
        ),
        (vec!["lobes", "--model", &m, "--plot", &missing], "--plot"),
        (vec!["frf", "--model", &m, "--out", &missing], "--out"),
        (
            vec!["frf", "--model", &m, "--plot", &existing_dir],
            "is a folder",
        ),
        (
            vec!["bands", "--model", &m, "--out", &missing],
            "does not exist",
        ),
        (
            vec![
                "bands",
                "--model",
                &t,
                "--kind",
                "montecarlo",
                "--covariance",
                &covariance,
                "--map-out",
                &missing,
            ],
            "--map-out",
        ),
        (
            vec![
                "simulate",
                "--model",
                &m,
                "--speed-rpm",
                "5000",
                "--depth-mm",
                "1",
                "--duration-s",
                "0.1",
                "--sample-rate-hz",
                "1000",
                "--seed",
                "1",
                "--out",
                &missing,
            ],
            "--out",
        ),
        (
            vec![
                "update",
                "--model",
                &t,
                "--observations",
                &turning_obs,
                "--seed",
                "1",
                "--out",
                &missing,
            ],
            "does not exist",
        ),
        (
            vec![
                "update",
                "--model",
                &t,
                "--observations",
                &turning_obs,
                "--seed",
                "1",
                "--out",
                &foreign,
            ],
            "thesis.tex",
        ),
        (
            vec![
                "update",
                "--model",
                &t,
                "--observations",
                &turning_obs,
                "--seed",
                "1",
                "--out",
                &a_file,
            ],
            "is a file",
        ),
        (
            vec![
                "diagnose",
                "--model",
                &m,
                "--observations",
                &milling_obs,
                "--seed",
                "1",
                "--out",
                &missing,
            ],
            "does not exist",
        ),
        (vec!["demo", "--out", &missing], "does not exist"),
        (vec!["demo", "--out", &foreign], "thesis.tex"),
        (vec!["demo", "--out", &a_file], "is a file"),
        (
            vec!["detect", "--observations", &signal_obs, "--out", &missing],
            "--out",
        ),
        (
            vec!["oma", "--observations", &signal_obs, "--plot", &missing],
            "--plot",
        ),
        (
            vec![
                "fit-frf",
                "--frf",
                &a_file,
                "--fmin-hz",
                "10",
                "--fmax-hz",
                "100",
                "--out",
                &missing,
            ],
            "--out",
        ),
        (
            vec![
                "fit-frf",
                "--frf",
                &a_file,
                "--fmin-hz",
                "100",
                "--fmax-hz",
                "10",
                "--out",
                &f.path("fit.json"),
            ],
            "--fmax-hz 10",
        ),
        (
            vec!["rcsa", "--assembly", &a_file, "--out", &missing],
            "--out",
        ),
    ] {
        c.push(case("output", strings(&args), &[expect]));
    }
    c
}

#[test]
fn every_bad_input_is_a_fast_clear_error() {
    let files = Files {
        dir: tempfile::tempdir().unwrap(),
    };
    let cases = cases(&files);
    let before = listing(files.dir.path());
    let mut failures = Vec::new();
    let mut counts = std::collections::BTreeMap::<&str, usize>::new();
    for case in &cases {
        *counts.entry(case.class).or_default() += 1;
        let line = case.args.join(" ");
        match run(&case.args) {
            Err(hang) => failures.push(format!("[{}] {line}: {hang}", case.class)),
            Ok((code, err)) => {
                let mut problems = Vec::new();
                if code == Some(0) || code.is_none() {
                    problems.push(format!("exit {code:?}"));
                }
                if err.contains("panicked") || err.contains("RUST_BACKTRACE") {
                    problems.push("panic".into());
                }
                for e in &case.expect {
                    if !err.contains(e.as_str()) {
                        problems.push(format!("no `{e}`"));
                    }
                }
                if !problems.is_empty() {
                    failures.push(format!(
                        "[{}] {line}: {}\n    stderr: {}",
                        case.class,
                        problems.join(", "),
                        err.trim()
                    ));
                }
            }
        }
    }
    let after = listing(files.dir.path());
    let written: Vec<_> = after.difference(&before).collect();
    eprintln!("{} cases by class: {counts:?}", cases.len());
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
    assert!(written.is_empty(), "bad inputs wrote {written:?}");
}

/// Every path under `dir`.
fn listing(dir: &Path) -> std::collections::BTreeSet<PathBuf> {
    let mut all = std::collections::BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p.clone());
            }
            all.insert(p);
        }
    }
    all
}

/// The valid edge cases of the issue keep working: full radial immersion, zero damping, very
/// stiff modes, and negative numbers that are in range (a negative normal coefficient).
#[test]
fn valid_edge_cases_keep_working() {
    let files = Files {
        dir: tempfile::tempdir().unwrap(),
    };
    let full = files.write("full.json", &milling("radial_immersion", "1"));
    let undamped = files.write("undamped.json", &milling("damping_ratio", "0"));
    let stiff = files.write("stiff.json", &milling("stiffness_n_per_m", "1e12"));
    let negative_kn = files.write("kn.json", &turning("kn_n_per_mm2", "-20"));
    for args in [
        vec![
            "lobes",
            "--quiet",
            "--model",
            &full,
            "--speeds",
            "5000:6000:3",
        ],
        vec![
            "lobes",
            "--quiet",
            "--model",
            &undamped,
            "--method",
            "zoa",
            "--speeds",
            "5000:6000:3",
        ],
        vec!["check", "--model", &undamped],
        // zero damping: |mu| = 1 at zero depth is marginal, not unstable (limit 0 where any
        // cut destabilizes the undamped mode)
        vec![
            "lobes",
            "--quiet",
            "--model",
            &undamped,
            "--method",
            "fdm",
            "--speeds",
            "5000:6000:3",
        ],
        vec![
            "lobes",
            "--quiet",
            "--model",
            &undamped,
            "--method",
            "sdm",
            "--speeds",
            "5000:6000:3",
        ],
        vec![
            "multiplier",
            "--model",
            &undamped,
            "--speed-rpm",
            "5000",
            "--depth-mm",
            "0.5",
        ],
        vec![
            "bands",
            "--model",
            &undamped,
            "--method",
            "fdm",
            "--speeds",
            "5000:6000:3",
        ],
        vec![
            "lobes",
            "--quiet",
            "--model",
            &stiff,
            "--speeds",
            "5000:6000:3",
        ],
        vec![
            "multiplier",
            "--model",
            &negative_kn,
            "--speed-rpm",
            "7000",
            "--depth-mm",
            "1",
        ],
    ] {
        let args = strings(&args);
        let (code, err) = run(&args).unwrap();
        assert_eq!(code, Some(0), "{}: {err}", args.join(" "));
    }
}

/// Speeds without a limit below the 100 mm depth ceiling (both modes 1e12 N/m, so the limits
/// lie near 200 m) get empty depth and chatter cells, never `inf,NaN`, and a warning that
/// counts them, for every method; `bands` says it leaves them out.
#[test]
fn unbounded_speeds_get_empty_cells_and_a_warning() {
    let files = Files {
        dir: tempfile::tempdir().unwrap(),
    };
    let model = files.write(
        "stiff.json",
        &milling("stiffness_n_per_m", "1e12").replace("3e6", "1e12"),
    );
    for method in ["zoa", "fdm", "sdm"] {
        let out = files.path(&format!("lobes_{method}.csv"));
        let args = strings(&[
            "lobes",
            "--quiet",
            "--model",
            &model,
            "--method",
            method,
            "--speeds",
            "5000:6000:3",
            "--out",
            &out,
        ]);
        let (code, err) = run(&args).unwrap();
        assert_eq!(code, Some(0), "{method}: {err}");
        assert!(
            err.contains(
                "warning: 3 of 3 speeds have no stability limit below the depth ceiling of 100 mm"
            ),
            "{method}: {err}"
        );
        let csv = std::fs::read_to_string(&out).unwrap();
        assert_eq!(
            csv, "speed_rpm,depth_mm,chatter_hz\n5000,,\n5500,,\n6000,,\n",
            "{method}"
        );
    }
    let args = strings(&["bands", "--model", &model, "--speeds", "5000:6000:3"]);
    let (_, err) = run(&args).unwrap();
    assert!(err.contains("they are left out of the bands"), "{err}");
}
