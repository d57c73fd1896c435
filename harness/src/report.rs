//! Per-case results (metrics, gate) and the files written under `reports/`.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::Error;
use crate::case::{Formulation, Gate, RunSpec};
use crate::csv::{Curve, read_curve, to_csv, write_file};
use crate::gate::{self, GateOutcome};
use crate::metrics::{FormulationMetrics, PairMetrics, ReferenceMetrics, tip_curve, tip_difference, window_stats};
use crate::plot::{Panel, Series, colors, panels_svg};
use crate::run::RunOutput;

/// Everything known about one run of a case.
#[derive(Debug, Clone)]
pub struct CaseResult {
    /// Run name.
    pub name: String,
    /// Description from the case file.
    pub description: String,
    /// Total span, m.
    pub span: f64,
    /// Runs of both formulations.
    pub runs: Vec<RunOutput>,
    /// Per-formulation metrics.
    pub metrics: BTreeMap<Formulation, FormulationMetrics>,
    /// ANCF–GEBF tip difference metrics (None if either produced no rows).
    pub pair: Option<PairMetrics>,
    /// Sampled ANCF–GEBF tip difference d(t).
    pub pair_diff: Vec<(f64, f64)>,
    /// External references: label, curve, time shift.
    pub reference_curves: Vec<(String, Curve, f64)>,
    /// Formulations against references.
    pub references: Vec<ReferenceMetrics>,
    /// References that could not be read.
    pub reference_errors: Vec<String>,
    /// Gate tolerances.
    pub gate: Option<Gate>,
    /// Gate outcome.
    pub gate_outcome: Option<GateOutcome>,
}

impl CaseResult {
    /// Compute metrics and the gate for finished runs.
    pub fn evaluate(spec: &RunSpec, runs: Vec<RunOutput>) -> Self {
        let case = &spec.ancf;
        let span = case.span();
        let metrics = runs.iter().map(|r| (r.formulation, FormulationMetrics::of(r))).collect();
        let find = |f: Formulation| runs.iter().find(|r| r.formulation == f && !r.rows.is_empty());
        let (pair, pair_diff) = match (find(Formulation::Ancf), find(Formulation::Gebf)) {
            (Some(a), Some(b)) => {
                let (m, d) = PairMetrics::of(a, b, span);
                (Some(m), d)
            }
            _ => (None, Vec::new()),
        };
        let mut reference_curves = Vec::new();
        let mut reference_errors = Vec::new();
        let mut references = Vec::new();
        for r in &case.references {
            match read_curve(&spec.dir.join(&r.file)) {
                Ok(c) => {
                    for run in runs.iter().filter(|x| !x.rows.is_empty()) {
                        let d = tip_difference(&tip_curve(&run.rows), &c, r.time_shift);
                        references.push(ReferenceMetrics {
                            label: r.label.clone(),
                            formulation: run.formulation,
                            diff: window_stats(&d, f64::NEG_INFINITY, f64::INFINITY),
                            tip_max_m: r.tip_max_m,
                        });
                    }
                    reference_curves.push((r.label.clone(), c, r.time_shift));
                }
                Err(e) => reference_errors.push(e.to_string()),
            }
        }
        let mut res = Self {
            name: spec.name.clone(),
            description: case.description.clone(),
            span,
            runs,
            metrics,
            pair,
            pair_diff,
            reference_curves,
            references,
            reference_errors,
            gate: case.gate.clone(),
            gate_outcome: None,
        };
        res.gate_outcome = gate::evaluate(&res);
        res
    }

    /// The run of a formulation.
    pub fn run(&self, f: Formulation) -> Option<&RunOutput> {
        self.runs.iter().find(|r| r.formulation == f)
    }

    /// One-word status: pass, FAIL, failed run, or "-" without a gate.
    pub fn status(&self) -> &'static str {
        match &self.gate_outcome {
            Some(g) if g.pass() => "pass",
            Some(_) => "FAIL",
            None if self.runs.iter().any(|r| r.error.is_some()) => "run failed",
            None => "-",
        }
    }
}

#[derive(Serialize)]
struct Summary<'a> {
    case: &'a str,
    description: &'a str,
    span_m: f64,
    formulations: &'a BTreeMap<Formulation, FormulationMetrics>,
    tip_difference: &'a Option<PairMetrics>,
    references: &'a [ReferenceMetrics],
    reference_errors: &'a [String],
    gate: Option<&'a GateOutcome>,
    gate_pass: Option<bool>,
}

