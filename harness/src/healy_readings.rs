//! Healy's flared-folding-wingtip experiment under every reading of issue 37 (point 5):
//! aerodynamics (the lattice, static strips, strips with the lifting-line tip loss) × section
//! polars (none, NeuralFoil NACA 0015) × geometry (the cases' reading, the experimenter's model
//! code's: hinge line through mid-chord, chord 80 mm). Per reading: the RMS coast-angle error on
//! the three shared curves, the coast angle's change per 5° of root pitch (pitch 0° → 5°, flare
//! 10°) and the root pitch at which the tip coasts level, each against the experiment
//! (docs/validation.md §2). Writes `healy_readings.csv` and the report's section
//! `healy_readings_section.html`. No parameter is fitted to the curves.

use std::fmt::Write as _;
use std::path::Path;

use rayon::prelude::*;
use serde::Serialize;

use crate::Error;
use crate::case::{CaseFile, Formulation, Override};
use crate::csv::write_file;

/// The three shared curves: case file stems (flare 10° pitch 0°, flare 10° pitch 5°, flare 30°
/// pitch 10°).
pub const CASES: [&str; 3] = ["healy_ffwt_flare10_aoa0", "healy_ffwt_flare10_aoa5", "healy_ffwt_flare30_aoa10"];
/// The report section's file under the output folder.
pub const SECTION_FILE: &str = "healy_readings_section.html";
/// Airspeeds over which the RMS is taken, m/s (the experiment's 12–33).
const BAND: std::ops::RangeInclusive<f64> = 12.0..=33.0;
/// Airspeeds from which the per-5° measure is averaged (the issue's "from 18 m/s up").
const PER5_FROM: f64 = 18.0;
/// The polar of the readings with polars: NeuralFoil NACA 0015, Re 0.5–2.0e5, read at each
/// strip's own Reynolds number; beyond its ±20° the flat-plate extrapolation.
const POLARS: &str =
    r#"aero.polars=[{"bodies":[0,1],"file":"polars/naca0015_neuralfoil.csv","bounds":{"alpha":"flat_plate"}}]"#;
/// The second reading of the geometry (LacaFramework `examples/+FWT_Model/gen_FWT.m`): chord
/// 80 mm (spar still at 25 % chord), the flare hinge line through mid-chord at 365 mm:
/// `hinge_line_y = le_offset − chord/2 = −0.020 m`.
const GEOMETRY_2: [&str; 3] = ["aero.chord=0.08", "aero.le_offset=0.02", "joints.1.hinge_line_y=-0.02"];

/// A point of a curve: airspeed (m/s), coast angle (degrees).
type Point = (f64, f64);

/// The aerodynamics of a reading.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Aero {
    /// The steady vortex lattice (the cases' own).
    Lattice,
    /// Two-dimensional static strips (`aero.model: "strip"`).
    Strip,
    /// Static strips with the lifting-line tip loss (`aero.strip_tip_loss: "lifting_line"`).
    StripTipLoss,
}

/// One reading of the experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Reading {
    /// Aerodynamics.
    pub aero: Aero,
    /// With the NeuralFoil NACA 0015 polars.
    pub polars: bool,
    /// Geometry reading: 1 (the cases', hinge line through the spar, chord 78 mm) or 2 (the
    /// model code's, hinge line through mid-chord, chord 80 mm).
    pub geometry: u8,
}

impl Reading {
    /// Every combination: 3 aerodynamics × polars off/on × geometry 1/2.
    pub fn all() -> Vec<Reading> {
        let mut v = Vec::new();
        for geometry in [1, 2] {
            for aero in [Aero::Lattice, Aero::Strip, Aero::StripTipLoss] {
                for polars in [false, true] {
                    v.push(Reading { aero, polars, geometry });
                }
            }
        }
        v
    }

    /// A short label: `lattice`, `strip`, `strip + tip loss`; `+ polars`; `geometry 2`.
    pub fn label(&self) -> String {
        let a = match self.aero {
            Aero::Lattice => "lattice",
            Aero::Strip => "strip",
            Aero::StripTipLoss => "strip + tip loss",
        };
        format!("{a}{}, geometry {}", if self.polars { " + polars" } else { "" }, self.geometry)
    }

