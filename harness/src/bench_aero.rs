//! `harness bench --aero`: where the aeroelastic analyses spend their time.
//!
//! Two parts, written to `<out>/bench/aero.{csv,md,json}` and `aero_wake.svg`:
//!
//! * **The step against the wake's length.** The coupled time step of the paper's wing
//!   (`wing_aoa5.json`) and of Healy's wing (`healy_ffwt_flare10_aoa5.json`), GEBF, with the
//!   wake cut to 20, 40, 80, 160 and 320 rows, summed directly in f64, directly in mixed
//!   precision and through the treecode (`aero.wake_aggregation`,
//!   `aero.wake_aggregation_min_segments`). A run marches until its wake is full and 32 steps
//!   more; an observer reads the process's CPU time at every step, and a run's figure is the mean
//!   over the last 32 steps (process time, so that the lattice's own threads count). Every
//!   configuration runs three times, interleaved with the others, and the table gives the
//!   median, then each case's aerodynamic solves per time step (more than one with the
//!   coupling's sub-iterations).
//! * **Whole analyses**, each once, process CPU and wall time: a 20 s run of the paper's wing and
//!   Healy's static sweep per formulation (the sweep as the median of 7 runs), each also with the
//!   committed NACA 0015 polars on both bodies (`cases/polars/`, interleaved with the runs
//!   without; the summary gives the ratio of their CPU times), the Goland wing's
//!   21-speed flutter sweep, and Healy's gust sweep (both formulations, run as `harness all` runs
//!   it).

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use plotters::prelude::*;
use serde::Serialize;

use crate::Error;
use crate::case::{CaseFile, Formulation, Override, RunSpec};
use crate::csv::write_file;
use crate::plot::colors;
use aeroelastic::run::{Observer, Row, Snapshot};

/// The wake lengths the step is timed at, rows.
pub const WAKE_ROWS: [usize; 5] = [20, 40, 80, 160, 320];
/// Steps timed once the wake is full: two rebuild periods of a kept tree, so that every window
/// holds the same number of rebuilds.
const TIMED_STEPS: usize = 64;
/// Timed runs of each step configuration, interleaved (every configuration once, then again);
/// the figure is their median.
const STEP_REPEATS: usize = 3;
/// The ending of the name of an analysis run with section polars.
const POLARS_SUFFIX: &str = ", NACA 0015 polars";

/// How the far wake is summed in a timed step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Summation {
    /// Directly, in f64 (`aero.wake_aggregation=false`).
    Direct,
    /// Directly, in mixed precision (the treecode never applies).
    Mixed,
    /// Through the treecode at every size (its near leaves in mixed precision).
    Treecode,
}

impl Summation {
    /// All three, in the table's order.
    pub const ALL: [Summation; 3] = [Summation::Direct, Summation::Mixed, Summation::Treecode];

    /// The name in the tables.
    pub fn name(self) -> &'static str {
        match self {
            Summation::Direct => "direct",
            Summation::Mixed => "mixed",
            Summation::Treecode => "treecode",
        }
    }

    /// The case overrides that select it.
    fn overrides(self) -> [String; 2] {
        let (on, min) = match self {
            Summation::Direct => (false, 0),
            Summation::Mixed => (true, usize::MAX),
            // The treecode at every size, to show where it breaks even.
            Summation::Treecode => (true, 0),
        };
        [format!("aero.wake_aggregation={on}"), format!("aero.wake_aggregation_min_segments={min}")]
    }
}

/// One timed step.
#[derive(Debug, Clone, Serialize)]
pub struct StepRow {
    /// Case name.
    pub case: String,
    /// Wake rows.
    pub rows: usize,
    /// How the far wake was summed.
    pub summation: Summation,
    /// Mean process CPU time of a step with the wake full, ms.
    pub cpu_ms: f64,
    /// Aerodynamic solves per time step over the run (with the coupling's sub-iterations,
    /// docs/coupling.md §4).
    pub aero_solves_per_step: f64,
    /// Why the run stopped early, if it did.
    pub error: Option<String>,
}