/// Write `<dir>/<formulation>.csv`, `summary.json` and the plots of one case.
pub fn write_case(dir: &Path, r: &CaseResult) -> Result<(), Error> {
    for run in &r.runs {
        write_file(&dir.join(format!("{}.csv", run.formulation)), &to_csv(&run.rows))?;
    }
    let summary = Summary {
        case: &r.name,
        description: &r.description,
        span_m: r.span,
        formulations: &r.metrics,
        tip_difference: &r.pair,
        references: &r.references,
        reference_errors: &r.reference_errors,
        gate: r.gate_outcome.as_ref(),
        gate_pass: r.gate_outcome.as_ref().map(GateOutcome::pass),
    };
    let json = serde_json::to_string_pretty(&summary).map_err(|e| Error::Io(e.to_string()))?;
    write_file(&dir.join("summary.json"), &json)?;
    write_plots(dir, r)
}

fn run_color(f: Formulation) -> plotters::style::RGBColor {
    match f {
        Formulation::Ancf => colors::ANCF,
        Formulation::Gebf => colors::GEBF,
    }
}

fn label(f: Formulation) -> &'static str {
    match f {
        Formulation::Ancf => "ANCF",
        Formulation::Gebf => "GEBF",
    }
}

fn t_end(r: &CaseResult) -> f64 {
    r.runs.iter().filter_map(|x| x.rows.last()).map(|x| x.t).fold(0.0, f64::max)
}

