//! Structure-aware fuzzing of case files: mutants of the real cases in `cases/` (keys deleted or
//! duplicated, values retyped, extreme numbers, huge arrays, hostile strings, invalid UTF-8,
//! truncation) taken through parse, validation, model building and a short run.
//!
//! * [`check`] runs one input in this process and classifies it ([`Class`]); the test suite runs
//!   a few thousand this way (`harness/tests/suite/fuzz.rs`) and replays every input that ever
//!   crashed (`harness/tests/fuzz_regressions.jsonl`).
//! * [`campaign`] (`harness fuzz`) runs each input in its own child process
//!   (`harness check <input> --max-steps N`, or `harness run` with `--run`) under an
//!   address-space limit and a wall-time limit,
//!   and classifies the outcome by exit status: 0, 1, 2 (naming the file or not), panic, abort,
//!   other signal, hang.

use std::collections::BTreeMap;
use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use serde::Serialize;
use serde_json::Value;

use crate::budget::Limits;
use crate::case::{CaseFile, Formulation};

/// A small deterministic generator (SplitMix64): the same seed gives the same mutants everywhere.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }
    fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.below(v.len())]
    }
}

/// Numbers that break naive code: zero, signs, the ends of f64, integers past u32 and u64,
/// counts too large to allocate.
const EXTREMES: &[&str] = &[
    "0",
    "-0.0",
    "-1",
    "1",
    "2",
    "0.5",
    "3",
    "7",
    "1e-300",
    "5e-324",
    "1e300",
    "1.7976931348623157e308",
    "-1e300",
    "4294967296",
    "18446744073709551615",
    "18446744073709551616",
    "1000000000",
    "1000",
    "100000",
    "1e-9",
    "1e9",
    "90",
    "89.999999",
    "-90",
    "1e-12",
];

/// Strings that break naive code.
fn hostile_string(rng: &mut Rng) -> Value {
    let s = match rng.below(9) {
        0 => String::new(),
        1 => "..".into(),
        2 => "../../x".into(),
        3 => "a\u{0}b".into(),
        4 => "x".repeat(10_000),
        5 => "é/ü".into(),
        6 => "inner".into(),
        7 => "fold".into(),
        _ => "reference/sharpy/none.csv".into(),
    };
    Value::String(s)
}