/// One timed analysis.
#[derive(Debug, Clone, Serialize)]
pub struct AnalysisRow {
    /// What ran.
    pub analysis: String,
    /// Formulation, or `both`.
    pub formulation: String,
    /// Process CPU time, s.
    pub cpu_s: f64,
    /// Wall time, s.
    pub wall_s: f64,
    /// Why it failed, if it did.
    pub error: Option<String>,
}

/// Everything `bench --aero` measured.
#[derive(Debug, Clone, Serialize)]
pub struct AeroBench {
    /// The step against the wake's length.
    pub steps: Vec<StepRow>,
    /// The whole analyses.
    pub analyses: Vec<AnalysisRow>,
}

/// CPU time of the whole process (every thread), s.
fn process_cpu_s() -> f64 {
    // SAFETY: `getrusage` fills the zeroed struct it is given and reads nothing else.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        return f64::NAN;
    }
    let s = |t: libc::timeval| t.tv_sec as f64 + 1e-6 * t.tv_usec as f64;
    s(u.ru_utime) + s(u.ru_stime)
}

/// Reads the process's CPU time at every row of a run.
#[derive(Default)]
struct CpuPerRow(Vec<f64>);

impl Observer for CpuPerRow {
    fn wants_snapshots(&self) -> bool {
        false
    }
    fn observe(&mut self, _snapshot: &Snapshot<'_>) -> Result<(), String> {
        Ok(())
    }
    fn row(&mut self, _row: &Row) -> Result<(), String> {
        self.0.push(process_cpu_s());
        Ok(())
    }
}

/// The run of case file `file` in `cases` with the overrides `sets`.
fn spec(cases: &Path, file: &str, sets: &[String]) -> Result<RunSpec, Error> {
    let path = cases.join(file);
    let case =
        CaseFile::read(&path).map_err(|e| Error::Case { file: path.display().to_string(), msg: e.to_string() })?;
    let overrides = sets
        .iter()
        .map(|s| s.parse::<Override>().map_err(|e| Error::Override(e.to_string())))
        .collect::<Result<Vec<_>, _>>()?;
    let mut runs =
        case.expand(&overrides).map_err(|e| Error::Case { file: path.display().to_string(), msg: e.to_string() })?;
    runs.truncate(1);
    runs.pop().ok_or_else(|| Error::Case { file: path.display().to_string(), msg: "no run".into() })
}

/// The mean CPU time of a GEBF step of `file` with a wake of `rows` rows, full.
fn step_row(cases: &Path, file: &str, rows: usize, summation: Summation) -> Result<StepRow, Error> {
    let probe = spec(cases, file, &[])?;
    let dt = probe.case(Formulation::ALL[1]).block(Formulation::ALL[1]).dt;
    let steps = rows + 2 + TIMED_STEPS;
    let [on, min] = summation.overrides();
    let sets = [
        format!("aero.n_wake_rows={rows}"),
        on,
        min,
        format!("t_end={}", steps as f64 * dt),
        format!("output_dt={dt}"),
    ];
    let run = spec(cases, file, &sets)?;
    let mut cpu = CpuPerRow::default();
    let out = aeroelastic::factory::run_formulation_observed(
        &run.case(Formulation::ALL[1]).problem(),
        Formulation::ALL[1],
        &mut cpu,
    );
    let n = cpu.0.len();
    let cpu_ms =
        if n > TIMED_STEPS { 1e3 * (cpu.0[n - 1] - cpu.0[n - 1 - TIMED_STEPS]) / TIMED_STEPS as f64 } else { f64::NAN };
    let aero_solves_per_step = out.aero_solves as f64 / out.aero_steps.max(1) as f64;
    Ok(StepRow { case: run.name.clone(), rows, summation, cpu_ms, aero_solves_per_step, error: out.error })
}

/// Time `work` once: process CPU and wall seconds and its error.
fn timed(analysis: &str, formulation: &str, work: impl FnOnce() -> Option<String>) -> AnalysisRow {
    let (c0, t0) = (process_cpu_s(), Instant::now());
    let error = work();
    AnalysisRow {
        analysis: analysis.into(),
        formulation: formulation.into(),
        cpu_s: process_cpu_s() - c0,
        wall_s: t0.elapsed().as_secs_f64(),
        error,
    }
}

