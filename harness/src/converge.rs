//! Refinement ladders and work-precision diagrams (speed against error).
//!
//! For each formulation three ladders are run from the case's own settings (n elements per body,
//! time step h), with L = 3 refinement levels (L = 2 for aeroelastic cases):
//! * **time**: n fixed, h·{2, 1, ½, ¼} against h/8 (L = 2: h·{2, 1, ½} against h/4);
//! * **space**: h·2/2ᴸ fixed, elements n·{½, 1, 2} (at least 1) against 4n (L = 2: n·{½, 1} against 2n);
//! * **diagonal** (work-precision): (n·2ᵏ, h/2ᵏ), k < L, against the finest rung k = L, or
//!   against an external reference marked `converged` in the case file.
//!
//! Aeroelastic cases keep the wake's physical length on every rung (rows scaled with 1/dt; the
//! chordwise lattice is fixed) and may use a shorter window (`converge_t_end`).
//!
//! Cost of a rung = its thread CPU time (wall time off Linux), the rungs run one after another
//! on one thread, so that no rung's time includes waiting for a core another rung holds.
//!
//! Error of a rung = max over time of the tip distance to its truth. Observed orders come from
//! successive rungs (`ln(e_k / e_{k+1}) / ln(h_k / h_{k+1})` over the rungs' step or element
//! ratio), and a Richardson estimate of the truth's own error is reported from the last two rungs.

use std::fmt::Write as _;
use std::path::Path;

use rayon::prelude::*;
use serde::Serialize;

use crate::Error;
use crate::case::{Block, Elements, Formulation, RunSpec};
use crate::csv::{Curve, read_curve, write_file};
use crate::metrics::{tip_curve, tip_difference, window_stats};
use crate::plot::{Dash, Marker, Panel, Series, Style, colors, panels_svg};
use crate::progress::Progress;
use crate::run::RunOutput;
use crate::scene::run_formulation;

/// Which ladder a rung belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Ladder {
    /// Time step refined at fixed elements.
    Time,
    /// Elements refined at a fixed small step.
    Space,
    /// Both refined together.
    Diagonal,
}

impl Ladder {
    fn as_str(self) -> &'static str {
        match self {
            Ladder::Time => "time",
            Ladder::Space => "space",
            Ladder::Diagonal => "diagonal",
        }
    }
}

/// One rung of a ladder.
#[derive(Debug, Clone, Serialize)]
pub struct Rung {
    /// Formulation.
    pub formulation: Formulation,
    /// Ladder.
    pub ladder: Ladder,
    /// Elements per body.
    pub elements: Elements,
    /// Time step, s.
    pub dt: f64,
    /// Whether this rung is the ladder's truth.
    pub is_truth: bool,
    /// Wall time, s.
    pub wall_s: f64,
    /// Thread CPU time of the run (wall time off Linux), s: the cost in the work-precision plot.
    pub cpu_s: f64,
    /// Steps taken.
    pub n_steps: usize,
    /// Max tip distance to the ladder's truth, m (NaN for the truth itself or a failed run).
    pub error_m: f64,
    /// What the error is measured against.
    pub against: String,
    /// Failure, if any.
    pub failure: Option<String>,
}

/// Observed convergence order of one ladder.
#[derive(Debug, Clone, Serialize)]
pub struct Order {
    /// Formulation.
    pub formulation: Formulation,
    /// Ladder.
    pub ladder: Ladder,
    /// Orders between successive rungs (refinement ratio 2).
    pub orders: Vec<f64>,
    /// Richardson estimate of the truth rung's own error, m.
    pub truth_error_estimate_m: f64,
}

/// Result of a convergence study.
#[derive(Debug, Clone, Serialize)]
pub struct ConvergeResult {
    /// Run name.
    pub name: String,
    /// All rungs.
    pub rungs: Vec<Rung>,
    /// Observed orders.
    pub orders: Vec<Order>,
    /// Peer codes' runs of the same case, drawn as single points.
    pub peers: Vec<Peer>,
}