/// The SVG plots of one case (file names as listed in [`PLOTS`]).
pub fn write_plots(dir: &Path, r: &CaseResult) -> Result<(), Error> {
    let t_max = t_end(r);
    // Tip X, Y, Z.
    let axis = ["X", "Y", "Z"];
    let tip_panels: Vec<Panel> = (0..3)
        .map(|k| {
            // References first, so the formulations are drawn on top of them.
            let mut series: Vec<Series> = r
                .reference_curves
                .iter()
                .enumerate()
                .map(|(i, (lab, c, shift))| Series {
                    label: lab.clone(),
                    color: colors::REFS[i % colors::REFS.len()],
                    points: c
                        .t
                        .iter()
                        .zip(&c.tip)
                        .map(|(&t, p)| (t - shift, p[k]))
                        .filter(|&(t, _)| t >= 0.0 && t <= t_max + 1e-9)
                        .collect(),
                })
                .collect();
            series.extend(r.runs.iter().map(|run| Series {
                label: label(run.formulation).into(),
                color: run_color(run.formulation),
                points: run.rows.iter().map(|x| (x.t, x.tip[k])).collect(),
            }));
            Panel {
                title: format!("{} — tip {}", r.name, axis[k]),
                x_label: "t [s]".into(),
                y_label: format!("tip {} [m]", axis[k]),
                log_y: false,
                legend_lower_right: false,
                series,
            }
        })
        .collect();
    panels_svg(&dir.join("tip.svg"), &tip_panels, 1, (900, 300))?;

    // Differences: ANCF–GEBF and each formulation against each reference.
    let mut diff =
        vec![Series { label: "|ANCF − GEBF|".into(), color: colors::EXTRA[2], points: r.pair_diff.clone() }];
    for (i, (lab, c, shift)) in r.reference_curves.iter().enumerate() {
        for run in r.runs.iter().filter(|x| !x.rows.is_empty()) {
            diff.push(Series {
                label: format!("|{} − {}|", label(run.formulation), lab),
                color: if run.formulation == Formulation::Ancf {
                    colors::EXTRA[(2 * i + 1) % 4]
                } else {
                    colors::REFS[(i + 1) % 4]
                },
                points: tip_difference(&tip_curve(&run.rows), c, *shift),
            });
        }
    }
    let diff_panel = Panel {
        title: format!("{} — tip distance", r.name),
        x_label: "t [s]".into(),
        y_label: "tip distance [m]".into(),
        log_y: true,
        legend_lower_right: false,
        series: diff,
    };
    panels_svg(&dir.join("tip_difference.svg"), &[diff_panel], 1, (900, 380))?;

    // Energies: components and drift.
    let mut comp = Vec::new();
    let mut drift = Vec::new();
    for run in &r.runs {
        let l = label(run.formulation);
        let base = if run.formulation == Formulation::Ancf { 0 } else { 2 };
        comp.push(Series {
            label: format!("{l} kinetic"),
            color: run_color(run.formulation),
            points: run.rows.iter().map(|x| (x.t, x.kinetic)).collect(),
        });
        comp.push(Series {
            label: format!("{l} elastic"),
            color: colors::EXTRA[base],
            points: run.rows.iter().map(|x| (x.t, x.elastic)).collect(),
        });
        comp.push(Series {
            label: format!("{l} potential"),
            color: colors::EXTRA[base + 1],
            points: run.rows.iter().map(|x| (x.t, x.potential)).collect(),
        });
        let e0 = run.rows.first().map_or(0.0, |x| x.total);
        let peak = r.metrics.get(&run.formulation).map_or(1.0, |m| m.peak_kinetic).max(f64::MIN_POSITIVE);
        let w = |x: &crate::run::Row| if x.aero_work.is_finite() { x.aero_work } else { 0.0 };
        let d = |x: &crate::run::Row| if x.dissipated.is_finite() { x.dissipated } else { 0.0 };
        drift.push(Series {
            label: l.to_string(),
            color: run_color(run.formulation),
            points: run.rows.iter().map(|x| (x.t, (x.total + d(x) - e0 - w(x)) / peak)).collect(),
        });
    }
    // The balance the drift panel shows: the terms the case has.
    let rows = || r.runs.iter().flat_map(|run| &run.rows);
    let balance = match (rows().any(|x| x.aero_work.is_finite()), rows().any(|x| x.dissipated.is_finite())) {
        (true, true) => "(E + W_damp − E0 − W_aero) / max T [-]",
        (true, false) => "(E − E0 − W_aero) / max T [-]",
        (false, true) => "(E + W_damp − E0) / max T [-]",
        (false, false) => "(E − E0) / max T [-]",
    };
    panels_svg(
        &dir.join("energy.svg"),
        &[
            Panel {
                title: format!("{} — energies", r.name),
                x_label: "t [s]".into(),
                y_label: "energy [J]".into(),
                log_y: false,
                legend_lower_right: false,
                series: comp,
            },
            Panel {
                title: format!("{} — energy drift", r.name),
                x_label: "t [s]".into(),
                y_label: balance.into(),
                log_y: false,
                legend_lower_right: false,
                series: drift,
            },
        ],
        1,
        (900, 330),
    )?;

    // Constraint residual and fold angle.
    let cres: Vec<Series> = r
        .runs
        .iter()
        .map(|run| Series {
            label: label(run.formulation).into(),
            color: run_color(run.formulation),
            points: run.rows.iter().map(|x| (x.t, x.constraint_residual)).collect(),
        })
        .collect();
    let fold: Vec<Series> = r
        .runs
        .iter()
        .map(|run| Series {
            label: label(run.formulation).into(),
            color: run_color(run.formulation),
            points: run.rows.iter().filter(|x| x.fold.is_finite()).map(|x| (x.t, x.fold.to_degrees())).collect(),
        })
        .collect();
    panels_svg(
        &dir.join("constraint.svg"),
        &[Panel {
            title: format!("{} — joint violation (gap and axis misalignment)", r.name),
            x_label: "t [s]".into(),
            y_label: "residual [m, rad]".into(),
            log_y: true,
            legend_lower_right: false,
            series: cres,
        }],
        1,
        (900, 330),
    )?;
    if has_aero(r) {
        let lift: Vec<Series> = r
            .runs
            .iter()
            .map(|run| Series {
                label: label(run.formulation).into(),
                color: run_color(run.formulation),
                points: run.rows.iter().filter(|x| x.lift.is_finite()).map(|x| (x.t, x.lift)).collect(),
            })
            .collect();
        panels_svg(
            &dir.join("lift.svg"),
            &[Panel {
                title: format!("{} — total lift", r.name),
                x_label: "t [s]".into(),
                y_label: "lift [N]".into(),
                log_y: false,
                legend_lower_right: false,
                series: lift,
            }],
            1,
            (900, 330),
        )?;
    }
    panels_svg(
        &dir.join("fold.svg"),
        &[Panel {
            title: format!("{} — fold angle", r.name),
            x_label: "t [s]".into(),
            y_label: "fold angle [deg]".into(),
            log_y: false,
            legend_lower_right: false,
            series: fold,
        }],
        1,
        (900, 330),
    )
}

/// Whether the case has aerodynamics (its rows carry a lift).
fn has_aero(r: &CaseResult) -> bool {
    r.runs.iter().any(|x| x.rows.iter().any(|y| y.lift.is_finite()))
}

/// Plot files of each case, with captions, in index order (`lift.svg` only with aerodynamics).
pub const PLOTS: [(&str, &str); 6] = [
    ("tip.svg", "Tip position, both formulations and references"),
    ("lift.svg", "Total aerodynamic lift"),
    ("tip_difference.svg", "Tip distance between formulations and to references"),
    ("fold.svg", "Fold angle"),
    ("energy.svg", "Energy components and drift"),
    ("constraint.svg", "Position-level joint violation"),
];

