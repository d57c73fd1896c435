//! The exceptions of `flexmb` and the mapping of the harness's errors onto them.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyOSError};
use pyo3::prelude::*;

create_exception!(
    _core,
    FlexmbError,
    PyException,
    "Base class of the errors flexmb raises (besides OSError for unreadable files)."
);
create_exception!(
    _core,
    CaseError,
    FlexmbError,
    "A case (or an override of it) is malformed or has an impossible value. `.field` is the \
     offending field's path as the case file spells it (`joints[1].flare_deg`, `ancf.dt`), or \
     None when the message names none; `.file` the case file."
);
create_exception!(
    _core,
    RunError,
    FlexmbError,
    "A run stopped before its end time (Newton diverged, a singular matrix, ...). `.formulation` \
     names it and `.result` holds the arrays of the rows computed until then."
);

/// The field a harness message starts with (`bodies[1].point_masses[0].at: ...`), extended by
/// the key of an "unknown field" message (`ancf: unknown field `dtt`` → `ancf.dtt`).
pub fn field_of(msg: &str) -> Option<String> {
    let unknown = |rest: &str| -> Option<String> {
        let r = rest.strip_prefix("unknown field `")?;
        Some(r[..r.find('`')?].to_string())
    };
    // An override's error inside a case error: `[ancf: |gebf: ]--set: `path`: …`.
    let msg = msg.strip_prefix("ancf: ").or_else(|| msg.strip_prefix("gebf: ")).unwrap_or(msg);
    let msg = msg.strip_prefix("--set: ").unwrap_or(msg);
    if let Some(u) = unknown(msg) {
        return Some(u);
    }
    // `--set` errors quote the path: "`joints.7`: index 7 out of range (length 2)".
    if let Some(r) = msg.strip_prefix('`') {
        return r.find("`:").map(|i| r[..i].to_string());
    }
    let (head, rest) = msg.split_once(": ")?;
    let plain = |c: char| c.is_ascii_alphanumeric() || "_.[]/ ".contains(c);
    if head.is_empty() || head.len() > 120 || !head.chars().all(plain) {
        return None;
    }
    let head = head.trim().to_string();
    // serde_path_to_error's path ends with an unknown key already; a path that does not gets it.
    Some(match unknown(rest) {
        Some(u) if head != u && !head.ends_with(&format!(".{u}")) => format!("{head}.{u}"),
        _ => head,
    })
}

/// A harness error as a Python exception: case and override errors as [`CaseError`] with
/// `.field` and `.file`, unreadable files as `OSError`.
pub fn to_py(py: Python<'_>, e: casefile::Error) -> PyErr {
    let set = |err: PyErr, field: Option<String>, file: Option<String>| -> PyErr {
        let v = err.value(py);
        let r = v.setattr("field", field).and_then(|_| v.setattr("file", file));
        match r {
            Ok(()) => err,
            Err(e) => e,
        }
    };
    match e {
        casefile::Error::Case { file, msg } => {
            let field = field_of(&msg);
            set(CaseError::new_err(format!("{file}: {msg}")), field, Some(file))
        }
        casefile::Error::Override(msg) => {
            let field = field_of(&msg);
            set(CaseError::new_err(format!("--set: {msg}")), field, None)
        }
        casefile::Error::Io(msg) => PyOSError::new_err(msg),
        other => FlexmbError::new_err(other.to_string()),
    }
}
