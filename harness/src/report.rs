//! Per-case results (metrics, gate) and the files written under `reports/`.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::Error;
use crate::case::{Formulation, Gate, RunSpec};
use crate::csv::{Curve, read_curve, to_csv, write_file};
use crate::gate::{self, GateOutcome};
use crate::metrics::{
    FormulationMetrics, PairMetrics, ReferenceMetrics, kinetic_resolution, tip_curve, tip_difference, window_stats,
};
use crate::plot::{Dash, Marker, Panel, Series, Style, colors, panels_svg};
use crate::run::RunOutput;
use plotters::style::RGBColor;

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
    /// The control surfaces' names (`aero.control_surfaces`): the CSV's hinge-moment columns.
    pub control_surfaces: Vec<String>,
    /// The joints' names, by index (the hinge events' file and table).
    pub joint_names: Vec<Option<String>>,
}

impl CaseResult {
    /// Compute metrics and the gate for finished runs.
    pub fn evaluate(spec: &RunSpec, runs: Vec<RunOutput>) -> Self {
        let case = &spec.ancf;
        let span = case.span();
        let metrics = runs
            .iter()
            .map(|r| {
                let mut m = FormulationMetrics::of(r);
                m.kinetic_resolution = kinetic_resolution(spec.case(r.formulation), r.formulation);
                (r.formulation, m)
            })
            .collect();
        let find = |f: Formulation| runs.iter().find(|r| r.formulation == f && !r.rows.is_empty());
        let [first, second] = Formulation::ALL;
        let (pair, pair_diff) = match (find(first), find(second)) {
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
            control_surfaces: casefile::csv::surface_names(case.aero.as_ref()),
            joint_names: case.joints.iter().map(|j| j.name().map(str::to_string)).collect(),
        };
        res.gate_outcome = gate::evaluate(&res);
        res
    }

    /// The run of a formulation.
    pub fn run(&self, f: Formulation) -> Option<&RunOutput> {
        self.runs.iter().find(|r| r.formulation == f)
    }

    /// One-word status: pass, FAIL, run failed, or "–" without a gate.
    pub fn status(&self) -> &'static str {
        match &self.gate_outcome {
            Some(g) if g.pass() => "pass",
            Some(_) => "FAIL",
            None if self.runs.iter().any(|r| r.error.is_some()) => "run failed",
            None => "–",
        }
    }
}

#[derive(Serialize)]
struct Summary<'a> {
    /// `"complete"` or `"interrupted"`, first, in the same write as the rest: a run killed
    /// between two writes must not leave a summary without it.
    status: &'a str,
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

/// Write `<dir>/<formulation>.csv`, `summary.json` (its `"status"` first) and the plots of one
/// case.
pub fn write_case(dir: &Path, r: &CaseResult, status: &str) -> Result<(), Error> {
    for run in &r.runs {
        write_file(&dir.join(format!("{}.csv", run.formulation)), &to_csv(&run.rows, &r.control_surfaces))?;
        if !run.events.is_empty() {
            let csv = casefile::csv::events_csv(&run.events, &r.joint_names);
            write_file(&dir.join(format!("{}_events.csv", run.formulation)), &csv)?;
        }
    }
    let summary = Summary {
        status,
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

/// The roll response of each formulation (empty without a roll joint).
fn roll_table(r: &CaseResult) -> String {
    let rows: Vec<Vec<String>> = Formulation::ALL
        .iter()
        .filter_map(|f| r.metrics.get(f).and_then(|m| m.roll).map(|x| (f, x)))
        .map(|(f, x)| {
            vec![
                f.label().to_string(),
                format!("{:.4}", x.steady_rate),
                format!("{:.2}", 100.0 * x.spread),
                format!("{:.3}", x.rise_time_s),
            ]
        })
        .collect();
    if rows.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "<h3>Roll</h3>\n<p class=\"note\">Steady roll rate: the mean over the last quarter of the run; spread: how much it still moves there; rise time: the first time the rate reaches 90 % of the steady one.</p>\n",
    );
    s.push_str(&html_table(&["formulation", "steady roll rate [rad/s]", "spread [%]", "rise time [s]"], &rows, &|i| {
        i >= 1
    }));
    s
}

/// The hinge events of a case's runs, one row per formulation and event (empty without events).
fn events_table(r: &CaseResult) -> String {
    let rows: Vec<Vec<String>> = r
        .runs
        .iter()
        .flat_map(|run| run.events.iter().map(move |e| (run.formulation, e)))
        .map(|(f, e)| {
            let joint = r.joint_names.get(e.joint).cloned().flatten().unwrap_or_else(|| format!("joint {}", e.joint));
            vec![
                f.label().to_string(),
                format!("{:.4}", e.time),
                esc(&joint),
                e.action.as_str().to_string(),
                format!("{:.3}", e.fold.to_degrees()),
                sci(Some(e.energy_loss), 3),
            ]
        })
        .collect();
    if rows.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "<h3>Hinge events</h3>\n<p class=\"note\">Each event acts at the end of the step nearest its time, or of the first step where its condition holds; a lock welds the hinge at the fold it has then and removes the kinetic energy of the impact (docs/coupling.md §8), counted in the dissipated work.</p>\n",
    );
    s.push_str(&html_table(
        &["formulation", "t [s]", "joint", "action", "fold [deg]", "energy loss [J]"],
        &rows,
        &|i| i == 1 || i >= 4,
    ));
    s
}

/// How each formulation is drawn wherever both appear: GEBF a solid line, ANCF dashed with
/// circles on top of it, so that either stays visible when the two coincide.
fn run_style(f: Formulation) -> Style {
    Style::of_formulation(f, colors::of(f))
}

