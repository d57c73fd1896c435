//! The tools outside cargo that the browser and VTK-reader tests drive: headless Chromium and a
//! Python virtual environment with VTK's own reader, both installed by `tools/ci-deps.sh` (which
//! `.ci/run` calls). Without them a test skips with a message saying what is missing; under CI
//! (`CI` set) it fails instead, so that CI cannot pass without running them.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Skip (print and return None) or, under CI, fail with `what` is missing.
pub fn missing<T>(test: &str, what: &str) -> Option<T> {
    let msg = format!("{test}: SKIPPED: {what}; run tools/ci-deps.sh to install it");
    if std::env::var_os("CI").is_some() {
        panic!("{msg} (CI is set: the test must run)");
    }
    eprintln!("{msg}");
    None
}

/// The virtual environment's Python with `vtk` importable: `$FLEXMB_TEST_VENV/bin/python`, else
/// `target/ci-venv/bin/python`.
pub fn venv_python(test: &str) -> Option<PathBuf> {
    let venv = std::env::var_os("FLEXMB_TEST_VENV").map_or_else(|| root().join("target/ci-venv"), PathBuf::from);
    let py = venv.join("bin/python");
    let ok = Command::new(&py).args(["-c", "import vtk"]).output().is_ok_and(|o| o.status.success());
    if ok { Some(py) } else { missing(test, &format!("no Python with vtk at {}", py.display())) }
}

/// Headless Chromium on the PATH.
pub fn chromium(test: &str) -> Option<PathBuf> {
    let found = std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).map(|d| d.join("chromium")).find(|c| c.is_file()))
        .unwrap_or_default();
    match found {
        Some(c) => Some(c),
        None => missing(test, "no `chromium` on the PATH"),
    }
}

/// A fresh temporary folder for `name`.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("harness-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Copy a folder tree.
pub fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let p = e.path();
        if p.is_dir() {
            copy_tree(&p, &to.join(e.file_name()));
        } else {
            std::fs::copy(&p, to.join(e.file_name())).unwrap();
        }
    }
}
