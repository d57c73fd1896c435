//! `flexmb._core`: the Rust side of the `flexmb` Python package.
//!
//! Every function here goes through the libraries exactly as the `harness` command line does
//! (the case files of [`casefile`], the analyses of [`aeroelastic`]; not the command line's crate,
//! so neither clap nor plotters is linked): [`CaseFile::read`]/[`CaseFile::from_bytes`],
//! [`CaseFile::expand`] with the `--set` overrides, then [`casefile::scene::run_formulation`] per
//! formulation (in parallel, as
//! `harness run` runs them), [`aeroelastic::statics::run_static`] or
//! [`aeroelastic::stability::run_stability`]. The arrays handed to Python are
//! the `f64`s of the rows the command line formats into its CSV files, column by column, so a
//! value printed by the CLI is the Python value rounded by that format (`flexmb.to_csv` re-renders
//! them with the CLI's own writer).
//!
//! A run releases the GIL. It runs on rayon's pool while the calling thread waits with the GIL
//! released and, every 20 ms, takes it back to let Python handle pending signals: a Ctrl-C
//! (`KeyboardInterrupt`) sets the library's stop flag ([`aeroelastic::interrupt::request_stop`]), which
//! both time loops read before each step, waits for the run to stop, clears the flag and raises.
#![warn(missing_docs)]

mod columns;
mod errors;

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;

use aeroelastic::run::RunOutput;
use casefile::{CaseFile, Formulation, Override, RunSpec};

use crate::errors::{CaseError, FlexmbError, RunError, to_py};

/// How often a waiting call takes the GIL back to let Python run its signal handlers.
const POLL: Duration = Duration::from_millis(20);

/// Parse the formulation names (`"ancf"`, `"gebf"`: [`Formulation::from_name`]).
fn formulations(names: &[String]) -> PyResult<Vec<Formulation>> {
    names.iter().map(|n| Formulation::from_name(n).ok_or_else(|| unknown_formulation(n))).collect()
}

/// The [`CaseError`] of a formulation name that is none, its `field` set to `formulation`.
fn unknown_formulation(name: &str) -> PyErr {
    let e = CaseError::new_err(format!("formulation: `{name}` is not one of \"ancf\", \"gebf\", \"both\""));
    match Python::with_gil(|py| e.value(py).setattr("field", "formulation")) {
        Ok(()) => e,
        Err(set_failed) => set_failed,
    }
}

/// Read a case (a path, or JSON text whose references resolve against `base_dir`), apply the
/// overrides and expand its sweep.
fn load(case: &str, from_path: bool, base_dir: &str, overrides: &[String]) -> Result<Vec<RunSpec>, casefile::Error> {
    let ovs = overrides.iter().map(|s| s.parse::<Override>()).collect::<Result<Vec<_>, _>>()?;
    let file = if from_path {
        CaseFile::read(Path::new(case))
    } else {
        CaseFile::from_bytes(&PathBuf::from(base_dir).join("<dict>"), case.as_bytes())
    }?;
    file.expand(&ovs)
}

/// Run `work` on rayon's pool with the GIL released, waiting on a channel in slices of [`POLL`];
/// between slices the caller takes the GIL to let Python run its signal handlers. A Ctrl-C
/// (`KeyboardInterrupt`) sets the library's stop flag, which the time loops read before each step,
/// waits for the work to return, clears the flag and raises.
fn interruptible<T: Send + 'static>(py: Python<'_>, work: impl FnOnce() -> T + Send + 'static) -> PyResult<T> {
    let (tx, mut rx) = mpsc::sync_channel(1);
    rayon::spawn(move || {
        let _ = tx.send(work());
    });
    let mut interrupt: Option<PyErr> = None;
    loop {
        let (got, back) = py.allow_threads(move || (rx.recv_timeout(POLL), rx));
        rx = back;
        match got {
            Ok(r) => {
                return match interrupt {
                    Some(e) => {
                        aeroelastic::interrupt::clear_stop();
                        Err(e)
                    }
                    None => Ok(r),
                };
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if interrupt.is_none()
                    && let Err(e) = py.check_signals()
                {
                    aeroelastic::interrupt::request_stop();
                    interrupt = Some(e);
                }
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                aeroelastic::interrupt::clear_stop();
                return Err(FlexmbError::new_err("the run panicked (a bug: please report the case)"));
            }
        }
    }
}

/// The runs of every spec and formulation, in parallel (rayon, as `harness run`).
fn run_specs(specs: &[RunSpec], fs: &[Formulation]) -> Vec<Vec<RunOutput>> {
    let jobs: Vec<(usize, Formulation)> = (0..specs.len()).flat_map(|i| fs.iter().map(move |&f| (i, f))).collect();
    let outs: Vec<(usize, RunOutput)> =
        jobs.par_iter().map(|&(i, f)| (i, casefile::scene::run_formulation(specs[i].case(f), f))).collect();
    let mut per: Vec<Vec<RunOutput>> = vec![Vec::new(); specs.len()];
    for (i, o) in outs {
        per[i].push(o);
    }
    per
}