/// How external reference `i` is drawn: its own colour, dash and marker.
fn ref_style(i: usize) -> Style {
    const MARKERS: [Marker; 4] = [Marker::Square, Marker::Triangle, Marker::Diamond, Marker::Cross];
    Style::solid(colors::REFS[i % colors::REFS.len()])
        .dash(if i.is_multiple_of(2) { Dash::Dotted } else { Dash::Solid })
        .marker(MARKERS[i % MARKERS.len()])
        .width(if i.is_multiple_of(2) { 3 } else { 1 })
}

/// Words for a style in a caption.
fn style_words(s: &Style) -> String {
    let line = match s.dash {
        Dash::Solid => "solid",
        Dash::Dashed => "dashed",
        Dash::Dotted => "dotted",
        Dash::None => "points",
    };
    let marker = match s.marker {
        Some(Marker::Circle) => ", circles",
        Some(Marker::Square) => ", squares",
        Some(Marker::Triangle) => ", triangles",
        Some(Marker::Cross) => ", crosses",
        Some(Marker::Diamond) => ", diamonds",
        None => "",
    };
    format!("{line}{marker}")
}

fn t_end(r: &CaseResult) -> f64 {
    r.runs.iter().filter_map(|x| x.rows.last()).map(|x| x.t).fold(0.0, f64::max)
}

/// The angles `a` (rad) made continuous: every jump of more than π between neighbours is taken as
/// a wrap through ±π and undone.
pub fn unwrap_angles(a: impl IntoIterator<Item = f64>) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    let mut turns = 0.0;
    let mut prev: Option<f64> = None;
    for v in a {
        if let Some(p) = prev {
            let d = v - p;
            if d > std::f64::consts::PI {
                turns -= std::f64::consts::TAU;
            } else if d < -std::f64::consts::PI {
                turns += std::f64::consts::TAU;
            }
        }
        prev = Some(v);
        out.push(v + turns);
    }
    out
}

/// Whether the case has aerodynamics (its rows carry a lift).
fn has_aero(r: &CaseResult) -> bool {
    r.runs.iter().any(|x| x.rows.iter().any(|y| y.lift.is_finite()))
}

/// Whether the case records a fold angle (it has a flared hinge).
/// Whether the case has a roll joint (the `roll_rate` column).
fn has_roll(r: &CaseResult) -> bool {
    r.runs.iter().any(|x| x.rows.iter().any(|y| y.roll_rate.is_finite()))
}

fn has_fold(r: &CaseResult) -> bool {
    r.runs.iter().any(|x| x.rows.iter().any(|y| y.fold.is_finite()))
}

/// Whether the case has force elements (its rows carry the spring energy and the dissipated work).
fn has_springs(r: &CaseResult) -> bool {
    r.runs.iter().any(|x| x.rows.iter().any(|y| y.spring.is_finite()))
}

/// One plot of a case: its file and a caption saying what it shows.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotFile {
    /// File name in the case folder.
    pub file: &'static str,
    /// Caption.
    pub caption: String,
}

/// The plots [`write_plots`] writes for `r`, in report order, with their captions.
pub fn plots(r: &CaseResult) -> Vec<PlotFile> {
    let refs: Vec<String> = r
        .reference_curves
        .iter()
        .enumerate()
        .map(|(i, (l, _, shift))| {
            let shifted = if *shift != 0.0 { format!(", read {:.1} ms later", 1e3 * shift) } else { String::new() };
            format!("{l} ({}{shifted})", style_words(&ref_style(i)))
        })
        .collect();
    let forms = Formulation::ALL
        .iter()
        .map(|&f| format!("{} ({})", f.label(), style_words(&run_style(f))))
        .collect::<Vec<_>>()
        .join(", ");
    let mut v = vec![PlotFile {
        file: "tip.svg",
        caption: if refs.is_empty() {
            format!("Tip position X, Y, Z against time: {forms}.")
        } else {
            format!("Tip position X, Y, Z against time: {forms}; references: {}.", refs.join(", "))
        },
    }];
    if has_aero(r) {
        v.push(PlotFile { file: "lift.svg", caption: format!("Total aerodynamic lift against time: {forms}.") });
    }
    v.push(PlotFile {
        file: "tip_difference.svg",
        caption: if refs.is_empty() {
            "Distance between the two formulations' tips against time (log scale).".into()
        } else {
            format!(
                "Distance between the two formulations' tips, and from each formulation to {}, against time (log scale).",
                r.reference_curves.iter().map(|x| x.0.as_str()).collect::<Vec<_>>().join(", ")
            )
        },
    });
    if has_roll(r) {
        v.push(PlotFile {
            file: "roll_rate.svg",
            caption: format!("Roll rate of the roll joint against time: {forms}."),
        });
    }
    if has_fold(r) {
        v.push(PlotFile {
            file: "fold.svg",
            caption: format!(
                "Fold angle of the flared hinge against time, unwrapped (continuous through ±180°): {forms}."
            ),
        });
    }
    let mut terms = vec!["kinetic", "elastic", "potential"];
    if has_springs(r) {
        terms.extend(["spring", "dissipated work"]);
    }
    if has_aero(r) {
        terms.push("aerodynamic work");
    }
    v.push(PlotFile {
        file: "energy.svg",
        caption: format!(
            "Energies ({}; ANCF dashed with circles, GEBF solid) and the energy balance's drift relative to the peak kinetic energy.",
            terms.join(", ")
        ),
    });
    v.push(PlotFile {
        file: "constraint.svg",
        caption: format!(
            "Position-level joint violation (gaps in m and axis misalignment in rad, log scale): {forms}."
        ),
    });
    v
}

/// The SVG plots of one case (the files [`plots`] lists).
pub fn write_plots(dir: &Path, r: &CaseResult) -> Result<(), Error> {
    write_tip(dir, r)?;
    write_tip_difference(dir, r)?;
    write_energy(dir, r)?;
    write_per_run(dir, r)
}

