//! The binary's behaviour on bad input: one clear line naming the problem, a non-zero exit
//! code, never a panic.

use crate::common::root;
use std::path::PathBuf;
use std::process::{Command, Output};

fn harness(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_harness")).args(args).current_dir(root()).output().expect("binary runs")
}

fn tmp_case(name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let src = root().join("cases/double_pendulum_c1_beta45.json");
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(src).unwrap()).unwrap();
    edit(&mut v);
    let p = std::env::temp_dir().join(format!("harness-cli-{}", std::process::id())).join(name);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
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
    // One formulation with an override: the folder says both.
    let dir = out.join("double_pendulum_c1_beta0__only-ancf__set_t_end=0.1");
    let csv = std::fs::read_to_string(dir.join("ancf.csv")).unwrap();
    assert!(!dir.join("gebf.csv").exists());
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

/// Every field of springs, point masses and the section's centre-of-mass offset, set to a value
/// no model accepts, is rejected with exit 2 and the field named, by `run`, `list` and `gate`.
#[test]
fn new_scene_fields_are_validated_by_every_command() {
    use serde_json::json;
    let point_mass = json!({"at": 0.5, "offset": [0.0, 0.01, 0.0], "mass": 0.1, "inertia": [1e-5, 1e-5, 1e-5]});
    let spring = json!({"stiffness": 1.0, "damping": 0.1, "rest_deg": 0.0});
    type Edit = fn(&mut serde_json::Value, &serde_json::Value, &serde_json::Value);
    let cases: [(&str, Edit, &str); 9] = [
        (
            "spring_k",
            |v, _, s| {
                v["joints"][1]["spring"] = s.clone();
                v["joints"][1]["spring"]["stiffness"] = json!(-1.0);
            },
            "joints[1].spring.stiffness",
        ),
        (
            "spring_c",
            |v, _, s| {
                v["joints"][0]["spring"] = s.clone();
                v["joints"][0]["spring"]["damping"] = json!(-0.5);
            },
            "joints[0].spring.damping",
        ),
        (
            "spring_rest",
            |v, _, s| {
                v["joints"][1]["spring"] = s.clone();
                v["joints"][1]["spring"]["rest_deg"] = json!("ninety");
            },
            // serde reports type errors inside a tagged joint at the joint (`joints[1]`), with the
            // offending type and value
            "joints[1]: invalid type: string \"ninety\", expected f64",
        ),
        (
            "pm_at",
            |v, p, _| {
                v["bodies"][1]["point_masses"] = json!([p]);
                v["bodies"][1]["point_masses"][0]["at"] = json!(0.7);
            },
            "bodies[1].point_masses[0].at",
        ),
        (
            "pm_mass",
            |v, p, _| {
                v["bodies"][0]["point_masses"] = json!([p]);
                v["bodies"][0]["point_masses"][0]["mass"] = json!(-0.1);
            },
            "bodies[0].point_masses[0].mass",
        ),
        (
            "pm_inertia",
            |v, p, _| {
                v["bodies"][0]["point_masses"] = json!([p]);
                v["bodies"][0]["point_masses"][0]["inertia"] = json!([1e-5, -1e-5, 1e-5]);
            },
            "bodies[0].point_masses[0].inertia[1]",
        ),
        (
            "pm_offset",
            |v, p, _| {
                v["bodies"][0]["point_masses"] = json!([p]);
                v["bodies"][0]["point_masses"][0]["offset"] = json!([0.0, 0.1]);
            },
            "bodies[0].point_masses[0].offset",
        ),
        (
            "pm_unknown",
            |v, p, _| {
                v["bodies"][0]["point_masses"] = json!([p]);
                v["bodies"][0]["point_masses"][0]["body"] = json!("tip");
            },
            "point_masses[0]",
        ),
        (
            "cg",
            |v, _, _| v["bodies"][1]["section"]["cg_offset"] = json!([0.0, -0.01, 0.3]),
            "bodies[1].section.cg_offset",
        ),
    ];
    for (name, edit, field) in cases {
        let p = tmp_case(&format!("{name}/case.json"), |v| edit(v, &point_mass, &spring));
        let path = p.to_str().unwrap();
        let folder = p.parent().unwrap().to_str().unwrap();
        for args in [vec!["run", path], vec!["list", "--cases", folder], vec!["gate", path]] {
            let o = harness(&args);
            assert_eq!(o.status.code(), Some(2), "{name}: {args:?}: {}", String::from_utf8_lossy(&o.stderr));
            assert_clean_error(&o, field);
        }
    }
}

