//! Set-up shared by the test modules: the repository root, a case file of `cases/` expanded
//! with overrides, and a case written from JSON into a test's temporary folder.

use std::path::PathBuf;

use harness::case::{CaseFile, Override, RunSpec};

/// The repository root (the workspace above the harness crate).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The first run of `cases/<name>` with the overrides `set` (`key=value`).
pub fn case(name: &str, set: &[&str]) -> RunSpec {
    let ov: Vec<Override> = set.iter().map(|s| s.parse().unwrap()).collect();
    CaseFile::read(&root().join("cases").join(name)).unwrap().expand(&ov).unwrap().remove(0)
}

/// Write the case `v` to `<tmp>/harness-<folder>-<pid>/<tag>.json` and expand its first run;
/// the reading or expansion error as text.
pub fn json_spec(v: &serde_json::Value, folder: &str, tag: &str) -> Result<RunSpec, String> {
    let dir = std::env::temp_dir().join(format!("harness-{folder}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("{tag}.json"));
    std::fs::write(&p, v.to_string()).unwrap();
    CaseFile::read(&p).map_err(|e| e.to_string())?.expand(&[]).map_err(|e| e.to_string()).map(|mut v| v.remove(0))
}