/// `tip.svg`: tip X, Y, Z of each run and of the references.
fn write_tip(dir: &Path, r: &CaseResult) -> Result<(), Error> {
    let t_max = t_end(r);
    // Tip X, Y, Z: references first, so the formulations are drawn on top of them.
    let axis = ["X", "Y", "Z"];
    let tip_panels: Vec<Panel> = (0..3)
        .map(|k| {
            let mut series: Vec<Series> = r
                .reference_curves
                .iter()
                .enumerate()
                .map(|(i, (lab, c, shift))| {
                    Series::new(
                        lab.clone(),
                        ref_style(i),
                        c.t.iter()
                            .zip(&c.tip)
                            .map(|(&t, p)| (t - shift, p[k]))
                            .filter(|&(t, _)| t >= 0.0 && t <= t_max + 1e-9)
                            .collect(),
                    )
                })
                .collect();
            series.extend(r.runs.iter().rev().map(|run| {
                Series::new(
                    run.formulation.label(),
                    run_style(run.formulation),
                    run.rows.iter().map(|x| (x.t, x.tip[k])).collect(),
                )
            }));
            Panel {
                title: format!("{} — tip {}", r.name, axis[k]),
                x_label: "t [s]".into(),
                y_label: format!("tip {} [m]", axis[k]),
                series,
                ..Panel::default()
            }
        })
        .collect();
    panels_svg(&dir.join("tip.svg"), &tip_panels, 1, (1000, 300))
}

/// `tip_difference.svg`: the tip distance between the formulations and to each reference.
fn write_tip_difference(dir: &Path, r: &CaseResult) -> Result<(), Error> {
    // Differences: ANCF–GEBF, and each formulation against each reference (colour: the
    // reference; dash, marker and width: the formulation, `Style::of_formulation`).
    let mut diff = vec![Series::new("|ANCF − GEBF|", Style::solid(colors::PALETTE[4]).width(2), r.pair_diff.clone())];
    for (i, (lab, c, shift)) in r.reference_curves.iter().enumerate() {
        let color = [colors::REFS[1], colors::REFS[2], colors::EXTRA[1], colors::EXTRA[2]][i % 4];
        for run in r.runs.iter().filter(|x| !x.rows.is_empty()) {
            let style = Style::of_formulation(run.formulation, color);
            diff.push(Series::new(
                format!("|{} − {}|", run.formulation.label(), lab),
                style,
                tip_difference(&tip_curve(&run.rows), c, *shift),
            ));
        }
    }
    let diff_panel = Panel {
        title: format!("{} — tip distance", r.name),
        x_label: "t [s]".into(),
        y_label: "tip distance [m]".into(),
        log_y: true,
        series: diff,
        ..Panel::default()
    };
    panels_svg(&dir.join("tip_difference.svg"), &[diff_panel], 1, (1000, 380))
}

/// `energy.svg`: the energy components of each run and its energy balance's drift.
fn write_energy(dir: &Path, r: &CaseResult) -> Result<(), Error> {
    // Energies: only the components the case has; colour: the component, dash: the formulation.
    type Get = fn(&crate::run::Row) -> f64;
    let mut components: Vec<(&str, Get, RGBColor)> = vec![
        ("kinetic", |x| x.kinetic, colors::PALETTE[0]),
        ("elastic", |x| x.elastic, colors::PALETTE[2]),
        ("potential", |x| x.potential, colors::PALETTE[3]),
    ];
    if has_springs(r) {
        components.push(("spring", |x| x.spring, colors::PALETTE[5]));
        components.push(("dissipated", |x| x.dissipated, colors::PALETTE[7]));
    }
    if has_aero(r) {
        components.push(("aero work", |x| x.aero_work, colors::PALETTE[6]));
    }
    let mut comp = Vec::new();
    let mut drift = Vec::new();
    for run in r.runs.iter().rev() {
        let l = run.formulation.label();
        for &(name, get, color) in &components {
            let style = Style::of_formulation(run.formulation, color);
            comp.push(Series::new(format!("{name} ({l})"), style, run.rows.iter().map(|x| (x.t, get(x))).collect()));
        }
        let e0 = run.rows.first().map_or(0.0, |x| x.total);
        let peak = r.metrics.get(&run.formulation).map_or(1.0, |m| m.peak_kinetic).max(f64::MIN_POSITIVE);
        let w = |x: &crate::run::Row| if x.aero_work.is_finite() { x.aero_work } else { 0.0 };
        let d = |x: &crate::run::Row| if x.dissipated.is_finite() { x.dissipated } else { 0.0 };
        // a thrust's work joins the balance as the aerodynamic work does
        let th = |x: &crate::run::Row| if x.thrust_work.is_finite() { x.thrust_work } else { 0.0 };
        drift.push(Series::new(
            l,
            run_style(run.formulation),
            run.rows.iter().map(|x| (x.t, (x.total + d(x) - e0 - w(x) - th(x)) / peak)).collect(),
        ));
    }
    // The balance the drift panel shows: the terms the case has.
    let balance = match (has_aero(r), has_springs(r)) {
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
                series: comp,
                ..Panel::default()
            },
            Panel {
                title: format!("{} — energy drift", r.name),
                x_label: "t [s]".into(),
                y_label: balance.into(),
                series: drift,
                ..Panel::default()
            },
        ],
        1,
        (1000, 340),
    )
}