/// The override giving both bodies the committed NACA 0015 polars (`cases/polars/`), flat-plate
/// beyond the table's incidences as Healy's readings use them, and the table's nearest Reynolds
/// number beyond its range (the paper's wing flies at 1.7e6 at sea-level viscosity): the cost is
/// what is timed here.
const NACA0015: &str = r#"aero.polars=[{"bodies":[0,1],"file":"polars/naca0015_neuralfoil.csv","bounds":{"alpha":"flat_plate","re":"clamp"}}]"#;

/// Runs of each static sweep, with and without polars interleaved; the figure is the median
/// (a sweep takes a fifth of a second, where one run's noise is tens of percent).
const STATIC_REPEATS: usize = 7;

/// The median CPU and wall time of `runs` timed runs, and the first error.
fn median_row(analysis: &str, formulation: &str, runs: &[AnalysisRow]) -> AnalysisRow {
    let mut cpu: Vec<f64> = runs.iter().map(|r| r.cpu_s).collect();
    let mut wall: Vec<f64> = runs.iter().map(|r| r.wall_s).collect();
    AnalysisRow {
        analysis: analysis.into(),
        formulation: formulation.into(),
        cpu_s: crate::bench::median(&mut cpu),
        wall_s: crate::bench::median(&mut wall),
        error: runs.iter().find_map(|r| r.error.clone()),
    }
}

/// Healy's static sweep per formulation without and with the polars, [`STATIC_REPEATS`] runs
/// of each, interleaved, as medians.
fn static_sweeps(cases: &Path) -> Result<Vec<AnalysisRow>, Error> {
    let mut out = Vec::new();
    let plain = spec(cases, "healy_ffwt_flare10_aoa5.json", &[])?;
    let polars = spec(cases, "healy_ffwt_flare10_aoa5.json", &[NACA0015.to_string()])?;
    for f in Formulation::ALL {
        let problems = [plain.case(f).problem(), polars.case(f).problem()];
        let mut runs: [Vec<AnalysisRow>; 2] = [Vec::new(), Vec::new()];
        for _ in 0..STATIC_REPEATS {
            for (p, r) in problems.iter().zip(runs.iter_mut()) {
                r.push(timed("", "", || {
                    aeroelastic::statics::run_static(p, f).points.iter().find_map(|x| x.error.clone())
                }));
            }
        }
        for (suffix, r) in ["", POLARS_SUFFIX].iter().zip(&runs) {
            out.push(median_row(&format!("Healy static sweep (12 airspeeds){suffix}"), &f.to_string(), r));
        }
    }
    Ok(out)
}

/// The whole analyses of the module docs.
fn analyses(cases: &Path) -> Result<Vec<AnalysisRow>, Error> {
    let mut out = Vec::new();
    for (suffix, sets) in [("", vec![]), (POLARS_SUFFIX, vec![NACA0015.to_string()])] {
        let wing = spec(cases, "wing_aoa5.json", &sets)?;
        for f in Formulation::ALL {
            let p = wing.case(f).problem();
            out.push(timed(&format!("{} s run of the paper's wing{suffix}", p.t_end), &f.to_string(), || {
                aeroelastic::factory::run_formulation(&p, f).error
            }));
        }
    }
    out.extend(static_sweeps(cases)?);
    let goland = spec(cases, "goland_flutter.json", &[])?;
    for f in Formulation::ALL {
        let p = goland.case(f).problem();
        let n = p.stability.as_ref().map_or(0, |s| s.airspeeds.len());
        out.push(timed(&format!("Goland flutter sweep ({n} airspeeds)"), &f.to_string(), || {
            aeroelastic::stability::run_stability(&p, f).error
        }));
    }
    let gust = spec(cases, "healy_ffwt_gust.json", &[])?;
    let base = gust.case(Formulation::ALL[0]).problem();
    let problems: Vec<_> = Formulation::ALL.iter().map(|&f| (f, gust.case(f).problem())).collect();
    let pairs: Vec<_> = problems.iter().map(|(f, p)| (*f, p)).collect();
    out.push(timed("Healy gust sweep", "both", || aeroelastic::gust::run_sweep(&base, &pairs).err()));
    Ok(out)
}

