//! Outputs of a static aeroelastic sweep (docs/statics.md §5, §7): `static_<f>.csv`,
//! `static_lift_<f>.csv`, `static_summary.json`, three SVG plots, and the report's section.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;
use rayon::prelude::*;
use serde::Serialize;

use crate::Error;
use crate::case::{Case, Formulation, RunSpec};
use crate::csv::write_file;
use crate::stability::WakeSettings;
use crate::statics::StaticOutput;

pub use casefile::csv::STATIC_HEADER as HEADER;
pub use casefile::curve::{parse_xy, read_xy};

/// Column header of `static_lift_<f>.csv`.
pub const LIFT_HEADER: &str = "airspeed,strip,s,x,y,z,lift_per_span,cl";

/// What a static sweep varies: the airspeed, or the sideslip angle at one airspeed
/// (`static.sideslips_deg`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Abscissa {
    /// Airspeed, m/s.
    Airspeed,
    /// Sideslip angle, degrees.
    Sideslip,
}

impl Abscissa {
    /// The abscissa of `case`'s static sweep.
    pub fn of(case: &Case) -> Self {
        if case.statics.as_ref().is_some_and(|s| !s.sideslips_deg.is_empty()) { Self::Sideslip } else { Self::Airspeed }
    }

    /// A point's abscissa.
    pub fn x(self, p: &crate::statics::StaticPoint) -> f64 {
        match self {
            Self::Airspeed => p.airspeed,
            Self::Sideslip => p.sideslip_deg,
        }
    }

    /// Axis label with its unit.
    pub fn label(self) -> &'static str {
        match self {
            Self::Airspeed => "airspeed [m/s]",
            Self::Sideslip => "sideslip [deg]",
        }
    }

    /// The points' name in the plural, for failures.
    pub fn plural(self) -> &'static str {
        match self {
            Self::Airspeed => "airspeeds",
            Self::Sideslip => "sideslip angles",
        }
    }

    /// The band the RMS errors against an experiment are taken over: 12–33 m/s (the Healy
    /// experiment's range, where the flow is attached and the tip free) for an airspeed sweep,
    /// every point for a sideslip sweep.
    fn band(self) -> std::ops::RangeInclusive<f64> {
        match self {
            Self::Airspeed => 12.0 - 1e-9..=33.0 + 1e-9,
            Self::Sideslip => -90.0..=90.0,
        }
    }

    /// The band in words.
    pub fn band_text(self) -> &'static str {
        match self {
            Self::Airspeed => "12–33 m/s",
            Self::Sideslip => "the sweep",
        }
    }

    /// A point's abscissa with its unit: `12 m/s`, `sideslip 4°`.
    fn describe(self, x: f64) -> String {
        match self {
            Self::Airspeed => format!("{x} m/s"),
            Self::Sideslip => format!("sideslip {x}°"),
        }
    }
}

/// The sweep as CSV text (one row per airspeed, or sideslip angle, NaN where a point failed),
/// with the hinge moments of the control surfaces `surfaces` (their names) at the end.
pub fn to_csv(out: &StaticOutput, surfaces: &[String]) -> String {
    let mut s = casefile::csv::static_header(surfaces);
    s.push('\n');
    for p in &out.points {
        let l = &p.loads;
        let _ = write!(
            s,
            "{},{:.6},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{},{},{:.9e},{},{:.9e},{:.9e}",
            p.airspeed,
            p.fold_deg,
            p.tip[0],
            p.tip[1],
            p.tip[2],
            l.root_bending_moment,
            l.root_torque,
            l.hinge_moment,
            p.lift,
            l.root_force[0],
            l.root_force[1],
            l.root_force[2],
            l.root_moment[0],
            l.root_moment[1],
            l.root_moment[2],
            p.newton_iterations,
            u8::from(p.error.is_none()),
            p.drag,
            p.sideslip_deg,
            p.profile_drag,
            p.drag - p.profile_drag
        );
        for i in 0..surfaces.len() {
            let _ = write!(s, ",{:.6e}", p.control_hinge_moments.get(i).copied().unwrap_or(f64::NAN));
        }
        s.push('\n');
    }
    s
}

/// The spanwise lift distributions as CSV text.
pub fn lift_csv(out: &StaticOutput) -> String {
    let mut s = String::from(LIFT_HEADER);
    s.push('\n');
    for p in &out.points {
        for (j, st) in p.strips.iter().enumerate() {
            let _ = writeln!(
                s,
                "{},{j},{:.6},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}",
                p.airspeed, st.s, st.position[0], st.position[1], st.position[2], st.lift_per_span, st.cl
            );
        }
    }
    s
}

/// (airspeed, reference angle, computed angle, error = computed − reference), m/s and degrees.
pub type PointError = (f64, f64, f64, f64);

/// A reference curve with its errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReferenceErrors {
    /// Label.
    pub label: String,
    /// File, relative to the case folder.
    pub file: String,
    /// An experiment (else a model).
    pub experiment: bool,
    /// The curve: airspeed (m/s) or sideslip (degrees), angle (degrees).
    pub points: Vec<(f64, f64)>,
    /// Per formulation: the errors at the reference's airspeeds inside the sweep's converged
    /// range.
    pub errors: Vec<(Formulation, Vec<PointError>)>,
    /// Per formulation: RMS error over 12–33 m/s, degrees; None (`null`) when the formulation
    /// has no equilibrium at the reference's airspeeds in that band (the summary's `failures`
    /// say why).
    pub rms_deg: Vec<(Formulation, Option<f64>)>,
}

