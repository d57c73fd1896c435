//! Streamed, atomic and owned outputs: time histories written as the run proceeds, files
//! replaced whole, folders owned by one run at a time, and signals that end a run cleanly.
//!
//! Kill test: a wing run (t_end 6 s, ~1 s of wall time) killed with SIGKILL or SIGINT at a random
//! moment leaves CSVs whose rows are whole and consecutive output steps from t = 0, and a
//! `summary.json` that parses and is either complete or says `"interrupted"`. Concurrency test:
//! pairs of identical runs started together into one output root leave whole, consistent folders.
//! `harness all` interrupted during its gust sweeps exits 130 without beginning its other phases.
//! The counts are small here; `HARNESS_KILLS=50 HARNESS_PAIRS=100 cargo test --release -p harness
//! --test suite streamed -- --nocapture` runs the larger campaign and prints its figures.

use crate::common::root;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(args)
        .current_dir(root())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("harness-streamed-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Rows of a CSV, checked: a header, whole rows of its width, times consecutive multiples of
/// `output_dt` from 0. Returns the number of rows.
fn check_csv(path: &Path, output_dt: f64) -> Result<usize, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if text.is_empty() {
        return Ok(0); // created, no row flushed yet
    }
    if !text.ends_with('\n') {
        return Err(format!("{}: last line cut", path.display()));
    }
    let mut lines = text.lines();
    let width = lines.next().unwrap().split(',').count();
    let mut n = 0;
    for (k, l) in lines.enumerate() {
        let f: Vec<f64> =
            l.split(',').map(|x| x.parse::<f64>()).collect::<Result<_, _>>().map_err(|e| format!("row {k}: {e}"))?;
        if f.len() != width {
            return Err(format!("row {k}: {} fields for {width}", f.len()));
        }
        if (f[0] - k as f64 * output_dt).abs() > 1e-6 {
            return Err(format!("row {k}: t = {} is not step {k}", f[0]));
        }
        n += 1;
    }
    Ok(n)
}

/// The summary's status; it must parse.
fn status(dir: &Path) -> Result<String, String> {
    let p = dir.join("summary.json");
    let text = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", p.display()))?;
    if text.matches("\"gate_pass\"").count() > 1 {
        return Err("two gate outcomes in one summary".into());
    }
    Ok(v["status"].as_str().unwrap_or("").to_string())
}

