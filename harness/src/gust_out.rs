//! Outputs of a gust sweep (docs/gust.md §6): `gust_<f>.csv` (one row per hinge state and
//! gradient), `gust_history_<f>.csv` (the incremental loads in time), `gust_summary.json` (peaks
//! and their times, alleviation against the locked hinge, ANCF–GEBF differences, CPU times),
//! SVG plots and the report's section.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::RGBColor;
use serde::Serialize;

use crate::Error;
use crate::case::Formulation;
use crate::csv::write_file;
use crate::gust::{GustRun, GustSpec, GustSweepOutput, HingeState};
use crate::static_out::{Curves, panel, style};

/// Column header of `gust_<f>.csv`.
pub const HEADER: &str = "hinge,spring_stiffness,gradient_m,frequency_hz,gust_velocity,\
peak_delta_root_bending_moment,t_peak_root_bending_moment,peak_delta_fold_deg,t_peak_fold,\
peak_delta_root_torque,peak_delta_hinge_moment,peak_delta_lift,static_root_bending_moment,static_fold_deg,\
alleviation_percent,cpu_s,error,max_delta_root_bending_moment,t_max_root_bending_moment";

/// Column header of `gust_history_<f>.csv`.
pub const HISTORY_HEADER: &str = "hinge,spring_stiffness,gradient_m,t,delta_root_bending_moment,delta_root_torque,\
delta_hinge_moment,delta_fold_deg,delta_lift";

/// The report fragment each sweep leaves in its folder.
pub const SECTION_FILE: &str = "gust_section.html";

/// Alleviation of one unlocked hinge state against the locked hinge at one gradient.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Alleviation {
    /// Formulation.
    pub formulation: Formulation,
    /// The unlocked hinge state.
    pub hinge: HingeState,
    /// Gradient, m.
    pub gradient_m: f64,
    /// `100 (1 − |ΔM_peak| / |ΔM_peak, locked|)`, % (positive: the hinge relieves the root).
    pub root_bending_moment_percent: f64,
}

/// ANCF against GEBF on one run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairDifference {
    /// Hinge state.
    pub hinge: HingeState,
    /// Gradient, m.
    pub gradient_m: f64,
    /// `|ΔM_A − ΔM_G| / max(|ΔM_A|, |ΔM_G|)` of the peak incremental root bending moments, %.
    pub peak_rbm_percent: f64,
    /// `|Δθ_A − Δθ_G|` of the peak incremental fold angles, degrees.
    pub peak_fold_deg: f64,
}

/// `gust_summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GustSummary {
    /// Run name.
    pub name: String,
    /// Airspeed, m/s.
    pub airspeed: f64,
    /// The case's gust (its gradient replaced in each run).
    pub gust: GustSpec,
    /// Every run.
    pub runs: Vec<GustRun>,
    /// Alleviation of every unlocked state against the locked hinge.
    pub alleviation: Vec<Alleviation>,
    /// ANCF–GEBF differences (both formulations run).
    pub ancf_gebf: Vec<PairDifference>,
    /// Largest ANCF–GEBF peak root bending moment difference over the runs both formulations
    /// finished, %; None (`null`) when there is no such pair (see the runs' `error`).
    pub max_peak_rbm_difference_percent: Option<f64>,
    /// Largest ANCF–GEBF peak fold difference, degrees; None as above.
    pub max_peak_fold_difference_deg: Option<f64>,
    /// Largest CPU time of one time march, s, per formulation.
    pub max_cpu_s: Vec<(Formulation, f64)>,
    /// Runs that failed or stopped early.
    pub n_failed: usize,
    /// Wall time of the sweep, s.
    pub wall_s: f64,
}

fn same_hinge(a: &HingeState, b: &HingeState) -> bool {
    a == b
}