/// The sweep's summary (`static_summary.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StaticSummary {
    /// Case name.
    pub name: String,
    /// Case description.
    pub description: String,
    /// What the sweep varies.
    pub abscissa: Abscissa,
    /// Each formulation's sweep.
    pub runs: Vec<StaticOutput>,
    /// The control surfaces' names (`aero.control_surfaces`): the CSV's hinge-moment columns.
    #[serde(skip)]
    pub control_surfaces: Vec<String>,
    /// References and the errors against them.
    pub references: Vec<ReferenceErrors>,
    /// Largest |fold_ANCF − fold_GEBF| over the airspeeds both solved, degrees; None (`null`)
    /// when no airspeed was solved by both (see `failures`).
    pub max_fold_difference_deg: Option<f64>,
    /// Largest |RBM_ANCF − RBM_GEBF| / |RBM_GEBF| over the airspeeds both solved; None as above.
    pub max_rbm_relative_difference: Option<f64>,
    /// Points without an equilibrium, all formulations.
    pub n_failed: usize,
    /// Each formulation with points without an equilibrium: where and why.
    pub failures: Vec<Failure>,
    /// The case's own time history (when it was run alongside): its mean over the second half
    /// of the run against the static solution at the same airspeed.
    pub history: Vec<HistoryComparison>,
    /// The model held at the experiment's coast angles ([`crate::static_hold`]; filled by
    /// [`hold_references`]).
    pub held: Vec<crate::static_hold::HeldPoint>,
}

/// The points of one formulation's sweep without an equilibrium: which formulation, at which
/// airspeeds (or load factors), and why. The summaries print this where a number would be NaN.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Failure {
    /// Formulation.
    pub formulation: Formulation,
    /// The airspeeds (m/s), or the load factors of a structural case, without an equilibrium.
    pub at: Vec<f64>,
    /// Points of the sweep.
    pub of: usize,
    /// `"airspeeds"` or `"load factors"`.
    pub unit: String,
    /// The distinct reasons (at most [`MAX_REASONS`]), each with the first point it was given at.
    pub reasons: Vec<(f64, String)>,
}

/// Most distinct reasons a [`Failure`] keeps.
pub const MAX_REASONS: usize = 3;

impl Failure {
    /// `ANCF failed at 12 of 12 airspeeds (10, 12, …, 33): <reason> (at 10); …`.
    pub fn text(&self) -> String {
        let at: Vec<String> = self.at.iter().map(|x| format!("{x}")).collect();
        let why: Vec<String> =
            self.reasons.iter().map(|(x, r)| if x.is_finite() { format!("{r} (at {x})") } else { r.clone() }).collect();
        format!(
            "{} failed at {} of {} {} ({}): {}",
            self.formulation.as_str().to_uppercase(),
            self.at.len(),
            self.of,
            self.unit,
            at.join(", "),
            why.join("; ")
        )
    }
}

/// The failures of each sweep of `runs` (formulations without a failed point are left out).
pub fn failures(runs: &[StaticOutput], abscissa: Abscissa) -> Vec<Failure> {
    let mut v = Vec::new();
    for r in runs {
        let structural = r.points.iter().any(|p| p.load_factor.is_some());
        let mut f = Failure {
            formulation: r.formulation,
            at: Vec::new(),
            of: r.points.len(),
            unit: if structural { "load factors" } else { abscissa.plural() }.into(),
            reasons: Vec::new(),
        };
        for p in &r.points {
            let Some(e) = &p.error else { continue };
            let x = p.load_factor.unwrap_or_else(|| abscissa.x(p));
            f.at.push(x);
            if f.reasons.len() < MAX_REASONS && !f.reasons.iter().any(|(_, r)| r == e) {
                f.reasons.push((x, e.clone()));
            }
        }
        if let (Some(e), true) = (&r.error, f.at.is_empty()) {
            f.reasons.push((f64::NAN, e.clone()));
        }
        if !f.reasons.is_empty() {
            v.push(f);
        }
    }
    v
}

/// The failure text of formulation `f` in `failures`, or `fallback`.
pub fn failure_of(failures: &[Failure], f: Formulation, fallback: &str) -> String {
    failures.iter().find(|x| x.formulation == f).map_or_else(|| fallback.to_string(), Failure::text)
}