/// A peer code's run of the case: its cost and its tip error against the same truth as the
/// diagonal ladder (`reference/peer_timings.csv` beside the case file).
#[derive(Debug, Clone, Serialize)]
pub struct Peer {
    /// Label (as the case's reference of the same run).
    pub label: String,
    /// Cost of one run, s.
    pub cost_s: f64,
    /// What the cost is: `cpu` or `wall`.
    pub cost_kind: String,
    /// Largest tip distance to the truth, m.
    pub error_m: f64,
    /// Where the error comes from: `measured` (by the harness, against the truth) or `file`
    /// (the estimate given in the timings file).
    pub error_source: String,
}

/// The peers of run `name` listed in `<dir>/reference/peer_timings.csv` (none when the file is
/// absent), their errors measured against `truth` over `t ≤ t_window` where the file gives none.
fn peers(
    dir: &Path,
    name: &str,
    truth: Option<&Curve>,
    shifts: &[(String, f64)],
    t_window: f64,
) -> Result<Vec<Peer>, Error> {
    let path = dir.join("reference").join("peer_timings.csv");
    let Ok(text) = std::fs::read_to_string(&path) else { return Ok(Vec::new()) };
    let bad = |msg: String| Error::Reference { file: path.display().to_string(), msg };
    let mut v = Vec::new();
    for (k, line) in text.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty()).enumerate().skip(1) {
        let c: Vec<&str> = line.split(',').map(str::trim).collect();
        if c.len() != 6 {
            return Err(bad(format!("data line {k}: {} fields, expected 6", c.len())));
        }
        if c[0] != name {
            continue;
        }
        let cost_s: f64 = c[3].parse().map_err(|_| bad(format!("data line {k}: cost_s `{}`", c[3])))?;
        let (error_m, error_source) = if c[5].is_empty() {
            let Some(truth) = truth else { continue };
            let curve = read_curve(&dir.join(c[2]))?;
            let shift = shifts.iter().find(|s| s.0 == c[1]).map_or(0.0, |s| s.1);
            let d = tip_difference(truth, &curve, shift);
            (window_stats(&d, f64::NEG_INFINITY, t_window).max, "measured".to_string())
        } else {
            (c[5].parse().map_err(|_| bad(format!("data line {k}: error_m `{}`", c[5])))?, "file".to_string())
        };
        v.push(Peer { label: c[1].to_string(), cost_s, cost_kind: c[4].to_string(), error_m, error_source });
    }
    Ok(v)
}

fn rung_spec(spec: &RunSpec, f: Formulation, elements: Elements, dt: f64) -> crate::case::Case {
    let mut c = spec.case(f).clone();
    let block = c.block_mut(f);
    let base_dt = std::mem::replace(block.dt, dt);
    *block.elements_per_body = elements;
    if let Some(t) = c.converge_t_end {
        c.t_end = t.min(c.t_end);
    }
    // Every rung ends at t_end: a step that does not divide it is rounded to one that does.
    let dt = crate::case::commensurate_dt(c.t_end, dt);
    *c.block_mut(f).dt = dt;
    // The wake sheds one row per step: keep its physical length (rows × V·dt) as dt changes, so
    // that every rung discretises the same wake.
    if let Some(aero) = c.aero.as_mut() {
        aero.n_wake_rows = ((aero.n_wake_rows as f64 * base_dt / dt).round() as usize).max(1);
    }
    // Common output grid: the coarsest step of the study, so that every rung is sampled alike.
    c.output_dt = None;
    c.gate = None;
    c
}

fn max_distance(a: &RunOutput, truth: &Curve) -> f64 {
    let d = tip_difference(&tip_curve(&a.rows), truth, 0.0);
    window_stats(&d, f64::NEG_INFINITY, f64::INFINITY).max
}

/// Plan of one study: (formulation, ladder, elements, dt, is_truth).
type Plan = Vec<(Formulation, Ladder, Elements, f64, bool)>;

