//! `--shard k/N` and `harness merge`: every unit of a sweep runs in exactly one shard,
//! the shards are balanced by estimated cost, and the merged folder equals one machine's.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use harness::case::CaseFile;
use harness::shard::{Plan, Shard, Unit};
use harness::stress;

use super::external::{root, temp_dir};

fn harness_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_harness")).args(args).current_dir(dir).output().expect("binary runs")
}

/// The stress matrix's units as `harness stress` deals them: every cell with its estimated cost.
fn stress_units() -> Vec<Unit> {
    let base = CaseFile::read(&root().join("cases/double_pendulum_c1_beta45.json")).unwrap().expand(&[]).unwrap();
    stress::jobs(&stress::Axes::default())
        .iter()
        .map(|j| Unit { id: stress::job_id(j), cost: stress::job_cost(&base[0], j) })
        .collect()
}

/// Every cell of the stress matrix is run by exactly one of N shards, for N = 1…8, and no shard
/// carries more than 4/3 of the best possible largest load (longest-processing-time bound).
#[test]
fn shard_covers_every_stress_cell_exactly_once_for_1_to_8_shards() {
    let units = stress_units();
    assert_eq!(units.len(), 2 * 4 * 6 * 3 * 4);
    let total: f64 = units.iter().map(|u| u.cost).sum();
    let biggest = units.iter().map(|u| u.cost).fold(0.0, f64::max);
    for n in 1..=8 {
        let mut count: BTreeMap<&str, usize> = BTreeMap::new();
        let mut loads = Vec::new();
        for k in 1..=n {
            let plan = Plan::new("stress", Shard::new(k, n).unwrap(), units.clone()).unwrap();
            // Each shard computes the same deal on its own.
            assert_eq!(plan, Plan::new("stress", Shard::new(k, n).unwrap(), units.clone()).unwrap());
            let mine = plan.my_units();
            loads.push(mine.iter().map(|id| units.iter().find(|u| u.id == *id).unwrap().cost).sum::<f64>());
            for id in mine {
                *count.entry(units.iter().find(|u| u.id == id).unwrap().id.as_str()).or_default() += 1;
            }
        }
        assert_eq!(count.len(), units.len(), "N = {n}: some cell in no shard");
        assert!(count.values().all(|&c| c == 1), "N = {n}: a cell in two shards");
        let max = loads.iter().copied().fold(0.0, f64::max);
        let lower = (total / n as f64).max(biggest);
        assert!(max <= 4.0 / 3.0 * lower + 1e-12, "N = {n}: loads {loads:?}, lower bound {lower}");
        eprintln!("N = {n}: largest shard {:.3} of the ideal total/N", max / (total / n as f64));
    }
}

/// A case with a 16-point sweep (4 stiffness scales × 4 flare angles) of 0.1 s pendulum runs, and
/// no references (the folder is temporary).
pub fn sweep16_cases(dir: &Path) -> PathBuf {
    let src = root().join("cases/double_pendulum_c1_beta45.json");
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(src).unwrap()).unwrap();
    let o = v.as_object_mut().unwrap();
    for k in ["references", "gate", "converge"] {
        o.remove(k);
    }
    o.insert("name".into(), "sweep16".into());
    o.insert("t_end".into(), serde_json::json!(0.1));
    o.insert(
        "sweep".into(),
        serde_json::json!([
            { "path": "stiffness_scale", "values": [1, 0.5, 0.2, 0.1] },
            { "path": "joints.1.flare_deg", "values": [0, 30, 45, 60] }
        ]),
    );
    let cases = dir.join("cases");
    std::fs::create_dir_all(&cases).unwrap();
    std::fs::write(cases.join("sweep16.json"), serde_json::to_string_pretty(&v).unwrap()).unwrap();
    cases
}

/// Every file under `dir`, relative, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    fn walk(base: &Path, d: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else if !p.file_name().unwrap().to_string_lossy().starts_with('.') {
                out.push(p.strip_prefix(base).unwrap().to_path_buf());
            }
        }
    }
    let mut v = Vec::new();
    walk(dir, dir, &mut v);
    v.sort();
    v
}

/// A JSON value without its measured times (`wall_s`, `aero_wall_s`, `steps_per_s`).
fn without_timings(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(m) => {
            m.retain(|k, _| !matches!(k.as_str(), "wall_s" | "aero_wall_s" | "steps_per_s"));
            m.values_mut().for_each(without_timings);
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(without_timings),
        _ => {}
    }
}