/// A time history's mean over a window against the static equilibrium at its airspeed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HistoryComparison {
    /// Formulation.
    pub formulation: Formulation,
    /// Airspeed of the time history, m/s.
    pub airspeed: f64,
    /// Averaging window, s.
    pub window: (f64, f64),
    /// Mean tip height over the window, m, and its range (min, max).
    pub tip_z_mean: f64,
    /// Tip height range over the window, m.
    pub tip_z_range: (f64, f64),
    /// Mean fold angle over the window, degrees.
    pub fold_mean_deg: f64,
    /// Fold range over the window, degrees.
    pub fold_range_deg: (f64, f64),
    /// Static tip height, m.
    pub static_tip_z: f64,
    /// Static fold angle, degrees.
    pub static_fold_deg: f64,
    /// (static − mean) / |mean| of the tip height.
    pub tip_z_relative_difference: f64,
    /// static − mean of the fold, degrees.
    pub fold_difference_deg: f64,
    /// The run's own wake (`aero.n_wake_rows` rows of airspeed × the formulation's `dt`, closed
    /// when `aero.wake_closure`), the steady wake of the like-for-like static solution below.
    pub run_wake: WakeSettings,
    /// Static tip height with the run's wake, m (NaN when that solve failed).
    pub run_wake_static_tip_z: f64,
    /// Static fold angle with the run's wake, degrees.
    pub run_wake_static_fold_deg: f64,
    /// (static with the run's wake − mean) / |mean| of the tip height.
    pub run_wake_tip_z_relative_difference: f64,
    /// static with the run's wake − mean of the fold, degrees.
    pub run_wake_fold_difference_deg: f64,
    /// Why the static solution with the run's wake failed, if it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run_wake_error: Option<String>,
}

/// Compare the static points of `summary` with the time histories `runs` of the same case (at
/// the case's airspeed), averaged over the second half of each run; and the static solution at
/// that airspeed with the run's own wake ([`static_with_run_wake`]) with the same means.
pub fn compare_with_history(summary: &mut StaticSummary, spec: &RunSpec, runs: &[crate::run::RunOutput]) {
    for run in runs.iter().filter(|r| r.error.is_none() && !r.rows.is_empty()) {
        let case = spec.case(run.formulation);
        let Some(aero) = &case.aero else { continue };
        let airspeed = aero.speed();
        let Some(st) = summary.runs.iter().find(|o| o.formulation == run.formulation) else { continue };
        let at = |p: &&crate::statics::StaticPoint| {
            (p.airspeed - airspeed).abs() < 1e-9 && (p.sideslip_deg - aero.sideslip_deg).abs() < 1e-9
        };
        let Some(p) = st.points.iter().filter(at).find(|p| p.error.is_none()) else {
            continue;
        };
        let (tip_z, fold) = (p.tip[2], p.fold_deg);
        let t_end = run.rows.last().map_or(0.0, |r| r.t);
        let window = (0.5 * t_end, t_end);
        let w: Vec<&crate::run::Row> = run.rows.iter().filter(|r| r.t >= window.0 - 1e-9).collect();
        let n = w.len() as f64;
        let tz: Vec<f64> = w.iter().map(|r| r.tip[2]).collect();
        let fo: Vec<f64> = w.iter().map(|r| r.fold.to_degrees()).collect();
        let range = |v: &[f64]| v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)));
        let (tz_mean, fo_mean) = (tz.iter().sum::<f64>() / n, fo.iter().sum::<f64>() / n);
        let run_wake = crate::stability::march_wake(&case.problem(), run.formulation, airspeed);
        // A closed wake is the steady one: the point above, bit for bit.
        let like = if run_wake.closure { Ok((tip_z, fold)) } else { static_with_run_wake(case, run.formulation) };
        let (rw_tip, rw_fold, rw_err) = match like {
            Ok((t, f)) => (t, f, None),
            Err(e) => (f64::NAN, f64::NAN, Some(e)),
        };
        summary.history.push(HistoryComparison {
            formulation: run.formulation,
            airspeed,
            window,
            tip_z_mean: tz_mean,
            tip_z_range: range(&tz),
            fold_mean_deg: fo_mean,
            fold_range_deg: range(&fo),
            static_tip_z: tip_z,
            static_fold_deg: fold,
            tip_z_relative_difference: (tip_z - tz_mean) / tz_mean.abs(),
            fold_difference_deg: fold - fo_mean,
            run_wake,
            run_wake_static_tip_z: rw_tip,
            run_wake_static_fold_deg: rw_fold,
            run_wake_tip_z_relative_difference: (rw_tip - tz_mean) / tz_mean.abs(),
            run_wake_fold_difference_deg: rw_fold - fo_mean,
            run_wake_error: rw_err,
        });
    }
}

/// A wake in words: `40 rows of 0.25 m, unclosed`.
pub fn wake_label(w: &WakeSettings) -> String {
    format!("{} rows of {} m, {}", w.rows, w.row_length, if w.closure { "closed" } else { "unclosed" })
}

/// The static equilibrium of `case` at its airspeed with the wake of its own time march
/// ([`crate::stability::march_wake`]) as the steady wake: tip height (m) and fold angle (degrees).
///
/// # Errors
/// A case without `aero`, or no equilibrium.
pub fn static_with_run_wake(case: &Case, f: Formulation) -> Result<(f64, f64), String> {
    let aero = case.aero.as_ref().ok_or("the case has no `aero` block")?;
    let problem = case.problem();
    let p = crate::statics::equilibrium_at(&problem, f, crate::stability::march_wake(&problem, f, aero.speed()))?;
    Ok((p.tip[2], p.fold_deg))
}