/// Every path (object keys and array indices) in `v`.
fn paths(v: &Value, prefix: &mut Vec<Key>, out: &mut Vec<Vec<Key>>) {
    out.push(prefix.clone());
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                prefix.push(Key::Field(k.clone()));
                paths(x, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                prefix.push(Key::Index(i));
                paths(x, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

#[derive(Debug, Clone)]
enum Key {
    Field(String),
    Index(usize),
}

fn get_mut<'a>(v: &'a mut Value, path: &[Key]) -> Option<&'a mut Value> {
    let mut cur = v;
    for k in path {
        cur = match (k, cur) {
            (Key::Field(f), Value::Object(m)) => m.get_mut(f)?,
            (Key::Index(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(cur)
}

/// The kinds of mutation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Mutation {
    /// Remove a key or an array element.
    Delete,
    /// Repeat an array element, or a key (textually: a duplicate key).
    Duplicate,
    /// Replace a value by one of another JSON type.
    Retype,
    /// Replace a value by an extreme number.
    Extreme,
    /// Scale a number by a power of ten.
    Scale,
    /// Replace a value by a long array.
    HugeArray,
    /// Replace a value by a hostile string.
    String,
    /// Insert bytes that are not UTF-8.
    BadUtf8,
    /// Cut the text.
    Truncate,
}

const MUTATIONS: [Mutation; 9] = [
    Mutation::Delete,
    Mutation::Duplicate,
    Mutation::Retype,
    Mutation::Extreme,
    Mutation::Scale,
    Mutation::HugeArray,
    Mutation::String,
    Mutation::BadUtf8,
    Mutation::Truncate,
];

/// Apply one (half the time) to three mutations to the text of a case file; returns the bytes and the
/// mutations made.
pub fn mutate(text: &str, rng: &mut Rng) -> (Vec<u8>, Vec<Mutation>) {
    let mut v: Value = serde_json::from_str(text).unwrap_or(Value::Null);
    // One mutation half the time (more mutants get past validation into the run), else two or three.
    let n = if rng.below(2) == 0 { 1 } else { 2 + rng.below(2) };
    let mut done = Vec::new();
    let mut text_ops = Vec::new();
    for _ in 0..n {
        let m = *rng.pick(&MUTATIONS);
        done.push(m);
        let mut all = Vec::new();
        paths(&v, &mut Vec::new(), &mut all);
        // Numbers are where most of the interesting values are: favour them.
        let numeric: Vec<&Vec<Key>> = all.iter().filter(|p| is_number(&v, p)).collect();
        let path = if matches!(m, Mutation::Extreme | Mutation::Scale) && !numeric.is_empty() {
            rng.pick(&numeric).to_vec()
        } else {
            rng.pick(&all).clone()
        };
        match m {
            Mutation::Delete => {
                if let Some((last, parent)) = path.split_last()
                    && let Some(p) = get_mut(&mut v, parent)
                {
                    match (last, p) {
                        (Key::Field(f), Value::Object(o)) => {
                            o.remove(f);
                        }
                        (Key::Index(i), Value::Array(a)) if *i < a.len() => {
                            a.remove(*i);
                        }
                        _ => {}
                    }
                }
            }
            Mutation::Duplicate => {
                if let Some((Key::Index(i), parent)) = path.split_last()
                    && let Some(Value::Array(a)) = get_mut(&mut v, parent)
                    && *i < a.len()
                {
                    let x = a[*i].clone();
                    a.insert(*i, x);
                } else {
                    text_ops.push(Mutation::Duplicate);
                }
            }
            Mutation::Retype => {
                let new = match rng.below(7) {
                    0 => Value::Null,
                    1 => Value::Bool(true),
                    2 => Value::String("1".into()),
                    3 => serde_json::json!([]),
                    4 => serde_json::json!({}),
                    5 => serde_json::json!(-1),
                    _ => serde_json::json!(1.5),
                };
                if let Some(x) = get_mut(&mut v, &path) {
                    *x = new;
                }
            }
            Mutation::Extreme => {
                let num: Value = serde_json::from_str(EXTREMES[rng.below(EXTREMES.len())]).unwrap_or(Value::Null);
                if let Some(x) = get_mut(&mut v, &path) {
                    *x = num;
                }
            }
            Mutation::Scale => {
                let k = rng.below(13) as i32 - 6;
                if let Some(x) = get_mut(&mut v, &path)
                    && let Some(f) = x.as_f64()
                {
                    let y = f * 10f64.powi(k);
                    *x = if x.is_u64() && (0.0..1e15).contains(&y) && y.fract() == 0.0 {
                        serde_json::json!(y as u64)
                    } else {
                        serde_json::json!(y)
                    };
                }
            }
            Mutation::HugeArray => {
                let len = *rng.pick(&[100usize, 1_000, 10_000, 100_000]);
                if let Some(x) = get_mut(&mut v, &path) {
                    // An array of copies of the value (or of a number), at most ~4 MB of text.
                    let item = if x.to_string().len() * len <= 4 << 20 { x.clone() } else { serde_json::json!(1) };
                    *x = Value::Array(vec![item; len]);
                }
            }
            Mutation::String => {
                let s = hostile_string(rng);
                if let Some(x) = get_mut(&mut v, &path) {
                    *x = s;
                }
            }
            Mutation::BadUtf8 | Mutation::Truncate => text_ops.push(m),
        }
    }
    let mut bytes = serde_json::to_string_pretty(&v).unwrap_or_default().into_bytes();
    for m in text_ops {
        match m {
            Mutation::Duplicate => {
                // Repeat a key of some object: `"key": 0,` in front of its first occurrence.
                let keys: Vec<usize> =
                    bytes.windows(3).enumerate().filter(|(_, w)| w == b"\": ").map(|(i, _)| i).collect();
                if let Some(&end) = keys.get(rng.below(keys.len().max(1)))
                    && let Some(start) = bytes[..end].iter().rposition(|&b| b == b'"')
                {
                    let mut ins = bytes[start..=end].to_vec();
                    ins.extend_from_slice(b": 0, ");
                    bytes.splice(start..start, ins);
                }
            }
            Mutation::BadUtf8 => {
                let at = rng.below(bytes.len() + 1);
                const BAD: [&[u8]; 4] = [&[0xff], &[0xc3], &[0xed, 0xa0, 0x80], &[0xf4, 0x90]];
                let bad = BAD[rng.below(BAD.len())];
                bytes.splice(at..at, bad.iter().copied());
            }
            Mutation::Truncate => {
                let at = rng.below(bytes.len() + 1);
                bytes.truncate(at);
            }
            _ => {}
        }
    }
    (bytes, done)
}

fn is_number(v: &Value, path: &[Key]) -> bool {
    let mut cur = v;
    for k in path {
        cur = match (k, cur) {
            (Key::Field(f), Value::Object(m)) => match m.get(f) {
                Some(x) => x,
                None => return false,
            },
            (Key::Index(i), Value::Array(a)) => match a.get(*i) {
                Some(x) => x,
                None => return false,
            },
            _ => return false,
        };
    }
    cur.is_number()
}

/// The command an input of a campaign goes through: `run` (as `harness check`: parse, validate,
/// build, a few steps), `list` (parse, validate, expand), `gate` (the gated runs, a few steps,
/// their gate), and the analyses `static`, `stability` and `gust` on mutants of the cases that
/// declare them, each reduced first ([`reduce_for`]) and under the analysis budget.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FuzzCommand {
    /// `harness check` / `harness run --max-steps`.
    Run,
    /// `harness list`.
    List,
    /// `harness gate`.
    Gate,
    /// `harness static`.
    Static,
    /// `harness stability`.
    Stability,
    /// `harness gust`.
    Gust,
}

impl FuzzCommand {
    /// The subcommand's name.
    pub fn name(self) -> &'static str {
        match self {
            FuzzCommand::Run => "run",
            FuzzCommand::List => "list",
            FuzzCommand::Gate => "gate",
            FuzzCommand::Static => "static",
            FuzzCommand::Stability => "stability",
            FuzzCommand::Gust => "gust",
        }
    }

    /// The analysis, for the three analyses.
    pub fn analysis(self) -> Option<crate::budget::Analysis> {
        match self {
            FuzzCommand::Static => Some(crate::budget::Analysis::Static),
            FuzzCommand::Stability => Some(crate::budget::Analysis::Stability),
            FuzzCommand::Gust => Some(crate::budget::Analysis::Gust),
            _ => None,
        }
    }

    /// The commands a seed case takes: `run`, `list` and `gate` always, each analysis where the
    /// case has its block.
    pub fn for_seed(text: &str) -> Vec<FuzzCommand> {
        let v: Value = serde_json::from_str(text).unwrap_or(Value::Null);
        let mut c = vec![FuzzCommand::Run, FuzzCommand::List, FuzzCommand::Gate];
        for (key, cmd) in
            [("static", FuzzCommand::Static), ("stability", FuzzCommand::Stability), ("gust", FuzzCommand::Gust)]
        {
            if v.get(key).is_some() {
                c.push(cmd);
            }
        }
        c
    }
}

/// The seed text for `cmd`: unchanged for `run`, `list` and `gate`; for an analysis, its sweep
/// cut to one point (the highest static airspeed, sideslip or load factor, the first stability airspeed
/// with at most 4 modes, the first gust gradient and hinge state with `gust.t_end` of
/// `max_steps` steps), so that a campaign can afford thousands of analyses. The mutations then
/// apply to the reduced case.
pub fn reduce_for(cmd: FuzzCommand, text: &str, max_steps: usize) -> String {
    let Ok(mut v) = serde_json::from_str::<Value>(text) else { return text.to_string() };
    let keep_one = |x: &mut Value, last: bool| {
        if let Value::Array(a) = x
            && !a.is_empty()
        {
            let k = if last { a.len() - 1 } else { 0 };
            *a = vec![a[k].clone()];
        }
    };
    match cmd {
        FuzzCommand::Static => {
            if let Some(st) = v.get_mut("static") {
                for key in ["airspeeds", "load_factors", "sideslips_deg"] {
                    if let Some(x) = st.get_mut(key) {
                        let last = key != "load_factors";
                        keep_one(x, last);
                    }
                }
            }
        }
        FuzzCommand::Stability => {
            if let Some(st) = v.get_mut("stability") {
                if let Some(x) = st.get_mut("airspeeds") {
                    keep_one(x, false);
                }
                if let Some(m) = st.get_mut("modes")
                    && m.as_u64().is_some_and(|n| n > 4)
                {
                    *m = serde_json::json!(4);
                }
                if let Some(o) = st.as_object_mut() {
                    o.remove("basis_modes");
                }
            }
        }
        FuzzCommand::Gust => {
            let dt = ["ancf", "gebf"]
                .iter()
                .filter_map(|f| v.get(*f).and_then(|x| x.get("dt")).and_then(Value::as_f64))
                .fold(0.0_f64, f64::max);
            if let Some(g) = v.get_mut("gust") {
                for key in ["gradients_m", "frequencies_hz", "hinges"] {
                    if let Some(x) = g.get_mut(key) {
                        keep_one(x, false);
                    }
                }
                if let (Some(o), true) = (g.as_object_mut(), dt > 0.0) {
                    o.insert("t_end".into(), serde_json::json!(max_steps as f64 * dt));
                }
            }
        }
        _ => return text.to_string(),
    }
    coarsen(&mut v);
    serde_json::to_string_pretty(&v).unwrap_or_else(|_| text.to_string())
}

/// Coarsen a case for an analysis of the campaign: at most 4 elements per body, 4 panels per
/// body, 2 chordwise panels and 10 wake rows (the same code paths at a fraction of the cost).
fn coarsen(v: &mut Value) {
    let cap = |x: &mut Value, n: u64| match x {
        Value::Number(k) if k.as_u64().is_some_and(|k| k > n) => *x = serde_json::json!(n),
        Value::Array(a) => {
            for y in a {
                if y.as_u64().is_some_and(|k| k > n) {
                    *y = serde_json::json!(n);
                }
            }
        }
        _ => {}
    };
    for f in ["ancf", "gebf"] {
        if let Some(e) = v.get_mut(f).and_then(|x| x.get_mut("elements_per_body")) {
            cap(e, 4);
        }
    }
    if let Some(a) = v.get_mut("aero") {
        for (key, n) in [("panels_per_body", 4), ("n_chordwise", 2), ("n_wake_rows", 10)] {
            if let Some(x) = a.get_mut(key) {
                cap(x, n);
            }
        }
    }
    if let Some(w) = v.get_mut("stability").and_then(|s| s.get_mut("wake")).and_then(|w| w.get_mut("rows")) {
        cap(w, 10);
    }
}

/// What became of an input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Class {
    /// Ran (exit 0).
    Ok,
    /// A run failed numerically (exit 1).
    RunFailed,
    /// Refused as bad input, naming the file (exit 2).
    Rejected,
    /// Refused (exit 2) without naming the file.
    RejectedUnnamed,
    /// A panic (exit 101 or a caught unwind).
    Panic,
    /// Ended by SIGABRT (failed allocation).
    Abort,
    /// Ended by another signal (e.g. SIGSEGV, SIGKILL).
    Signal,
    /// Did not end within the time limit.
    Hang,
    /// A summary (stdout, summary JSON or report section) shows NaN where a failure should be
    /// named (issue 38).
    NanInSummary,
    /// Any other exit status.
    Other,
}

impl Class {
    /// Whether the class is a defect (the input goes to the regression file).
    pub fn is_crash(self) -> bool {
        matches!(
            self,
            Class::RejectedUnnamed
                | Class::Panic
                | Class::Abort
                | Class::Signal
                | Class::Hang
                | Class::NanInSummary
                | Class::Other
        )
    }
}

/// Run one input in this process: parse, validate and expand as `harness run` does, build both
/// formulations and run each at most `max_steps` steps. A panic is caught and classified.
///
/// The budget ([`crate::budget`]) is checked against `limits` for runs of `max_steps` steps:
/// what could not finish within the limits is refused.
pub fn check(input_path: &Path, bytes: &[u8], max_steps: usize, limits: &Limits) -> (Class, String) {
    check_parsed(input_path, || CaseFile::from_bytes(input_path, bytes), max_steps, limits)
}

/// As [`check`], reading the file at `path` as `harness run` does (`harness check`).
pub fn check_file(path: &Path, max_steps: usize, limits: &Limits) -> (Class, String) {
    check_parsed(path, || CaseFile::read(path), max_steps, limits)
}

fn check_parsed(
    input_path: &Path,
    read: impl FnOnce() -> Result<CaseFile, crate::case::Error>,
    max_steps: usize,
    limits: &Limits,
) -> (Class, String) {
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let runs = match read().and_then(|c| c.expand_within(&[], limits, Some(max_steps))) {
            Ok(r) => r,
            Err(e) => {
                let m = e.to_string();
                let named = m.contains(&input_path.display().to_string());
                return (if named { Class::Rejected } else { Class::RejectedUnnamed }, m);
            }
        };
        let mut failed = None;
        for mut spec in runs.into_iter().take(2) {
            crate::driver::limit_steps(&mut spec, max_steps);
            for f in Formulation::ALL {
                let out = crate::scene::run_formulation(spec.case(f), f);
                if let Some(e) = out.error {
                    failed = Some(format!("{} {f}: {e}", spec.name));
                }
            }
        }
        match failed {
            Some(e) => (Class::RunFailed, e),
            None => (Class::Ok, String::new()),
        }
    }));
    r.unwrap_or_else(|p| {
        let msg = p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default();
        (Class::Panic, msg)
    })
}

