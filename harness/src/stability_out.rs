//! Files of a stability sweep: `stability_<f>.csv`, `stability_<f>.json`, the V-g, V-f and
//! root-locus plots, the mode shapes, and the report fragment (docs/stability.md).

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::Error;
use crate::case::Formulation;
use crate::csv::write_file;
use crate::plot::{Dash, Marker, Panel, Series, Style, colors, panels_svg};
use crate::stability::StabilityOutput;

/// The CSV of one formulation: one row per airspeed and tracked mode.
pub fn to_csv(out: &StabilityOutput) -> String {
    let mut s = String::from("airspeed,mode,real,imag,frequency_hz,frequency_rad_s,damping_ratio,converged\n");
    for p in &out.points {
        for r in &p.roots {
            let _ = writeln!(
                s,
                "{},{},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{}",
                p.airspeed,
                r.mode,
                r.real,
                r.imag,
                r.frequency_hz(),
                r.imag,
                r.damping_ratio(),
                u8::from(r.converged)
            );
        }
    }
    s
}

/// The rigid-body roots of a sweep about trim (`flight_modes_<f>.csv`): one row per airspeed
/// and root; `None` when the sweep has none.
pub fn flight_modes_csv(out: &StabilityOutput) -> Option<String> {
    if out.points.iter().all(|p| p.flight_roots.is_empty()) {
        return None;
    }
    let mut s =
        String::from("airspeed,name,real,imag,frequency_rad_s,period_s,damping_ratio,time_to_half_s,symmetric,rigid\n");
    for p in &out.points {
        for r in &p.flight_roots {
            let _ = writeln!(
                s,
                "{},{},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.6},{:.6}",
                p.airspeed,
                r.name,
                r.real,
                r.imag,
                r.real.hypot(r.imag),
                r.period_s(),
                r.damping_ratio(),
                -std::f64::consts::LN_2 / r.real,
                r.symmetric,
                r.rigid
            );
        }
    }
    Some(s)
}

/// The JSON summary of one formulation.
#[derive(Debug, Serialize)]
struct Summary<'a> {
    case: &'a str,
    formulation: Formulation,
    flutter_speed: Option<f64>,
    flutter_frequency_rad_s: Option<f64>,
    flutter_mode: Option<usize>,
    divergence_speed: Option<f64>,
    n_dof: usize,
    n_free: usize,
    n_basis: usize,
    n_rings: usize,
    n_wake_rings: usize,
    n_evaluations: usize,
    build_s: f64,
    solve_s: f64,
    wall_s: f64,
    error: &'a Option<String>,
    /// Airspeeds that could not be analysed (their `error` says why).
    n_failed_points: usize,
    /// Roots whose iteration did not converge, over all airspeeds (`converged: false` in
    /// `points`); a script reads this, or `roots_converged`, to trust the flutter speed.
    n_unconverged_roots: usize,
    /// Every root of every analysed airspeed converged.
    roots_converged: bool,
    points: &'a [crate::stability::StabilityPoint],
}

/// Roots that did not converge, over all airspeeds of a sweep.
pub fn unconverged_roots(out: &StabilityOutput) -> usize {
    out.points.iter().flat_map(|p| &p.roots).filter(|r| !r.converged).count()
}

/// Per-formulation metrics of the case's time-domain run (for the damping comparison).
pub type History = std::collections::BTreeMap<Formulation, crate::metrics::FormulationMetrics>;