/// `constraint.svg`, and with aerodynamics `lift.svg`, with a fold hinge `fold.svg`: one series
/// per run.
fn write_per_run(dir: &Path, r: &CaseResult) -> Result<(), Error> {
    let per_run = |get: &dyn Fn(&RunOutput) -> Vec<(f64, f64)>| -> Vec<Series> {
        r.runs
            .iter()
            .rev()
            .map(|run| Series::new(run.formulation.label(), run_style(run.formulation), get(run)))
            .collect()
    };
    panels_svg(
        &dir.join("constraint.svg"),
        &[Panel {
            title: format!("{} — joint violation (gap and axis misalignment)", r.name),
            x_label: "t [s]".into(),
            y_label: "residual [m, rad]".into(),
            log_y: true,
            series: per_run(&|run| run.rows.iter().map(|x| (x.t, x.constraint_residual)).collect()),
            ..Panel::default()
        }],
        1,
        (1000, 330),
    )?;
    if has_aero(r) {
        panels_svg(
            &dir.join("lift.svg"),
            &[Panel {
                title: format!("{} — total lift", r.name),
                x_label: "t [s]".into(),
                y_label: "lift [N]".into(),
                series: per_run(&|run| run.rows.iter().filter(|x| x.lift.is_finite()).map(|x| (x.t, x.lift)).collect()),
                ..Panel::default()
            }],
            1,
            (1000, 330),
        )?;
    }
    if has_roll(r) {
        panels_svg(
            &dir.join("roll_rate.svg"),
            &[Panel {
                title: format!("{} — roll rate", r.name),
                x_label: "t [s]".into(),
                y_label: "roll rate [rad/s]".into(),
                series: per_run(&|run| run.rows.iter().map(|x| (x.t, x.roll_rate)).collect()),
                ..Panel::default()
            }],
            1,
            (1000, 330),
        )?;
    }
    if has_fold(r) {
        panels_svg(
            &dir.join("fold.svg"),
            &[Panel {
                title: format!("{} — fold angle", r.name),
                x_label: "t [s]".into(),
                y_label: "fold angle, unwrapped [deg]".into(),
                series: per_run(&|run| {
                    let rows: Vec<_> = run.rows.iter().filter(|x| x.fold.is_finite()).collect();
                    let un = unwrap_angles(rows.iter().map(|x| x.fold));
                    rows.iter().zip(un).map(|(x, a)| (x.t, a.to_degrees())).collect()
                }),
                ..Panel::default()
            }],
            1,
            (1000, 330),
        )?;
    }
    Ok(())
}

/// A number for a table: fixed-point with `prec` decimals, "–" when absent or not finite.
fn fixed(v: Option<f64>, prec: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.prec$}"),
        _ => "–".into(),
    }
}

/// A dimensionless or mixed-unit number for a table: scientific with `prec` decimals, "–" when
/// absent or not finite.
fn sci(v: Option<f64>, prec: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.prec$e}"),
        _ => "–".into(),
    }
}

/// The energy-drift entry of a table: [`UNRESOLVED`] when the run's peak kinetic energy is at or
/// below its [`kinetic_resolution`] (the ratio would be one residue over another).
fn drift_cell(m: &FormulationMetrics) -> String {
    match m.resolved_energy_drift() {
        Some(d) => sci(Some(d), 2),
        None => UNRESOLVED.into(),
    }
}

/// The energy-drift entry of a run that did not move: see [`drift_cell`] and [`unresolved_note`].
const UNRESOLVED: &str = "–*";

/// What [`UNRESOLVED`] means, with the runs it stands for (`(name, formulation, metrics)`); None
/// when there are none.
fn unresolved_note<'a>(runs: impl Iterator<Item = (&'a str, Formulation, &'a FormulationMetrics)>) -> Option<String> {
    let list: Vec<String> = runs
        .filter(|(_, _, m)| m.resolved_energy_drift().is_none())
        .map(|(name, f, m)| {
            format!("{name} {f}: peak {:.1e} J, resolution {:.1e} J", m.peak_kinetic, m.kinetic_resolution)
        })
        .collect();
    (!list.is_empty()).then(|| {
        format!(
            "{UNRESOLVED} energy drift not shown: the run's peak kinetic energy is at or below the kinetic energy it \
             resolves, ½·M·(atol/dt)² (the structure's mass M moving by Newton's absolute tolerance in one step), \
             so nothing moved and the drift would be a ratio of two residues of the solve ({}).",
            list.join("; ")
        )
    })
}