    /// The case overrides of this reading.
    ///
    /// # Errors
    /// Never for the built-in readings (an override that does not parse).
    pub fn overrides(&self) -> Result<Vec<Override>, Error> {
        let mut s: Vec<&str> = Vec::new();
        match self.aero {
            Aero::Lattice => {}
            Aero::Strip => s.push("aero.model=strip"),
            Aero::StripTipLoss => s.extend(["aero.model=strip", "aero.strip_tip_loss=lifting_line"]),
        }
        if self.polars {
            s.push(POLARS);
        }
        if self.geometry == 2 {
            s.extend(GEOMETRY_2);
        }
        s.iter().map(|x| x.parse::<Override>().map_err(|e| Error::Override(e.to_string()))).collect()
    }
}

/// One curve of one reading.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurveResult {
    /// Case name.
    pub case: String,
    /// The model's coast angle per airspeed `(airspeed, fold °)`, converged points only.
    pub model: Vec<(f64, f64)>,
    /// At the experiment's airspeeds: `(airspeed, experiment °, model °)`.
    pub points: Vec<(f64, f64, f64)>,
    /// RMS of model − experiment over 12–33 m/s, degrees.
    pub rms_deg: Option<f64>,
    /// RMS of model − Healy's own model at that model's airspeeds in 12–33 m/s, degrees (none on
    /// the flare-30° curve, which has no such model curve).
    pub rms_vs_healy_deg: Option<f64>,
    /// Points without an equilibrium (their messages).
    pub failures: Vec<String>,
}

/// What one reading reaches.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReadingResult {
    /// The reading.
    pub reading: Reading,
    /// The three curves, in the order of [`CASES`].
    pub curves: Vec<CurveResult>,
    /// Per experiment airspeed: `(airspeed, model, experiment)` change of coast angle from root
    /// pitch 0° to 5° at flare 10°, degrees.
    pub per_5deg: Vec<(f64, f64, f64)>,
    /// Per experiment airspeed: `(airspeed, model, experiment)` root pitch of a level coast at
    /// flare 10°, degrees (the model's by a root-find, NaN where it failed; the experiment's
    /// interpolated from its pitch-0° and pitch-5° curves).
    pub level_pitch: Vec<(f64, f64, f64)>,
    /// Why a level pitch is missing.
    pub level_failures: Vec<String>,
}

/// The experiment's and Healy's own model's curves of the three cases.
struct References {
    experiment: Vec<Vec<(f64, f64)>>,
    healy: Vec<Vec<(f64, f64)>>,
}

fn read_references(cases: &Path) -> Result<References, Error> {
    let dir = cases.join("reference/healy_ffwt");
    let read = |f: &str| crate::static_out::read_xy(&dir.join(f));
    let experiment = ["exp_flare10_aoa0.csv", "exp_flare10_aoa5.csv", "exp_flare30_aoa10.csv"]
        .iter()
        .map(|f| read(f))
        .collect::<Result<Vec<_>, _>>()?;
    let healy = ["healy_model_flare10_aoa0.csv", "healy_model_flare10_aoa5.csv"]
        .iter()
        .map(|f| read(f))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(References { experiment, healy })
}

/// Linear interpolation of `pts` (sorted by x) at `x`; None outside.
fn interp(pts: &[(f64, f64)], x: f64) -> Option<f64> {
    let i = pts.iter().position(|p| p.0 >= x)?;
    if (pts[i].0 - x).abs() < 1e-12 {
        return Some(pts[i].1);
    }
    let (a, b) = (pts.get(i.checked_sub(1)?)?, pts[i]);
    Some(a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0))
}

