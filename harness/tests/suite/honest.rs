//! Honest answers: the binary refuses what it cannot do faithfully (a gate window it did not
//! simulate, a t_end it cannot reach, ambiguous or unsafe input) instead of reporting success.

use crate::common::root;
use std::path::PathBuf;
use std::process::{Command, Output};

fn harness(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_harness")).args(args).current_dir(root()).output().expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn gate_fails_a_window_the_run_did_not_cover() {
    let o = harness(&["gate", "cases/double_pendulum_c1_beta45.json", "--set", "t_end=0.01"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("[0, 2]") && err.contains("0.01"), "{err}");
}

#[test]
fn t_end_and_output_dt_must_be_whole_numbers_of_steps() {
    let c = "cases/double_pendulum_c1_beta45.json";
    let cases: [(&[&str], &str); 3] = [
        (&["t_end=0.1", "ancf.dt=0.03"], "ancf.dt: t_end = 0.1 is not a whole number of steps of 0.03 s"),
        (&["t_end=0.01", "output_dt=0.005"], "output_dt = 0.005 is not a whole number of steps of 0.002 s"),
        (&["t_end=0.001"], "t_end = 0.001 is shorter than one step of 0.002 s"),
    ];
    for (sets, needle) in cases {
        let mut args = vec!["run", c];
        for s in sets {
            args.extend(["--set", s]);
        }
        let o = harness(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{sets:?}: {err}");
        assert!(err.contains(needle), "{sets:?}: {err}");
    }
    // Every committed case (sweeps included) holds whole steps.
    let o = harness(&["list"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

fn tmp_text(name: &str, edit: impl FnOnce(String) -> String) -> PathBuf {
    let src = root().join("cases/double_pendulum_c1_beta45.json");
    let text = edit(std::fs::read_to_string(src).unwrap());
    let d = std::env::temp_dir().join(format!("harness-honest-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn duplicate_json_keys_are_errors_naming_key_and_path() {
    let cases: [(&str, &str, &str, &str); 2] = [
        ("dup_top.json", "\"t_end\": 2.0,", "\"t_end\": -1, \"t_end\": 0.01,", "duplicate key \"t_end\""),
        (
            "dup_body.json",
            "\"length\": 0.5,",
            "\"length\": 0.5, \"length\": 0.7,",
            "bodies[0]: duplicate key \"length\"",
        ),
    ];
    for (name, from, to, needle) in cases {
        let p = tmp_text(name, |t| t.replacen(from, to, 1));
        let o = harness(&["run", p.to_str().unwrap()]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(needle), "{name}: {err}");
    }
}

#[test]
fn unreadable_reference_is_an_input_error_before_any_run() {
    let inside = root().join("cases/reference/exudyn/rigid_beta45_ode.csv");
    let outside = inside.canonicalize().unwrap();
    let cases: [(&str, String, &str); 4] = [
        ("ref_missing.json", "nope.csv".into(), "nope.csv"),
        ("ref_dir.json", ".".into(), "not a regular file"),
        ("ref_outside.json", outside.display().to_string(), "not under the case file's folder"),
        ("ref_dev.json", "/dev/null".into(), "/dev/null"),
    ];
    for (name, file, needle) in cases {
        let p = tmp_text(name, |t| {
            let mut v: serde_json::Value = serde_json::from_str(&t).unwrap();
            v["references"][0]["file"] = serde_json::json!(file);
            serde_json::to_string(&v).unwrap()
        });
        let out = std::env::temp_dir().join(format!("harness-honest-out-{}-{name}", std::process::id()));
        let o = harness(&["run", p.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains("references[0].file") && err.contains(needle), "{name}: {err}");
        assert!(!out.exists(), "{name}: a run wrote {}", out.display());
    }
}

#[test]
fn case_names_are_safe_file_names() {
    let long = "a".repeat(121);
    for bad in ["", ".", "..", "a/b", "a b", "../x", "é", long.as_str()] {
        let p = tmp_text("bad_name.json", |t| {
            let mut v: serde_json::Value = serde_json::from_str(&t).unwrap();
            v["name"] = serde_json::json!(bad);
            serde_json::to_string(&v).unwrap()
        });
        let o = harness(&["run", p.to_str().unwrap()]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {err}");
        assert!(err.contains("name: `"), "{bad:?}: {err}");
    }
    // What a sweep appends is allowed, arrays and negative or exponent numbers included.
    let p = tmp_text("sweep_name.json", |t| {
        let mut v: serde_json::Value = serde_json::from_str(&t).unwrap();
        v["references"] = serde_json::json!([]);
        v["sweep"] = serde_json::json!([
            {"path": "stiffness_scale", "values": [1e-5, 0.5]},
            {"path": "bodies.0.x_axis", "values": [[1, 0, 0]]},
            {"path": "ancf.path", "values": ["ode"]},
        ]);
        serde_json::to_string(&v).unwrap()
    });
    let out = std::env::temp_dir().join(format!("harness-honest-out-{}-sweep", std::process::id()));
    let o = harness(&["run", p.to_str().unwrap(), "--set", "t_end=0.002", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}
