//! The stress matrix: where each formulation survives on hard cases.
//!
//! Cells are the product of stiffness scale c, flare angle β, time-step factor (× the case's dt)
//! and rho_inf, applied to a base case (the paper's double pendulum). Each cell records success or
//! the failure (time and reason), Newton statistics, energy drift and constraint drift. Extra
//! single runs (e.g. a 20 s pendulum) are listed beside the matrix.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::case::{Case, Formulation, Joint, RunSpec};
use crate::csv::write_file;
use crate::metrics::FormulationMetrics;
use crate::progress::Progress;
use crate::scene::run_formulation;

/// The axes of the matrix.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Axes {
    /// Stiffness scales c.
    pub c: Vec<f64>,
    /// Flare angles β, degrees.
    pub beta_deg: Vec<f64>,
    /// Multiples of the case's time step.
    pub dt_factor: Vec<f64>,
    /// Spectral radii.
    pub rho_inf: Vec<f64>,
}

impl Default for Axes {
    fn default() -> Self {
        Self {
            c: vec![1.0, 0.1, 0.01, 0.001],
            beta_deg: vec![0.0, 10.0, 45.0, 80.0, 89.0, 90.0],
            dt_factor: vec![1.0, 2.0, 5.0],
            rho_inf: vec![0.6, 0.8, 0.9, 1.0],
        }
    }
}

/// One cell.
#[derive(Debug, Clone, Serialize)]
pub struct Cell {
    /// Formulation.
    pub formulation: Formulation,
    /// Stiffness scale.
    pub c: f64,
    /// Flare angle, degrees.
    pub beta_deg: f64,
    /// Time-step factor.
    pub dt_factor: f64,
    /// Spectral radius.
    pub rho_inf: f64,
    /// Metrics of the run (incl. failure and the time reached).
    pub metrics: FormulationMetrics,
    /// When the fixed-step run failed: the same cell rerun with the integrator's local error
    /// control ([`RECOVERY_ERROR_TOL`], up to [`RECOVERY_HALVINGS`] halvings of a step).
    pub recovery: Option<FormulationMetrics>,
}

/// Local error tolerance of a recovery run, m (rotations weighted by the body length).
pub const RECOVERY_ERROR_TOL: f64 = 1e-5;
/// Step halvings allowed in a recovery run (down to dt/64).
pub const RECOVERY_HALVINGS: usize = 6;

impl Cell {
    /// Whether the fixed-step run reached its end time.
    pub fn ok(&self) -> bool {
        self.metrics.error.is_none()
    }

    /// Whether the cell failed at fixed steps but reached its end time with step control.
    pub fn recovered(&self) -> bool {
        recovered(&self.metrics, self.recovery.as_ref())
    }
}

/// Make the case of one cell.
fn cell_case(base: &Case, c: f64, beta: f64, dt_factor: f64, rho: f64) -> Case {
    let mut k = base.clone();
    k.stiffness_scale = c;
    for j in &mut k.joints {
        if let Joint::FlaredHinge { flare_deg, .. } = j {
            *flare_deg = beta;
        }
    }
    // Rounded to a whole number of steps in t_end, so that every cell ends at t_end.
    k.ancf.dt = crate::case::commensurate_dt(k.t_end, k.ancf.dt * dt_factor);
    k.gebf.dt = crate::case::commensurate_dt(k.t_end, k.gebf.dt * dt_factor);
    k.ancf.rho_inf = rho;
    k.gebf.rho_inf = rho;
    k.gate = None;
    k.references.clear();
    // Coarser output keeps memory small; metrics only need the sampled history.
    k.output_dt = Some(0.01_f64.max(k.ancf.dt.max(k.gebf.dt)));
    k
}

/// One cell to run: formulation, c, β (degrees), dt factor, rho_inf.
pub type Job = (Formulation, f64, f64, f64, f64);

/// The cells of the matrix in their order (formulation, then c, β, dt factor, rho_inf).
pub fn jobs(axes: &Axes) -> Vec<Job> {
    let mut jobs = Vec::new();
    for f in Formulation::ALL {
        for &c in &axes.c {
            for &b in &axes.beta_deg {
                for &d in &axes.dt_factor {
                    for &r in &axes.rho_inf {
                        jobs.push((f, c, b, d, r));
                    }
                }
            }
        }
    }
    jobs
}