/// Summarise a sweep. The alleviations and the ANCF–GEBF differences are taken over the runs
/// that finished; a failed run is named by its `error`, never compared as NaN.
pub fn summarise(out: GustSweepOutput) -> GustSummary {
    let runs = out.runs;
    let ok = |r: &&GustRun| r.error.is_none();
    let mut alleviation = Vec::new();
    for r in runs.iter().filter(ok).filter(|r| !matches!(r.hinge, HingeState::Locked)) {
        if let Some(l) = runs.iter().filter(ok).find(|l| {
            l.formulation == r.formulation && matches!(l.hinge, HingeState::Locked) && l.gradient_m == r.gradient_m
        }) {
            alleviation.push(Alleviation {
                formulation: r.formulation,
                hinge: r.hinge,
                gradient_m: r.gradient_m,
                root_bending_moment_percent: 100.0
                    * (1.0 - r.peak_delta_root_bending_moment.0.abs() / l.peak_delta_root_bending_moment.0.abs()),
            });
        }
    }
    let mut ancf_gebf = Vec::new();
    let [first, second] = Formulation::ALL;
    for a in runs.iter().filter(ok).filter(|r| r.formulation == first) {
        if let Some(g) = runs
            .iter()
            .filter(ok)
            .find(|g| g.formulation == second && same_hinge(&g.hinge, &a.hinge) && g.gradient_m == a.gradient_m)
        {
            let (ma, mg) = (a.peak_delta_root_bending_moment.0, g.peak_delta_root_bending_moment.0);
            ancf_gebf.push(PairDifference {
                hinge: a.hinge,
                gradient_m: a.gradient_m,
                peak_rbm_percent: 100.0 * (ma - mg).abs() / ma.abs().max(mg.abs()),
                peak_fold_deg: (a.peak_delta_fold_deg.0 - g.peak_delta_fold_deg.0).abs(),
            });
        }
    }
    let nan_max = |v: &mut dyn Iterator<Item = f64>| v.fold(f64::NAN, |m, x| if x > m || m.is_nan() { x } else { m });
    let some_max = |v: &mut dyn Iterator<Item = f64>| Some(nan_max(v)).filter(|x| x.is_finite());
    let max_peak_rbm_difference_percent = some_max(&mut ancf_gebf.iter().map(|d| d.peak_rbm_percent));
    let max_peak_fold_difference_deg = some_max(&mut ancf_gebf.iter().map(|d| d.peak_fold_deg));
    // Over the runs that have a CPU time (a run that failed before its march has none); a
    // formulation without one is left out and the report says so.
    let max_cpu_s = Formulation::ALL
        .iter()
        .filter_map(|&f| {
            let timed = runs.iter().filter(|r| r.formulation == f && r.cpu_s.is_finite());
            some_max(&mut timed.map(|r| r.cpu_s)).map(|c| (f, c))
        })
        .collect();
    let n_failed = runs.iter().filter(|r| r.error.is_some()).count();
    GustSummary {
        name: out.name,
        airspeed: out.airspeed,
        gust: out.gust,
        runs,
        alleviation,
        ancf_gebf,
        max_peak_rbm_difference_percent,
        max_peak_fold_difference_deg,
        max_cpu_s,
        n_failed,
        wall_s: out.wall_s,
    }
}

fn alleviation_of(s: &GustSummary, r: &GustRun) -> f64 {
    s.alleviation
        .iter()
        .find(|a| a.formulation == r.formulation && a.hinge == r.hinge && a.gradient_m == r.gradient_m)
        .map_or(f64::NAN, |a| a.root_bending_moment_percent)
}

/// `gust_<f>.csv` of formulation `f`.
pub fn to_csv(s: &GustSummary, f: Formulation) -> String {
    let mut t = String::from(HEADER);
    t.push('\n');
    for r in s.runs.iter().filter(|r| r.formulation == f) {
        let eq = r.equilibrium.as_ref();
        let _ = writeln!(
            t,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.hinge.label(),
            r.hinge.stiffness(),
            r.gradient_m,
            r.frequency_hz,
            r.gust_velocity,
            r.peak_delta_root_bending_moment.0,
            r.peak_delta_root_bending_moment.1,
            r.peak_delta_fold_deg.0,
            r.peak_delta_fold_deg.1,
            r.peak_delta_root_torque.0,
            r.peak_delta_hinge_moment.0,
            r.peak_delta_lift.0,
            eq.map_or(f64::NAN, |e| e.root_bending_moment),
            eq.map_or(f64::NAN, |e| e.fold_deg),
            alleviation_of(s, r),
            r.cpu_s,
            r.error.as_deref().unwrap_or("").replace([',', '\n'], ";"),
            r.max_delta_root_bending_moment.0,
            r.max_delta_root_bending_moment.1
        );
    }
    t
}