fn fmt_opt(v: Option<f64>, prec: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.prec$e}"),
        _ => "–".into(),
    }
}

/// Rows of the results table: one per case and formulation.
fn table_rows(results: &[CaseResult]) -> Vec<[String; 11]> {
    let mut rows = Vec::new();
    for r in results {
        for f in Formulation::ALL {
            let Some(m) = r.metrics.get(&f) else { continue };
            let refs: Vec<String> = r
                .references
                .iter()
                .filter(|x| x.formulation == f)
                .map(|x| format!("{}: {:.2} mm", x.label, 1e3 * x.diff.max))
                .collect();
            rows.push([
                r.name.clone(),
                f.to_string(),
                if m.error.is_some() { format!("failed at {:.4} s", m.t_reached) } else { "ok".into() },
                format!("{:.1}", 1e3 * m.wall_s),
                format!("{:.2}", m.newton_per_step),
                fmt_opt(Some(m.energy_drift), 2),
                fmt_opt(Some(m.max_constraint_residual), 1),
                fmt_opt(r.pair.as_ref().map(|p| 1e3 * p.all.max), 2),
                fmt_opt(r.pair.as_ref().map(|p| 1e3 * p.first_second.max), 2),
                refs.join("; "),
                r.status().to_string(),
            ]);
        }
    }
    rows
}

const TABLE_HEAD: [&str; 11] = [
    "case",
    "formulation",
    "run",
    "wall [ms]",
    "Newton/step",
    "energy drift",
    "max constraint",
    "max tip diff [mm]",
    "tip diff t≤1 s [mm]",
    "max tip distance to references",
    "gate",
];