/// As [`check_file`], through command `cmd` ([`FuzzCommand`]): `list` expands only; `gate` runs
/// the gated runs `max_steps` steps and evaluates their gate (a failed gate is
/// [`Class::RunFailed`]); an analysis is refused (exit 2) without its block or over the budget,
/// else runs, and its summaries must not show NaN ([`Class::NanInSummary`]).
pub fn check_command(cmd: FuzzCommand, path: &Path, max_steps: usize, limits: &Limits) -> (Class, String) {
    if cmd == FuzzCommand::Run {
        return check_file(path, max_steps, limits);
    }
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let rejected = |e: crate::case::Error| {
            let m = e.to_string();
            let named = m.contains(&path.display().to_string());
            (if named { Class::Rejected } else { Class::RejectedUnnamed }, m)
        };
        let file = match CaseFile::read(path) {
            Ok(f) => f,
            Err(e) => return rejected(e),
        };
        match cmd {
            FuzzCommand::List => match file.expand_within(&[], limits, None) {
                Ok(_) => (Class::Ok, String::new()),
                Err(e) => rejected(e),
            },
            FuzzCommand::Gate => {
                let mut runs = match file.expand_within(&[], limits, Some(max_steps)) {
                    Ok(r) => r,
                    Err(e) => return rejected(e),
                };
                runs.retain(|r| r.ancf.gate.is_some());
                runs.truncate(2);
                for r in &mut runs {
                    crate::driver::limit_steps(r, max_steps);
                }
                let results = crate::driver::run_all(&runs, &Formulation::ALL, false);
                match results.iter().find(|r| r.status() != "pass") {
                    Some(r) => (Class::RunFailed, format!("{}: gate {}", r.name, r.status())),
                    None => (Class::Ok, String::new()),
                }
            }
            _ => check_analysis(cmd, path, &file, limits),
        }
    }));
    r.unwrap_or_else(|p| {
        let msg = p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default();
        (Class::Panic, msg)
    })
}