/// The name of a cell as a unit of a sharded sweep (`stress:gebf:c=1:beta=45:dt=2:rho=0.8`).
pub fn job_id(&(f, c, b, d, r): &Job) -> String {
    format!("stress:{f}:c={c}:beta={b}:dt={d}:rho={r}")
}

/// The estimated cost of a cell, s ([`crate::budget::estimate`] of its case).
pub fn job_cost(base: &RunSpec, &(f, c, b, d, r): &Job) -> f64 {
    crate::budget::estimate(&cell_case(base.case(f), c, b, d, r), f, None).seconds
}

/// Run the matrix on `base` (rayon over cells), counting the cells on `progress`.
pub fn run(base: &RunSpec, axes: &Axes, progress: &Progress) -> Vec<Cell> {
    run_jobs(base, &jobs(axes), progress)
}

/// Run the given cells of the matrix on `base` (rayon over cells), in their order, counting
/// them on `progress`.
pub fn run_jobs(base: &RunSpec, jobs: &[Job], progress: &Progress) -> Vec<Cell> {
    let bar = progress.counter(jobs.len(), "stress cells");
    let cells = jobs
        .par_iter()
        .map(|&(f, c, b, d, r)| {
            let case = cell_case(base.case(f), c, b, d, r);
            let out = run_formulation(&case, f);
            // Recover a failed cell with step control: same nominal dt, steps halved where the
            // local error estimate (or Newton) asks for it.
            let recovery =
                out.error.is_some().then(|| FormulationMetrics::of(&run_formulation(&with_step_control(&case), f)));
            bar.inc(1);
            Cell {
                formulation: f,
                c,
                beta_deg: b,
                dt_factor: d,
                rho_inf: r,
                metrics: FormulationMetrics::of(&out),
                recovery,
            }
        })
        .collect();
    bar.finish_and_clear();
    cells
}

/// CSV columns shared by matrix cells and extra runs: the fixed-step run, then its recovery.
const RUN_COLUMNS: &str = "ok,t_reached,newton_per_step,max_newton_iters,energy_drift,max_constraint_residual,wall_s,failure,recovered,recovery_t_reached,recovery_newton_per_step,recovery_energy_drift,recovery_wall_s";

/// A run failed at fixed steps and its rerun with step control reached the end time.
fn recovered(m: &FormulationMetrics, recovery: Option<&FormulationMetrics>) -> bool {
    m.error.is_some() && recovery.is_some_and(|r| r.error.is_none())
}

/// The [`RUN_COLUMNS`] of one run and its optional recovery.
fn run_columns(m: &FormulationMetrics, recovery: Option<&FormulationMetrics>) -> String {
    let rec = |f: fn(&FormulationMetrics) -> f64| recovery.map_or(f64::NAN, f);
    format!(
        "{},{:.4},{:.3},{},{:.3e},{:.3e},{:.4},\"{}\",{},{:.4},{:.3},{:.3e},{:.4}",
        m.error.is_none(),
        m.t_reached,
        m.newton_per_step,
        m.max_newton_iters,
        m.energy_drift,
        m.max_constraint_residual,
        m.wall_s,
        m.error.clone().unwrap_or_default().replace('"', "'"),
        recovered(m, recovery),
        rec(|r| r.t_reached),
        rec(|r| r.newton_per_step),
        rec(|r| r.energy_drift),
        rec(|r| r.wall_s),
    )
}

/// Write `stress.csv`, `stress.json` and one heat map per formulation (`stress_<f>.svg`).
pub fn write(dir: &Path, axes: &Axes, cells: &[Cell]) -> Result<(), Error> {
    let mut csv = format!("formulation,c,beta_deg,dt_factor,rho_inf,{RUN_COLUMNS}\n");
    for k in cells {
        let cols = run_columns(&k.metrics, k.recovery.as_ref());
        let _ = writeln!(csv, "{},{},{},{},{},{cols}", k.formulation, k.c, k.beta_deg, k.dt_factor, k.rho_inf);
    }
    write_file(&dir.join("stress.csv"), &csv)?;
    write_file(&dir.join("stress.json"), &serde_json::to_string_pretty(cells).map_err(|e| Error::Io(e.to_string()))?)?;
    for f in Formulation::ALL {
        heat_map(&dir.join(format!("stress_{f}.svg")), axes, cells, f)?;
    }
    Ok(())
}