/// Linear interpolation of the converged points `(airspeed, value)` (sorted) at `u`; None
/// outside their range.
fn interp(pts: &[(f64, f64)], u: f64) -> Option<f64> {
    let i = pts.iter().position(|p| p.0 >= u)?;
    if (pts[i].0 - u).abs() < 1e-12 {
        return Some(pts[i].1);
    }
    if i == 0 {
        return None;
    }
    let (a, b) = (pts[i - 1], pts[i]);
    Some(a.1 + (b.1 - a.1) * (u - a.0) / (b.0 - a.0))
}

fn curve(out: &StaticOutput, x: Abscissa, f: impl Fn(&crate::statics::StaticPoint) -> f64) -> Vec<(f64, f64)> {
    let mut v: Vec<(f64, f64)> =
        out.points.iter().filter(|p| p.error.is_none()).map(|p| (x.x(p), f(p))).filter(|p| p.1.is_finite()).collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v
}

/// Evaluate the sweeps against each other and the case's references.
pub fn summarise(case: &Case, dir_of_case: &Path, runs: Vec<StaticOutput>) -> StaticSummary {
    let abscissa = Abscissa::of(case);
    let mut references = Vec::new();
    for r in case.statics.iter().flat_map(|s| &s.references) {
        let points = read_xy(&dir_of_case.join(&r.file)).unwrap_or_default();
        let mut errors = Vec::new();
        let mut rms_deg = Vec::new();
        for out in &runs {
            let ours = curve(out, abscissa, |p| p.fold_deg);
            let e: Vec<(f64, f64, f64, f64)> =
                points.iter().filter_map(|&(u, a)| interp(&ours, u).map(|c| (u, a, c, c - a))).collect();
            let band: Vec<f64> = e.iter().filter(|x| abscissa.band().contains(&x.0)).map(|x| x.3).collect();
            let rms = (!band.is_empty()).then(|| (band.iter().map(|x| x * x).sum::<f64>() / band.len() as f64).sqrt());
            errors.push((out.formulation, e));
            rms_deg.push((out.formulation, rms));
        }
        references.push(ReferenceErrors {
            label: r.label.clone(),
            file: r.file.clone(),
            experiment: r.experiment,
            points,
            errors,
            rms_deg,
        });
    }
    let (mut dfold, mut drbm): (Option<f64>, Option<f64>) = (None, None);
    if let [a, g] = runs.as_slice() {
        for (pa, pg) in a.points.iter().zip(&g.points) {
            if pa.error.is_none() && pg.error.is_none() {
                let d = (pa.fold_deg - pg.fold_deg).abs();
                if d.is_finite() {
                    dfold = Some(dfold.map_or(d, |x| x.max(d)));
                }
                let (ra, rg) = (pa.loads.root_bending_moment, pg.loads.root_bending_moment);
                let r = (ra - rg).abs() / rg.abs().max(1e-12);
                if r.is_finite() {
                    drbm = Some(drbm.map_or(r, |x| x.max(r)));
                }
            }
        }
    }
    let n_failed = runs.iter().flat_map(|r| &r.points).filter(|p| p.error.is_some()).count();
    let failures = failures(&runs, abscissa);
    StaticSummary {
        name: case.name.clone(),
        description: case.description.clone(),
        abscissa,
        runs,
        control_surfaces: casefile::csv::surface_names(case.aero.as_ref()),
        references,
        max_fold_difference_deg: dfold,
        max_rbm_relative_difference: drbm,
        n_failed,
        failures,
        history: Vec::new(),
        held: Vec::new(),
    }
}