/// Every run of `results` with its case's name, in table order.
fn all_runs(results: &[CaseResult]) -> impl Iterator<Item = (&str, Formulation, &FormulationMetrics)> {
    results.iter().flat_map(|r| r.metrics.iter().map(move |(f, m)| (r.name.as_str(), *f, m)))
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
                drift_cell(m),
                sci(Some(m.max_constraint_residual), 1),
                fixed(r.pair.as_ref().map(|p| 1e3 * p.all.max), 3),
                fixed(r.pair.as_ref().map(|p| 1e3 * p.first_second.max), 3),
                if refs.is_empty() { "–".into() } else { refs.join("; ") },
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
    if let Some(n) = unresolved_note(all_runs(results)) {
        s.push_str(&format!("\n{n}\n"));
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

/// The report fragments `<out>/<case>/<file>` that the analyses leave in their cases' folders,
/// concatenated in case-name order; empty when there are none.
pub fn fragments(out: &Path, file: &str) -> String {
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(out)
        .map(|rd| rd.filter_map(|e| e.ok()).map(|e| e.path().join(file)).filter(|p| p.is_file()).collect())
        .unwrap_or_default();
    files.sort();
    files.iter().filter_map(|f| std::fs::read_to_string(f).ok()).collect()
}

/// Text escaped for HTML.
pub(crate) fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// The CSS class of a gate status: only a failure is styled as one; "–" (no gate) is plain.
fn status_class(status: &str) -> &'static str {
    match status {
        "pass" => "pass",
        "FAIL" | "run failed" => "fail",
        _ => "nogate",
    }
}

/// An HTML table; `numeric` columns are right-aligned.
fn html_table(head: &[&str], rows: &[Vec<String>], numeric: &dyn Fn(usize) -> bool) -> String {
    let mut s = String::from("<table><tr>");
    for h in head {
        let _ = write!(s, "<th>{}</th>", esc(h));
    }
    s.push_str("</tr>\n");
    for row in rows {
        s.push_str("<tr>");
        for (i, c) in row.iter().enumerate() {
            let class = if numeric(i) { " class=\"num\"" } else { "" };
            let _ = write!(s, "<td{class}>{}</td>", esc(c));
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</table>\n");
    s
}

/// A CSV file (header line, comma-separated, quotes only around whole fields) as an HTML table;
/// None when it cannot be read.
fn csv_table(path: &Path) -> Option<String> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut lines = text.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let split = |l: &str| -> Vec<String> {
        let mut v = Vec::new();
        let mut cur = String::new();
        let mut quoted = false;
        for ch in l.chars() {
            match ch {
                '"' => quoted = !quoted,
                ',' if !quoted => v.push(std::mem::take(&mut cur)),
                c => cur.push(c),
            }
        }
        v.push(cur);
        v
    };
    let head = split(lines.next()?);
    let rows: Vec<Vec<String>> = lines.map(split).collect();
    let head_refs: Vec<&str> = head.iter().map(String::as_str).collect();
    let numeric = |i: usize| rows.first().and_then(|r| r.get(i)).is_some_and(|c| c.parse::<f64>().is_ok());
    Some(html_table(&head_refs, &rows, &numeric))
}

/// The tables of a Markdown file (lines starting with `|`) as HTML tables, the other lines as
/// paragraphs; None when it cannot be read.
fn markdown_tables(path: &Path) -> Option<String> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut out = String::new();
    let mut block: Vec<Vec<String>> = Vec::new();
    let flush = |block: &mut Vec<Vec<String>>, out: &mut String| {
        if block.is_empty() {
            return;
        }
        let head: Vec<String> = block.remove(0);
        let rows: Vec<Vec<String>> =
            block.drain(..).filter(|r| !r.iter().all(|c| c.chars().all(|ch| ch == '-' || ch == ':'))).collect();
        let head_refs: Vec<&str> = head.iter().map(String::as_str).collect();
        let numeric = |i: usize| i > 0;
        out.push_str(&html_table(&head_refs, &rows, &numeric));
    };
    for l in text.lines() {
        let t = l.trim();
        if t.starts_with('|') {
            block.push(t.trim_matches('|').split('|').map(|c| c.trim().replace('`', "")).collect());
        } else {
            flush(&mut block, &mut out);
            let t = t.trim_start_matches('#').trim();
            if !t.is_empty() {
                let _ = writeln!(out, "<p>{}</p>", esc(&t.replace('`', "")));
            }
        }
    }
    flush(&mut block, &mut out);
    Some(out)
}

/// Which group of the contents bar a section belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Group {
    /// The overview (results table) and other whole-report sections.
    Overview,
    /// One case.
    Case,
    /// A study over several runs (refinement, energy, speed, stress, or a new analysis).
    Study,
}

/// One section of `index.html`: an entry of the contents bar and its body. A new part of the
/// report (e.g. a static analysis) is a `Section` in the `extra` list of [`index_html`]:
/// tables first, then figures, every linked file relative to the report folder.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// Anchor (unique in the page).
    pub id: String,
    /// Title in the contents bar and above the section.
    pub title: String,
    /// Group in the contents bar.
    pub group: Group,
    /// Body HTML (without the heading).
    pub html: String,
    /// Optional badge after the title in the contents bar: (text, CSS class).
    pub badge: Option<(String, &'static str)>,
}

fn figure(src: &str, caption: &str) -> String {
    format!(
        "<figure><img src=\"{}\" alt=\"{}\" loading=\"lazy\"><figcaption>{}</figcaption></figure>\n",
        esc(src),
        esc(caption),
        esc(caption)
    )
}

/// The section of one case: its table, data links, 3-D view (when `<out>/<case>/view_*.json`
/// exist), then its plots.
pub fn case_section(out: &Path, r: &CaseResult) -> Section {
    let mut s = String::new();
    let _ = writeln!(s, "<p>{}</p>", esc(&r.description));
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
    // Table: per formulation, then the distances.
    let rows: Vec<Vec<String>> = Formulation::ALL
        .iter()
        .filter_map(|f| r.metrics.get(f).map(|m| (f, m)))
        .map(|(f, m)| {
            vec![
                f.label().to_string(),
                if m.error.is_some() { format!("failed at {:.4} s", m.t_reached) } else { "ok".into() },
                m.n_steps.to_string(),
                format!("{:.1}", 1e3 * m.wall_s),
                format!("{:.2}", m.newton_per_step),
                m.max_newton_iters.to_string(),
                drift_cell(m),
                sci(Some(m.max_constraint_residual), 1),
            ]
        })
        .collect();
    s.push_str(&html_table(
        &["formulation", "run", "steps", "wall [ms]", "Newton/step", "max Newton", "energy drift", "max constraint"],
        &rows,
        &|i| i >= 2,
    ));
    if let Some(n) = unresolved_note(r.metrics.iter().map(|(f, m)| (r.name.as_str(), *f, m))) {
        let _ = writeln!(s, "<p class=\"note\">{}</p>", esc(&n));
    }
    let mut dist: Vec<Vec<String>> = Vec::new();
    if let Some(p) = &r.pair {
        dist.push(vec![
            "ANCF − GEBF".into(),
            "–".into(),
            fixed(Some(1e3 * p.all.max), 3),
            fixed(Some(1e3 * p.all.rms), 3),
            fixed(Some(1e3 * p.first_second.max), 3),
            "–".into(),
        ]);
    }
    for x in &r.references {
        dist.push(vec![
            format!("{} − {}", x.formulation.label(), x.label),
            x.formulation.label().into(),
            fixed(Some(1e3 * x.diff.max), 3),
            fixed(Some(1e3 * x.diff.rms), 3),
            "–".into(),
            fixed(x.tip_max_m.map(|v| 1e3 * v), 1),
        ]);
    }
    if !dist.is_empty() {
        s.push_str(&html_table(
            &["tip distance", "formulation", "max [mm]", "RMS [mm]", "max t≤1 s [mm]", "gate limit [mm]"],
            &dist,
            &|i| i >= 2,
        ));
    }
    for e in &r.reference_errors {
        let _ = writeln!(s, "<p class=\"fail\">{}</p>", esc(e));
    }
    s.push_str(&events_table(r));
    s.push_str(&roll_table(r));
    let name = esc(&r.name);
    let _ = writeln!(
        s,
        "<p>Data: <a href=\"{name}/ancf.csv\">ancf.csv</a>, <a href=\"{name}/gebf.csv\">gebf.csv</a>, <a href=\"{name}/summary.json\">summary.json</a></p>"
    );
    if let Some(v) = crate::view3d::view_html(out, &r.name, &r.name) {
        let what = if has_aero(r) {
            "the beam axes, the wing's leading and trailing edges with the panels between them, and the wake"
        } else {
            "the beam axes with a tick along each section's chord direction (y axis) showing the twist"
        };
        let _ = writeln!(
            s,
            "<h3>3-D view</h3><p class=\"note\">Both formulations overlaid (ANCF blue, GEBF orange): {what}. Drag to turn, wheel to zoom; decimated in time and space.</p>{v}"
        );
    }
    s.push_str("<h3>Plots</h3>\n");
    for p in plots(r) {
        s.push_str(&figure(&format!("{}/{}", r.name, p.file), &p.caption));
    }
    Section {
        id: r.name.clone(),
        title: r.name.clone(),
        group: Group::Case,
        html: s,
        badge: Some((r.status().to_string(), status_class(r.status()))),
    }
}