/// Colour of a cell: red = failed, blue = failed at fixed steps but recovered with step control,
/// orange = energy drift > 10 %, yellow > 1 %, green otherwise.
fn cell_color(k: &Cell) -> RGBColor {
    if k.recovered() {
        RGBColor(100, 150, 230)
    } else if !k.ok() {
        RGBColor(214, 39, 40)
    } else if k.metrics.energy_drift.is_nan() || k.metrics.energy_drift > 0.1 {
        RGBColor(255, 160, 60)
    } else if k.metrics.energy_drift > 0.01 {
        RGBColor(240, 220, 80)
    } else {
        RGBColor(90, 180, 90)
    }
}

fn heat_map(path: &Path, axes: &Axes, cells: &[Cell], f: Formulation) -> Result<(), Error> {
    let err = |m: String| Error::Plot { file: path.display().to_string(), msg: m };
    let rows: Vec<(f64, f64)> = axes.c.iter().flat_map(|&c| axes.beta_deg.iter().map(move |&b| (c, b))).collect();
    let cols: Vec<(f64, f64)> =
        axes.dt_factor.iter().flat_map(|&d| axes.rho_inf.iter().map(move |&r| (d, r))).collect();
    let (cw, ch, left, top) = (74i32, 26i32, 150i32, 90i32);
    let w = (left + cw * cols.len() as i32 + 20) as u32;
    let h = (top + ch * rows.len() as i32 + 70) as u32;
    let file = crate::atomic::TempFile::new(path)?;
    let tmp = file.path().to_path_buf();
    let root = SVGBackend::new(&tmp, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let txt = |s: &str, x: i32, y: i32, size: i32| Text::new(s.to_string(), (x, y), ("sans-serif", size).into_font());
    let title = format!(
        "Stress matrix, {}: cell = (c, β) row × (dt factor, ρ∞) column; text = Newton/step or failure time [s]",
        f.as_str().to_uppercase()
    );
    root.draw(&txt(&title, 10, 8, 15)).map_err(|e| err(e.to_string()))?;
    for (j, (d, r)) in cols.iter().enumerate() {
        let x = left + cw * j as i32 + 4;
        root.draw(&txt(&format!("dt×{d}"), x, top - 40, 13)).map_err(|e| err(e.to_string()))?;
        root.draw(&txt(&format!("ρ∞ {r}"), x, top - 22, 13)).map_err(|e| err(e.to_string()))?;
    }
    for (i, (c, b)) in rows.iter().enumerate() {
        let y = top + ch * i as i32;
        root.draw(&txt(&format!("c {c}, β {b}°"), 8, y + 6, 13)).map_err(|e| err(e.to_string()))?;
        for (j, (d, r)) in cols.iter().enumerate() {
            let x = left + cw * j as i32;
            let Some(k) = cells
                .iter()
                .find(|k| k.formulation == f && k.c == *c && k.beta_deg == *b && k.dt_factor == *d && k.rho_inf == *r)
            else {
                continue;
            };
            root.draw(&Rectangle::new([(x, y), (x + cw - 2, y + ch - 2)], cell_color(k).filled()))
                .map_err(|e| err(e.to_string()))?;
            let label = if k.ok() {
                format!("{:.1}", k.metrics.newton_per_step)
            } else if k.recovered() {
                format!("✗{:.2}↻", k.metrics.t_reached)
            } else {
                format!("✗{:.2}", k.metrics.t_reached)
            };
            root.draw(&txt(&label, x + 6, y + 6, 12)).map_err(|e| err(e.to_string()))?;
        }
    }
    let ly = top + ch * rows.len() as i32 + 16;
    let legend = [
        (RGBColor(90, 180, 90), "ok, drift ≤ 1 %"),
        (RGBColor(240, 220, 80), "ok, drift ≤ 10 %"),
        (RGBColor(255, 160, 60), "ok, drift > 10 %"),
        (RGBColor(214, 39, 40), "failed (time reached)"),
        (RGBColor(100, 150, 230), "↻ reached t_end with step control"),
    ];
    for (n, (col, s)) in legend.iter().enumerate() {
        let x = 10 + 170 * n as i32;
        root.draw(&Rectangle::new([(x, ly), (x + 16, ly + 14)], col.filled())).map_err(|e| err(e.to_string()))?;
        root.draw(&txt(s, x + 22, ly, 13)).map_err(|e| err(e.to_string()))?;
    }
    root.present().map_err(|e| err(e.to_string()))?;
    file.commit()
}

/// (cells reaching t_end at fixed steps, cells recovered with step control, cells) per formulation.
pub fn survival(cells: &[Cell], f: Formulation) -> (usize, usize, usize) {
    let of_f: Vec<&Cell> = cells.iter().filter(|k| k.formulation == f).collect();
    (of_f.iter().filter(|k| k.ok()).count(), of_f.iter().filter(|k| k.recovered()).count(), of_f.len())
}

/// One extra hard run beside the matrix (a long pendulum, a wing at high incidence).
#[derive(Debug, Clone, Serialize)]
pub struct Extra {
    /// What it is.
    pub label: String,
    /// Formulation.
    pub formulation: Formulation,
    /// Metrics (failure, time reached, Newton, drifts).
    pub metrics: FormulationMetrics,
    /// A failed run repeated with step control (as for the matrix cells).
    pub recovery: Option<FormulationMetrics>,
}

/// The case rerun with local error control after a fixed-step failure.
fn with_step_control(case: &Case) -> Case {
    let mut k = case.clone();
    for n in [&mut k.ancf.newton, &mut k.gebf.newton] {
        n.local_error_tol = RECOVERY_ERROR_TOL;
        n.max_step_halvings = RECOVERY_HALVINGS;
    }
    k
}

/// An observer that only reports progress.
struct Progressed(crate::progress::RunProgress);

impl crate::run::Observer for Progressed {
    fn wants_snapshots(&self) -> bool {
        false
    }
    fn observe(&mut self, _: &crate::run::Snapshot<'_>) -> Result<(), String> {
        Ok(())
    }
    fn row(&mut self, row: &crate::run::Row) -> Result<(), String> {
        self.0.update(row.t);
        Ok(())
    }
}

/// Run extra cases (label, case spec) with both formulations in parallel, each rerun with step
/// control if it fails, with per-run progress on `progress`.
pub fn run_extras(extras: &[(String, RunSpec)], progress: &Progress) -> Vec<Extra> {
    let jobs: Vec<(usize, Formulation)> =
        (0..extras.len()).flat_map(|i| Formulation::ALL.into_iter().map(move |f| (i, f))).collect();
    jobs.par_iter()
        .map(|&(i, f)| {
            let case = extras[i].1.case(f);
            // These runs take minutes: show their progress (simulated time, steps/s, time left).
            let dt = case.block(f).dt;
            let mut progress = Progressed(progress.run(&extras[i].0, f, case.t_end, dt));
            let out = crate::scene::run_formulation_observed(case, f, &mut progress);
            let recovery =
                out.error.is_some().then(|| FormulationMetrics::of(&run_formulation(&with_step_control(case), f)));
            Extra { label: extras[i].0.clone(), formulation: f, metrics: FormulationMetrics::of(&out), recovery }
        })
        .collect()
}

/// Write `extras.csv`.
pub fn write_extras(dir: &Path, extras: &[Extra]) -> Result<(), Error> {
    let mut csv = format!("label,formulation,{RUN_COLUMNS}\n");
    for e in extras {
        let _ = writeln!(csv, "\"{}\",{},{}", e.label, e.formulation, run_columns(&e.metrics, e.recovery.as_ref()));
    }
    write_file(&dir.join("extras.csv"), &csv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::RunOutput;

    /// A failed run with a successful recovery: one value per header column, quoted failure text.
    #[test]
    fn run_columns_match_the_header() {
        let failed = FormulationMetrics::of(&RunOutput::failed(Formulation::Gebf, "step 3: \"singular\"".into()));
        let mut ok = failed.clone();
        ok.error = None;
        let row = run_columns(&failed, Some(&ok));
        assert_eq!(row.split(',').count(), RUN_COLUMNS.split(',').count(), "{row}");
        assert!(recovered(&failed, Some(&ok)) && !recovered(&ok, Some(&ok)) && !recovered(&failed, None));
        assert!(row.contains("'singular'"), "{row}");
    }
}