/// One analysis of [`check_command`], as its command runs it (budget, block, sweep, summary).
fn check_analysis(cmd: FuzzCommand, path: &Path, file: &CaseFile, limits: &Limits) -> (Class, String) {
    let Some(a) = cmd.analysis() else { return (Class::Other, format!("{cmd:?} is not an analysis")) };
    let runs = match file.expand_for_analysis(&[], limits, a, &Formulation::ALL) {
        Ok(r) => r,
        Err(e) => {
            let m = e.to_string();
            return (if m.contains(&path.display().to_string()) { Class::Rejected } else { Class::RejectedUnnamed }, m);
        }
    };
    let Some(spec) = runs.first() else { return (Class::Ok, String::new()) };
    let has = match cmd {
        FuzzCommand::Static => spec.ancf.statics.is_some(),
        FuzzCommand::Stability => spec.ancf.stability.is_some(),
        _ => spec.ancf.gust.is_some(),
    };
    if !has {
        return (Class::Rejected, format!("{}: {}: the case has no `{}` block", path.display(), a.name(), a.name()));
    }
    // The summaries' texts, and the failure messages they quote (which may say "NaN" of a
    // residual: naming the failure is what they are for).
    let (failed, texts, errors): (Option<String>, Vec<String>, Vec<String>) = match cmd {
        FuzzCommand::Static => {
            let outs: Vec<_> =
                Formulation::ALL.iter().map(|&f| crate::statics::run_static(&spec.case(f).problem(), f)).collect();
            let s = crate::static_out::summarise(&spec.ancf, &spec.dir, outs);
            let failed = s.n_failed > 0 || s.runs.iter().any(|r| r.error.is_some());
            let errors = s.runs.iter().flat_map(|r| r.error.iter().chain(r.points.iter().flat_map(|p| &p.error)));
            let errors: Vec<String> = errors.cloned().collect();
            let texts = vec![serde_json::to_string(&s).unwrap_or_default(), crate::static_out::section_html(&s, "x")];
            (failed.then(|| s.failures.iter().map(|f| f.text()).collect::<Vec<_>>().join("; ")), texts, errors)
        }
        FuzzCommand::Stability => {
            let outs: Vec<_> =
                Formulation::ALL.iter().map(|&f| crate::stability::run_stability(&spec.case(f).problem(), f)).collect();
            let errors = outs.iter().flat_map(|o| o.error.iter().chain(o.points.iter().flat_map(|p| &p.error)));
            let errors: Vec<String> = errors.cloned().collect();
            (errors.first().cloned(), vec![crate::stability_out::section_html(&spec.name, "x", &outs)], errors)
        }
        _ => match spec.gust_sweep(&Formulation::ALL) {
            Err(m) => return (Class::Rejected, format!("{}: {m}", path.display())),
            Ok(sweep) => {
                let s = crate::gust_out::summarise(sweep);
                let errors: Vec<String> = s.runs.iter().filter_map(|r| r.error.clone()).collect();
                let texts = vec![serde_json::to_string(&s).unwrap_or_default(), crate::gust_out::section_html(&s, "x")];
                (errors.first().cloned(), texts, errors)
            }
        },
    };
    let strip = |t: &String| {
        let mut t = t.clone();
        for e in &errors {
            let json = serde_json::to_string(e).unwrap_or_default();
            let json = json.trim_matches('"');
            let html = e.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
            for x in [e.as_str(), json, &html, &html.replace('"', "&quot;")] {
                if !x.is_empty() {
                    t = t.replace(x, "");
                }
            }
        }
        t
    };
    let texts: Vec<String> = texts.iter().map(strip).collect();
    if let Some(t) = texts.iter().find(|t| t.contains("NaN")) {
        let at = t.find("NaN").unwrap_or(0);
        let lo = t[..at].char_indices().rev().nth(120).map_or(0, |(i, _)| i);
        return (Class::NanInSummary, format!("{}: ...{}", a.name(), &t[lo..(at + 3).min(t.len())]));
    }
    match failed {
        Some(e) => (Class::RunFailed, e),
        None => (Class::Ok, String::new()),
    }
}