/// One section per refinement ladder under `out/converge/`, in name order.
fn converge_sections(out: &Path) -> Vec<Section> {
    let mut v = Vec::new();
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
    for n in &names {
        let d = conv.join(n);
        let mut s = String::from(
            "<p>Each formulation refined in time (fixed elements), in space (small fixed step) and in both (diagonal). \
             Error: the largest tip distance over the window to the ladder's truth, named in the column <code>against</code> \
             (the finest rung, or a converged external reference). Cost: the thread CPU time of each rung, run one after \
             another on one core.</p>\n",
        );
        if let Some(t) = csv_table(&d.join("converge.csv")) {
            s.push_str(&t);
        }
        let _ = writeln!(
            s,
            "<p>Data: <a href=\"converge/{0}/converge.csv\">converge.csv</a>, <a href=\"converge/{0}/converge.json\">converge.json</a></p>",
            esc(n)
        );
        s.push_str(&figure(
            &format!("converge/{n}/work_precision.svg"),
            "Work-precision, log–log: largest tip error against CPU time, one marker per rung; peer codes as single points where measured.",
        ));
        s.push_str(&figure(
            &format!("converge/{n}/convergence.svg"),
            "Error against time step (time ladder) and against elements of the first body (space ladder), log–log.",
        ));
        v.push(Section {
            id: format!("converge-{n}"),
            title: format!("Refinement: {n}"),
            group: Group::Study,
            html: s,
            badge: None,
        });
    }
    v
}

/// The sections of the studies found on disk under `out`: the static equilibria
/// (`<case>/static_section.html`), the gust sweeps (`<case>/gust_section.html`), `converge/<case>/`, `energy/`, `bench/` and `stress/` (each
/// table first, then its figures).
pub fn study_sections(out: &Path) -> Vec<Section> {
    let mut v = Vec::new();
    let statics = crate::static_out::sections_html(out);
    if !statics.is_empty() {
        // The fragment's own heading becomes the section's title.
        let body = statics.split_once("</h2>\n").map_or(statics.as_str(), |x| x.1);
        v.push(Section {
            id: "static".into(),
            title: "Static aeroelastic equilibria".into(),
            group: Group::Study,
            html: body.to_string(),
            badge: None,
        });
    }
    if let Ok(readings) = std::fs::read_to_string(out.join(crate::healy_readings::SECTION_FILE)) {
        v.push(Section {
            id: "healy-readings".into(),
            title: "Healy's experiment: every reading".into(),
            group: Group::Study,
            html: readings,
            badge: None,
        });
    }
    let stab = crate::stability_out::sections_html(out);
    if !stab.is_empty() {
        v.push(Section {
            id: "stability".into(),
            title: "Linearised stability".into(),
            group: Group::Study,
            html: format!(
                "<p>Roots of the flutter equation about each airspeed's equilibrium (or the undeformed wing): \
                 the structure's modes coupled to the UVLM linearised in the Laplace domain (frozen wake, exact \
                 delays), continued over the sweep by Newton's method (docs/stability.md). Files per case: \
                 <code>stability_ancf.csv</code>, <code>stability_gebf.csv</code>, <code>stability_*.json</code>.</p>\n{stab}"
            ),
            badge: None,
        });
    }
    let trims = crate::trim_out::sections_html(out);
    if !trims.is_empty() {
        v.push(Section {
            id: "trim".into(),
            title: "Trim in level flight".into(),
            group: Group::Study,
            html: format!(
                "<p>The angle of attack, elevator deflection and thrust with which the free aircraft's flexible \
                 static equilibrium carries no net force and pitching moment (docs/trim.md). Files per case: \
                 <code>trim_ancf.json</code>, <code>trim_gebf.json</code>.</p>\n{trims}"
            ),
            badge: None,
        });
    }
    let gusts = crate::gust_out::sections_html(out);
    if !gusts.is_empty() {
        v.push(Section {
            id: "gust".into(),
            title: "Gust response and load alleviation".into(),
            group: Group::Study,
            html: gusts,
            badge: None,
        });
    }
    v.extend(converge_sections(out));
    if out.join("energy/energy.svg").exists() {
        let mut s = String::from(
            "<p>No aerodynamics and no numerical dissipation (ρ<sub>∞</sub> = 1): the exact energy (with the dampers' work for the sprung case) is constant, so its change divided by the peak kinetic energy is the scheme's error. Each formulation in the Arnold–Brüls form (forces at the end of the step: the trapezoidal rule) and in the Chung–Hulbert form (forces at the α-weighted state: the implicit midpoint rule), every step recorded, at the case's dt and at dt/2.</p>\n",
        );
        if let Some(t) = markdown_tables(&out.join("energy/energy.md")) {
            s.push_str(&t);
        }
        s.push_str(
            "<p>Data: <a href=\"energy/energy.md\">energy.md</a>, <a href=\"energy/energy.csv\">energy.csv</a></p>\n",
        );
        s.push_str(&figure(
            "energy/energy.svg",
            "Energy error against time, per case, formulation and integrator form.",
        ));
        v.push(Section {
            id: "energy".into(),
            title: "Energy at ρ∞ = 1".into(),
            group: Group::Study,
            html: s,
            badge: None,
        });
    }
    if out.join("bench/bench.svg").exists() {
        let mut s = String::from(
            "<p>Median thread CPU time of repeated serial runs at each case's own settings (ANCF on both solve paths), with the Newton work per step. The horizontal lines in the figure are the targets for the paper's pendulums.</p>\n",
        );
        if let Some(t) = markdown_tables(&out.join("bench/bench.md")) {
            s.push_str(&t);
        }
        s.push_str(
            "<p>Data: <a href=\"bench/bench.md\">bench.md</a>, <a href=\"bench/bench.json\">bench.json</a></p>\n",
        );
        s.push_str(&figure("bench/bench.svg", "CPU time per run, per case and formulation."));
        v.push(Section { id: "bench".into(), title: "Speed".into(), group: Group::Study, html: s, badge: None });
    }
    if out.join("stress/stress_ancf.svg").exists() {
        let mut s = String::from(
            "<p>The base pendulum over stiffness scale c × flare β × step factor × ρ<sub>∞</sub>, 2 s per cell, both formulations; a cell that fails at fixed steps is rerun with step control. Then two extra hard runs (a 20 s pendulum and the wing at AoA 15°).</p>\n",
        );
        if let Some(t) = csv_table(&out.join("stress/extras.csv")) {
            s.push_str(&t);
        }
        s.push_str(
            "<p>Data: <a href=\"stress/stress.csv\">stress.csv</a>, <a href=\"stress/extras.csv\">extras.csv</a></p>\n",
        );
        for f in Formulation::ALL {
            s.push_str(&figure(
                &format!("stress/stress_{f}.svg"),
                &format!("Stress matrix, {}: outcome of each cell.", f.label()),
            ));
        }
        v.push(Section {
            id: "stress".into(),
            title: "Stress matrix".into(),
            group: Group::Study,
            html: s,
            badge: None,
        });
    }
    v
}