/// Write the sweep's files of every formulation in `runs` into `dir`; with the case's
/// time-domain metrics, the section compares the least-damped roots with the dominant
/// oscillation of the run (matrix pencil, last window).
pub fn write_with_history(
    dir: &Path,
    name: &str,
    runs: &[StabilityOutput],
    history: Option<&History>,
) -> Result<(), Error> {
    for out in runs {
        write_file(&dir.join(format!("stability_{}.csv", out.formulation)), &to_csv(out))?;
        if let Some(csv) = flight_modes_csv(out) {
            write_file(&dir.join(format!("flight_modes_{}.csv", out.formulation)), &csv)?;
        }
        let sum = Summary {
            case: name,
            formulation: out.formulation,
            flutter_speed: out.flutter_speed,
            flutter_frequency_rad_s: out.flutter_frequency_rad_s,
            flutter_mode: out.flutter_mode,
            divergence_speed: out.divergence_speed,
            n_dof: out.n_dof,
            n_free: out.n_free,
            n_basis: out.n_basis,
            n_rings: out.n_rings,
            n_wake_rings: out.n_wake_rings,
            n_evaluations: out.n_evaluations,
            build_s: out.build_s,
            solve_s: out.solve_s,
            wall_s: out.wall_s,
            error: &out.error,
            n_failed_points: out.points.iter().filter(|p| p.error.is_some()).count(),
            n_unconverged_roots: unconverged_roots(out),
            roots_converged: unconverged_roots(out) == 0,
            points: &out.points,
        };
        let json = serde_json::to_string_pretty(&sum).map_err(|e| Error::Io(e.to_string()))?;
        write_file(&dir.join(format!("stability_{}.json", out.formulation)), &json)?;
    }
    plots(dir, runs)?;
    let folder = dir.file_name().map_or_else(|| name.to_string(), |n| n.to_string_lossy().into_owned());
    let mut html = section_html(name, &folder, runs);
    if let Some(h) = history {
        html.push_str(&history_table(runs, h));
    }
    write_file(&dir.join(SECTION_FILE), &html)
}

/// The eigen-analysis's root nearest in frequency to the time history's dominant oscillation
/// (last window), per formulation, at the first airspeed.
fn history_table(runs: &[StabilityOutput], h: &History) -> String {
    let mut s = String::from(
        "<table><tr><th>formulation</th><th>time history (last window)</th><th>f (Hz)</th><th>growth (1/s)</th>\
         <th>eigen-analysis f (Hz)</th><th>growth (1/s)</th></tr>\n",
    );
    for o in runs {
        let (Some(m), Some(p)) = (h.get(&o.formulation), o.points.first()) else { continue };
        let Some(osc) = m.oscillations.last() else { continue };
        let Some(r) = p.roots.iter().filter(|r| r.converged).min_by(|a, b| {
            (a.frequency_hz() - osc.frequency_hz).abs().total_cmp(&(b.frequency_hz() - osc.frequency_hz).abs())
        }) else {
            continue;
        };
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{} {:.1}–{:.1} s</td><td>{:.4}</td><td>{:+.4}</td><td>{:.4}</td><td>{:+.4}</td></tr>",
            o.formulation.as_str().to_uppercase(),
            m.oscillation_signal,
            osc.t_start,
            osc.t_end,
            osc.frequency_hz,
            osc.growth_rate,
            r.frequency_hz(),
            r.real
        );
    }
    s.push_str("</table>\n");
    s
}

fn color(f: Formulation) -> plotters::style::RGBColor {
    colors::of(f)
}

