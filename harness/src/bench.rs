//! `harness bench`: how fast each formulation runs each case at the case's own settings.
//!
//! Every run is repeated serially on the calling thread. The figure reported is the median
//! *thread CPU time*, which other processes on a shared machine disturb far less than wall
//! time. A run covers model set-up, the consistent start and the time loop. Sensors are read
//! only at the start and the end, so the timing is the solver's.
//! ANCF runs on both of its paths (the DAE with multipliers and the ODE of the constant velocity
//! transformation), GEBF on its one; a march from a trim (`initial: "trim"`, which needs ANCF's
//! DAE path) on the DAE path only. The work behind each time (Newton iterations, factorisations
//! and step halvings per step) comes with it, so a change in speed can be told apart from a
//! change in work. A case with a `trim` block also times the trim alone (path `trim`: its static
//! solves in the `steps` column).

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use serde::Serialize;

use crate::Error;
use crate::case::{AncfPath, Formulation, RunSpec};
use crate::csv::write_file;
use crate::plot::colors;
use crate::scene::run_formulation;

/// Speed targets of the paper's double pendulums (docs/cases.md), ms per 2 s run; the paper's
/// MATLAB code took ~20 s and SHARPy ~40 s CPU.
/// In [`Formulation::ALL`] order: ANCF 50 ms, GEBF 100 ms.
pub const TARGET_MS: [(Formulation, f64); 2] = [(Formulation::ALL[0], 50.0), (Formulation::ALL[1], 100.0)];

/// One benchmarked configuration.
#[derive(Debug, Clone, Serialize)]
pub struct BenchRow {
    /// Run name.
    pub case: String,
    /// Formulation.
    pub formulation: Formulation,
    /// `dae` or `ode` for ANCF, `-` for GEBF; `trim` for the trim alone.
    pub path: String,
    /// Number of timed runs.
    pub repeats: usize,
    /// Median thread CPU time of a run, ms.
    pub cpu_median_ms: f64,
    /// Smallest thread CPU time, ms.
    pub cpu_min_ms: f64,
    /// Median wall time, ms.
    pub wall_median_ms: f64,
    /// Time steps.
    pub steps: usize,
    /// Newton iterations per step.
    pub newton_per_step: f64,
    /// Factorisations per step.
    pub factorizations_per_step: f64,
    /// Step halvings in the run.
    pub halvings: usize,
    /// Why the run stopped early, if it did (then the times are not comparable).
    pub error: Option<String>,
}

/// CPU time consumed by the calling thread, s (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`, ns
/// resolution); `None` off Linux, where the caller falls back to wall time.
pub(crate) use aeroelastic::clock::thread_cpu_s;