/// RMS of `model − experiment` at the experiment's airspeeds in the band.
fn rms(points: &[(f64, f64, f64)]) -> Option<f64> {
    let e: Vec<f64> = points.iter().filter(|p| BAND.contains(&p.0)).map(|p| p.2 - p.1).collect();
    (!e.is_empty()).then(|| (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt())
}

/// The experiment's level pitch from its pitch-0° and pitch-5° coast angles (linear in pitch).
fn level_from(c0: f64, c5: f64) -> f64 {
    -5.0 * c0 / (c5 - c0)
}

/// The problem of case `stem` (in `cases`) under `reading`, for formulation `f`.
fn problem(cases: &Path, stem: &str, reading: &Reading, f: Formulation) -> Result<aeroelastic::Problem, Error> {
    let file = CaseFile::read(&cases.join(format!("{stem}.json")))?;
    let spec = file
        .expand(&reading.overrides()?)?
        .into_iter()
        .next()
        .ok_or_else(|| Error::Case { file: stem.into(), msg: "expands into no run".into() })?;
    Ok(spec.case(f).problem())
}

/// One curve of a reading against its experiment.
fn curve(
    problem: &aeroelastic::Problem,
    f: Formulation,
    stem: &str,
    (exp, healy): (&[Point], Option<&[Point]>),
) -> CurveResult {
    let out = aeroelastic::statics::run_static(problem, f);
    let mut model: Vec<(f64, f64)> = out
        .points
        .iter()
        .filter(|p| p.error.is_none() && p.fold_deg.is_finite())
        .map(|p| (p.airspeed, p.fold_deg))
        .collect();
    model.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut failures: Vec<String> =
        out.points.iter().filter_map(|p| p.error.as_ref().map(|e| format!("{} m/s: {e}", p.airspeed))).collect();
    failures.extend(out.error);
    let against = |r: &[(f64, f64)]| -> Vec<(f64, f64, f64)> {
        r.iter().filter_map(|&(u, c)| interp(&model, u).map(|m| (u, c, m))).collect()
    };
    let rms_vs_healy_deg = healy.and_then(|h| rms(&against(h)));
    let points = against(exp);
    CurveResult { case: stem.into(), rms_deg: rms(&points), rms_vs_healy_deg, model, points, failures }
}

/// Every reading of the experiment with formulation `f` (cases and references under `cases`).
///
/// # Errors
/// A case file or reference that cannot be read.
pub fn run(cases: &Path, f: Formulation) -> Result<Vec<ReadingResult>, Error> {
    let refs = read_references(cases)?;
    Reading::all()
        .into_par_iter()
        .map(|reading| {
            let problems = CASES.iter().map(|stem| problem(cases, stem, &reading, f)).collect::<Result<Vec<_>, _>>()?;
            let curves: Vec<CurveResult> = CASES
                .par_iter()
                .zip(&problems)
                .enumerate()
                .map(|(k, (stem, p))| curve(p, f, stem, (&refs.experiment[k], refs.healy.get(k).map(Vec::as_slice))))
                .collect();
            let (per_5deg, level_pitch, level_failures) = pitch_measures(&problems[0], f, &curves, &refs);
            Ok(ReadingResult { reading, curves, per_5deg, level_pitch, level_failures })
        })
        .collect()
}

/// The two relative measures of a reading at the experiment's airspeeds: the change of coast
/// angle per 5° of root pitch, and the level-coast pitch (a root-find on the pitch-0° problem
/// `p0`, started from the model's pitch-0° and pitch-5° coast angles).
#[allow(clippy::type_complexity)] // three columns of one table
fn pitch_measures(
    p0: &aeroelastic::Problem,
    f: Formulation,
    curves: &[CurveResult],
    refs: &References,
) -> (Vec<(f64, f64, f64)>, Vec<(f64, f64, f64)>, Vec<String>) {
    let (e0, e5) = (&refs.experiment[0], &refs.experiment[1]);
    let airspeeds: Vec<f64> = e0.iter().map(|p| p.0).filter(|u| interp(e5, *u).is_some()).collect();
    let per: Vec<(f64, f64, f64, f64, f64)> = airspeeds
        .iter()
        .filter_map(|&u| {
            let (m0, m5) = (interp(&curves[0].model, u)?, interp(&curves[1].model, u)?);
            let (x0, x5) = (interp(e0, u)?, interp(e5, u)?);
            Some((u, m0, m5, x0, x5))
        })
        .collect();
    let per_5deg = per.iter().map(|&(u, m0, m5, x0, x5)| (u, m5 - m0, x5 - x0)).collect();
    let found: Vec<(f64, Result<f64, String>, f64)> = per
        .par_iter()
        .map(|&(u, m0, m5, x0, x5)| {
            let r = aeroelastic::level_coast::level_pitch(p0, f, u, [(0.0, m0), (5.0, m5)], 1e-3);
            (u, r.map(|l| l.pitch_deg), level_from(x0, x5))
        })
        .collect();
    let failures = found.iter().filter_map(|(_, r, _)| r.as_ref().err().cloned()).collect();
    let level = found.into_iter().map(|(u, r, x)| (u, r.unwrap_or(f64::NAN), x)).collect();
    (per_5deg, level, failures)
}

/// Healy's own model (strip theory) on the two flare-10° curves, as a row of the table: its RMS
/// against the experiment and its two relative measures (level pitch interpolated as the
/// experiment's).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HealyModel {
    /// RMS on the flare-10° pitch-0° and pitch-5° curves, degrees.
    pub rms_deg: [Option<f64>; 2],
    /// `(airspeed, Healy's model, experiment)` per 5° of pitch.
    pub per_5deg: Vec<(f64, f64, f64)>,
    /// `(airspeed, Healy's model, experiment)` level pitch.
    pub level_pitch: Vec<(f64, f64, f64)>,
}