/// The rungs' indices by decreasing estimated cost: elements × steps, times the wake rows (∝ 1/dt)
/// for an aeroelastic case, whose Biot–Savart sums grow with the wake.
fn costliest_first(plan: &Plan, aero: bool) -> Vec<usize> {
    let cost = |i: usize| {
        let (_, _, ref e, dt, _) = plan[i];
        // Per body: the same factor scales every body's count, so one body's count orders the rungs.
        let steps = 1.0 / dt;
        e.for_body(0) as f64 * steps * if aero { steps } else { 1.0 }
    };
    let mut order: Vec<usize> = (0..plan.len()).collect();
    order.sort_by(|&a, &b| cost(b).total_cmp(&cost(a)));
    order
}

/// Refinement levels below the case's own settings: 3 for structural cases; 2 for aeroelastic
/// ones, whose cost per step grows with the wake rows (∝ 1/dt), so a level costs 4× in time.
fn levels(spec: &RunSpec) -> i32 {
    if spec.ancf.aero.is_some() { 2 } else { 3 }
}

fn plan(spec: &RunSpec) -> Plan {
    let mut p = Vec::new();
    let l = levels(spec);
    let fine = 2f64.powi(l);
    for f in Formulation::ALL {
        let c = spec.case(f);
        let Block { elements_per_body: n, dt: h, .. } = c.block(f);
        // time: h·{2, 1, …, 2/fine} against h/fine
        for k in -1..=l {
            p.push((f, Ladder::Time, n.clone(), h / 2f64.powi(k), k == l));
        }
        // space at h·2/fine: n·{½, 1, …} against n·fine/2
        let mut space: Vec<Elements> = (-1..l).map(|k| n.scaled(2f64.powi(k))).collect();
        space.dedup();
        let last = space.len() - 1;
        for (k, e) in space.into_iter().enumerate() {
            p.push((f, Ladder::Space, e, 2.0 * h / fine, k == last));
        }
        for k in 0..=l {
            let s = 2f64.powi(k);
            p.push((f, Ladder::Diagonal, n.scaled(s), h / s, k == l));
        }
    }
    p
}