fn plots(dir: &Path, runs: &[StabilityOutput]) -> Result<(), Error> {
    let n_modes = runs.iter().flat_map(|o| o.points.iter().map(|p| p.roots.len())).max().unwrap_or(0);
    let mut vg = Panel {
        title: "V-g: damping ratio of the tracked roots".into(),
        x_label: "airspeed (m/s)".into(),
        y_label: "damping ratio ζ (−)".into(),
        ..Default::default()
    };
    let mut vf = Panel {
        title: "V-f: frequency of the tracked roots".into(),
        x_label: "airspeed (m/s)".into(),
        y_label: "frequency (Hz)".into(),
        ..Default::default()
    };
    let mut locus = Panel {
        title: "Root locus over the sweep".into(),
        x_label: "Re s (1/s)".into(),
        y_label: "Im s (rad/s)".into(),
        pad_x: true,
        ..Default::default()
    };
    for out in runs {
        let dash = Style::formulation_dash(out.formulation);
        for m in 0..n_modes {
            let pick = |f: &dyn Fn(&crate::stability::Root) -> f64| -> Vec<(f64, f64)> {
                out.points
                    .iter()
                    .filter_map(|p| p.roots.get(m).filter(|r| r.converged).map(|r| (p.airspeed, f(r))))
                    .collect()
            };
            let style = Style {
                color: Style::nth(m).color,
                dash,
                marker: Some(Style::nth(m).marker.unwrap_or(Marker::Circle)),
                width: 2,
            };
            let label = format!("{} mode {}", out.formulation.as_str().to_uppercase(), m + 1);
            vg.series.push(Series::new(label.clone(), style, pick(&|r| r.damping_ratio())));
            vf.series.push(Series::new(label.clone(), style, pick(&|r| r.frequency_hz())));
            let pts: Vec<(f64, f64)> = out
                .points
                .iter()
                .filter_map(|p| p.roots.get(m).filter(|r| r.converged).map(|r| (r.real, r.imag)))
                .collect();
            locus.series.push(Series::new(label, style, pts));
        }
        let _ = color(out.formulation);
    }
    panels_svg(&dir.join("stability_vg.svg"), &[vg, vf], 2, (620, 440))?;
    panels_svg(&dir.join("stability_locus.svg"), &[locus], 1, (760, 520))?;
    // Mode shapes of the first airspeed: vertical and chordwise displacement of the axis.
    let mut panels = Vec::new();
    for out in runs.iter().take(1) {
        for (i, sh) in out.shapes.iter().take(6).enumerate() {
            let z: Vec<(f64, f64)> = sh.s.iter().zip(&sh.displacement).map(|(s, d)| (*s, d[2])).collect();
            let y: Vec<(f64, f64)> = sh.s.iter().zip(&sh.displacement).map(|(s, d)| (*s, d[1])).collect();
            let x: Vec<(f64, f64)> = sh.s.iter().zip(&sh.displacement).map(|(s, d)| (*s, d[0])).collect();
            panels.push(Panel {
                title: if sh.omega >= 0.0 {
                    format!(
                        "{} mode {}: {:.3} Hz",
                        out.formulation.as_str().to_uppercase(),
                        i + 1,
                        sh.omega / (2.0 * std::f64::consts::PI)
                    )
                } else {
                    // ω² < 0: statically unstable with the aerodynamic loads held (the lift's
                    // stiffness is in the flutter equation, not in these modes).
                    format!(
                        "{} mode {}: ω² < 0, |f| = {:.3} Hz",
                        out.formulation.as_str().to_uppercase(),
                        i + 1,
                        -sh.omega / (2.0 * std::f64::consts::PI)
                    )
                },
                x_label: "wing arclength (m)".into(),
                y_label: "axis displacement (−)".into(),
                series: vec![
                    Series::new("z", Style::solid(colors::ANCF), z),
                    Series::new("y", Style::solid(colors::GEBF).dash(Dash::Dashed), y),
                    Series::new("x", Style::nth(2).dash(Dash::Dotted), x),
                ],
                ..Default::default()
            });
        }
    }
    if !panels.is_empty() {
        panels_svg(&dir.join("stability_modes.svg"), &panels, 3, (420, 300))?;
    }
    Ok(())
}

/// The report fragment each sweep leaves in its folder.
pub const SECTION_FILE: &str = "stability_section.html";

fn fmt_opt(x: Option<f64>, d: usize) -> String {
    x.map_or_else(|| "none in the sweep".into(), |v| format!("{v:.d$}"))
}