/// Healy's own model's row (cases and references under `cases`).
///
/// # Errors
/// A reference that cannot be read.
pub fn healy_model(cases: &Path) -> Result<HealyModel, Error> {
    let r = read_references(cases)?;
    let at = |m: &[(f64, f64)], e: &[(f64, f64)]| -> Vec<(f64, f64, f64)> {
        e.iter().filter_map(|&(u, c)| interp(m, u).map(|x| (u, c, x))).collect()
    };
    let (a, b) = (at(&r.healy[0], &r.experiment[0]), at(&r.healy[1], &r.experiment[1]));
    let mut per_5deg = Vec::new();
    let mut level_pitch = Vec::new();
    for (&(u, x0, m0), &(_, x5, m5)) in a.iter().zip(&b).filter(|(p, q)| p.0 == q.0) {
        per_5deg.push((u, m5 - m0, x5 - x0));
        level_pitch.push((u, level_from(m0, m5), level_from(x0, x5)));
    }
    Ok(HealyModel { rms_deg: [rms(&a), rms(&b)], per_5deg, level_pitch })
}

/// Mean of the second and third columns over airspeeds from [`PER5_FROM`] up.
fn mean_from(v: &[(f64, f64, f64)]) -> (f64, f64) {
    let s: Vec<_> = v.iter().filter(|p| p.0 >= PER5_FROM && p.1.is_finite()).collect();
    let n = s.len().max(1) as f64;
    (s.iter().map(|p| p.1).sum::<f64>() / n, s.iter().map(|p| p.2).sum::<f64>() / n)
}

/// RMS of the model's level pitch against the experiment's over the band, degrees.
fn level_rms(v: &[(f64, f64, f64)]) -> Option<f64> {
    rms(&v.iter().map(|&(u, m, x)| (u, x, m)).filter(|p| p.2.is_finite()).collect::<Vec<_>>())
}