/// Run a case: returns `[(run name, {formulation: (columns, error or None)})]`, one entry per
/// sweep point, the columns named as in the CLI's CSV.
#[pyfunction]
#[pyo3(signature = (case, from_path, base_dir, formulations, overrides))]
fn run<'py>(
    py: Python<'py>,
    case: &str,
    from_path: bool,
    base_dir: &str,
    formulations: Vec<String>,
    overrides: Vec<String>,
) -> PyResult<Bound<'py, PyList>> {
    let fs = self::formulations(&formulations)?;
    let specs = py.allow_threads(|| load(case, from_path, base_dir, &overrides)).map_err(|e| to_py(py, e))?;
    let specs = std::sync::Arc::new(specs);
    let outs = {
        let (specs, fs) = (specs.clone(), fs.clone());
        interruptible(py, move || run_specs(&specs, &fs))?
    };
    let list = PyList::empty(py);
    for (spec, runs) in specs.iter().zip(outs) {
        let per = PyDict::new(py);
        for out in runs {
            let names = casefile::csv::surface_names(spec.case(out.formulation).aero.as_ref());
            let cols = columns::run_columns(py, &out.rows, &names)?;
            per.set_item(out.formulation.as_str(), (cols, out.error))?;
        }
        list.append((spec.name.as_str(), per))?;
    }
    Ok(list)
}

/// The static sweep of a case: `[(run name, {formulation: (columns, error or None)})]`, the
/// columns named as in `static_<f>.csv`.
#[pyfunction]
#[pyo3(signature = (case, from_path, base_dir, formulations, overrides))]
fn static_sweep<'py>(
    py: Python<'py>,
    case: &str,
    from_path: bool,
    base_dir: &str,
    formulations: Vec<String>,
    overrides: Vec<String>,
) -> PyResult<Bound<'py, PyList>> {
    let fs = self::formulations(&formulations)?;
    let specs = py.allow_threads(|| load(case, from_path, base_dir, &overrides)).map_err(|e| to_py(py, e))?;
    if let Some(s) = specs.iter().find(|s| s.ancf.statics.is_none()) {
        let e = CaseError::new_err(format!("{}: static: the case has no `static` block (airspeeds to sweep)", s.name));
        e.value(py).setattr("field", "static")?;
        return Err(e);
    }
    let specs = std::sync::Arc::new(specs);
    let outs = {
        let (specs, fs) = (specs.clone(), fs.clone());
        interruptible(py, move || {
            specs
                .iter()
                .map(|spec| {
                    fs.par_iter()
                        .map(|&f| aeroelastic::statics::run_static(&spec.case(f).problem(), f))
                        .collect::<Vec<_>>()
                })
                .collect::<Vec<_>>()
        })?
    };
    let list = PyList::empty(py);
    for (spec, runs) in specs.iter().zip(outs) {
        let per = PyDict::new(py);
        for out in runs {
            let names = casefile::csv::surface_names(spec.case(out.formulation).aero.as_ref());
            let cols = columns::static_columns(py, &out, &names)?;
            per.set_item(out.formulation.as_str(), (cols, out.error))?;
        }
        list.append((spec.name.as_str(), per))?;
    }
    Ok(list)
}

/// The level-flight trim of a case (`harness trim`): `[(run name, {formulation: (trim as JSON
/// text, error or None)})]`.
#[pyfunction]
#[pyo3(signature = (case, from_path, base_dir, formulations, overrides))]
fn trim<'py>(
    py: Python<'py>,
    case: &str,
    from_path: bool,
    base_dir: &str,
    formulations: Vec<String>,
    overrides: Vec<String>,
) -> PyResult<Bound<'py, PyList>> {
    let fs = self::formulations(&formulations)?;
    let specs = py.allow_threads(|| load(case, from_path, base_dir, &overrides)).map_err(|e| to_py(py, e))?;
    if let Some(s) = specs.iter().find(|s| fs.iter().any(|&f| s.case(f).trim.is_none())) {
        let e = CaseError::new_err(format!("{}: trim: the case has no `trim` block", s.name));
        e.value(py).setattr("field", "trim")?;
        return Err(e);
    }
    let specs = std::sync::Arc::new(specs);
    let outs = {
        let (specs, fs) = (specs.clone(), fs.clone());
        interruptible(py, move || {
            specs
                .iter()
                .map(|spec| {
                    fs.par_iter()
                        .filter_map(|&f| {
                            let c = spec.case(f);
                            c.trim.as_ref().map(|t| aeroelastic::trim::run_trim(&c.problem(), f, t))
                        })
                        .collect::<Vec<_>>()
                })
                .collect::<Vec<_>>()
        })?
    };
    let list = PyList::empty(py);
    for (spec, runs) in specs.iter().zip(outs) {
        let per = PyDict::new(py);
        for out in runs {
            let text = serde_json::to_string(&out).map_err(|e| RunError::new_err(e.to_string()))?;
            per.set_item(out.formulation.as_str(), (text, out.error.clone()))?;
        }
        list.append((spec.name.as_str(), per))?;
    }
    Ok(list)
}