pub(crate) fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The configurations of `spec`: each formulation on each of its solve paths (ANCF with
/// multipliers and by eliminating the joints, GEBF on its one; a march from a trim on ANCF's DAE
/// path only), in [`Formulation::ALL`] order.
fn configurations(spec: &RunSpec) -> Vec<(Formulation, String, crate::case::Case)> {
    let mut out = Vec::new();
    for f in Formulation::ALL {
        let base = spec.case(f);
        if base.block(f).path.is_none() {
            out.push((f, "-".to_string(), base.clone()));
            continue;
        }
        let paths: &[AncfPath] =
            if base.initial.is_reference() { &[AncfPath::Dae, AncfPath::Ode] } else { &[AncfPath::Dae] };
        for &path in paths {
            let mut c = base.clone();
            if let Some(p) = c.block_mut(f).path {
                *p = path;
            }
            let name = if path == AncfPath::Dae { "dae" } else { "ode" };
            out.push((f, name.to_string(), c));
        }
    }
    out
}

/// The median and smallest thread CPU time and the median wall time of `repeats` calls of `work`
/// (stopping after the first that fails), ms, and the last call's result.
fn timed<T>(
    repeats: usize,
    mut work: impl FnMut() -> T,
    failed: impl Fn(&T) -> bool,
) -> Option<((f64, f64, f64, usize), T)> {
    let (mut cpu, mut wall) = (Vec::with_capacity(repeats), Vec::with_capacity(repeats));
    let mut last = None;
    for _ in 0..repeats {
        let (c0, t0) = (thread_cpu_s(), Instant::now());
        let out = work();
        let w = t0.elapsed().as_secs_f64();
        wall.push(1e3 * w);
        cpu.push(1e3 * c0.and_then(|c0| Some(thread_cpu_s()? - c0)).unwrap_or(w));
        let stop = failed(&out);
        last = Some(out);
        if stop {
            break; // a failed run is reported once, not timed again
        }
    }
    let n = cpu.len();
    let min = cpu.iter().copied().fold(f64::INFINITY, f64::min);
    last.map(|out| ((median(&mut cpu), min, median(&mut wall), n), out))
}

/// The trim of `spec` alone (its `trim` block), per formulation, timed as [`run`] times a march.
fn trim_rows(spec: &RunSpec, repeats: usize) -> Vec<BenchRow> {
    let mut rows = Vec::new();
    for f in Formulation::ALL {
        let case = spec.case(f);
        let Some(t) = case.trim.as_ref() else { return rows };
        let problem = case.problem();
        let work = || aeroelastic::trim::run_trim(&problem, f, t);
        let Some(((cpu_median_ms, cpu_min_ms, wall_median_ms, n), out)) = timed(repeats, work, |o| o.error.is_some())
        else {
            continue;
        };
        rows.push(BenchRow {
            case: spec.name.clone(),
            formulation: f,
            path: "trim".into(),
            repeats: n,
            cpu_median_ms,
            cpu_min_ms,
            wall_median_ms,
            steps: out.static_solves,
            newton_per_step: f64::NAN,
            factorizations_per_step: f64::NAN,
            halvings: 0,
            error: out.error,
        });
    }
    rows
}

/// Time every configuration of every spec `repeats` times (at least once), serially.
pub fn run(specs: &[RunSpec], repeats: usize, progress: bool) -> Vec<BenchRow> {
    let repeats = repeats.max(1);
    let mut rows = Vec::new();
    for spec in specs {
        let trims = trim_rows(spec, repeats);
        if progress {
            for r in &trims {
                println!(
                    "bench {:<28} {:<4} trim: cpu median {:8.1} ms (min {:8.1}), {} static solves",
                    r.case, r.formulation, r.cpu_median_ms, r.cpu_min_ms, r.steps
                );
            }
        }
        rows.extend(trims);
        for (f, path, mut case) in configurations(spec) {
            case.output_dt = Some(case.t_end);
            let work = || run_formulation(&case, f);
            let Some(((cpu_median_ms, cpu_min_ms, wall_median_ms, n), out)) =
                timed(repeats, work, |o| o.error.is_some())
            else {
                continue;
            };
            let st = out.stats;
            let per = |x: usize| if st.n_steps > 0 { x as f64 / st.n_steps as f64 } else { f64::NAN };
            let row = BenchRow {
                case: spec.name.clone(),
                formulation: f,
                path,
                repeats: n,
                cpu_min_ms,
                cpu_median_ms,
                wall_median_ms,
                steps: st.n_steps,
                newton_per_step: per(st.n_newton_iters),
                factorizations_per_step: per(st.n_factorizations),
                halvings: st.n_step_halvings,
                error: out.error,
            };
            if progress {
                println!(
                    "bench {:<28} {:<4} {:<3}: cpu median {:8.1} ms (min {:8.1}), {:.2} Newton, {:.2} fact. per step",
                    row.case,
                    row.formulation,
                    row.path,
                    row.cpu_median_ms,
                    row.cpu_min_ms,
                    row.newton_per_step,
                    row.factorizations_per_step
                );
            }
            rows.push(row);
        }
    }
    rows
}

fn label(r: &BenchRow) -> String {
    match r.path.as_str() {
        "-" => r.formulation.label().to_string(),
        path => format!("{} {}", r.formulation.label(), path.to_uppercase()),
    }
}

/// The table as Markdown, with each formulation's target where the case is a pendulum (no
/// aerodynamics: the targets are the issues' figures for the paper's double pendulums).
pub fn markdown(rows: &[BenchRow], targets: impl Fn(&str) -> bool) -> String {
    let mut s = String::from(
        "| case | solver | CPU median (min), ms | wall median, ms | target, ms | Newton / step | factorisations / step | halvings |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let target = TARGET_MS
            .iter()
            .find(|(f, _)| *f == r.formulation && targets(&r.case))
            .map_or("–".to_string(), |(_, t)| format!("{t:.0}"));
        let times = match &r.error {
            Some(e) => format!("failed: {e}"),
            None => format!("{:.1} ({:.1})", r.cpu_median_ms, r.cpu_min_ms),
        };
        let per_step = |x: f64| if x.is_finite() { format!("{x:.2}") } else { "–".into() };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {} | {} | {} | {} |",
            r.case,
            label(r),
            times,
            r.wall_median_ms,
            target,
            per_step(r.newton_per_step),
            per_step(r.factorizations_per_step),
            r.halvings
        );
    }
    s
}