/// `summary.md` without the columns of measured times (a header cell naming `wall`).
fn markdown_without_timings(text: &str) -> String {
    let mut drop: Vec<usize> = Vec::new();
    let mut out = String::new();
    for line in text.lines() {
        if line.starts_with('|') {
            let cells: Vec<&str> = line.split('|').collect();
            if cells.iter().any(|c| c.contains("wall")) {
                drop = cells.iter().enumerate().filter(|(_, c)| c.contains("wall")).map(|(i, _)| i).collect();
            }
            let kept: Vec<&str> =
                cells.iter().enumerate().filter(|(i, _)| !drop.contains(i)).map(|(_, c)| *c).collect();
            out.push_str(&kept.join("|"));
        } else {
            drop.clear();
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// The merged folder holds the same files as one machine's: CSV files byte for byte, every
/// `summary.json` and `summary.md` equal apart from the measured times. Returns the number of CSV
/// files compared.
pub fn assert_same_report(single: &Path, merged: &Path) -> usize {
    let (a, b) = (files(single), files(merged));
    assert_eq!(a, b, "the merged folder holds other files than the single machine's");
    let mut csvs = 0;
    for f in &a {
        let (x, y) = (single.join(f), merged.join(f));
        let name = f.file_name().unwrap().to_string_lossy();
        if name.ends_with(".csv") {
            assert!(std::fs::read(&x).unwrap() == std::fs::read(&y).unwrap(), "{} differs", f.display());
            csvs += 1;
        } else if name == "summary.json" {
            let mut jx: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&x).unwrap()).unwrap();
            let mut jy: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&y).unwrap()).unwrap();
            without_timings(&mut jx);
            without_timings(&mut jy);
            assert_eq!(jx, jy, "{} differs beyond timings", f.display());
        } else if name == "summary.md" {
            let (mx, my) = (std::fs::read_to_string(&x).unwrap(), std::fs::read_to_string(&y).unwrap());
            assert_eq!(markdown_without_timings(&mx), markdown_without_timings(&my), "{} differs", f.display());
        }
    }
    csvs
}

/// Four shards of a 16-run sweep (two in their own folders, two sharing one) merge into the
/// single-machine report; a merge without one shard names its runs and exits 1.
#[test]
fn sharded_sweep_merges_into_the_single_machine_report() {
    let dir = temp_dir("shard-merge");
    let cases = sweep16_cases(&dir);
    let c = cases.to_str().unwrap();
    let o = harness_in(&dir, &["all", "--quick", "--cases", c, "--out", "single"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (k, out) in [(1, "a"), (2, "b"), (3, "shared"), (4, "shared")] {
        let s = format!("{k}/4");
        let o = harness_in(&dir, &["all", "--quick", "--cases", c, "--out", out, "--shard", &s]);
        assert!(o.status.success(), "shard {s}: {}", String::from_utf8_lossy(&o.stderr));
        assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("all: shard {k} of 4: 4 of 16 units")));
        assert!(!dir.join(out).join("index.html").exists(), "a shard writes no report");
    }
    let o = harness_in(&dir, &["merge", "a", "b", "shared", "shared", "--out", "merged"]);
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    let csvs = assert_same_report(&dir.join("single"), &dir.join("merged"));
    assert_eq!(csvs, 32);
    // Without shard 2: its four runs are named, and the exit status says so.
    let o = harness_in(&dir, &["merge", "a", "shared", "--out", "partial"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("4 run(s) missing"), "{err}");
    let named = err.lines().filter(|l| l.contains("run:sweep16__") && l.contains("(shard 2)")).count();
    assert_eq!(named, 4, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--shard` takes k/N with 1 ≤ k ≤ N, or `slurm` inside an array task only.
#[test]
fn bad_shard_arguments_are_one_clear_line() {
    let o = harness_in(&root(), &["stress", "--shard", "5/4"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("k must be in 1..=N"));
    let o = Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(["static", "cases/healy_ffwt_flare10_aoa0.json", "--shard", "slurm"])
        .env_remove("SLURM_ARRAY_TASK_ID")
        .current_dir(root())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("SLURM_ARRAY_TASK_ID is not set"));
}