/// A flare angle the lattice cannot take is an input error of the case, not a run-time failure.
#[test]
fn a_flare_beyond_the_lattice_limit_is_rejected_before_the_run() {
    let src = root().join("cases/wing_aoa5.json");
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(src).unwrap()).unwrap();
    let i = v["joints"].as_array().unwrap().iter().position(|j| j["type"] == "flared_hinge").unwrap();
    v["joints"][i]["flare_deg"] = serde_json::json!(85.0);
    let dir = std::env::temp_dir().join(format!("harness-cli-{}/wing_flare85", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("case.json"), serde_json::to_string(&v).unwrap()).unwrap();
    let o = harness(&["list", "--cases", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert_clean_error(&o, &format!("joints[{i}].flare_deg"));
}

/// An integrator setting the time loop would refuse is an input error found by `list` too.
#[test]
fn a_zero_newton_tolerance_is_an_input_error_for_list() {
    let p = tmp_case("rtol0/case.json", |v| v["gebf"]["newton"] = serde_json::json!({"rtol": 0.0}));
    let o = harness(&["list", "--cases", p.parent().unwrap().to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert_clean_error(&o, "gebf.newton.rtol: 0 is not a positive number");
}

/// Issue 38: `"sweep": [{"path": "stiffness_scale", "values": [1, 1]}]` made two runs of one
/// name, and `harness run` waited for ever on the folder lock its first run held. It is an
/// input error naming the sweep's field.
#[test]
fn duplicate_sweep_points_exit_2_naming_the_field_issue_38() {
    let p = tmp_case("dup_sweep.json", |v| {
        v["sweep"] = serde_json::json!([{ "path": "stiffness_scale", "values": [1, 1] }]);
    });
    let out = std::env::temp_dir().join(format!("harness-cli-dup-{}", std::process::id()));
    let mut child = Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(["run", p.to_str().unwrap(), "--set", "t_end=0.01", "--out", out.to_str().unwrap()])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // A guard against the old behaviour (a wait for ever), not a timing: the run is refused
    // before anything starts.
    let status = wait_or_kill(&mut child, 120);
    let mut err = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
    assert_eq!(status, Some(2), "{err}");
    assert!(err.contains("sweep[0].values") && err.contains("duplicate"), "{err}");
}

/// The exit code of `child`, or None after killing it when it has not ended within `secs`.
fn wait_or_kill(child: &mut std::process::Child, secs: u64) -> Option<i32> {
    let t0 = std::time::Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s.code();
        }
        if t0.elapsed() > std::time::Duration::from_secs(secs) {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Issue 38: a run waiting for another process's lock on its output folder ignored SIGTERM.
/// The wait polls the signal flag: SIGTERM ends it with the interrupted exit code (130).
#[cfg(target_os = "linux")]
#[test]
fn a_run_waiting_on_a_folder_lock_answers_sigterm_issue_38() {
    let out = std::env::temp_dir().join(format!("harness-cli-lock-{}", std::process::id()));
    let case = root().join("cases/double_pendulum_c1_beta45.json");
    // This test holds the folder the run will want.
    let held = harness::atomic::claim_dir(&out.join("double_pendulum_c1_beta45__set_t_end=0.01")).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(["run", case.to_str().unwrap(), "--set", "t_end=0.01", "--out", out.to_str().unwrap()])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until it says it is waiting.
    let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut seen = String::new();
    loop {
        let mut line = String::new();
        let n = std::io::BufRead::read_line(&mut stderr, &mut line).unwrap();
        seen.push_str(&line);
        assert!(n > 0, "the run ended without waiting: {seen}");
        if line.contains("waiting for another run") {
            break;
        }
    }
    // SAFETY: kill sends a signal to the child this test started.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
    let status = wait_or_kill(&mut child, 120);
    drop(held);
    let _ = std::fs::remove_dir_all(&out);
    assert_eq!(status, Some(130), "the run did not end on SIGTERM while waiting");
}

/// A free joint (issue 35) frees a root body; on a body that already hangs from a hinge it is
/// refused with exit 2, named at the free joint whichever comes first. A free root falls freely
/// under gravity: after 0.2 s the tip has dropped g t²/2 = 0.196 m.
#[test]
fn a_free_joint_frees_a_root_and_refuses_a_child() {
    use serde_json::json;
    let free = |body: &str| json!({"type": "free", "name": "flight", "body": body});
    let after = tmp_case("free_after.json", |v| v["joints"].as_array_mut().unwrap().push(free("outer")));
    let o = harness(&["run", after.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert_clean_error(&o, "joints[2].body");
    let before = tmp_case("free_before.json", |v| v["joints"].as_array_mut().unwrap().insert(0, free("outer")));
    let o = harness(&["run", before.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert_clean_error(&o, "joints[0].body");
    let root = tmp_case("free_root.json", |v| {
        v["joints"][0] = free("inner");
        v["t_end"] = json!(0.2);
        for k in ["references", "gate", "converge"] {
            v.as_object_mut().unwrap().remove(k);
        }
    });
    let out = root.with_file_name("free_root_out");
    let o = harness(&["run", root.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["ancf", "gebf"] {
        let csv = std::fs::read_to_string(out.join("double_pendulum_c1_beta45").join(format!("{f}.csv"))).unwrap();
        let last: Vec<f64> = csv.lines().last().unwrap().split(',').take(4).map(|x| x.parse().unwrap()).collect();
        assert!((last[0] - 0.2).abs() < 1e-9 && (last[3] + 0.196).abs() < 1e-9, "{f}: {last:?}");
    }
}

/// Hinge events (issue 35) refused with exit 2, naming the field: an event on a joint that is
/// not a flared hinge, one on no joint, a time outside the run, a lock of a hinge locked at the
/// time, a release of a free one, events on ANCF's ODE path, a time and a condition together,
/// a condition with two thresholds, and a root bending moment trigger without aerodynamics.
#[test]
fn bad_hinge_events_exit_2_naming_the_field() {
    use serde_json::json;
    type Edit = fn(&mut serde_json::Value);
    let cases: [(&str, Edit, &str); 8] = [
        (
            "not_hinge",
            |v| v["events"] = json!([{"time": 0.5, "joint": "root", "action": "release"}]),
            "events[0].joint",
        ),
        ("no_joint", |v| v["events"] = json!([{"time": 0.5, "joint": "nope", "action": "lock"}]), "events[0].joint"),
        ("late", |v| v["events"] = json!([{"time": 5.0, "joint": "fold", "action": "lock"}]), "events[0].time"),
        (
            "double_lock",
            |v| v["events"] = json!([{"time": 0.9, "joint": "fold", "action": "lock"}, {"time": 0.5, "joint": "fold", "action": "lock"}]),
            "events[0].action",
        ),
        (
            "free_release",
            |v| v["events"] = json!([{"time": 0.5, "joint": "fold", "action": "release"}]),
            "events[0].action",
        ),
        (
            "both",
            |v| v["events"] = json!([{"time": 0.5, "when": {"fold_deg_above": 10}, "joint": "fold", "action": "lock"}]),
            "events[0]: give either",
        ),
        (
            "two_thresholds",
            |v| {
                v["events"] =
                    json!([{"when": {"fold_deg_above": 10, "fold_deg_below": -10}, "joint": "fold", "action": "lock"}])
            },
            "events[0].when: give exactly one",
        ),
        (
            "rbm_no_aero",
            |v| v["events"] = json!([{"when": {"root_bending_moment_above": 10}, "joint": "fold", "action": "lock"}]),
            "events[0].when.root_bending_moment_above",
        ),
    ];
    for (name, edit, needle) in cases {
        let p = tmp_case(&format!("events_{name}.json"), edit);
        let o = harness(&["run", p.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{name}: {}", String::from_utf8_lossy(&o.stderr));
        assert_clean_error(&o, needle);
    }
}

/// `roll_joint` (issue 35) must name a ground hinge: a flared hinge or no joint is refused with
/// exit 2 naming the field; with the ground hinge the CSV gains `roll_rate` after `fold`.
#[test]
fn roll_joint_names_a_ground_hinge() {
    use serde_json::json;
    for (name, joint, needle) in
        [("flared", "fold", "roll_joint: `fold` is not a ground hinge"), ("none", "nope", "roll_joint: no joint")]
    {
        let p = tmp_case(&format!("roll_{name}.json"), |v| v["roll_joint"] = json!(joint));
        let o = harness(&["run", p.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2));
        assert_clean_error(&o, needle);
    }
    let p = tmp_case("roll_ok.json", |v| {
        v["roll_joint"] = json!("root");
        v["t_end"] = json!(0.01);
        for k in ["references", "gate", "converge"] {
            v.as_object_mut().unwrap().remove(k);
        }
    });
    let out = p.with_file_name("roll_ok_out");
    let o = harness(&["run", p.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("double_pendulum_c1_beta45").join("gebf.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(lines.next().unwrap().starts_with("t,tip_x,tip_y,tip_z,fold,roll_rate,kinetic,"));
    // Released from rest under gravity, the pendulum swings down about +Y: a positive rate.
    let last: Vec<f64> = lines.last().unwrap().split(',').map(|x| x.parse().unwrap()).collect();
    assert!(last[5] > 0.0, "{last:?}");
}

/// Thrust (case field `thrust`): a point outside its body, an unknown body, a zero direction and
/// a schedule that does not increase are refused with exit 2 naming the field (JSON carries no
/// non-finite number; the scene's own test names one); a valid thrust runs and its CSV gains `thrust_work` after `total`, which grows from 0.
#[test]
fn thrust_is_validated_and_its_work_is_a_column() {
    use serde_json::json;
    let good = json!({ "body": "outer", "at": 0.5, "direction": [0.0, 0.0, 1.0], "magnitude": 2.0 });
    let bad = [
        ("at", "at", json!(0.7), "thrust[0].at: 0.7 is not in [0, 0.5]"),
        ("body", "body", json!("tip"), "thrust[0].body: no body named `tip`"),
        ("direction", "direction", json!([0.0, 0.0, 0.0]), "thrust[0].direction: the direction has zero length"),
        (
            "schedule",
            "magnitude",
            json!([[0.0, 1.0], [0.0, 2.0]]),
            "thrust[0].magnitude[1][0]: t = 0 does not exceed the previous point's t = 0",
        ),
    ];
    for (name, field, value, needle) in bad {
        let p = tmp_case(&format!("thrust_{name}/case.json"), |v| {
            let mut t = good.clone();
            t[field] = value.clone();
            v["thrust"] = t;
        });
        let (path, folder) = (p.to_str().unwrap(), p.parent().unwrap().to_str().unwrap());
        for args in [vec!["run", path], vec!["list", "--cases", folder], vec!["gate", path]] {
            let o = harness(&args);
            assert_eq!(o.status.code(), Some(2), "{name}: {args:?}: {}", String::from_utf8_lossy(&o.stderr));
            assert_clean_error(&o, needle);
        }
    }
    let p = tmp_case("thrust_ok.json", |v| {
        v["thrust"] = json!([good.clone()]);
        v["t_end"] = json!(0.02);
        for k in ["references", "gate", "converge"] {
            v.as_object_mut().unwrap().remove(k);
        }
    });
    let out = p.with_file_name("thrust_ok_out");
    let o = harness(&["run", p.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["ancf", "gebf"] {
        let csv = std::fs::read_to_string(out.join("double_pendulum_c1_beta45").join(format!("{f}.csv"))).unwrap();
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = header.iter().position(|c| *c == "thrust_work").expect("a thrust_work column");
        assert_eq!(header[col - 1], "total", "{header:?}");
        let work: Vec<f64> = lines.map(|l| l.split(',').nth(col).unwrap().parse().unwrap()).collect();
        assert_eq!(work[0], 0.0);
        assert!(work.last().unwrap().abs() > 0.0, "{f}: {work:?}");
    }
    std::fs::remove_dir_all(out).ok();
}