/// Settings of a campaign.
#[derive(Debug, Clone)]
pub struct Campaign {
    /// The seed cases (`cases/*.json`) and their folder (its `reference/` is copied beside the
    /// mutants so that references resolve).
    pub cases: PathBuf,
    /// Output folder: `fuzz.json`, `fuzz.md`, `crashes/`, `work/`.
    pub out: PathBuf,
    /// Number of inputs.
    pub inputs: usize,
    /// First input index (to continue a campaign).
    pub first: usize,
    /// Seed.
    pub seed: u64,
    /// Child processes at once.
    pub jobs: usize,
    /// Time limit of one input: CPU time of its process (a child niced on a busy machine waits
    /// without running), and 6 × this of wall time not spent waiting for a CPU (a child
    /// blocked without running, on a lock or a pipe; [`run_delay_seconds`]).
    pub timeout: Duration,
    /// Address-space limit of one child, bytes.
    pub address_space: u64,
    /// Steps each run of an input takes at most.
    pub max_steps: usize,
    /// Children run `harness run` (writing every output file) instead of `harness check`.
    pub run: bool,
    /// One child process per input (`harness check` or `harness run`) instead of long-lived
    /// workers (`harness fuzz-worker`, restarted after any crash or hang).
    pub exec_each: bool,
}

/// A long-lived child that checks inputs one at a time (`harness fuzz-worker`): the path of an
/// input on its stdin, one line `<class>\t<message>` on its stdout. A panic is caught and
/// reported; an abort, another signal or a hang ends the worker, which is then restarted.
struct Worker {
    child: std::process::Child,
    stdin: std::process::ChildStdin,
    lines: std::sync::mpsc::Receiver<String>,
}

impl Worker {
    fn start(exe: &Path, c: &Campaign) -> std::io::Result<Self> {
        let mut cmd = Command::new(exe);
        // What cannot finish within half the time limit is refused by the budget.
        let hours = c.timeout.as_secs_f64() / 2.0 / 3600.0;
        cmd.arg("fuzz-worker")
            .arg("--max-steps")
            .arg(c.max_steps.to_string())
            .arg("--max-hours")
            .arg(hours.to_string());
        cmd.stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::null());
        limit(&mut cmd, c.address_space);
        let mut child = cmd.spawn()?;
        let stdin = child.stdin.take().ok_or_else(|| std::io::Error::other("no stdin"))?;
        let stdout = child.stdout.take().ok_or_else(|| std::io::Error::other("no stdout"))?;
        let (tx, lines) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            use std::io::BufRead as _;
            for l in std::io::BufReader::new(stdout).lines() {
                let Ok(l) = l else { break };
                if tx.send(l).is_err() {
                    break;
                }
            }
        });
        Ok(Self { child, stdin, lines })
    }

    /// Check one input; `Err(class)` means the worker is gone (the class comes from its status,
    /// or it was a hang: more than `timeout` of CPU time, or 6 × `timeout` of wall time, on the
    /// input).
    fn check(&mut self, cmd: FuzzCommand, file: &Path, timeout: Duration) -> Result<(Class, String), Class> {
        use std::io::Write as _;
        let cpu0 = cpu_seconds(self.child.id());
        let delay0 = run_delay_seconds(self.child.id());
        let t0 = Instant::now();
        let sent = writeln!(self.stdin, "{}\t{}", cmd.name(), file.display()).and_then(|()| self.stdin.flush());
        let reply = if sent.is_ok() {
            loop {
                match self.lines.recv_timeout(Duration::from_millis(250)) {
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                        let cpu = cpu_seconds(self.child.id()).zip(cpu0).map(|(a, b)| a - b);
                        let over = cpu.map_or(t0.elapsed() > timeout, |c| c > timeout.as_secs_f64());
                        let awake = awake_seconds(self.child.id(), t0, delay0);
                        if over || awake > 6.0 * timeout.as_secs_f64() {
                            break Some(Err(std::sync::mpsc::RecvTimeoutError::Timeout));
                        }
                    }
                    r => break Some(r),
                }
            }
        } else {
            None
        };
        match reply {
            Some(Ok(l)) => {
                let (k, msg) = l.split_once('\t').unwrap_or((&l, ""));
                let class = serde_json::from_value(Value::String(k.to_string())).unwrap_or(Class::Other);
                Ok((class, msg.to_string()))
            }
            Some(Err(std::sync::mpsc::RecvTimeoutError::Timeout)) => {
                let _ = self.child.kill();
                let _ = self.child.wait();
                Err(Class::Hang)
            }
            _ => {
                let st = self.child.wait();
                Err(st.map_or(Class::Other, classify_status))
            }
        }
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The loop of `harness fuzz-worker`: one input path per stdin line, one reply line each.
pub fn worker_main(max_steps: usize) -> std::io::Result<()> {
    use std::io::{BufRead as _, Write as _};
    // Panics are caught and reported on stdout; their default message would only be noise.
    std::panic::set_hook(Box::new(|_| {}));
    let stdin = std::io::stdin();
    let mut out = std::io::stdout().lock();
    for line in stdin.lock().lines() {
        let line = line?;
        // `<command>\t<path>`, or a bare path for `run`.
        let (cmd, file) = match line.split_once('\t') {
            Some((c, f)) => (serde_json::from_value(Value::String(c.to_string())).unwrap_or(FuzzCommand::Run), f),
            None => (FuzzCommand::Run, line.as_str()),
        };
        let (class, msg) = check_command(cmd, Path::new(file), max_steps, &crate::budget::limits());
        let k = serde_json::to_value(class).ok().and_then(|v| v.as_str().map(str::to_string)).unwrap_or_default();
        let msg: String = msg.chars().take(4000).map(|c| if c == '\n' || c == '\t' { ' ' } else { c }).collect();
        writeln!(out, "{k}\t{msg}")?;
        out.flush()?;
    }
    Ok(())
}

