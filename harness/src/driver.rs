//! Running many cases: discovery, expansion, parallel runs (rayon), reports.

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use crate::Error;
use crate::case::{CaseFile, Formulation, Override, RunSpec};
use crate::csv::write_file;
use crate::report::{CaseResult, index_html, summary_markdown, write_case};
use crate::run::{NoObserver, Observer};
use crate::scene::run_formulation_observed;

/// All `*.json` case files in a folder, sorted by name (`*.schema.json` excluded).
pub fn discover(dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let rd = std::fs::read_dir(dir).map_err(|e| Error::Io(format!("{}: {e}", dir.display())))?;
    let mut v: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json") && !p.to_string_lossy().ends_with(".schema.json"))
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
            Err(e) => errors.push(e),
        }
    }
    (runs, errors)
}

/// Run the given formulations of every run in parallel (rayon), with a progress bar when
/// `progress` is set; results in input order.
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
    let jobs: Vec<(usize, Formulation)> =
        (0..runs.len()).flat_map(|i| formulations.iter().map(move |&f| (i, f))).collect();
    let bar = if progress {
        let b = ProgressBar::new(jobs.len() as u64);
        if let Ok(style) = ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}") {
            b.set_style(style);
        }
        b
    } else {
        ProgressBar::hidden()
    };
    let outputs: Vec<_> = jobs
        .par_iter()
        .map(|&(i, f)| {
            let mut obs = observer(&runs[i], f);
            let out = run_formulation_observed(runs[i].case(f), f, &mut *obs);
            bar.set_message(format!("{} {f}", runs[i].name));
            bar.inc(1);
            (i, out)
        })
        .collect();
    bar.finish_and_clear();
    let mut per: Vec<Vec<_>> = vec![Vec::new(); runs.len()];
    for (i, o) in outputs {
        per[i].push(o);
    }
    runs.iter().zip(per).map(|(spec, outs)| CaseResult::evaluate(spec, outs)).collect()
}

/// Write every case's files plus `index.html` and `summary.md` under `out`.
pub fn write_reports(out: &Path, results: &[CaseResult]) -> Result<(), Error> {
    let errs: Vec<Error> = results.par_iter().filter_map(|r| write_case(&out.join(&r.name), r).err()).collect();
    if let Some(e) = errs.into_iter().next() {
        return Err(e);
    }
    write_file(&out.join("index.html"), &index_html(out, results, &[]))?;
    write_file(&out.join("summary.md"), &summary_markdown(results))
}