/// Run both parts; with `progress`, print each figure as it comes.
pub fn run(cases: &Path, progress: bool) -> Result<AeroBench, Error> {
    let configs: Vec<(&str, usize, Summation)> = ["wing_aoa5.json", "healy_ffwt_flare10_aoa5.json"]
        .into_iter()
        .flat_map(|f| WAKE_ROWS.into_iter().flat_map(move |r| Summation::ALL.map(|s| (f, r, s))))
        .collect();
    let mut runs: Vec<Vec<StepRow>> = vec![Vec::new(); configs.len()];
    for _ in 0..STEP_REPEATS {
        for (k, &(file, rows, summation)) in configs.iter().enumerate() {
            runs[k].push(step_row(cases, file, rows, summation)?);
        }
    }
    let mut steps = Vec::new();
    for mut reps in runs {
        let mut cpu: Vec<f64> = reps.iter().map(|r| r.cpu_ms).collect();
        // A repeat that failed is reported even when the others make a median.
        let error = reps.iter().find_map(|r| r.error.clone());
        let mut r = reps.swap_remove(0);
        r.cpu_ms = crate::bench::median(&mut cpu);
        r.error = error;
        if progress {
            let how = r.summation.name();
            println!("bench --aero {:<26} {:>4} rows {how:<8}: {:8.2} ms CPU per step", r.case, r.rows, r.cpu_ms);
        }
        steps.push(r);
    }
    let analyses = analyses(cases)?;
    if progress {
        for a in &analyses {
            println!(
                "bench --aero {:<40} {:<4}: {:8.2} s CPU, {:8.2} s wall",
                a.analysis, a.formulation, a.cpu_s, a.wall_s
            );
        }
    }
    Ok(AeroBench { steps, analyses })
}

/// The ratio of the step's cost at the longest wake to that at 1/8 of it, per case and summation.
pub fn scaling(b: &AeroBench) -> Vec<(String, Summation, f64)> {
    let mut out = Vec::new();
    for r in b.steps.iter().filter(|r| r.rows == WAKE_ROWS[4]) {
        let short = b.steps.iter().find(|s| s.case == r.case && s.summation == r.summation && s.rows == WAKE_ROWS[1]);
        if let Some(s) = short {
            out.push((r.case.clone(), r.summation, r.cpu_ms / s.cpu_ms));
        }
    }
    out
}

/// The CPU time of each analysis run with polars over the same analysis without, per
/// formulation: `(analysis, formulation, ratio)`.
pub fn polar_cost(b: &AeroBench) -> Vec<(String, String, f64)> {
    let mut out = Vec::new();
    for a in &b.analyses {
        let Some(plain) = a.analysis.strip_suffix(POLARS_SUFFIX) else { continue };
        if let Some(p) = b.analyses.iter().find(|x| x.analysis == plain && x.formulation == a.formulation) {
            out.push((plain.to_string(), a.formulation.clone(), a.cpu_s / p.cpu_s));
        }
    }
    out
}