/// A deterministic spread of kill moments (SplitMix64 on the test's index).
fn moment(i: u64, max_ms: u64) -> Duration {
    let mut z = (i + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    Duration::from_millis(20 + (z ^ (z >> 27)) % max_ms)
}

/// `var` from the environment, else `default`.
fn count(var: &str, default: u64) -> u64 {
    std::env::var(var).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// Kill `n` runs with `signal`; returns (interrupted, complete, interrupted runs whose CSVs
/// already held rows past t = 0: the rows reached the file while the run went on).
fn kill_runs(signal: i32, n: u64, name: &str) -> (usize, usize, usize) {
    let out = tmp(name);
    let o = out.to_str().unwrap();
    let args = ["run", "cases/wing_aoa5.json", "--set", "t_end=6", "--out", o];
    // A previous complete run in the folder.
    assert!(spawn(&args).wait().unwrap().success());
    let dir = out.join("wing_aoa5__set_t_end=6");
    assert_eq!(status(&dir).unwrap(), "complete");
    let (mut interrupted, mut complete, mut streamed) = (0, 0, 0);
    for i in 0..n {
        let mut child = spawn(&args);
        std::thread::sleep(moment(i + 100 * signal as u64, 1200));
        // SAFETY: signalling our own child by its id.
        unsafe { libc::kill(child.id() as i32, signal) };
        let st = child.wait().unwrap();
        let mut rows = usize::MAX;
        for f in ["ancf", "gebf"] {
            let r = check_csv(&dir.join(format!("{f}.csv")), 0.01).unwrap_or_else(|e| panic!("kill {i}: {f}: {e}"));
            rows = rows.min(r);
        }
        match status(&dir).unwrap_or_else(|e| panic!("kill {i}: {e}")).as_str() {
            "interrupted" => {
                interrupted += 1;
                if rows > 1 && rows < 601 {
                    streamed += 1;
                }
            }
            "complete" => {
                complete += 1;
                assert!(st.success() || signal == libc::SIGKILL, "kill {i}: complete but {st:?}");
            }
            s => panic!("kill {i}: status `{s}`"),
        }
        if signal == libc::SIGINT && !st.success() {
            // SIGINT ends the run after its step: exit 130 and a summary that says so.
            assert_eq!(st.code(), Some(130), "kill {i}");
            assert_eq!(status(&dir).unwrap(), "interrupted");
        }
        assert!(!std::fs::read_dir(&dir).unwrap().any(|e| e.unwrap().file_name().to_string_lossy().contains(".tmp-")));
    }
    let _ = std::fs::remove_dir_all(&out);
    (interrupted, complete, streamed)
}

#[test]
fn sigkill_at_any_moment_leaves_whole_rows_and_an_honest_summary() {
    let n = count("HARNESS_KILLS", 8);
    let (interrupted, complete, streamed) = kill_runs(libc::SIGKILL, n, "sigkill");
    eprintln!("SIGKILL: {n} kills, {interrupted} interrupted ({streamed} with rows on disk), {complete} complete");
    assert!(interrupted >= 1 && streamed >= 1, "{interrupted} interrupted, {streamed} with rows on disk");
}

#[test]
fn sigint_finishes_the_step_writes_the_rows_and_marks_the_summary() {
    let n = count("HARNESS_KILLS", 6);
    let (interrupted, complete, streamed) = kill_runs(libc::SIGINT, n, "sigint");
    eprintln!("SIGINT: {n} signals, {interrupted} interrupted ({streamed} with rows on disk), {complete} complete");
    assert!(interrupted >= 1 && streamed >= 1, "{interrupted} interrupted, {streamed} with rows");
}

#[test]
fn concurrent_runs_into_one_folder_never_mix() {
    let out = tmp("pairs");
    let o = out.to_str().unwrap();
    let args = ["run", "cases/double_pendulum_c1_beta45.json", "--set", "t_end=0.2", "--out", o];
    let pairs = count("HARNESS_PAIRS", 4);
    let mut waited = 0;
    for pair in 0..pairs {
        let (a, b) = (spawn(&args), spawn(&args));
        for c in [a, b] {
            let r = c.wait_with_output().unwrap();
            assert!(r.status.success(), "pair {pair}: {}", String::from_utf8_lossy(&r.stderr));
            waited += usize::from(String::from_utf8_lossy(&r.stderr).contains("waiting for another run"));
        }
        let dir = out.join("double_pendulum_c1_beta45__set_t_end=0.2");
        assert_eq!(status(&dir).unwrap(), "complete", "pair {pair}");
        for f in ["ancf", "gebf"] {
            assert_eq!(check_csv(&dir.join(format!("{f}.csv")), 0.002).unwrap(), 101, "pair {pair} {f}");
        }
        let stray: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains(".tmp-"))
            .collect();
        assert!(stray.is_empty(), "pair {pair}: {stray:?}");
    }
    eprintln!("{pairs} concurrent pairs: 0 mixed or corrupt folders; the second run waited for the lock in {waited}");
    let _ = std::fs::remove_dir_all(&out);
}

/// `--formulation ancf` and `--set` runs never write into (or leave files beside) the plain
/// run's folder.
#[test]
fn variants_write_to_their_own_folders() {
    let out = tmp("variants");
    let o = out.to_str().unwrap();
    let c = "cases/double_pendulum_c1_beta45.json";
    assert!(spawn(&["run", c, "--set", "t_end=0.02", "--out", o]).wait().unwrap().success());
    assert!(spawn(&["run", c, "--set", "t_end=0.02", "--formulation", "ancf", "--out", o]).wait().unwrap().success());
    let err = spawn(&["run", c, "--set", "t_end=0.02", "--set", "joints.1.flare_deg=30", "--out", o])
        .wait_with_output()
        .unwrap();
    assert!(err.status.code() == Some(0) || err.status.code() == Some(1));
    let mut names: Vec<String> =
        std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(
        names,
        [
            "double_pendulum_c1_beta45__only-ancf__set_t_end=0.02",
            "double_pendulum_c1_beta45__set_t_end=0.02",
            "double_pendulum_c1_beta45__set_t_end=0.02,joints.1.flare_deg=30",
        ]
    );
    let single = out.join("double_pendulum_c1_beta45__only-ancf__set_t_end=0.02");
    assert!(single.join("ancf.csv").exists() && !single.join("gebf.csv").exists());
    let _ = std::fs::remove_dir_all(&out);
}

/// `harness all` stopped by SIGINT during its gust sweeps, which run first and alone: exit 130,
/// the cases, sweeps and studies not begun, and nothing in the output folder (the sweep's
/// results are written after the sweep, a run's folder by the lanes that never started).
#[test]
fn sigint_during_the_gust_sweeps_skips_the_lanes_and_writes_nothing() {
    use std::io::{BufRead, BufReader};
    let cases = tmp("all-sigint-cases");
    std::fs::create_dir_all(&cases).unwrap();
    std::fs::copy(root().join("cases/wing_gust.json"), cases.join("wing_gust.json")).unwrap();
    let out = tmp("all-sigint-out");
    let (c, o) = (cases.to_str().unwrap(), out.to_str().unwrap());
    // Three gradients: 18 runs of a few CPU seconds each, far longer than the wait below.
    let mut child = spawn(&["all", "--cases", c, "--out", o, "--set", "gust.gradients_m=[9,15,25]"]);
    let stderr = child.stderr.take().unwrap();
    let (started, began) = std::sync::mpsc::channel();
    let log = std::thread::spawn(move || {
        let mut log = String::new();
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if line.contains("== gust sweep of wing_gust") {
                let _ = started.send(());
            }
            log.push_str(&line);
            log.push('\n');
        }
        log
    });
    let sweeping = began.recv_timeout(Duration::from_secs(300));
    std::thread::sleep(Duration::from_millis(1500));
    // SAFETY: signalling our own child by its id.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let st = child.wait().unwrap();
    let log = log.join().unwrap();
    assert!(sweeping.is_ok(), "the gust sweep did not start:\n{log}");
    assert_eq!(st.code(), Some(130), "{log}");
    assert!(log.contains("interrupted during the gust sweeps"), "{log}");
    assert!(!log.contains("== cases"), "{log}");
    let written: Vec<_> = match std::fs::read_dir(&out) {
        Ok(d) => d.map(|e| e.unwrap().file_name()).collect(),
        Err(_) => Vec::new(),
    };
    assert!(written.is_empty(), "{written:?}\n{log}");
    let _ = std::fs::remove_dir_all(&cases);
    let _ = std::fs::remove_dir_all(&out);
}
