//! Structure-aware fuzzing of the real case files through parse, validation, model building and
//! a short run (`harness::fuzz`), in this process: no input may panic (an abort or a hang would
//! end or stall the test binary), and every refusal names the file. Also replays every input
//! that ever crashed (`harness/tests/fuzz_regressions.jsonl`). The long campaign, each input in
//! its own process under time and memory limits, is `harness fuzz` (README, "Fuzzing").

use std::collections::BTreeMap;
use std::path::PathBuf;

use harness::budget::Limits;
use harness::case::set_path;
use harness::fuzz::{Class, Rng, check, mutate, seeds};
use serde_json::Value;

fn cases() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases")
}

/// Runs of at most this many steps.
const STEPS: usize = 2;

/// Each input within 2 GB and 10 s (estimated), as a campaign child under 4 GB and 20 s.
const LIMITS: Limits = Limits { memory_bytes: 2e9, seconds: 10.0 };

#[test]
fn mutated_case_files_never_panic_and_every_refusal_names_the_file() {
    let seeds = seeds(&cases()).unwrap();
    let path = cases().join(".fuzz-input.json");
    let mut counts: BTreeMap<Class, usize> = BTreeMap::new();
    let mut crashes = Vec::new();
    // 3,000 inputs, a fixed seed: the same mutants on every machine.
    for i in 0..3000_usize {
        let mut rng = Rng::new(0x5eed_0019 ^ (i as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
        let (name, text) = &seeds[i % seeds.len()];
        let (bytes, muts) = mutate(text, &mut rng);
        let (class, msg) = check(&path, &bytes, STEPS, &LIMITS);
        *counts.entry(class).or_default() += 1;
        if class.is_crash() {
            crashes.push(format!("input {i} ({name}, {muts:?}): {class:?}: {msg}"));
        }
    }
    assert!(crashes.is_empty(), "{} crashes: {:#?}", crashes.len(), &crashes[..crashes.len().min(10)]);
    // The mutants reach every stage: some are refused, some run.
    assert!(counts.get(&Class::Rejected).copied().unwrap_or(0) > 300, "{counts:?}");
    assert!(
        counts.get(&Class::Ok).copied().unwrap_or(0) + counts.get(&Class::RunFailed).copied().unwrap_or(0) > 100,
        "{counts:?}"
    );
}

fn hex(s: &str) -> Vec<u8> {
    (0..s.len() / 2).map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).unwrap()).collect()
}

/// Every input that ever crashed a command (the issue's reproducers, then what the campaigns
/// found), replayed: each gives its expected class and message.
#[test]
fn every_input_that_ever_crashed_is_handled_fuzz_regressions_issue_19() {
    let text = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions.jsonl"))
        .unwrap();
    let path = cases().join("fuzz-regression.json");
    let mut n = 0;
    for line in text.lines().filter(|l| !l.trim().is_empty()) {
        let e: Value = serde_json::from_str(line).unwrap();
        let name = e["name"].as_str().unwrap();
        let bytes = if let Some(h) = e["hex"].as_str() {
            hex(h)
        } else if let Some(t) = e["text"].as_str() {
            t.as_bytes().to_vec()
        } else {
            let base = std::fs::read_to_string(cases().join(e["base"].as_str().unwrap())).unwrap();
            let mut v: Value = serde_json::from_str(&base).unwrap();
            for s in e["set"].as_array().unwrap() {
                let s = s.as_str().unwrap().replace("LONG", &"x".repeat(100_000));
                let (k, val) = s.split_once('=').unwrap();
                let val = serde_json::from_str(val).unwrap_or(Value::String(val.to_string()));
                set_path(&mut v, k, val).unwrap();
            }
            serde_json::to_vec_pretty(&v).unwrap()
        };
        // The whole run, as `harness run` would make it: the budget judges the full length.
        let (class, msg) = check(&path, &bytes, usize::MAX, &LIMITS);
        let expect = e["expect"].as_str().unwrap();
        assert_eq!(serde_json::to_value(class).unwrap(), expect, "{name}: {msg}");
        if let Some(needle) = e["needle"].as_str() {
            assert!(msg.contains(needle), "{name}: `{needle}` not in: {msg}");
        }
        assert!(msg.len() < 2000, "{name}: message of {} bytes", msg.len());
        n += 1;
    }
    assert!(n >= 20, "{n} regressions");
}

/// A campaign over a seed folder without `reference/` (the structural static cases of
/// `cases/statics`) counts every input: it once skipped them all, uncounted, because its work
/// folder was only created by copying the references. Every input is checked in a worker under
/// the limits, and none crashes.
#[test]
fn a_campaign_over_cases_without_references_counts_every_input() {
    let out = std::env::temp_dir().join(format!("harness-fuzz-statics-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let r = std::process::Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(["fuzz", "--cases", "cases/statics", "--inputs", "60", "--jobs", "1", "--out"])
        .arg(&out)
        .current_dir(cases().join(".."))
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let report: Value = serde_json::from_str(&std::fs::read_to_string(out.join("fuzz.json")).unwrap()).unwrap();
    assert_eq!(report["inputs"], 60, "{report}");
    let counted: u64 = report["classes"].as_object().unwrap().values().map(|v| v.as_u64().unwrap()).sum();
    assert_eq!(counted, 60, "{report}");
    let _ = std::fs::remove_dir_all(&out);
}

/// Issue 38: the fuzzer covers every command, the analyses on mutants of the cases that
/// declare them (reduced to one point, under the analysis budget). 14 inputs per seed case (so
/// each case keeps its share as cases are added), of a fixed seed, through `check_command` in
/// this process: no crash (a panic, an unnamed refusal or NaN in a
/// summary), and the analyses are reached (some of their inputs run or fail numerically rather
/// than being refused).
#[test]
fn every_command_is_fuzzed_analyses_included_issue_38() {
    use harness::fuzz::{FuzzCommand, check_command, input_command};
    let seeds = seeds(&cases()).unwrap();
    let path = cases().join(".fuzz-command-input.json");
    let limits = Limits { memory_bytes: 2e9, seconds: 3.0 };
    let mut counts: BTreeMap<(FuzzCommand, Class), usize> = BTreeMap::new();
    let mut crashes = Vec::new();
    for i in 0..14 * seeds.len() {
        let (name, cmd, bytes, muts) = input_command(&seeds, 38, i, STEPS);
        std::fs::write(&path, &bytes).unwrap();
        let (class, msg) = check_command(cmd, &path, STEPS, &limits);
        *counts.entry((cmd, class)).or_default() += 1;
        if class.is_crash() {
            crashes.push(format!("input {i} ({name}, {cmd:?}, {muts:?}): {class:?}: {msg}"));
        }
    }
    let _ = std::fs::remove_file(&path);
    assert!(crashes.is_empty(), "{} crashes: {:#?}", crashes.len(), &crashes[..crashes.len().min(10)]);
    let reached = |c: FuzzCommand| {
        counts.get(&(c, Class::Ok)).copied().unwrap_or(0) + counts.get(&(c, Class::RunFailed)).copied().unwrap_or(0)
    };
    for c in [FuzzCommand::Run, FuzzCommand::List, FuzzCommand::Static, FuzzCommand::Stability] {
        assert!(reached(c) > 0, "{c:?} never ran: {counts:?}");
    }
}