/// The linearised stability sweep of a case (`harness stability`): `[(run name, {formulation:
/// (columns, error or None)})]`, the columns named as in `stability_<f>.csv` plus `summary`.
#[pyfunction]
#[pyo3(signature = (case, from_path, base_dir, formulations, overrides))]
fn stability<'py>(
    py: Python<'py>,
    case: &str,
    from_path: bool,
    base_dir: &str,
    formulations: Vec<String>,
    overrides: Vec<String>,
) -> PyResult<Bound<'py, PyList>> {
    let fs = self::formulations(&formulations)?;
    let specs = py.allow_threads(|| load(case, from_path, base_dir, &overrides)).map_err(|e| to_py(py, e))?;
    if let Some(s) = specs.iter().find(|s| s.ancf.stability.is_none()) {
        let e = CaseError::new_err(format!(
            "{}: stability: the case has no `stability` block (airspeeds to analyse)",
            s.name
        ));
        e.value(py).setattr("field", "stability")?;
        return Err(e);
    }
    let specs = std::sync::Arc::new(specs);
    let outs = {
        let (specs, fs) = (specs.clone(), fs.clone());
        interruptible(py, move || {
            specs
                .iter()
                .map(|spec| {
                    fs.par_iter()
                        .map(|&f| aeroelastic::stability::run_stability(&spec.case(f).problem(), f))
                        .collect::<Vec<_>>()
                })
                .collect::<Vec<_>>()
        })?
    };
    let list = PyList::empty(py);
    for (spec, runs) in specs.iter().zip(outs) {
        let per = PyDict::new(py);
        for out in runs {
            let cols = columns::stability_columns(py, &out)?;
            per.set_item(out.formulation.as_str(), (cols, out.error))?;
        }
        list.append((spec.name.as_str(), per))?;
    }
    Ok(list)
}

/// The CSV text the CLI writes for a run with these columns (`casefile::csv::to_csv`).
#[pyfunction]
fn to_csv(columns: &Bound<'_, PyDict>) -> PyResult<String> {
    let rows = columns::rows_of(columns)?;
    Ok(casefile::csv::to_csv(&rows, &columns::surface_names(columns)?))
}

/// The ANCF–GEBF tip distance as the CLI computes it (`casefile::curve::tip_difference`, no time
/// shift): `(t, d)` with the maximum being the CLI's "max tip difference".
#[pyfunction]
fn tip_difference(a: &Bound<'_, PyDict>, b: &Bound<'_, PyDict>) -> PyResult<(Vec<f64>, Vec<f64>)> {
    let (ra, rb) = (columns::rows_of(a)?, columns::rows_of(b)?);
    let (ca, cb) = (casefile::curve::tip_curve(&ra), casefile::curve::tip_curve(&rb));
    Ok(casefile::curve::tip_difference(&ca, &cb, 0.0).into_iter().unzip())
}

/// The benchmark's reference: the same load and runs as [`run`], timed inside Rust with no Python
/// object built (s, wall time).
#[pyfunction]
#[pyo3(signature = (case, from_path, base_dir, formulations, overrides))]
fn native_seconds(
    py: Python<'_>,
    case: &str,
    from_path: bool,
    base_dir: &str,
    formulations: Vec<String>,
    overrides: Vec<String>,
) -> PyResult<f64> {
    let fs = self::formulations(&formulations)?;
    py.allow_threads(|| {
        let t = Instant::now();
        let specs = load(case, from_path, base_dir, &overrides)?;
        let outs = run_specs(&specs, &fs);
        std::hint::black_box(&outs);
        Ok(t.elapsed().as_secs_f64())
    })
    .map_err(|e| to_py(py, e))
}

/// The Rust extension of `flexmb`.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("FlexmbError", py.get_type::<FlexmbError>())?;
    m.add("CaseError", py.get_type::<CaseError>())?;
    m.add("RunError", py.get_type::<RunError>())?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(static_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(stability, m)?)?;
    m.add_function(wrap_pyfunction!(trim, m)?)?;
    m.add_function(wrap_pyfunction!(to_csv, m)?)?;
    m.add_function(wrap_pyfunction!(tip_difference, m)?)?;
    m.add_function(wrap_pyfunction!(native_seconds, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