/// `gust_history_<f>.csv` of formulation `f`.
pub fn history_csv(s: &GustSummary, f: Formulation) -> String {
    let mut t = String::from(HISTORY_HEADER);
    t.push('\n');
    for r in s.runs.iter().filter(|r| r.formulation == f) {
        let Some(h) = r.history.as_ref().map(|h| &h.increments) else { continue };
        for i in 0..h.t.len() {
            let _ = writeln!(
                t,
                "{},{},{},{},{},{},{},{},{}",
                r.hinge.label(),
                r.hinge.stiffness(),
                r.gradient_m,
                h.t[i],
                h.delta_root_bending_moment[i],
                h.delta_root_torque[i],
                h.delta_hinge_moment[i],
                h.delta_fold_deg[i],
                h.delta_lift[i]
            );
        }
    }
    t
}

fn hinge_name(h: &HingeState) -> String {
    match h {
        HingeState::Spring { stiffness, .. } => format!("spring {stiffness} N·m/rad"),
        HingeState::Release { root_bending_moment_increment_above: m } => format!("released at ΔM {m} N·m"),
        _ => h.label().to_string(),
    }
}

fn hinge_color(hinges: &[HingeState], h: &HingeState) -> RGBColor {
    const PALETTE: [RGBColor; 6] = [
        RGBColor(31, 119, 180),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(188, 189, 34),
    ];
    if matches!(h, HingeState::Locked) {
        return RGBColor(30, 30, 30);
    }
    let k = hinges.iter().filter(|x| !matches!(x, HingeState::Locked)).position(|x| x == h).unwrap_or(0);
    PALETTE[k % PALETTE.len()]
}

fn hinges_of(s: &GustSummary) -> Vec<HingeState> {
    let mut v: Vec<HingeState> = Vec::new();
    for r in &s.runs {
        if !v.contains(&r.hinge) {
            v.push(r.hinge);
        }
    }
    v
}

fn envelope(s: &GustSummary, value: impl Fn(&GustRun) -> f64) -> Curves {
    let hinges = hinges_of(s);
    let mut curves = Curves::new();
    for f in Formulation::ALL {
        for h in &hinges {
            let mut pts: Vec<(f64, f64)> = s
                .runs
                .iter()
                .filter(|r| r.formulation == f && r.hinge == *h && r.error.is_none())
                .map(|r| (r.gradient_m, value(r)))
                .collect();
            if pts.is_empty() {
                continue;
            }
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            curves.push((
                format!("{} {}", f.as_str().to_uppercase(), hinge_name(h)),
                hinge_color(&hinges, h),
                pts,
                style(f),
            ));
        }
    }
    curves
}

/// The gradient whose locked run has the largest peak incremental root bending moment (the
/// time histories are drawn for it), or the first gradient.
fn critical_gradient(s: &GustSummary) -> Option<f64> {
    s.runs
        .iter()
        .filter(|r| matches!(r.hinge, HingeState::Locked) && r.error.is_none())
        .max_by(|a, b| a.peak_delta_root_bending_moment.0.abs().total_cmp(&b.peak_delta_root_bending_moment.0.abs()))
        .or_else(|| s.runs.first())
        .map(|r| r.gradient_m)
}

fn histories(s: &GustSummary, h_crit: f64, value: impl Fn(&crate::gust::Increments) -> &Vec<f64>) -> Curves {
    let hinges = hinges_of(s);
    let mut curves = Curves::new();
    for f in Formulation::ALL {
        for r in s.runs.iter().filter(|r| r.formulation == f && r.gradient_m == h_crit) {
            let Some(hist) = &r.history else { continue };
            let inc = &hist.increments;
            let pts = inc.t.iter().copied().zip(value(inc).iter().copied()).collect();
            curves.push((
                format!("{} {}", f.as_str().to_uppercase(), hinge_name(&r.hinge)),
                hinge_color(&hinges, &r.hinge),
                pts,
                style(f),
            ));
        }
    }
    // Markers on every sample of a long history hide the line: keep at most ~60 markers.
    for c in &mut curves {
        let n = c.2.len();
        if n > 120 {
            let step = n.div_ceil(120);
            c.2 = c.2.iter().copied().step_by(step).collect();
        }
    }
    curves
}