/// RMS error of a model reference against an experiment reference of the same summary (at the
/// experiment's airspeeds in 12–33 m/s, or at all its sideslip angles), degrees; None when the
/// curves do not overlap there.
pub fn model_rms(summary: &StaticSummary) -> Vec<(String, Option<f64>)> {
    let Some(exp) = summary.references.iter().find(|r| r.experiment) else { return Vec::new() };
    summary
        .references
        .iter()
        .filter(|r| !r.experiment)
        .map(|m| {
            let mut pts = m.points.clone();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let e: Vec<f64> = exp
                .points
                .iter()
                .filter(|p| summary.abscissa.band().contains(&p.0))
                .filter_map(|&(u, a)| interp(&pts, u).map(|c| c - a))
                .collect();
            let rms = (!e.is_empty()).then(|| (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt());
            (m.label.clone(), rms)
        })
        .collect()
}

/// Column header of `static_<f>.csv` of a structural static case (`static.point_loads`).
pub const LOAD_HEADER: &str = "load_factor,tip_x,tip_y,tip_z,fold_deg,newton_iterations,converged";

/// A structural static case's points as CSV text (one row per load factor, NaN where a point
/// failed).
pub fn load_csv(out: &StaticOutput) -> String {
    let mut s = String::from(LOAD_HEADER);
    s.push('\n');
    for p in &out.points {
        let _ = writeln!(
            s,
            "{},{:.9e},{:.9e},{:.9e},{:.6},{},{}",
            p.load_factor.unwrap_or(f64::NAN),
            p.tip[0],
            p.tip[1],
            p.tip[2],
            p.fold_deg,
            p.newton_iterations,
            u8::from(p.error.is_none())
        );
    }
    s
}

/// Write the sweep's files into `dir`. A structural static case (its points carry load
/// factors) writes `static_<f>.csv` ([`LOAD_HEADER`]) and `static_summary.json` only.
pub fn write(dir: &Path, summary: &StaticSummary) -> Result<(), Error> {
    if summary.runs.iter().flat_map(|r| &r.points).any(|p| p.load_factor.is_some()) {
        for out in &summary.runs {
            write_file(&dir.join(format!("static_{}.csv", out.formulation)), &load_csv(out))?;
        }
        let json = serde_json::to_string_pretty(summary).map_err(|e| Error::Io(e.to_string()))?;
        return write_file(&dir.join("static_summary.json"), &json);
    }
    for out in &summary.runs {
        write_file(&dir.join(format!("static_{}.csv", out.formulation)), &to_csv(out, &summary.control_surfaces))?;
        write_file(&dir.join(format!("static_lift_{}.csv", out.formulation)), &lift_csv(out))?;
    }
    let json = serde_json::to_string_pretty(summary).map_err(|e| Error::Io(e.to_string()))?;
    write_file(&dir.join("static_summary.json"), &json)?;
    plot_coast(&dir.join("static_coast.svg"), summary)?;
    plot_rbm(&dir.join("static_rbm.svg"), summary)?;
    plot_lift(&dir.join("static_lift.svg"), summary)?;
    // The section links the plots by the folder they are in (a run's variant folder under
    // `--set` is not the case's name).
    let folder = dir.file_name().map_or_else(|| summary.name.clone(), |n| n.to_string_lossy().into_owned());
    write_file(&dir.join(SECTION_FILE), &section_html(summary, &folder))
}

/// The report fragment each sweep leaves in its folder for `reports/index.html`.
pub const SECTION_FILE: &str = "static_section.html";

/// The static sections of every sweep written under `out` (`<out>/<case>/static_section.html`),
/// in name order, with a heading; empty when there are none.
pub fn sections_html(out: &Path) -> String {
    let cases = crate::report::fragments(out, SECTION_FILE);
    if cases.is_empty() {
        return cases;
    }
    let mut s = String::from(
        "<h2 id=\"static\">Static aeroelastic equilibria</h2>\n<p>Newton on the structure under the steady UVLM loads \
         of its own deformed lattice (semi-infinite wake along the free stream), continued in airspeed from the \
         highest; loads from the free body of the wing (docs/statics.md). Files per case: <code>static_ancf.csv</code>, \
         <code>static_gebf.csv</code>, <code>static_lift_*.csv</code>, <code>static_summary.json</code>.</p>\n",
    );
    s.push_str(&cases);
    s
}

const ANCF: RGBColor = RGBColor(31, 119, 180);
const GEBF: RGBColor = RGBColor(255, 127, 14);
const EXP: RGBColor = RGBColor(30, 30, 30);
const MODEL: RGBColor = RGBColor(44, 160, 44);

fn color(f: Formulation) -> RGBColor {
    [ANCF, GEBF][f.index()]
}

fn range(vals: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) =
        vals.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        return (0.0, 1.0);
    }
    let d = if hi - lo < 1e-12 { 1.0_f64.max(lo.abs() * 0.1) } else { 0.06 * (hi - lo) };
    (lo - d, hi + d)
}

/// How a curve is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Style {
    /// Solid line with open circles.
    Solid,
    /// Dashed line with filled triangles (drawn over a solid one it stays visible).
    Dashed,
    /// Crosses only (measurements).
    Points,
}

pub(crate) type Curves = Vec<(String, RGBColor, Vec<(f64, f64)>, Style)>;

/// Decimals that tell neighbouring ticks apart on an axis spanning `lo..hi`.
fn decimals(lo: f64, hi: f64) -> usize {
    let step = (hi - lo).abs() / 6.0;
    if !(step.is_finite() && step > 0.0) {
        return 2;
    }
    (-step.log10().floor()).clamp(0.0, 6.0) as usize
}

