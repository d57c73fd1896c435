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
