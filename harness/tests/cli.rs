//! The binary's behaviour on bad input: one clear line naming the problem, a non-zero exit
//! code, never a panic.

use std::path::PathBuf;
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn harness(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_harness")).args(args).current_dir(root()).output().expect("binary runs")
}

fn tmp_case(name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let src = root().join("cases/double_pendulum_c1_beta45.json");
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(src).unwrap()).unwrap();
    edit(&mut v);
    let dir = std::env::temp_dir().join(format!("harness-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
    p
}

fn assert_clean_error(o: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "expected failure, got success; stderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    assert!(err.contains(needle), "stderr does not mention `{needle}`: {err}");
}

#[test]
fn unknown_cli_argument_is_one_clear_line() {
    let o = harness(&["all", "--no-such-flag"]);
    assert_eq!(o.status.code(), Some(2));
    assert_clean_error(&o, "--no-such-flag");
}

#[test]
fn missing_case_file_names_the_file() {
    let o = harness(&["run", "cases/does_not_exist.json"]);
    assert_eq!(o.status.code(), Some(2));
    assert_clean_error(&o, "does_not_exist.json");
}

#[test]
fn unknown_field_names_the_field() {
    let p = tmp_case("unknown_field.json", |v| {
        v["bodies"][0]["lenght"] = serde_json::json!(0.5);
    });
    let o = harness(&["run", p.to_str().unwrap()]);
    assert_clean_error(&o, "bodies[0]");
    assert_clean_error(&o, "lenght");
}

#[test]
fn negative_length_names_the_field() {
    let p = tmp_case("negative_length.json", |v| v["bodies"][1]["length"] = serde_json::json!(-0.5));
    let o = harness(&["run", p.to_str().unwrap()]);
    assert_clean_error(&o, "bodies[1].length");
}

#[test]
fn unknown_body_in_joint_names_the_field() {
    let p = tmp_case("unknown_body.json", |v| v["joints"][1]["child"] = serde_json::json!("tip"));
    let o = harness(&["run", p.to_str().unwrap()]);
    assert_clean_error(&o, "joints[1].child");
}

#[test]
fn zero_elements_names_the_field() {
    let p = tmp_case("zero_elements.json", |v| v["gebf"]["elements_per_body"] = serde_json::json!(0));
    let o = harness(&["run", p.to_str().unwrap()]);
    assert_clean_error(&o, "gebf.elements_per_body");
}

#[test]
fn bad_override_names_the_path() {
    let o = harness(&["run", "cases/double_pendulum_c1_beta45.json", "--set", "joints.7.flare_deg=3"]);
    assert_clean_error(&o, "joints.7");
}

#[test]
fn single_formulation_run_writes_its_csv() {
    let out = std::env::temp_dir().join(format!("harness-cli-out-{}", std::process::id()));
    let o = harness(&[
        "run",
        "cases/double_pendulum_c1_beta0.json",
        "--formulation",
        "ancf",
        "--set",
        "t_end=0.1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("double_pendulum_c1_beta0/ancf.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("t,tip_x,tip_y,tip_z,fold,kinetic,elastic,potential,total,constraint_residual,newton_iterations")
    );
    assert_eq!(lines.count(), 51); // t = 0 plus 50 steps of 0.002 s
    std::fs::remove_dir_all(out).ok();
}

#[test]
fn committed_json_schema_is_current() {
    let o = harness(&["schema"]);
    assert!(o.status.success());
    let committed = std::fs::read_to_string(root().join("cases/case.schema.json")).unwrap();
    assert!(
        String::from_utf8_lossy(&o.stdout).trim() == committed.trim(),
        "cases/case.schema.json is stale: run `cargo run -p harness -- schema > cases/case.schema.json`"
    );
}

/// `harness bench` times ANCF on both paths and GEBF, and writes a table with the work per step.
#[test]
fn bench_writes_a_row_per_solver() {
    let out = std::env::temp_dir().join(format!("harness-bench-{}", std::process::id()));
    let o = harness(&[
        "bench",
        "cases/double_pendulum_c1_beta0.json",
        "--repeats",
        "2",
        "--set",
        "t_end=0.05",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(out.join("bench/bench.md")).unwrap();
    for solver in ["ANCF DAE", "ANCF ODE", "GEBF"] {
        let line = md.lines().find(|l| l.contains(solver)).unwrap_or_else(|| panic!("no {solver} row: {md}"));
        // 25 steps of 2 ms at paper settings: at least one Newton iteration per step
        let newton: f64 = line.split('|').nth(6).unwrap().trim().parse().unwrap();
        assert!(newton >= 1.0, "{line}");
    }
    let rows: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("bench/bench.json")).unwrap()).unwrap();
    assert_eq!(rows.as_array().unwrap().len(), 3);
    assert!(rows[0]["cpu_median_ms"].as_f64().unwrap() > 0.0);
    assert!(out.join("bench/bench.svg").exists());
    std::fs::remove_dir_all(out).ok();
}