/// A panel of curves with the legend beside the data.
pub(crate) fn panel(path: &Path, title: &str, xl: &str, yl: &str, curves: &Curves) -> Result<(), Error> {
    let err = |e: String| Error::Plot { file: path.display().to_string(), msg: e };
    let file = crate::atomic::TempFile::new(path)?;
    let tmp = file.path().to_path_buf();
    let root = SVGBackend::new(&tmp, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let (x0, x1) = range(curves.iter().flat_map(|c| c.2.iter().map(|p| p.0)));
    let (y0, y1) = range(curves.iter().flat_map(|c| c.2.iter().map(|p| p.1)));
    let (dx, dy) = (decimals(x0, x1), decimals(y0, y1));
    // Legend to the right of the data.
    let (plot_area, legend_area) = root.split_horizontally(640);
    let mut chart = ChartBuilder::on(&plot_area)
        .caption(title, ("sans-serif", 17))
        .margin(10)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| err(e.to_string()))?;
    chart
        .configure_mesh()
        .x_desc(xl)
        .y_desc(yl)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .x_label_formatter(&|v| format!("{v:.dx$}"))
        .y_label_formatter(&|v| format!("{v:.dy$}"))
        .draw()
        .map_err(|e| err(e.to_string()))?;
    for (_, c, pts, style) in curves {
        match style {
            Style::Points => {
                chart
                    .draw_series(pts.iter().map(|&p| Cross::new(p, 6, c.stroke_width(2))))
                    .map_err(|e| err(e.to_string()))?;
            }
            Style::Solid => {
                chart
                    .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(3)))
                    .map_err(|e| err(e.to_string()))?;
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 5, c.stroke_width(2))))
                    .map_err(|e| err(e.to_string()))?;
            }
            Style::Dashed => {
                chart
                    .draw_series(DashedLineSeries::new(pts.iter().copied(), 8, 5, c.stroke_width(2)))
                    .map_err(|e| err(e.to_string()))?;
                chart
                    .draw_series(pts.iter().map(|&p| TriangleMarker::new(p, 4, c.filled())))
                    .map_err(|e| err(e.to_string()))?;
            }
        }
    }
    for (k, (label, c, _, style)) in curves.iter().enumerate() {
        let y = 40 + 26 * k as i32;
        let text = TextStyle::from(("sans-serif", 14).into_font()).color(&BLACK);
        let e = |e: plotters::drawing::DrawingAreaErrorKind<std::io::Error>| err(e.to_string());
        match style {
            Style::Points => legend_area.draw(&Cross::new((16, y), 6, c.stroke_width(2))).map_err(e)?,
            Style::Solid => {
                legend_area.draw(&PathElement::new(vec![(2, y), (30, y)], c.stroke_width(3))).map_err(e)?;
                legend_area.draw(&Circle::new((16, y), 5, c.stroke_width(2))).map_err(e)?;
            }
            Style::Dashed => {
                for x in [2, 14, 26] {
                    legend_area.draw(&PathElement::new(vec![(x, y), (x + 7, y)], c.stroke_width(2))).map_err(e)?;
                }
                legend_area.draw(&TriangleMarker::new((16, y), 4, c.filled())).map_err(e)?;
            }
        }
        legend_area.draw(&Text::new(label.clone(), (38, y - 7), text)).map_err(e)?;
    }
    root.present().map_err(|e| err(e.to_string()))?;
    file.commit()
}

/// How formulation `f`'s curves are drawn: the first of [`Formulation::ALL`] solid, the second
/// dashed over it.
pub(crate) fn style(f: Formulation) -> Style {
    [Style::Solid, Style::Dashed][f.index()]
}

fn plot_coast(path: &Path, s: &StaticSummary) -> Result<(), Error> {
    let mut curves: Curves = s
        .runs
        .iter()
        .map(|o| {
            (
                format!("{} (UVLM, steady)", o.formulation.as_str().to_uppercase()),
                color(o.formulation),
                curve(o, s.abscissa, |p| p.fold_deg),
                style(o.formulation),
            )
        })
        .collect();
    for r in &s.references {
        let st = if r.experiment { Style::Points } else { Style::Solid };
        curves.push((r.label.clone(), if r.experiment { EXP } else { MODEL }, r.points.clone(), st));
    }
    panel(path, &format!("{}: coast angle", s.name), s.abscissa.label(), "fold angle [deg] (tip up +)", &curves)
}

fn plot_rbm(path: &Path, s: &StaticSummary) -> Result<(), Error> {
    let curves: Curves = s
        .runs
        .iter()
        .map(|o| {
            (
                o.formulation.as_str().to_uppercase(),
                color(o.formulation),
                curve(o, s.abscissa, |p| p.loads.root_bending_moment),
                style(o.formulation),
            )
        })
        .collect();
    panel(path, &format!("{}: root bending moment", s.name), s.abscissa.label(), "root bending moment [N m]", &curves)
}

fn plot_lift(path: &Path, s: &StaticSummary) -> Result<(), Error> {
    // One colour per airspeed, the formulation's line style.
    const SPEEDS: [RGBColor; 3] = [RGBColor(31, 119, 180), RGBColor(44, 160, 44), RGBColor(214, 39, 40)];
    let mut curves: Curves = Vec::new();
    for o in &s.runs {
        let ok: Vec<_> = o.points.iter().filter(|p| p.error.is_none() && !p.strips.is_empty()).collect();
        let mut speeds: Vec<f64> = ok.iter().map(|p| s.abscissa.x(p)).collect();
        speeds.sort_by(f64::total_cmp);
        let picks: Vec<f64> = match speeds.len() {
            0 => Vec::new(),
            1 | 2 => speeds.clone(),
            n => vec![speeds[0], speeds[n / 2], speeds[n - 1]],
        };
        for (k, u) in picks.iter().enumerate() {
            if let Some(p) = ok.iter().find(|p| s.abscissa.x(p) == *u) {
                curves.push((
                    format!("{} {}", o.formulation.as_str().to_uppercase(), s.abscissa.describe(*u)),
                    SPEEDS[k % 3],
                    p.strips.iter().map(|st| (st.s, st.lift_per_span)).collect(),
                    style(o.formulation),
                ));
            }
        }
    }
    panel(
        path,
        &format!("{}: spanwise lift", s.name),
        "arclength along the wing [m]",
        "lift per unit span [N/m]",
        &curves,
    )
}