const STYLE: &str = "body{font-family:sans-serif;margin:0;color:#111}\
nav{position:fixed;top:0;left:0;bottom:0;width:250px;overflow-y:auto;background:#f4f4f4;border-right:1px solid #ccc;padding:10px 12px;font-size:13px;box-sizing:border-box}\
nav h2{font-size:14px;margin:12px 0 4px}nav ul{list-style:none;margin:0;padding:0}nav li{margin:2px 0;overflow-wrap:anywhere}\
nav a{text-decoration:none;color:#124}nav a:hover{text-decoration:underline}\
main{margin-left:270px;padding:10px 24px;max-width:1150px}\
section{border-top:2px solid #ddd;padding-top:6px;margin-top:18px}\
table{border-collapse:collapse;font-size:13px;margin:8px 0}td,th{border:1px solid #ccc;padding:3px 6px;text-align:left}\
td.num{text-align:right;font-variant-numeric:tabular-nums}th{background:#eee}\
.pass{color:#070}.fail{color:#c00;font-weight:bold}.nogate{color:#555}\
.badge{font-size:11px;margin-left:4px}\
img{max-width:100%;border:1px solid #ddd;margin:4px 0}figure{margin:10px 0}figcaption{font-size:13px;color:#333}\
.view3d canvas{border:1px solid #bbb;max-width:100%;cursor:grab;touch-action:none}.view3d .controls{font-size:13px;margin:4px 0}\
.view3d input.time{width:380px;vertical-align:middle}.note{font-size:13px;color:#333}\
#js-errors{color:#c00;white-space:pre-wrap}";