/// `bench.json`, `bench.md` and `bench.svg` (CPU medians as bars, targets as lines) in `dir`.
pub fn write(dir: &Path, rows: &[BenchRow], targets: impl Fn(&str) -> bool) -> Result<(), Error> {
    write_file(&dir.join("bench.json"), &serde_json::to_string_pretty(rows).map_err(|e| Error::Io(e.to_string()))?)?;
    write_file(&dir.join("bench.md"), &markdown(rows, &targets))?;
    let p = dir.join("bench.svg");
    svg(&p, rows, &targets).map_err(|e| Error::Plot { file: p.display().to_string(), msg: e.to_string() })
}

fn svg(path: &Path, rows: &[BenchRow], targets: &impl Fn(&str) -> bool) -> Result<(), Box<dyn std::error::Error>> {
    let mut cases: Vec<&str> = Vec::new();
    for r in rows {
        if !cases.contains(&r.case.as_str()) {
            cases.push(&r.case);
        }
    }
    let configs = ["ANCF DAE", "ANCF ODE", "GEBF"];
    let fill = [colors::ANCF, RGBColor(120, 170, 215), colors::GEBF];
    let ok = |r: &&BenchRow| r.error.is_none() && r.cpu_median_ms.is_finite();
    let y_max = rows.iter().filter(ok).map(|r| r.cpu_median_ms).fold(100.0_f64, f64::max) * 1.5; // room for the legend
    let width = (160 * cases.len().max(1) + 120) as u32;
    let file = crate::atomic::TempFile::new(path)?;
    let tmp = file.path().to_path_buf();
    let root = SVGBackend::new(&tmp, (width, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("Thread CPU time per run (median), one thread", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(70)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..cases.len() as f64, 0.0..y_max)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .light_line_style(WHITE)
        .x_labels(0)
        .y_desc("CPU time, ms")
        .x_desc("case")
        .draw()?;
    for (i, c) in cases.iter().enumerate() {
        let (px, py) = chart.backend_coord(&(i as f64 + 0.5, 0.0));
        let style = TextStyle::from(("sans-serif", 13).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
        root.draw(&Text::new(c.trim_start_matches("double_pendulum_").to_string(), (px, py + 8), style))?;
    }
    for (k, (name, color)) in configs.iter().zip(fill).enumerate() {
        let bars: Vec<Rectangle<(f64, f64)>> = rows
            .iter()
            .filter(ok)
            .filter(|r| label(r) == *name)
            .filter_map(|r| {
                let i = cases.iter().position(|c| *c == r.case)? as f64;
                let x0 = i + 0.12 + 0.26 * k as f64;
                Some(Rectangle::new([(x0, 0.0), (x0 + 0.24, r.cpu_median_ms)], color.filled()))
            })
            .collect();
        chart
            .draw_series(bars)?
            .label(*name)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], color.filled()));
    }
    for (f, t) in TARGET_MS {
        let color = colors::of(f);
        let segs: Vec<PathElement<(f64, f64)>> = cases
            .iter()
            .enumerate()
            .filter(|(_, c)| targets(c))
            .map(|(i, _)| PathElement::new(vec![(i as f64 + 0.05, t), (i as f64 + 0.95, t)], color.stroke_width(2)))
            .collect();
        if !segs.is_empty() {
            chart
                .draw_series(segs)?
                .label(format!("{} target {t:.0} ms", f.to_string().to_uppercase()))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], color.stroke_width(2)));
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(file.commit()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn thread_cpu_time_advances_with_work() {
        let Some(t0) = thread_cpu_s() else { return }; // not on Linux: no thread clock to test
        let mut x = 0.0_f64;
        for i in 0..2_000_000 {
            x += (i as f64).sqrt();
        }
        std::hint::black_box(x);
        let t1 = thread_cpu_s().unwrap();
        assert!(t1 > t0, "{t0} -> {t1}");
    }
}
