//! Honest answers: the binary refuses what it cannot do faithfully (a gate window it did not
//! simulate, a t_end it cannot reach, ambiguous or unsafe input) instead of reporting success.

use std::path::PathBuf;
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn harness(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_harness")).args(args).current_dir(root()).output().expect("binary runs")
}

fn tmp_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("harness-honest-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
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
