//! Running many cases: discovery, expansion, parallel runs (rayon), reports.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::Error;
use crate::atomic::{DirLock, claim_dir, clear_outputs};
use crate::case::{CaseFile, Formulation, Override, RunSpec};
use crate::csv::{CsvStream, write_file};
use crate::progress::{Progress, RunProgress};
use crate::report::{CaseResult, index_html, summary_markdown, write_case};
use crate::run::{NoObserver, Observer, Row, RunOutput, Snapshot};
use crate::scene::run_formulation_observed;

/// All `*.json` case files in a folder, sorted by name (`*.schema.json` and hidden files, whose
/// names start with a dot, excluded).
pub fn discover(dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let rd = std::fs::read_dir(dir).map_err(|e| Error::Io(format!("{}: {e}", dir.display())))?;
    let mut v: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json") && !p.to_string_lossy().ends_with(".schema.json"))
        .filter(|p| !p.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.')))
        .collect();
    v.sort();
    Ok(v)
}

/// Read and expand case files; returns the runs and, separately, the files that failed to load.
pub fn expand_all(files: &[PathBuf], overrides: &[Override]) -> (Vec<RunSpec>, Vec<Error>) {
    let mut runs = Vec::new();
    let mut errors = Vec::new();
    for f in files {
        match CaseFile::read(f).and_then(|c| c.expand(overrides)) {
            Ok(r) => runs.extend(r),
            Err(e) => errors.push(e.into()),
        }
    }
    (runs, errors)
}

/// Run the given formulations of every run in parallel (rayon), with per-run progress when
/// `progress` is set ([`Progress::new`]); results in input order.
pub fn run_all(runs: &[RunSpec], formulations: &[Formulation], progress: bool) -> Vec<CaseResult> {
    run_all_observed(runs, formulations, progress, &|_, _| Box::new(NoObserver))
}

/// As [`run_all`], each run handing its output steps to the observer `observer(run, formulation)`
/// makes (e.g. a [`crate::vtk::VtkWriter`]); the observer is dropped when its run ends.
pub fn run_all_observed(
    runs: &[RunSpec],
    formulations: &[Formulation],
    progress: bool,
    observer: &(dyn Fn(&RunSpec, Formulation) -> Box<dyn Observer> + Sync),
) -> Vec<CaseResult> {
    run_into(runs, formulations, None, &Progress::new(progress), observer)
}

/// Run the given formulations of every run in parallel, streaming each run's rows to
/// `<dirs[i]>/<formulation>.csv` as they are computed when `dirs` is given (one folder per run,
/// claimed with [`claim_outputs`]), showing `progress` and handing the output steps to
/// `observer`; results in input order.
pub fn run_into(
    runs: &[RunSpec],
    formulations: &[Formulation],
    dirs: Option<&[PathBuf]>,
    progress: &Progress,
    observer: &(dyn Fn(&RunSpec, Formulation) -> Box<dyn Observer> + Sync),
) -> Vec<CaseResult> {
    let jobs: Vec<(usize, Formulation)> =
        (0..runs.len()).flat_map(|i| formulations.iter().map(move |&f| (i, f))).collect();
    // A single run may thread its aerodynamics; several share the threads one each.
    let _runs = crate::aero::register_runs(jobs.len());
    // On a pool thread: a lone run's parallel loops then split their work with the thread that
    // marches, instead of each loop being handed to the pool from outside and waited on.
    let outputs: Vec<_> = rayon::scope(|_| {
        jobs.par_iter()
            .map(|&(i, f)| {
                let case = runs[i].case(f);
                let csv = match dirs
                    .map(|d| {
                        CsvStream::create(
                            &d[i].join(format!("{f}.csv")),
                            casefile::csv::surface_names(case.aero.as_ref()),
                        )
                    })
                    .transpose()
                {
                    Ok(c) => c,
                    Err(e) => return (i, RunOutput::failed(f, e.to_string())),
                };
                let dt = case.block(f).dt;
                let mut obs = Streamed {
                    csv,
                    progress: progress.run(&runs[i].name, f, case.t_end, dt),
                    inner: observer(&runs[i], f),
                };
                let out = run_formulation_observed(case, f, &mut obs);
                (i, out)
            })
            .collect()
    });
    let mut per: Vec<Vec<_>> = vec![Vec::new(); runs.len()];
    for (i, o) in outputs {
        per[i].push(o);
    }
    runs.iter().zip(per).map(|(spec, outs)| CaseResult::evaluate(spec, outs)).collect()
}

/// The observer of a run in [`run_into`]: its rows to the CSV stream and the progress, its
/// snapshots to the caller's observer.
struct Streamed {
    csv: Option<CsvStream>,
    progress: RunProgress,
    inner: Box<dyn Observer>,
}

impl Observer for Streamed {
    fn wants_snapshots(&self) -> bool {
        self.inner.wants_snapshots()
    }
    fn observe(&mut self, snapshot: &Snapshot<'_>) -> Result<(), String> {
        self.inner.observe(snapshot)
    }
    fn row(&mut self, row: &Row) -> Result<(), String> {
        if let Some(c) = &mut self.csv {
            c.push(row)?;
        }
        self.progress.update(row.t);
        self.inner.row(row)
    }
}

/// The name of a run's output folder: the run's name, with `__only-<formulation>` when one
/// formulation runs and `__set_<overrides>` when `--set` overrides apply (the overrides spelt
/// out when short and plain, else a 16-digit hash of them), so that a variant never writes into
/// (or compares against the references of) the plain case's folder.
pub fn variant_name(name: &str, overrides: &[Override], formulations: &[Formulation]) -> String {
    let mut n = name.to_string();
    if let [f] = formulations {
        n.push_str(&format!("__only-{f}"));
    }
    if !overrides.is_empty() {
        let text: Vec<String> = overrides
            .iter()
            .map(|o| {
                let v = match &o.value {
                    serde_json::Value::String(s) => s.clone(),
                    v => v.to_string(),
                };
                format!("{}{}={v}", o.only.map(|f| format!("{f}-")).unwrap_or_default(), o.path)
            })
            .collect();
        let text = text.join(",");
        let safe = |c: char| c.is_ascii_alphanumeric() || "._-+=,".contains(c);
        if text.len() <= 60 && text.chars().all(safe) {
            n.push_str(&format!("__set_{text}"));
        } else {
            // FNV-1a, 64 bits: stable across runs and platforms.
            let h = text.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
            n.push_str(&format!("__set_{h:016x}"));
        }
    }
    n
}

/// Claim the output folder of every run (`<out>/<run name>`; see [`crate::atomic::claim_dir`]),
/// clear what an earlier run left there, and write a `summary.json` whose `"status"` is
/// `"interrupted"` until [`finish_case`] replaces it: a run killed at any moment leaves a
/// summary that says so beside its partial CSV. Returns the locks (held until dropped) and the
/// folders.
pub fn claim_outputs(out: &Path, runs: &[RunSpec]) -> Result<(Vec<DirLock>, Vec<PathBuf>), Error> {
    let mut locks = Vec::new();
    let mut dirs = Vec::new();
    for r in runs {
        let dir = out.join(&r.name);
        let lock = claim_dir(&dir)?;
        // First the summary that says "interrupted" (replacing the last run's in one rename),
        // then the last run's other files go: at no moment does a summary sit beside files it
        // does not describe.
        let started = serde_json::json!({
            "case": r.name,
            "status": "interrupted",
            "note": "written when the run started and replaced when it ends: a run that was killed leaves this",
        });
        crate::atomic::write(&dir.join("summary.json"), started.to_string().as_bytes())?;
        clear_outputs(&lock, &["summary.json"])?;
        locks.push(lock);
        dirs.push(dir);
    }
    Ok((locks, dirs))
}

/// Whether any run of the results was stopped by a signal. A signal that arrives after every
/// run finished stops nothing: the summaries say `"complete"`, and so must the exit code (the
/// runs' own errors say whether a signal cut one, including one it kept from starting).
pub fn any_interrupted(results: &[CaseResult]) -> bool {
    results
        .iter()
        .flat_map(|r| &r.runs)
        .any(|r| r.error.as_deref().is_some_and(|e| e.starts_with(crate::run::INTERRUPTED)))
}

/// Write a case's files ([`write_case`]: CSV, `summary.json`, plots, each atomically), the run's
/// `"status"` (`"complete"` or `"interrupted"`) at the top of its `summary.json`, in the same
/// write: a kill at any moment leaves either the summary that says "interrupted" from
/// [`claim_outputs`] or this one, never one without a status.
pub fn finish_case(dir: &Path, r: &CaseResult) -> Result<(), Error> {
    let interrupted = r.runs.iter().any(|x| x.error.as_deref().is_some_and(|e| e.starts_with(crate::run::INTERRUPTED)));
    write_case(dir, r, if interrupted { "interrupted" } else { "complete" })
}

/// Write `index.html` and `summary.md` under `out` (the cases' own files are written already).
pub fn write_index(out: &Path, results: &[CaseResult]) -> Result<(), Error> {
    write_file(&out.join("index.html"), &index_html(out, results, &[]))?;
    write_file(&out.join("summary.md"), &summary_markdown(results))
}

/// Write every case's files plus `index.html` and `summary.md` under `out`.
pub fn write_reports(out: &Path, results: &[CaseResult]) -> Result<(), Error> {
    let errs: Vec<Error> = results.par_iter().filter_map(|r| finish_case(&out.join(&r.name), r).err()).collect();
    if let Some(e) = errs.into_iter().next() {
        return Err(e);
    }
    write_file(&out.join("index.html"), &index_html(out, results, &[]))?;
    write_file(&out.join("summary.md"), &summary_markdown(results))
}

/// Shorten every formulation of `spec` to at most `steps` steps of its own `dt` (a smoke test of
/// a case: `harness run --max-steps`, the fuzz campaign). The end time stays a whole number of
/// steps.
pub fn limit_steps(spec: &mut RunSpec, steps: usize) {
    for f in Formulation::ALL {
        let case = spec.case_mut(f);
        let dt = case.block(f).dt;
        let t = steps as f64 * dt;
        if t < case.t_end {
            case.t_end = t;
        }
    }
}