/// Run the three ladders of both formulations (rayon over rungs), counting the rungs on
/// `progress`.
pub fn converge(spec: &RunSpec, progress: &Progress) -> Result<ConvergeResult, Error> {
    let plan = plan(spec);
    // A converged external reference, if the case names one.
    let case = &spec.ancf;
    let external: Option<(String, Curve)> = match case.references.iter().find(|r| r.converged) {
        Some(r) => Some((r.label.clone(), read_curve(&spec.dir.join(&r.file))?)),
        None => None,
    };
    let bar = progress.counter(plan.len(), &format!("ladders of {}", spec.name));
    // Rungs side by side on the rayon threads, costliest first (one task each, so that the long
    // fine rungs start at once and the short ones fill in). Each rung runs on one thread (its
    // Biot–Savart sums single-threaded: several runs are registered), so the thread's CPU time
    // is the rung's own cost.
    let order = costliest_first(&plan, spec.ancf.aero.is_some());
    let _runs = aeroelastic::aero_settings::register_runs(plan.len());
    let mut outs: Vec<(usize, RunOutput, f64)> = order
        .par_iter()
        .with_max_len(1)
        .map(|&i| {
            let (f, _, ref e, dt, _) = plan[i];
            let c0 = crate::bench::thread_cpu_s();
            let out = run_formulation(&rung_spec(spec, f, e.clone(), dt), f);
            let cpu = c0.and_then(|c0| Some(crate::bench::thread_cpu_s()? - c0)).unwrap_or(out.wall_s);
            bar.inc(1);
            (i, out, cpu)
        })
        .collect();
    bar.finish_and_clear();
    outs.sort_by_key(|x| x.0);
    let cpu: Vec<f64> = outs.iter().map(|x| x.2).collect();
    let outs: Vec<RunOutput> = outs.into_iter().map(|x| x.1).collect();

    let mut rungs = Vec::new();
    let mut orders = Vec::new();
    for f in Formulation::ALL {
        for ladder in [Ladder::Time, Ladder::Space, Ladder::Diagonal] {
            let idx: Vec<usize> = (0..plan.len()).filter(|&i| plan[i].0 == f && plan[i].1 == ladder).collect();
            let truth_i = *idx.iter().find(|&&i| plan[i].4).expect("every ladder has a truth");
            let own_truth = tip_curve(&outs[truth_i].rows);
            let use_external = ladder == Ladder::Diagonal && external.is_some();
            let (mut against, truth) = match (&external, use_external) {
                (Some((label, c)), true) => (label.clone(), c),
                _ => (format!("{} rung ({} el, dt {:.3e})", f, plan[truth_i].2, plan[truth_i].3), &own_truth),
            };
            // A failed truth measures nothing: no errors on this ladder.
            let truth_failed = !use_external && outs[truth_i].error.is_some();
            if truth_failed {
                against = format!("{against}: failed");
            }
            let mut errs = Vec::new();
            // The rung's mesh size: dt on the time and diagonal ladders (the diagonal refines
            // both by one ratio), 1 / elements on the space ladder.
            let mut sizes = Vec::new();
            for &i in &idx {
                let (_, _, ref e, dt, is_truth) = plan[i];
                let o = &outs[i];
                let error_m = if o.error.is_some() || truth_failed || (is_truth && !use_external) {
                    f64::NAN
                } else {
                    max_distance(o, truth)
                };
                if !is_truth || use_external {
                    errs.push(error_m);
                    sizes.push(match ladder {
                        Ladder::Space => 1.0 / e.for_body(0).max(1) as f64,
                        _ => dt,
                    });
                }
                rungs.push(Rung {
                    formulation: f,
                    ladder,
                    elements: e.clone(),
                    dt,
                    is_truth: is_truth && !use_external,
                    wall_s: o.wall_s,
                    cpu_s: cpu[i],
                    n_steps: o.stats.n_steps,
                    error_m,
                    against: against.clone(),
                    failure: o.error.clone(),
                });
            }
            // Orders from successive rungs over their actual refinement ratio (the space ladder's
            // first step need not be 2): p = ln(e_k / e_{k+1}) / ln(h_k / h_{k+1}).
            let obs: Vec<f64> =
                errs.windows(2).zip(sizes.windows(2)).map(|(e, h)| (e[0] / e[1]).ln() / (h[0] / h[1]).ln()).collect();
            let p_last = obs.iter().rev().find(|x| x.is_finite()).copied().unwrap_or(f64::NAN);
            let last = errs.iter().rev().find(|x| x.is_finite()).copied().unwrap_or(f64::NAN);
            let ratio = sizes.windows(2).last().map_or(2.0, |h| h[0] / h[1]);
            orders.push(Order {
                formulation: f,
                ladder,
                orders: obs,
                // Richardson needs an observed order clearly above zero; otherwise no estimate.
                truth_error_estimate_m: if p_last > 0.5 { last / (ratio.powf(p_last) - 1.0) } else { f64::NAN },
            });
        }
    }
    // Peers against the diagonal ladder's truth: the external reference, else GEBF's finest rung.
    let gebf_truth = (0..plan.len())
        .find(|&i| plan[i].0 == Formulation::Gebf && plan[i].1 == Ladder::Diagonal && plan[i].4)
        .filter(|&i| outs[i].error.is_none())
        .map(|i| tip_curve(&outs[i].rows));
    let truth = external.as_ref().map(|e| &e.1).or(gebf_truth.as_ref());
    let shifts: Vec<(String, f64)> = case.references.iter().map(|r| (r.label.clone(), r.time_shift)).collect();
    let t_window = case.converge_t_end.map_or(case.t_end, |t| t.min(case.t_end));
    let peers = peers(&spec.dir, &spec.name, truth, &shifts, t_window)?;
    Ok(ConvergeResult { name: spec.name.clone(), rungs, orders, peers })
}