/// Write the sweep's files into `dir`.
pub fn write(dir: &Path, s: &GustSummary) -> Result<(), Error> {
    for f in Formulation::ALL {
        if s.runs.iter().any(|r| r.formulation == f) {
            write_file(&dir.join(format!("gust_{f}.csv")), &to_csv(s, f))?;
            write_file(&dir.join(format!("gust_history_{f}.csv")), &history_csv(s, f))?;
        }
    }
    let json = serde_json::to_string_pretty(s).map_err(|e| Error::Io(e.to_string()))?;
    write_file(&dir.join("gust_summary.json"), &json)?;
    panel(
        &dir.join("gust_envelope.svg"),
        &format!("{}: peak incremental root bending moment", s.name),
        "gust gradient H [m]",
        "peak ΔM_root [N·m]",
        &envelope(s, |r| r.peak_delta_root_bending_moment.0),
    )?;
    panel(
        &dir.join("gust_fold.svg"),
        &format!("{}: peak incremental fold angle", s.name),
        "gust gradient H [m]",
        "peak Δθ_fold [°]",
        &envelope(s, |r| r.peak_delta_fold_deg.0),
    )?;
    if let Some(h) = critical_gradient(s) {
        panel(
            &dir.join("gust_history_rbm.svg"),
            &format!("{}: H = {h:.3} m, incremental root bending moment", s.name),
            "t [s]",
            "ΔM_root [N·m]",
            &histories(s, h, |x| &x.delta_root_bending_moment),
        )?;
        panel(
            &dir.join("gust_history_fold.svg"),
            &format!("{}: H = {h:.3} m, incremental fold angle", s.name),
            "t [s]",
            "Δθ_fold [°]",
            &histories(s, h, |x| &x.delta_fold_deg),
        )?;
    }
    let folder = dir.file_name().map_or_else(|| s.name.clone(), |n| n.to_string_lossy().into_owned());
    write_file(&dir.join(SECTION_FILE), &section_html(s, &folder))
}

use crate::report::esc;

/// "ancf 0.12 s, gebf 0.34 s", or what no run timed.
fn cpu_phrase(max_cpu_s: &[(Formulation, f64)]) -> String {
    if max_cpu_s.is_empty() {
        return "none (no march ran)".into();
    }
    max_cpu_s.iter().map(|(f, c)| format!("{f} {c:.2} s")).collect::<Vec<_>>().join(", ")
}