/// The CSV: one row per reading, measure, curve and airspeed
/// (`reading,aero,polars,geometry,measure,curve,airspeed,model,experiment`; `measure` is
/// `coast_deg`, `rms_deg` and `rms_vs_healy_model_deg` (airspeed empty), `per_5deg_pitch` or
/// `level_pitch_deg`).
pub fn to_csv(results: &[ReadingResult], healy: &HealyModel) -> String {
    let mut s = String::from("reading,aero,polars,geometry,measure,curve,airspeed,model,experiment\n");
    let aero = |a: Aero| serde_json::to_value(a).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default();
    let num = |x: f64| if x.is_finite() { format!("{x:.4}") } else { String::new() };
    for r in results {
        let g = &r.reading;
        let head = format!("\"{}\",{},{},{}", g.label(), aero(g.aero), g.polars, g.geometry);
        for c in &r.curves {
            for &(u, x, m) in &c.points {
                let _ = writeln!(s, "{head},coast_deg,{},{u},{},{}", c.case, num(m), num(x));
            }
            let _ = writeln!(s, "{head},rms_deg,{},,{},", c.case, c.rms_deg.map_or(String::new(), num));
            if let Some(r) = c.rms_vs_healy_deg {
                let _ = writeln!(s, "{head},rms_vs_healy_model_deg,{},,{},", c.case, num(r));
            }
        }
        for &(u, m, x) in &r.per_5deg {
            let _ = writeln!(s, "{head},per_5deg_pitch,flare10,{u},{},{}", num(m), num(x));
        }
        for &(u, m, x) in &r.level_pitch {
            let _ = writeln!(s, "{head},level_pitch_deg,flare10,{u},{},{}", num(m), num(x));
        }
    }
    let head = "\"Healy's own model (strip theory)\",healy,,";
    for (k, r) in healy.rms_deg.iter().enumerate() {
        let _ = writeln!(s, "{head},rms_deg,{},,{},", CASES[k], r.map_or(String::new(), num));
    }
    for &(u, m, x) in &healy.per_5deg {
        let _ = writeln!(s, "{head},per_5deg_pitch,flare10,{u},{},{}", num(m), num(x));
    }
    for &(u, m, x) in &healy.level_pitch {
        let _ = writeln!(s, "{head},level_pitch_deg,flare10,{u},{},{}", num(m), num(x));
    }
    s
}

fn cell(x: Option<f64>, digits: usize) -> String {
    x.filter(|v| v.is_finite()).map_or_else(|| "–".into(), |v| format!("{v:.digits$}"))
}

/// The report's section: the RMS table with the two measures' means, then both measures per
/// airspeed.
pub fn to_html(results: &[ReadingResult], healy: &HealyModel, f: Formulation) -> String {
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<p>Every reading of issue 37 (point 5), {f}: aerodynamics × NeuralFoil NACA 0015 polars × geometry \
         (1: the cases', hinge line through the spar at 25 % chord, chord 78 mm; 2: the experimenter's model code, \
         hinge line through mid-chord at 365 mm, chord 80 mm). RMS of the coast-angle error over 12–33 m/s on the \
         three shared curves; Δ/5°: the coast angle's change from root pitch 0° to 5° at flare 10°, mean from \
         18 m/s up (experiment in brackets); level pitch: the root pitch of a level coast at flare 10°, RMS \
         against the experiment's (interpolated from its two curves). No parameter is fitted \
         (docs/validation.md §2). File: <code>healy_readings.csv</code>.</p>"
    );
    h.push_str(
        "<table><tr><th>reading</th><th>flare 10°, pitch 0°</th><th>flare 10°, pitch 5°</th>\
         <th>flare 30°, pitch 10°</th><th>Δ/5° (exp.)</th><th>level pitch RMS</th>\
         <th>against Healy's model (pitch 0° / 5°)</th><th>failed points</th></tr>\n",
    );
    for r in results {
        let (m, x) = mean_from(&r.per_5deg);
        let failed: usize = r.curves.iter().map(|c| c.failures.len()).sum::<usize>() + r.level_failures.len();
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}°</td><td>{}°</td><td>{}°</td><td>{m:.1}° ({x:.1}°)</td><td>{}°</td>\
             <td>{}° / {}°</td><td>{failed}</td></tr>",
            r.reading.label(),
            cell(r.curves[0].rms_deg, 1),
            cell(r.curves[1].rms_deg, 1),
            cell(r.curves[2].rms_deg, 1),
            cell(level_rms(&r.level_pitch), 2),
            cell(r.curves[0].rms_vs_healy_deg, 1),
            cell(r.curves[1].rms_vs_healy_deg, 1),
        );
    }
    let (m, x) = mean_from(&healy.per_5deg);
    let _ = writeln!(
        h,
        "<tr><td>Healy's own model (strip theory)</td><td>{}°</td><td>{}°</td><td>–</td><td>{m:.1}° ({x:.1}°)</td><td>{}°</td><td>–</td><td></td></tr></table>",
        cell(healy.rms_deg[0], 1),
        cell(healy.rms_deg[1], 1),
        cell(level_rms(&healy.level_pitch), 2)
    );
    per_airspeed_html(&mut h, results, healy);
    h
}