/// The section of one case.
pub fn section_html(name: &str, folder: &str, runs: &[StabilityOutput]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "<h3 id=\"stability-{name}\">{name}</h3>");
    s.push_str(
        "<table><tr><th>formulation</th><th>flutter speed (m/s)</th><th>flutter frequency (rad/s)</th>\
         <th>divergence speed (m/s)</th><th>basis modes</th><th>rings (bound + wake)</th><th>time (s)</th></tr>\n",
    );
    for o in runs {
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{} + {}</td><td>{:.2}</td></tr>",
            o.formulation.as_str().to_uppercase(),
            fmt_opt(o.flutter_speed, 2),
            fmt_opt(o.flutter_frequency_rad_s, 2),
            fmt_opt(o.divergence_speed, 2),
            o.n_basis,
            o.n_rings,
            o.n_wake_rings,
            o.wall_s
        );
        if let Some(e) = &o.error {
            let _ = writeln!(s, "<tr><td colspan=\"7\" class=\"fail\">{}</td></tr>", e.replace('<', "&lt;"));
        }
    }
    s.push_str("</table>\n");
    // Least-damped roots at each airspeed.
    s.push_str("<table><tr><th>formulation</th><th>airspeed (m/s)</th><th>fold (deg)</th><th>least-damped root: f (Hz)</th><th>ζ (%)</th><th>Re s (1/s)</th></tr>\n");
    for o in runs {
        for p in &o.points {
            if let Some(r) = p.roots.iter().filter(|r| r.converged).min_by(|a, b| b.real.total_cmp(&a.real)) {
                let _ = writeln!(
                    s,
                    "<tr><td>{}</td><td>{:.2}</td><td>{}</td><td>{:.4}</td><td>{:.3}</td><td>{:+.4}</td></tr>",
                    o.formulation.as_str().to_uppercase(),
                    p.airspeed,
                    if p.fold_deg.is_finite() { format!("{:.2}", p.fold_deg) } else { "–".into() },
                    r.frequency_hz(),
                    100.0 * r.damping_ratio(),
                    r.real
                );
            }
        }
    }
    s.push_str("</table>\n");
    s.push_str(&flight_table(runs));
    for (file, cap) in [
        ("stability_vg.svg", "V-g and V-f (ANCF solid, GEBF dashed)"),
        ("stability_locus.svg", "Root locus"),
        ("stability_modes.svg", "Structural mode shapes at the first airspeed"),
    ] {
        let _ = writeln!(
            s,
            "<figure><img src=\"{folder}/{file}\" alt=\"{cap}\" loading=\"lazy\"><figcaption>{cap}</figcaption></figure>"
        );
    }
    s
}

/// The rigid-body roots of sweeps about trim: per formulation and airspeed, each root's name,
/// `s`, period, damping ratio and time to half (negative: to double) amplitude. Empty without.
fn flight_table(runs: &[StabilityOutput]) -> String {
    if runs.iter().all(|o| o.points.iter().all(|p| p.flight_roots.is_empty())) {
        return String::new();
    }
    let mut s = String::from(
        "<table><caption>Flight-dynamics roots about the trim</caption><tr><th>formulation</th>\
         <th>airspeed (m/s)</th><th>mode</th><th>s (1/s)</th><th>period (s)</th><th>ζ</th>\
         <th>time to half (s; negative: to double)</th></tr>\n",
    );
    for o in runs {
        for p in &o.points {
            for r in &p.flight_roots {
                let period = if r.imag > 0.0 { format!("{:.3}", r.period_s()) } else { "–".into() };
                let _ = writeln!(
                    s,
                    "<tr><td>{}</td><td>{:.2}</td><td>{}</td><td>{:+.5} {} {:.5}i</td><td>{period}</td>\
                     <td>{:.4}</td><td>{:.2}</td></tr>",
                    o.formulation.as_str().to_uppercase(),
                    p.airspeed,
                    r.name.replace('_', " "),
                    r.real,
                    if r.imag >= 0.0 { '+' } else { '−' },
                    r.imag.abs(),
                    r.damping_ratio(),
                    -std::f64::consts::LN_2 / r.real
                );
            }
        }
    }
    s.push_str("</table>\n");
    s
}

/// The stability sections of every sweep written under `out`, in name order.
pub fn sections_html(out: &Path) -> String {
    crate::report::fragments(out, SECTION_FILE)
}