/// `reports/index.html`: a contents bar with a section per case and per study, the results table
/// first, then each case (tables, 3-D view, plots), the studies found on disk under `out`
/// ([`study_sections`]) and the `extra` sections (e.g. a new analysis), in that order.
pub fn index_html(out: &Path, results: &[CaseResult], extra: &[Section]) -> String {
    let mut sections = Vec::new();
    // The overview: the results table.
    let mut t = String::from(
        "<p>Every case run with both formulations. Tip difference = |p<sub>ANCF</sub>(t) − p<sub>GEBF</sub>(t)| in millimetres; energy drift = the largest change of the case's energy balance (E, plus the dampers' work where there are dampers, minus the aerodynamic work where there is a flow) divided by the peak kinetic energy; constraint = position-level joint gap [m] and axis misalignment [rad]. Gate: pass, FAIL, or – where the case declares no gate.</p>\n<table><tr>",
    );
    for h in TABLE_HEAD {
        let _ = write!(t, "<th>{}</th>", esc(h));
    }
    t.push_str("</tr>\n");
    for row in table_rows(results) {
        t.push_str("<tr>");
        for (i, c) in row.iter().enumerate() {
            let class = match i {
                10 => format!(" class=\"{}\"", status_class(c)),
                3..=8 => " class=\"num\"".into(),
                _ => String::new(),
            };
            let cell = if i == 0 { format!("<a href=\"#{0}\">{0}</a>", esc(c)) } else { esc(c) };
            // The reason for a drift left out, on the cell itself (and below the table).
            let title = if i == 5 && c == UNRESOLVED {
                " title=\"not shown: the peak kinetic energy is below what the run resolves (note below the table)\""
            } else {
                ""
            };
            let _ = write!(t, "<td{class}{title}>{cell}</td>");
        }
        t.push_str("</tr>\n");
    }
    t.push_str("</table>\n");
    if let Some(n) = unresolved_note(all_runs(results)) {
        let _ = writeln!(t, "<p class=\"note\">{}</p>", esc(&n));
    }
    t.push_str("<p>The same table in Markdown: <a href=\"summary.md\">summary.md</a>.</p>\n");
    sections.push(Section {
        id: "results".into(),
        title: "Results".into(),
        group: Group::Overview,
        html: t,
        badge: None,
    });
    sections.extend(results.iter().map(|r| case_section(out, r)));
    sections.extend(study_sections(out));
    sections.extend(extra.iter().cloned());

    let mut s = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>flexmb report</title>\n<style>{STYLE}</style></head><body>\n<nav><h2>Contents</h2>"
    );
    for (group, title) in [(Group::Overview, None), (Group::Case, Some("Cases")), (Group::Study, Some("Studies"))] {
        let items: Vec<&Section> = sections.iter().filter(|x| x.group == group).collect();
        if items.is_empty() {
            continue;
        }
        if let Some(t) = title {
            let _ = write!(s, "<h2>{t}</h2>");
        }
        s.push_str("<ul>");
        for x in items {
            let badge = x
                .badge
                .as_ref()
                .map(|(b, c)| format!("<span class=\"badge {c}\">{}</span>", esc(b)))
                .unwrap_or_default();
            let _ = write!(s, "<li><a href=\"#{}\">{}</a>{badge}</li>", esc(&x.id), esc(&x.title));
        }
        s.push_str("</ul>");
    }
    s.push_str("</nav>\n<main>\n<h1>flexmb report: ANCF and GEBF</h1>\n<div id=\"js-errors\" hidden></div>\n");
    for x in &sections {
        let badge =
            x.badge.as_ref().map(|(b, c)| format!(" <span class=\"{c}\">[{}]</span>", esc(b))).unwrap_or_default();
        let _ = write!(s, "<section id=\"{}\"><h2>{}{badge}</h2>\n{}</section>\n", esc(&x.id), esc(&x.title), x.html);
    }
    s.push_str("</main>\n");
    if s.contains("class=\"view3d\"") {
        let _ = write!(s, "<script>\n{}</script>\n", crate::view3d::VIEWER_JS);
    }
    s.push_str("</body></html>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unwrap_removes_jumps_through_180_degrees() {
        let a = [3.0, 3.1, -3.1, -3.0, 3.1];
        let u = unwrap_angles(a);
        assert!(u.windows(2).all(|w| (w[1] - w[0]).abs() < 0.3), "{u:?}");
        assert!((u[2] - (-3.1 + std::f64::consts::TAU)).abs() < 1e-12);
        assert!((u[4] - 3.1).abs() < 1e-12);
    }

    #[test]
    fn no_gate_is_not_styled_as_a_failure() {
        assert_eq!(status_class("–"), "nogate");
        assert_eq!(status_class("FAIL"), "fail");
        assert_eq!(status_class("run failed"), "fail");
        assert_eq!(status_class("pass"), "pass");
    }

    #[test]
    fn millimetre_columns_are_fixed_point() {
        assert_eq!(fixed(Some(0.000123 * 1e3), 3), "0.123");
        assert_eq!(fixed(None, 3), "–");
    }

    /// The energy-drift column showed 1.0 for the Goland and HALE runs, whose peak kinetic
    /// energy is 1e-18 J: a ratio of nothing to nothing (issue 33, item 9). A run at rest shows
    /// "–*" and a note; a moving one its drift.
    #[test]
    fn a_run_at_rest_shows_no_energy_drift_issue_33() {
        use crate::case::CaseFile;
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases");
        let spec = |file: &str, set: &[&str]| {
            let set: Vec<_> = set.iter().map(|s| s.parse().unwrap()).collect();
            CaseFile::read(&dir.join(file)).unwrap().expand(&set).unwrap().remove(0)
        };
        let f = Formulation::Gebf;
        // The Goland wing at zero incidence without gravity: nothing moves.
        let goland = spec("goland_flutter.json", &[]);
        let r = CaseResult::evaluate(&goland, vec![crate::scene::run_formulation(&goland.gebf, f)]);
        let m = &r.metrics[&f];
        assert!(m.error.is_none(), "{:?}", m.error);
        // ½·M·(atol/dt)²: 35.71 kg/m over 6.096 m, atol 1e-10 m, dt 0.005 s.
        let expected = 0.5 * 35.71 * 6.096 * (1e-10_f64 / 0.005).powi(2);
        approx::assert_relative_eq!(m.kinetic_resolution, expected, max_relative = 1e-12);
        assert!(m.peak_kinetic < 1e-3 * m.kinetic_resolution, "peak {:e} J", m.peak_kinetic);
        assert_eq!(m.resolved_energy_drift(), None);
        assert_eq!(drift_cell(m), UNRESOLVED);
        assert!(m.energy_drift.is_finite(), "summary.json keeps the ratio");
        let md = summary_markdown(std::slice::from_ref(&r));
        assert!(md.contains("| –* |") && md.contains("energy drift not shown"), "{md}");
        // The paper's pendulum moves: its drift is shown, and there is no note.
        let pendulum = spec("double_pendulum_c1_beta45.json", &["t_end=0.1"]);
        let r = CaseResult::evaluate(&pendulum, vec![crate::scene::run_formulation(&pendulum.gebf, f)]);
        let m = &r.metrics[&f];
        assert!(m.peak_kinetic > 1e6 * m.kinetic_resolution, "peak {:e} J", m.peak_kinetic);
        assert_eq!(m.resolved_energy_drift(), Some(m.energy_drift));
        assert_eq!(drift_cell(m), sci(Some(m.energy_drift), 2));
        assert!(!summary_markdown(std::slice::from_ref(&r)).contains("not shown"));
    }
}