/// The two measures per airspeed.
fn per_airspeed_html(h: &mut String, results: &[ReadingResult], healy: &HealyModel) {
    let speeds: Vec<f64> = healy.per_5deg.iter().map(|p| p.0).collect();
    for (title, pick) in [
        ("Change of coast angle per 5° of root pitch (flare 10°), degrees", 0usize),
        ("Root pitch of a level coast (flare 10°), degrees", 1),
    ] {
        let _ = write!(h, "<p>{title}</p>\n<table><tr><th>reading</th>");
        for u in &speeds {
            let _ = write!(h, "<th>{u} m/s</th>");
        }
        h.push_str("</tr>\n");
        let row = |h: &mut String, label: &str, v: &[(f64, f64, f64)], exp: bool| {
            let _ = write!(h, "<tr><td>{label}</td>");
            for u in &speeds {
                let p = v.iter().find(|p| p.0 == *u);
                let _ = write!(h, "<td>{}</td>", cell(p.map(|p| if exp { p.2 } else { p.1 }), 1));
            }
            h.push_str("</tr>\n");
        };
        let of = |r: &ReadingResult| if pick == 0 { r.per_5deg.clone() } else { r.level_pitch.clone() };
        let hv = if pick == 0 { &healy.per_5deg } else { &healy.level_pitch };
        row(h, "experiment", hv, true);
        row(h, "Healy's own model", hv, false);
        for r in results {
            row(h, &r.reading.label(), &of(r), false);
        }
        h.push_str("</table>\n");
    }
}

/// The coast angle of every geometry-1 reading on curve `k`, with the experiment and Healy's
/// own model, into `path` (SVG).
fn plot_curve(path: &Path, k: usize, results: &[ReadingResult], refs: &References) -> Result<(), Error> {
    use crate::static_out::Style;
    use plotters::style::RGBColor;
    const COLOURS: [RGBColor; 3] = [RGBColor(31, 119, 180), RGBColor(214, 39, 40), RGBColor(148, 103, 189)];
    let mut curves: crate::static_out::Curves = results
        .iter()
        .filter(|r| r.reading.geometry == 1)
        .map(|r| {
            let colour = COLOURS[r.reading.aero as usize];
            let style = if r.reading.polars { Style::Dashed } else { Style::Solid };
            (r.reading.label().replace(", geometry 1", ""), colour, r.curves[k].model.clone(), style)
        })
        .collect();
    curves.push(("experiment".into(), RGBColor(30, 30, 30), refs.experiment[k].clone(), Style::Points));
    if let Some(h) = refs.healy.get(k) {
        let band: Vec<(f64, f64)> = h.iter().copied().filter(|p| (11.0..=34.0).contains(&p.0)).collect();
        curves.push(("Healy's own model".into(), RGBColor(44, 160, 44), band, Style::Points));
    }
    let title = ["flare 10°, pitch 0°", "flare 10°, pitch 5°", "flare 30°, pitch 10°"][k];
    crate::static_out::panel(
        path,
        &format!("Healy {title}: coast angle by reading"),
        "airspeed [m/s]",
        "fold angle [deg] (tip up +)",
        &curves,
    )
}

/// Write `healy_readings.csv`, the coast-angle figures `healy_readings_<case>.svg` and the
/// report's section into `out` (cases and references under `cases`).
///
/// # Errors
/// A file that cannot be written or a reference that cannot be read.
pub fn write(
    out: &Path,
    cases: &Path,
    results: &[ReadingResult],
    healy: &HealyModel,
    f: Formulation,
) -> Result<(), Error> {
    write_file(&out.join("healy_readings.csv"), &to_csv(results, healy))?;
    let refs = read_references(cases)?;
    let mut html = to_html(results, healy, f);
    for (k, stem) in CASES.iter().enumerate() {
        let file = format!("healy_readings_{stem}.svg");
        plot_curve(&out.join(&file), k, results, &refs)?;
        let _ = writeln!(html, "<figure><img src=\"{file}\" alt=\"coast angle by reading, {stem}\"></figure>");
    }
    write_file(&out.join(SECTION_FILE), &html)
}