/// CPU time (user + system) a process has used, s (Linux: `/proc/<pid>/stat`).
pub fn cpu_seconds(pid: u32) -> Option<f64> {
    #[cfg(target_os = "linux")]
    {
        let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
        // Fields after the command name (which may hold spaces) in parentheses.
        let rest = &stat[stat.rfind(')')? + 2..];
        let f: Vec<&str> = rest.split_whitespace().collect();
        let (u, s) = (f.get(11)?.parse::<f64>().ok()?, f.get(12)?.parse::<f64>().ok()?);
        // SAFETY: sysconf reads a constant.
        let tick = unsafe { libc::sysconf(libc::_SC_CLK_TCK) } as f64;
        Some((u + s) / tick.max(1.0))
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = pid;
        None
    }
}

/// Time the threads of a process have waited on a run queue, runnable but not running, s
/// (Linux: `/proc/<pid>/task/*/schedstat`, summed over the threads alive now).
pub fn run_delay_seconds(pid: u32) -> Option<f64> {
    #[cfg(target_os = "linux")]
    {
        let mut sum = 0.0;
        for t in std::fs::read_dir(format!("/proc/{pid}/task")).ok()? {
            let Ok(t) = t else { continue };
            let Ok(st) = std::fs::read_to_string(t.path().join("schedstat")) else { continue };
            sum += st.split_whitespace().nth(1).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0) * 1e-9;
        }
        Some(sum)
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = pid;
        None
    }
}

/// The wall time since `t0` that a child was not kept waiting for a CPU (`delay0`: its
/// [`run_delay_seconds`] at `t0`), s. A niced child on a busy machine waits on the run queue for
/// most of its wall time; a child blocked on a lock sleeps, and that time counts.
fn awake_seconds(pid: u32, t0: Instant, delay0: Option<f64>) -> f64 {
    let wall = t0.elapsed().as_secs_f64();
    let starved = run_delay_seconds(pid).zip(delay0).map_or(0.0, |(a, b)| (a - b).max(0.0));
    (wall - starved).max(0.0)
}

/// Set the address-space limit (and no core files) of a child.
fn limit(cmd: &mut Command, address_space: u64) {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::process::CommandExt as _;
        // SAFETY: setrlimit is async-signal-safe; nothing else runs between fork and exec.
        unsafe {
            cmd.pre_exec(move || {
                let r = libc::rlimit { rlim_cur: address_space, rlim_max: address_space };
                libc::setrlimit(libc::RLIMIT_AS, &r);
                let z = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
                libc::setrlimit(libc::RLIMIT_CORE, &z);
                Ok(())
            });
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (cmd, address_space);
}

/// The class of a child's exit status.
fn classify_status(status: std::process::ExitStatus) -> Class {
    match status.code() {
        Some(0) => Class::Ok,
        Some(1) => Class::RunFailed,
        Some(2) => Class::Rejected,
        Some(101) => Class::Panic,
        Some(_) => Class::Other,
        None => {
            #[cfg(target_os = "linux")]
            {
                use std::os::unix::process::ExitStatusExt as _;
                match status.signal() {
                    Some(libc::SIGABRT) => Class::Abort,
                    _ => Class::Signal,
                }
            }
            #[cfg(not(target_os = "linux"))]
            Class::Signal
        }
    }
}

/// Counts of a campaign by class (and by mutation for the crashes).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Report {
    /// Inputs run.
    pub inputs: usize,
    /// Per class.
    pub classes: BTreeMap<Class, usize>,
    /// Wall time, s.
    pub wall_s: f64,
    /// Longest single input, s.
    pub slowest_s: f64,
    /// Seed.
    pub seed: u64,
    /// Inputs kept in `crashes/`.
    pub crashes: Vec<String>,
    /// Per command, per class.
    pub commands: BTreeMap<FuzzCommand, BTreeMap<Class, usize>>,
}