/// A table of each experiment's points that the sweep did not compute (a sideslip sweep's
/// angles rarely coincide with the experiment's): the experiment, and each formulation's model
/// interpolated there with its error.
fn errors_at_reference_points(h: &mut String, s: &StaticSummary) {
    let computed: Vec<f64> = s.runs.iter().flat_map(|r| r.points.iter().map(|p| s.abscissa.x(p))).collect();
    for r in s.references.iter().filter(|r| r.experiment) {
        let off_grid = r.errors.iter().flat_map(|(_, e)| e).any(|e| !computed.iter().any(|x| (x - e.0).abs() < 1e-9));
        if !off_grid {
            continue;
        }
        let label = html_escape(&r.label);
        let _ = writeln!(h, "<p>At the points of {label} (the model interpolated linearly between its own):</p>");
        let _ = write!(h, "<table><tr><th>{}</th><th>{label} [°]</th>", s.abscissa.label());
        for (f, _) in &r.errors {
            let f = f.as_str().to_uppercase();
            let _ = write!(h, "<th>{f} [°]</th><th>{f} − {label} [°]</th>");
        }
        h.push_str("</tr>\n");
        let Some((_, first)) = r.errors.first() else { continue };
        for e in first {
            let _ = write!(h, "<tr><td>{}</td><td>{:.2}</td>", e.0, e.1);
            for (_, errors) in &r.errors {
                match errors.iter().find(|x| (x.0 - e.0).abs() < 1e-9) {
                    Some(x) => {
                        let _ = write!(h, "<td>{:.2}</td><td>{:+.2}</td>", x.2, x.3);
                    }
                    None => h.push_str("<td></td><td></td>"),
                }
            }
            h.push_str("</tr>\n");
        }
        h.push_str("</table>\n");
    }
}

/// The report's section for a static sweep (HTML fragment; links relative to the report root).
pub fn section_html(s: &StaticSummary, folder: &str) -> String {
    let mut h = String::new();
    let _ = write!(h, "<h3 id=\"static-{0}\">{0}</h3>\n<p>{1}</p>\n", s.name, html_escape(&s.description));
    match (s.max_fold_difference_deg, s.max_rbm_relative_difference) {
        (Some(d), Some(r)) => {
            let _ = writeln!(
                h,
                "<p>ANCF–GEBF: coast angles within {d:.3}°, root bending moments within {:.3} % over the points \
                 both solved; {} point(s) without an equilibrium.</p>",
                100.0 * r,
                s.n_failed
            );
        }
        _ if s.runs.len() == 2 => {
            let _ = writeln!(
                h,
                "<p>ANCF–GEBF: no comparison, no point has an equilibrium in both; {} point(s) without an \
                 equilibrium.</p>",
                s.n_failed
            );
        }
        _ => {}
    }
    for f in &s.failures {
        let _ = writeln!(h, "<p class=\"fail\">FAILED: {}</p>", html_escape(&f.text()));
    }
    let _ = write!(h, "<table><tr><th>{}</th>", s.abscissa.label());
    for r in &s.runs {
        let f = r.formulation.as_str().to_uppercase();
        let _ = write!(
            h,
            "<th>{f} fold [°]</th><th>{f} RBM [N·m]</th><th>{f} hinge moment [N·m]</th><th>{f} lift [N]</th>"
        );
    }
    for r in &s.references {
        let _ = write!(h, "<th>{}</th>", html_escape(&r.label));
    }
    for r in s.references.iter().filter(|r| r.experiment) {
        for (f, _) in &r.errors {
            let _ = write!(h, "<th>{} − {} [°]</th>", f.as_str().to_uppercase(), html_escape(&r.label));
        }
    }
    h.push_str("</tr>\n");
    if let Some(first) = s.runs.first() {
        for (i, p) in first.points.iter().enumerate() {
            let x = s.abscissa.x(p);
            let _ = write!(h, "<tr><td>{x}</td>");
            for r in &s.runs {
                let q = &r.points[i];
                if q.error.is_some() {
                    h.push_str("<td colspan=4>no equilibrium</td>");
                } else {
                    let _ = write!(
                        h,
                        "<td>{:.2}</td><td>{:.4}</td><td>{:.2e}</td><td>{:.3}</td>",
                        q.fold_deg, q.loads.root_bending_moment, q.loads.hinge_moment, q.lift
                    );
                }
            }
            for r in &s.references {
                match r.points.iter().find(|r| (r.0 - x).abs() < 1e-9) {
                    Some(x) => {
                        let _ = write!(h, "<td>{:.2}</td>", x.1);
                    }
                    None => h.push_str("<td></td>"),
                }
            }
            for r in s.references.iter().filter(|r| r.experiment) {
                for (_, errors) in &r.errors {
                    match errors.iter().find(|e| (e.0 - x).abs() < 1e-9) {
                        Some(e) => {
                            let _ = write!(h, "<td>{:+.2}</td>", e.3);
                        }
                        None => h.push_str("<td></td>"),
                    }
                }
            }
            h.push_str("</tr>\n");
        }
    }
    h.push_str("</table>\n");
    errors_at_reference_points(&mut h, s);
    h.push_str("<ul>\n");
    let band = s.abscissa.band_text();
    for r in s.references.iter().filter(|r| r.experiment) {
        for (f, rms) in &r.rms_deg {
            let label = html_escape(&r.label);
            let _ = match rms {
                Some(rms) => {
                    writeln!(h, "<li>{f} against {label}: RMS coast-angle error {rms:.2}° over {band}</li>")
                }
                None => writeln!(
                    h,
                    "<li>{f} against {label}: no RMS error, no equilibrium at its points in {band} ({})</li>",
                    html_escape(&failure_of(&s.failures, *f, "no converged point in the band"))
                ),
            };
        }
    }
    for (label, rms) in model_rms(s) {
        let label = html_escape(&label);
        let _ = match rms {
            Some(rms) => writeln!(h, "<li>{label} against the experiment: RMS {rms:.2}° over {band}</li>"),
            None => writeln!(h, "<li>{label} against the experiment: no common point in {band}</li>"),
        };
    }
    for c in &s.history {
        let _ = writeln!(
            h,
            "<li>{} time history at {} m/s, mean over {:.0}–{:.0} s: tip height {:.4} m (range {:.4} to {:.4}), fold {:.3}° \
             (range {:.2} to {:.2}); static (semi-infinite wake): tip height {:.4} m ({:+.2} %), fold {:.3}° \
             ({:+.3}°); static with the run's wake ({}): {}</li>",
            c.formulation.as_str().to_uppercase(),
            c.airspeed,
            c.window.0,
            c.window.1,
            c.tip_z_mean,
            c.tip_z_range.0,
            c.tip_z_range.1,
            c.fold_mean_deg,
            c.fold_range_deg.0,
            c.fold_range_deg.1,
            c.static_tip_z,
            100.0 * c.tip_z_relative_difference,
            c.static_fold_deg,
            c.fold_difference_deg,
            html_escape(&wake_label(&c.run_wake)),
            match &c.run_wake_error {
                Some(e) => format!("failed: {}", html_escape(e)),
                None => format!(
                    "tip height {:.4} m ({:+.2} %), fold {:.3}° ({:+.3}°)",
                    c.run_wake_static_tip_z,
                    100.0 * c.run_wake_tip_z_relative_difference,
                    c.run_wake_static_fold_deg,
                    c.run_wake_fold_difference_deg
                ),
            }
        );
    }
    h.push_str("</ul>\n");
    h.push_str(&held_html(&s.held));
    for (file, alt) in [
        ("static_coast.svg", "coast angle"),
        ("static_rbm.svg", "root bending moment"),
        ("static_lift.svg", "spanwise lift at three points of the sweep"),
    ] {
        let _ = writeln!(h, "<p><img src=\"{}/{file}\" alt=\"{alt}\" width=\"900\"></p>", html_escape(folder));
    }
    h
}