/// The markdown summary.
pub fn markdown(b: &AeroBench) -> String {
    let mut s = String::from("# Aerodynamic benchmark\n\nCPU time per coupled step (GEBF) with the wake full, ms:\n\n");
    s.push_str("| case | summation |");
    for r in WAKE_ROWS {
        let _ = write!(s, " {r} rows |");
    }
    s.push_str(" 320 / 40 rows |\n|---|---|");
    s.push_str(&"---|".repeat(WAKE_ROWS.len() + 1));
    s.push('\n');
    let ratios = scaling(b);
    let mut seen: Vec<(String, Summation)> = Vec::new();
    for r in &b.steps {
        if seen.contains(&(r.case.clone(), r.summation)) {
            continue;
        }
        seen.push((r.case.clone(), r.summation));
        let _ = write!(s, "| {} | {} |", r.case, r.summation.name());
        for rows in WAKE_ROWS {
            let x = b.steps.iter().find(|x| x.case == r.case && x.summation == r.summation && x.rows == rows);
            let _ = write!(s, " {:.2} |", x.map_or(f64::NAN, |x| x.cpu_ms));
        }
        let ratio = ratios.iter().find(|x| x.0 == r.case && x.1 == r.summation).map_or(f64::NAN, |x| x.2);
        let _ = writeln!(s, " {ratio:.2}× |");
    }
    // The issue's figure: the treecode at 320 rows over the faster summation at 40 rows.
    s.push_str("\nA wake 8× longer, the treecode's 320-row step over the faster 40-row step:");
    for case in seen.iter().filter(|x| x.1 == Summation::Treecode).map(|x| &x.0) {
        let at = |rows: usize, how: Option<Summation>| {
            b.steps
                .iter()
                .filter(|x| &x.case == case && x.rows == rows && how.is_none_or(|h| x.summation == h))
                .map(|x| x.cpu_ms)
                .fold(f64::INFINITY, f64::min)
        };
        let _ = write!(s, " {case} {:.2}×;", at(320, Some(Summation::Treecode)) / at(40, None));
    }
    // What a step is: one aerodynamic solve loosely coupled, more with sub-iterations.
    s.push_str("\n\nAerodynamic solves per time step (mean over the case's runs):");
    for case in seen.iter().filter(|x| x.1 == Summation::Treecode).map(|x| &x.0) {
        let per: Vec<f64> = b.steps.iter().filter(|x| &x.case == case).map(|x| x.aero_solves_per_step).collect();
        let _ = write!(s, " {case} {:.2};", per.iter().sum::<f64>() / per.len().max(1) as f64);
    }
    s.push_str("\n\nWhole analyses:\n\n| analysis | formulation | CPU s | wall s | error |\n|---|---|---|---|---|\n");
    for a in &b.analyses {
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {:.2} | {} |",
            a.analysis,
            a.formulation,
            a.cpu_s,
            a.wall_s,
            a.error.as_deref().unwrap_or("")
        );
    }
    s.push_str("\nCPU time with the section polars over the time without:\n\n");
    s.push_str("| analysis | formulation | with / without |\n|---|---|---|\n");
    for (analysis, formulation, ratio) in polar_cost(b) {
        let _ = writeln!(s, "| {analysis} | {formulation} | {ratio:.3} |");
    }
    s
}

/// Write `aero.csv`, `aero.md`, `aero.json` and `aero_wake.svg` into `dir`.
pub fn write(dir: &Path, b: &AeroBench) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::Io(format!("{}: {e}", dir.display())))?;
    let mut csv = String::from("case,rows,summation,cpu_ms_per_step,aero_solves_per_step\n");
    for r in &b.steps {
        let _ =
            writeln!(csv, "{},{},{},{:.4},{:.3}", r.case, r.rows, r.summation.name(), r.cpu_ms, r.aero_solves_per_step);
    }
    write_file(&dir.join("aero.csv"), &csv)?;
    write_file(&dir.join("aero.md"), &markdown(b))?;
    let json = serde_json::to_string_pretty(b).map_err(|e| Error::Io(e.to_string()))?;
    write_file(&dir.join("aero.json"), &json)?;
    svg(&dir.join("aero_wake.svg"), b).map_err(|e| Error::Plot { file: "aero_wake.svg".into(), msg: e.to_string() })
}