/// The sweep's section of `reports/index.html`; plots linked under `folder`.
pub fn section_html(s: &GustSummary, folder: &str) -> String {
    let mut h = String::new();
    let _ = writeln!(h, "<h3 id=\"gust-{0}\">{0}</h3>", esc(&s.name));
    let pair = match (s.max_peak_rbm_difference_percent, s.max_peak_fold_difference_deg) {
        (Some(m), Some(f)) => {
            format!("ANCF–GEBF: peak ΔM_root within {m:.3} %, peak fold within {f:.3}° (runs both finished).")
        }
        _ => "ANCF–GEBF: no pair of runs both formulations finished.".into(),
    };
    let _ = writeln!(
        h,
        "<p>{} m/s, gust <code>{}</code>; {} run(s) failed. {pair} Largest CPU time of one run: {}.</p>",
        s.airspeed,
        esc(&serde_json::to_string(&s.gust).unwrap_or_default()),
        s.n_failed,
        cpu_phrase(&s.max_cpu_s)
    );
    h.push_str(
        "<table><tr><th>hinge</th><th>H [m]</th><th>f [Hz]</th><th>U_ds [m/s]</th>\
         <th>ANCF peak ΔM [N·m]</th><th>GEBF peak ΔM [N·m]</th><th>Δ [%]</th>\
         <th>ANCF peak Δθ [°]</th><th>GEBF peak Δθ [°]</th><th>alleviation ANCF [%]</th><th>alleviation GEBF [%]</th></tr>\n",
    );
    // One row per hinge and gradient: from the first formulation's run, or the second's where the
    // first did not run.
    let [first, second] = Formulation::ALL;
    for a in s.runs.iter().filter(|r| r.formulation == first || !s.runs.iter().any(|x| x.formulation == first)) {
        let g = s.runs.iter().find(|g| g.formulation == second && g.hinge == a.hinge && g.gradient_m == a.gradient_m);
        let d = s.ancf_gebf.iter().find(|d| d.hinge == a.hinge && d.gradient_m == a.gradient_m);
        let al = |f: Formulation| {
            s.runs
                .iter()
                .find(|r| r.formulation == f && r.hinge == a.hinge && r.gradient_m == a.gradient_m)
                .map_or(f64::NAN, |r| alleviation_of(s, r))
        };
        // A failed run's peaks read "failed" (its error is named below the table).
        let peak = |r: Option<&GustRun>, x: fn(&GustRun) -> f64, digits: usize| match r {
            Some(r) if r.error.is_some() => "failed".to_string(),
            Some(r) if x(r).is_finite() => format!("{:.*}", digits, x(r)),
            _ => "–".into(),
        };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{:.3}</td><td>{:.3}</td><td>{:.3}</td><td>{}</td><td>{}</td><td>{}</td>\
             <td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            esc(&hinge_name(&a.hinge)),
            a.gradient_m,
            a.frequency_hz,
            a.gust_velocity,
            peak(Some(a), |r| r.peak_delta_root_bending_moment.0, 5),
            peak(g, |r| r.peak_delta_root_bending_moment.0, 5),
            d.map_or_else(|| "–".into(), |d| format!("{:.3}", d.peak_rbm_percent)),
            peak(Some(a), |r| r.peak_delta_fold_deg.0, 3),
            peak(g, |r| r.peak_delta_fold_deg.0, 3),
            percent_cell(al(first)),
            percent_cell(al(second)),
        );
    }
    h.push_str("</table>\n");
    for r in s.runs.iter().filter(|r| r.error.is_some()) {
        let _ = writeln!(
            h,
            "<p class=\"fail\">{} {} H = {}: {}</p>",
            r.formulation,
            esc(&hinge_name(&r.hinge)),
            r.gradient_m,
            esc(r.error.as_deref().unwrap_or(""))
        );
    }
    for (file, cap) in [
        ("gust_envelope.svg", "Peak incremental root bending moment against the gust gradient, per hinge state"),
        ("gust_fold.svg", "Peak incremental fold angle against the gust gradient"),
        ("gust_history_rbm.svg", "Incremental root bending moment in time at the critical gradient of the locked wing"),
        ("gust_history_fold.svg", "Incremental fold angle in time at the same gradient"),
    ] {
        let _ = writeln!(
            h,
            "<figure><img src=\"{0}/{1}\" alt=\"{2}\" loading=\"lazy\"><figcaption>{2}</figcaption></figure>",
            esc(folder),
            file,
            esc(cap)
        );
    }
    h
}

/// The gust sections of every sweep written under `out` (`<out>/<case>/gust_section.html`), in
/// name order; empty when there are none.
pub fn sections_html(out: &Path) -> String {
    let cases = crate::report::fragments(out, SECTION_FILE);
    if cases.is_empty() {
        return cases;
    }
    let mut s = String::from(
        "<p>1-cos gusts through the UVLM from the static aeroelastic equilibrium of each hinge state (the steady \
         wake laid out behind it), incremental loads over their equilibrium values; alleviation is the reduction of \
         the peak incremental root bending moment against the locked hinge (docs/gust.md). Files per case: \
         <code>gust_ancf.csv</code>, <code>gust_gebf.csv</code>, <code>gust_history_*.csv</code>, \
         <code>gust_summary.json</code>.</p>\n",
    );
    s.push_str(&cases);
    s
}

/// A percentage to one decimal, or a dash where there is none (the locked hinge's alleviation).
fn percent_cell(x: f64) -> String {
    if x.is_finite() { format!("{x:.1}") } else { "–".into() }
}