/// `reports/summary.md`: the results table in Markdown.
pub fn summary_markdown(results: &[CaseResult]) -> String {
    let mut s = String::from("# Results\n\n");
    s.push_str(&format!("| {} |\n", TABLE_HEAD.join(" | ")));
    s.push_str(&format!("|{}\n", "---|".repeat(TABLE_HEAD.len())));
    for row in table_rows(results) {
        s.push_str(&format!("| {} |\n", row.join(" | ")));
    }
    for r in results {
        let errs: Vec<String> = r
            .runs
            .iter()
            .filter_map(|x| x.error.as_ref().map(|e| format!("- {} {}: {e}", r.name, x.formulation)))
            .collect();
        for e in errs {
            s.push_str(&format!("\n{e}"));
        }
    }
    s.push('\n');
    s
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// HTML section for the studies found on disk under `out`: `converge/<case>/`, `bench/` and
/// `stress/`.
pub fn studies_html(out: &Path) -> String {
    let mut s = crate::static_out::sections_html(out);
    let conv = out.join("converge");
    let mut names: Vec<String> = std::fs::read_dir(&conv)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .filter(|e| e.path().join("work_precision.svg").exists())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    if !names.is_empty() {
        s.push_str("<h2 id=\"converge\">Speed against error: refinement ladders</h2>\n<p>Each formulation refined in time (fixed elements), in space (small fixed step) and in both (diagonal); error = max tip distance to the ladder's truth (finest rung, or a converged external reference). Tables: <code>converge.csv</code>.</p>\n");
        for n in &names {
            let _ = writeln!(
                s,
                "<h3>{0}</h3><p><a href=\"converge/{0}/converge.csv\">converge.csv</a></p><figure><img src=\"converge/{0}/work_precision.svg\" alt=\"work-precision {0}\"><figcaption>Work-precision: max tip error against wall time</figcaption></figure><figure><img src=\"converge/{0}/convergence.svg\" alt=\"convergence {0}\"><figcaption>Error against time step and against elements per body</figcaption></figure>",
                esc(n)
            );
        }
    }
    if out.join("energy/energy.svg").exists() {
        s.push_str("<h2 id=\"energy\">Energy at ρ<sub>∞</sub> = 1: the integrator's two forms</h2>\n<p>No aerodynamics and no numerical dissipation: the exact energy is constant, so |E − E(0)| / max T is the scheme's error. Each formulation in the default Arnold–Brüls form (forces at the end of the step: the trapezoidal rule) and in the Chung–Hulbert form (forces at the α-weighted state: the implicit midpoint rule), every step recorded, at the case's dt and at dt/2 (the table gives the observed order): <a href=\"energy/energy.md\">energy.md</a>, <a href=\"energy/energy.csv\">energy.csv</a>.</p>\n<figure><img src=\"energy/energy.svg\" alt=\"energy\"><figcaption>Energy error against time</figcaption></figure>\n");
    }
    if out.join("bench/bench.svg").exists() {
        s.push_str("<h2 id=\"bench\">Speed</h2>\n<p>Median thread CPU time of repeated serial runs at each case's own settings (ANCF on both solve paths), with the Newton work per step: <a href=\"bench/bench.md\">bench.md</a>, <a href=\"bench/bench.json\">bench.json</a>. Lines: the issues' targets for the paper's pendulums.</p>\n<figure><img src=\"bench/bench.svg\" alt=\"speed\"><figcaption>CPU time per run</figcaption></figure>\n");
    }
    if out.join("stress/stress_ancf.svg").exists() {
        s.push_str("<h2 id=\"stress\">Stability on hard cases: the stress matrix</h2>\n<p><a href=\"stress/stress.csv\">stress.csv</a>; extra hard runs (20 s pendulum, wing at AoA 15°): <a href=\"stress/extras.csv\">extras.csv</a></p>\n");
        for f in Formulation::ALL {
            let _ = writeln!(
                s,
                "<figure><img src=\"stress/stress_{f}.svg\" alt=\"stress {f}\"><figcaption>Stress matrix, {f}</figcaption></figure>"
            );
        }
    }
    s
}

/// `reports/index.html`: static page with the table and every plot (no JavaScript).
/// `studies` is extra HTML appended after the cases (see [`studies_html`]).
pub fn index_html(results: &[CaseResult], studies: &str) -> String {
    let mut s = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Flared-hinge verification harness</title>\n\
         <style>body{font-family:sans-serif;margin:2em;max-width:1200px}table{border-collapse:collapse;font-size:13px}\
         td,th{border:1px solid #ccc;padding:3px 6px;text-align:right}th{background:#eee}td:first-child{text-align:left}\
         .pass{color:#080}.FAIL,.fail{color:#c00;font-weight:bold}img{max-width:100%;border:1px solid #ddd;margin:4px 0}\
         details{margin:1em 0}</style></head><body>\n<h1>Flared-hinge verification harness: ANCF vs GEBF</h1>\n",
    );
    s.push_str("<p>Every case run with both formulations. Tip difference = |p<sub>ANCF</sub>(t) − p<sub>GEBF</sub>(t)|; energy drift = max|E(t) − E(0)| / max T; constraint = position-level joint gap [m] and axis misalignment [rad].</p>\n<table><tr>");
    for h in TABLE_HEAD {
        let _ = write!(s, "<th>{}</th>", esc(h));
    }
    s.push_str("</tr>\n");
    for row in table_rows(results) {
        s.push_str("<tr>");
        for (i, c) in row.iter().enumerate() {
            let class = if i == 10 {
                format!(" class=\"{}\"", if c == "pass" { "pass" } else { "fail" })
            } else {
                String::new()
            };
            let cell = if i == 0 { format!("<a href=\"#{0}\">{0}</a>", esc(c)) } else { esc(c) };
            let _ = write!(s, "<td{class}>{cell}</td>");
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</table>\n");
    for r in results {
        let _ = write!(
            s,
            "<h2 id=\"{0}\">{0} <span class=\"{1}\">[{1}]</span></h2>\n<p>{2}</p>\n",
            esc(&r.name),
            r.status(),
            esc(&r.description)
        );
        for run in &r.runs {
            if let Some(e) = &run.error {
                let _ = writeln!(s, "<p class=\"fail\">{}: {}</p>", run.formulation, esc(e));
            }
        }
        if let Some(g) = &r.gate_outcome {
            for l in g.failed_lines() {
                let _ = writeln!(s, "<p class=\"fail\">gate: {}</p>", esc(&l));
            }
        }
        let _ = writeln!(
            s,
            "<p>Data: <a href=\"{0}/ancf.csv\">ancf.csv</a>, <a href=\"{0}/gebf.csv\">gebf.csv</a>, <a href=\"{0}/summary.json\">summary.json</a></p>",
            esc(&r.name)
        );
        for (file, caption) in PLOTS {
            if file == "lift.svg" && !has_aero(r) {
                continue;
            }
            let _ = writeln!(
                s,
                "<figure><img src=\"{}/{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
                esc(&r.name),
                file,
                caption,
                caption
            );
        }
    }
    s.push_str(studies);
    s.push_str("</body></html>\n");
    s
}