/// The table of the model held at the experiment's coast angles (empty without such points).
fn held_html(held: &[crate::static_hold::HeldPoint]) -> String {
    if held.is_empty() {
        return String::new();
    }
    let mut h = String::from(
        "<p>The model held at the experiment's coast angles (docs/statics.md §7): the moment about the hinge axis \
         that the model's tip has there and the experiment's tip did not (fold-up positive), over the dynamic \
         pressure (constant where the difference is aerodynamic), and the root pitch change that cancels it.</p>\n\
         <table><tr><th>formulation</th><th>airspeed [m/s]</th><th>measured coast [°]</th><th>hinge moment [N·m]</th>\
         <th>per dynamic pressure [m³]</th><th>equivalent pitch [°]</th></tr>\n",
    );
    for p in held {
        let f = p.formulation.as_str().to_uppercase();
        match &p.error {
            Some(e) => {
                let _ = writeln!(
                    h,
                    "<tr><td>{f}</td><td>{}</td><td>{:.2}</td><td colspan=3>failed: {}</td></tr>",
                    p.airspeed,
                    p.coast_deg,
                    html_escape(e)
                );
            }
            None => {
                let _ = writeln!(
                    h,
                    "<tr><td>{f}</td><td>{}</td><td>{:.2}</td><td>{:+.5}</td><td>{:+.3e}</td><td>{:+.2}</td></tr>",
                    p.airspeed, p.coast_deg, p.hinge_moment, p.per_dynamic_pressure, p.equivalent_pitch_deg
                );
            }
        }
    }
    h.push_str("</table>\n");
    h
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}
/// Hold each formulation's model of `spec` at every point of the experiment references of
/// `summary` inside that formulation's converged airspeed range (the points its errors are
/// taken at), in parallel; stored in `summary.held`. Nothing for a case without a free fold
/// hinge or without an experiment.
pub fn hold_references(spec: &RunSpec, summary: &mut StaticSummary) {
    // The held model is defined at the experiment's airspeeds (at the case's sideslip).
    if summary.abscissa != Abscissa::Airspeed {
        return;
    }
    let mut jobs = Vec::new();
    for r in summary.references.iter().filter(|r| r.experiment) {
        for (f, errors) in &r.errors {
            if !aeroelastic::static_hold::can_hold(&spec.case(*f).problem()) {
                continue;
            }
            jobs.extend(errors.iter().map(|&(u, coast, _, _)| (*f, u, coast)));
        }
    }
    summary.held = jobs
        .par_iter()
        .map(|&(f, u, coast)| aeroelastic::static_hold::hold(&spec.case(f).problem(), f, u, coast))
        .collect();
}