/// The bytes of input `i` of a campaign with `seed` over the seed texts.
pub fn input(seeds: &[(String, String)], seed: u64, i: usize) -> (String, Vec<u8>, Vec<Mutation>) {
    let mut rng = Rng::new(seed ^ (i as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
    let (name, text) = &seeds[i % seeds.len()];
    let (bytes, m) = mutate(text, &mut rng);
    (name.clone(), bytes, m)
}

/// Input `i` of a campaign over every command: the seed's name, the command (one of those the
/// seed takes, [`FuzzCommand::for_seed`], chosen by the input's generator), the mutant of the
/// seed reduced for that command ([`reduce_for`]) and the mutations.
pub fn input_command(
    seeds: &[(String, String)],
    seed: u64,
    i: usize,
    max_steps: usize,
) -> (String, FuzzCommand, Vec<u8>, Vec<Mutation>) {
    let mut rng = Rng::new(seed ^ (i as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
    let (name, text) = &seeds[i % seeds.len()];
    let cmds = FuzzCommand::for_seed(text);
    let cmd = cmds[rng.below(cmds.len())];
    let (bytes, m) = mutate(&reduce_for(cmd, text, max_steps), &mut rng);
    (name.clone(), cmd, bytes, m)
}

/// The seed cases of a folder: (file stem, text).
pub fn seeds(dir: &Path) -> Result<Vec<(String, String)>, crate::Error> {
    let mut v = Vec::new();
    for p in crate::driver::discover(dir)? {
        let text = std::fs::read_to_string(&p).map_err(|e| crate::Error::Io(format!("{}: {e}", p.display())))?;
        v.push((p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default(), text));
    }
    if v.is_empty() {
        return Err(crate::Error::Io(format!("{}: no case files", dir.display())));
    }
    Ok(v)
}

fn copy_dir(from: &Path, to: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for e in std::fs::read_dir(from)? {
        let e = e?;
        let p = e.path();
        if e.file_type()?.is_dir() {
            copy_dir(&p, &to.join(e.file_name()))?;
        } else {
            std::fs::copy(&p, to.join(e.file_name()))?;
        }
    }
    Ok(())
}

/// Run one child, `exe check <file> --max-steps N` (or `exe run <file> --out <out> --max-steps
/// N` with `c.run`), under the limits; its class.
pub fn run_child(exe: &Path, file: &Path, out: &Path, c: &Campaign) -> (Class, String, f64) {
    run_command_child(exe, FuzzCommand::Run, file, out, c)
}

/// As [`run_child`], through command `command`: `list --cases <the input's folder>`, `gate
/// <file>`, `static|stability|gust <file> --out <out>` (what cannot finish within half the time
/// limit refused by the budget: `--max-hours`).
pub fn run_command_child(
    exe: &Path,
    command: FuzzCommand,
    file: &Path,
    out: &Path,
    c: &Campaign,
) -> (Class, String, f64) {
    let mut cmd = Command::new(exe);
    let hours = c.timeout.as_secs_f64() / 2.0 / 3600.0;
    match command {
        FuzzCommand::Run if c.run => {
            cmd.arg("run").arg(file).arg("--out").arg(out).arg("--max-steps").arg(c.max_steps.to_string());
        }
        FuzzCommand::Run => {
            cmd.arg("check").arg(file).arg("--max-steps").arg(c.max_steps.to_string());
        }
        FuzzCommand::List => {
            cmd.arg("list").arg("--cases").arg(file.parent().unwrap_or(Path::new(".")));
        }
        FuzzCommand::Gate => {
            cmd.arg("gate").arg(file);
        }
        a => {
            cmd.arg(a.name()).arg(file).arg("--out").arg(out);
        }
    }
    cmd.arg("--max-hours").arg(hours.to_string());
    cmd.stdin(Stdio::null()).stdout(Stdio::null()).stderr(Stdio::piped());
    cmd.env("RUST_BACKTRACE", "0");
    limit(&mut cmd, c.address_space);
    let t0 = Instant::now();
    let mut child = match cmd.spawn() {
        Ok(ch) => ch,
        Err(e) => return (Class::Other, format!("spawn: {e}"), 0.0),
    };
    // Read stderr on a thread so that a chatty child cannot block on a full pipe.
    let mut err_pipe = child.stderr.take();
    let reader = std::thread::spawn(move || {
        let mut s = Vec::new();
        if let Some(p) = &mut err_pipe {
            let _ = p.take(1 << 16).read_to_end(&mut s);
            let _ = std::io::copy(p, &mut std::io::sink());
        }
        String::from_utf8_lossy(&s).into_owned()
    });
    let pid = child.id();
    let delay0 = run_delay_seconds(pid);
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break Some(s),
            Ok(None)
                if cpu_seconds(pid).map_or(t0.elapsed() > c.timeout, |x| x > c.timeout.as_secs_f64())
                    || awake_seconds(pid, t0, delay0) > 6.0 * c.timeout.as_secs_f64() =>
            {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(5)),
            Err(_) => break None,
        }
    };
    let secs = t0.elapsed().as_secs_f64();
    let err = reader.join().unwrap_or_default();
    let Some(status) = status else { return (Class::Hang, err, secs) };
    let class = match classify_status(status) {
        Class::Rejected if !err.contains(&file.display().to_string()) => Class::RejectedUnnamed,
        k => k,
    };
    let class = if err.contains("panicked") && class != Class::Abort { Class::Panic } else { class };
    (class, err, secs)
}

/// Run a campaign; prints a progress line every 30 s and writes `fuzz.json`, `fuzz.md` and every
/// crashing input under `crashes/` (with its stderr).
pub fn campaign(c: &Campaign) -> Result<Report, crate::Error> {
    let io = |p: &Path, e: std::io::Error| crate::Error::Io(format!("{}: {e}", p.display()));
    let seeds = seeds(&c.cases)?;
    let exe = std::env::current_exe().map_err(|e| crate::Error::Io(e.to_string()))?;
    let work = c.out.join("work");
    let crashes = c.out.join("crashes");
    std::fs::create_dir_all(&crashes).map_err(|e| io(&crashes, e))?;
    // The mutants' folders, one per job (`list` reads a whole folder), each with the seeds'
    // `reference/` (a seed folder of its own, such as `cases/statics`, may have none).
    let refs = c.cases.join("reference");
    for w in 0..c.jobs.max(1) {
        let d = work.join(format!("w{w}"));
        std::fs::create_dir_all(&d).map_err(|e| io(&d, e))?;
        if refs.is_dir() {
            copy_dir(&refs, &d.join("reference")).map_err(|e| io(&d, e))?;
        }
    }
    let next = AtomicUsize::new(c.first);
    let end = c.first + c.inputs;
    let report = Mutex::new(Report { seed: c.seed, ..Default::default() });
    let t0 = Instant::now();
    let last_line = Mutex::new(Instant::now());
    std::thread::scope(|s| {
        for w in 0..c.jobs.max(1) {
            let (next, report, seeds, exe, work, crashes, last_line) =
                (&next, &report, &seeds, &exe, &work, &crashes, &last_line);
            s.spawn(move || {
                let mut worker: Option<Worker> = None;
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= end || crate::signal::interrupted() {
                        break;
                    }
                    let (name, command, bytes, muts) = input_command(seeds, c.seed, i, c.max_steps);
                    let file = work.join(format!("w{w}")).join(format!("{name}.json"));
                    let out = work.join(format!("out{w}"));
                    let (class, err, secs) = if let Err(e) = std::fs::write(&file, &bytes) {
                        // Counted, not skipped: a campaign that cannot write its inputs says so.
                        (Class::Other, format!("{}: {e}", file.display()), 0.0)
                    } else if c.exec_each || c.run {
                        let r = run_command_child(exe, command, &file, &out, c);
                        let _ = std::fs::remove_dir_all(&out);
                        r
                    } else {
                        let t = Instant::now();
                        if worker.is_none() {
                            worker = Worker::start(exe, c).ok();
                        }
                        let r = match worker.as_mut().map(|wk| wk.check(command, &file, c.timeout)) {
                            Some(Ok((k, m))) => (k, m),
                            Some(Err(k)) => {
                                worker = None;
                                (k, String::new())
                            }
                            None => (Class::Other, "the worker did not start".into()),
                        };
                        // Worker mode reports the message, not the stderr: a refusal names the file there.
                        let k = match r.0 {
                            Class::Rejected if !r.1.contains(&file.display().to_string()) => Class::RejectedUnnamed,
                            k => k,
                        };
                        (k, r.1, t.elapsed().as_secs_f64())
                    };
                    let mut r = report.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                    r.inputs += 1;
                    *r.classes.entry(class).or_default() += 1;
                    *r.commands.entry(command).or_default().entry(class).or_default() += 1;
                    r.slowest_s = r.slowest_s.max(secs);
                    if class.is_crash() {
                        let stem = format!("{:?}-{i}-{}-{name}", class, command.name()).to_lowercase();
                        let _ = std::fs::write(crashes.join(format!("{stem}.json")), &bytes);
                        let _ = std::fs::write(
                            crashes.join(format!("{stem}.txt")),
                            format!(
                                "input {i} seed {} command {} mutations {muts:?} ({secs:.1} s)\n{err}",
                                c.seed,
                                command.name()
                            ),
                        );
                        r.crashes.push(stem);
                    }
                    let mut l = last_line.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                    if l.elapsed() >= Duration::from_secs(30) {
                        *l = Instant::now();
                        eprintln!(
                            "fuzz: {} of {} inputs in {:.0} s: {:?}",
                            r.inputs,
                            c.inputs,
                            t0.elapsed().as_secs_f64(),
                            r.classes
                        );
                    }
                }
            });
        }
    });
    let mut r = report.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner);
    r.wall_s = t0.elapsed().as_secs_f64();
    let json = serde_json::to_string_pretty(&r).map_err(|e| crate::Error::Io(e.to_string()))?;
    crate::atomic::write(&c.out.join("fuzz.json"), json.as_bytes())?;
    let mut md = format!(
        "# Fuzz campaign\n\n{} inputs (seed {}, first {}), {} at a time, each under {} s and {} GB of address \
         space, at most {} steps per run; {:.0} s wall, slowest input {:.1} s.\n\n| class | inputs |\n|---|---|\n",
        r.inputs,
        c.seed,
        c.first,
        c.jobs,
        c.timeout.as_secs(),
        c.address_space >> 30,
        c.max_steps,
        r.wall_s,
        r.slowest_s
    );
    let label = |k: &Class| serde_json::to_string(k).unwrap_or_default().trim_matches('"').to_string();
    for (k, n) in &r.classes {
        md.push_str(&format!("| {} | {n} |\n", label(k)));
    }
    md.push_str("\n| command | inputs | by class |\n|---|---|---|\n");
    for (cmd, classes) in &r.commands {
        let by: Vec<String> = classes.iter().map(|(k, n)| format!("{} {n}", label(k))).collect();
        md.push_str(&format!("| {} | {} | {} |\n", cmd.name(), classes.values().sum::<usize>(), by.join(", ")));
    }
    crate::atomic::write(&c.out.join("fuzz.md"), md.as_bytes())?;
    let _ = std::fs::remove_dir_all(&work);
    Ok(r)
}