/// Step time against wake rows, log–log, one line per case and summation.
fn svg(path: &Path, b: &AeroBench) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (720, 440)).into_drawing_area();
    root.fill(&WHITE)?;
    let ok: Vec<&StepRow> = b.steps.iter().filter(|r| r.cpu_ms.is_finite() && r.cpu_ms > 0.0).collect();
    let lo = ok.iter().map(|r| r.cpu_ms).fold(f64::INFINITY, f64::min).min(1.0) * 0.7;
    let hi = ok.iter().map(|r| r.cpu_ms).fold(0.0, f64::max).max(lo * 10.0) * 1.4;
    let (x0, x1) = (WAKE_ROWS[0] as f64 * 0.8, WAKE_ROWS[4] as f64 * 1.25);
    let mut chart = ChartBuilder::on(&root)
        .caption("CPU time per coupled step against the wake's length", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(
            (x0..x1).log_scale().with_key_points(WAKE_ROWS.iter().map(|&r| r as f64).collect()),
            (lo..hi).log_scale().with_key_points(vec![0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0]),
        )?;
    chart
        .configure_mesh()
        .light_line_style(TRANSPARENT)
        .x_desc("wake rows")
        .y_desc("ms per step (process CPU)")
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y}"))
        .draw()?;
    let palette = colors::PALETTE;
    let mut k = 0;
    let mut seen: Vec<(String, Summation)> = Vec::new();
    for r in &ok {
        if seen.contains(&(r.case.clone(), r.summation)) {
            continue;
        }
        seen.push((r.case.clone(), r.summation));
        let pts: Vec<(f64, f64)> = ok
            .iter()
            .filter(|x| x.case == r.case && x.summation == r.summation)
            .map(|x| (x.rows as f64, x.cpu_ms))
            .collect();
        let c = palette[k % palette.len()];
        k += 1;
        let label = format!("{} ({})", r.case, r.summation.name());
        let style = if r.summation == Summation::Treecode { c.stroke_width(2) } else { c.stroke_width(1) };
        chart
            .draw_series(LineSeries::new(pts.clone(), style))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2)));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table's ratio is the 320-row step over the 40-row one, and every file is written.
    #[test]
    fn the_table_reports_the_eightfold_wake_and_the_files_are_written() {
        let step = |case: &str, rows: usize, summation: Summation, cpu_ms: f64| StepRow {
            case: case.into(),
            rows,
            summation,
            cpu_ms,
            aero_solves_per_step: if rows == 40 { 2.0 } else { 1.0 },
            error: None,
        };
        let mut steps = Vec::new();
        for (k, rows) in WAKE_ROWS.iter().enumerate() {
            steps.push(step("wing", *rows, Summation::Direct, 1.0 + k as f64));
            steps.push(step("wing", *rows, Summation::Mixed, 1.5 + k as f64));
            steps.push(step("wing", *rows, Summation::Treecode, 2.0 * (1.0 + k as f64).sqrt()));
        }
        let row = |analysis: &str, formulation: &str, cpu_s: f64| AnalysisRow {
            analysis: analysis.into(),
            formulation: formulation.into(),
            cpu_s,
            wall_s: 2.0,
            error: None,
        };
        let analyses = vec![
            row("a run", "gebf", 1.5),
            row("a run", "ancf", 2.0),
            row(&format!("a run{POLARS_SUFFIX}"), "ancf", 2.5),
        ];
        let b = AeroBench { steps, analyses };
        assert_eq!(polar_cost(&b), vec![("a run".to_string(), "ancf".to_string(), 1.25)]);
        let ratios = scaling(&b);
        assert_eq!(ratios.len(), 3);
        assert!((ratios[0].2 - 5.0 / 2.0).abs() < 1e-12, "{ratios:?}");
        let md = markdown(&b);
        assert!(md.contains("| wing | direct | 1.00 | 2.00 | 3.00 | 4.00 | 5.00 | 2.50× |"), "{md}");
        assert!(md.contains("| wing | mixed | 1.50 | 2.50 | 3.50 | 4.50 | 5.50 | 2.20× |"), "{md}");
        assert!(md.contains("| a run | ancf | 1.250 |"), "{md}");
        // 2√5 at 320 rows through the treecode over the direct 2.00 at 40 rows (below its 2√2).
        assert!(md.contains("wing 2.24×;"), "{md}");
        // Over the 15 runs: three at 40 rows with 2 solves a step, twelve with 1.
        assert!(md.contains("solves per time step (mean over the case's runs): wing 1.20;"), "{md}");
        let dir = std::env::temp_dir().join(format!("flexmb-bench-aero-{}", std::process::id()));
        write(&dir, &b).unwrap();
        for f in ["aero.csv", "aero.md", "aero.json", "aero_wake.svg"] {
            assert!(dir.join(f).is_file(), "{f}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