/// Write `converge.csv`, `converge.json`, `work_precision.svg` and `convergence.svg` into `dir`.
pub fn write(dir: &Path, r: &ConvergeResult) -> Result<(), Error> {
    let mut csv =
        String::from("formulation,ladder,elements_per_body,dt,is_truth,cpu_s,wall_s,n_steps,error_m,against,failure\n");
    for g in &r.rungs {
        let _ = writeln!(
            csv,
            "{},{},{},{:.6e},{},{:.6},{:.6},{},{:.6e},\"{}\",\"{}\"",
            g.formulation,
            g.ladder.as_str(),
            g.elements,
            g.dt,
            g.is_truth,
            g.cpu_s,
            g.wall_s,
            g.n_steps,
            g.error_m,
            g.against,
            g.failure.clone().unwrap_or_default().replace('"', "'")
        );
    }
    write_file(&dir.join("converge.csv"), &csv)?;
    write_file(&dir.join("converge.json"), &serde_json::to_string_pretty(r).map_err(|e| Error::Io(e.to_string()))?)?;
    // Colour: the formulation; dash and marker: the ladder.
    let style = |f: Formulation, l: Ladder| {
        let c = colors::of(f);
        match l {
            Ladder::Diagonal => Style::solid(c).marker(Marker::Circle).width(2),
            Ladder::Time => Style::solid(c).dash(Dash::Dashed).marker(Marker::Square),
            Ladder::Space => Style::solid(c).dash(Dash::Dotted).marker(Marker::Triangle).width(3),
        }
    };
    let series = |x: &dyn Fn(&Rung) -> f64, ladders: &[Ladder]| -> Vec<Series> {
        let mut v = Vec::new();
        for f in Formulation::ALL {
            for &l in ladders {
                let pts: Vec<(f64, f64)> = r
                    .rungs
                    .iter()
                    .filter(|g| g.formulation == f && g.ladder == l && g.error_m.is_finite() && g.error_m > 0.0)
                    .map(|g| (x(g), g.error_m))
                    .collect();
                if !pts.is_empty() {
                    v.push(Series::new(format!("{} {}", f.as_str().to_uppercase(), l.as_str()), style(f, l), pts));
                }
            }
        }
        v
    };
    let mut wp_series = series(&|g| g.cpu_s.max(1e-6), &[Ladder::Diagonal, Ladder::Time, Ladder::Space]);
    let peer_markers = [Marker::Diamond, Marker::Cross, Marker::Square, Marker::Triangle];
    for (k, p) in r.peers.iter().enumerate() {
        wp_series.push(Series::new(
            format!("{} ({} time)", p.label, p.cost_kind),
            Style::solid(colors::REFS[(k + 1) % colors::REFS.len()]).dash(Dash::None).marker(peer_markers[k % 4]),
            vec![(p.cost_s, p.error_m)],
        ));
    }
    let wp = Panel {
        title: format!("{} — work-precision", r.name),
        x_label: "CPU time per run [s]".into(),
        y_label: "max tip error [m]".into(),
        log_x: true,
        log_y: true,
        series: wp_series,
        ..Default::default()
    };
    panels_svg(&dir.join("work_precision.svg"), &[wp], 1, (1000, 480))?;
    let t = Panel {
        title: format!("{} — error against time step", r.name),
        x_label: "dt [s]".into(),
        y_label: "max tip error [m]".into(),
        log_x: true,
        log_y: true,
        series: series(&|g| g.dt, &[Ladder::Time]),
        ..Default::default()
    };
    let s = Panel {
        title: format!("{} — error against elements", r.name),
        x_label: "elements of the first body [-]".into(),
        y_label: "max tip error [m]".into(),
        log_x: true,
        log_y: true,
        series: series(&|g| g.elements.for_body(0) as f64, &[Ladder::Space]),
        ..Default::default()
    };
    panels_svg(&dir.join("convergence.svg"), &[t, s], 2, (700, 420))
}
