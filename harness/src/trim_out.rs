//! `harness trim`: the trimmed state of each formulation as `trim_<formulation>.json`, and the
//! lines the command prints (docs/trim.md, docs/outputs.md §5).

use std::path::Path;

use serde_json::json;

use crate::Error;
use crate::case::RunSpec;
use crate::report::esc;
use aeroelastic::Formulation;
use aeroelastic::trim::{TrimOutput, run_trim};

/// Trim `spec` with each formulation of `fs` (in parallel); the outputs in `fs`'s order, or the
/// message when the case has no `trim` block.
pub fn run(spec: &RunSpec, fs: &[Formulation]) -> Result<Vec<TrimOutput>, String> {
    use rayon::prelude::*;
    let settings: Vec<_> = fs
        .iter()
        .map(|&f| spec.case(f).trim.clone().ok_or_else(|| "trim: the case has no `trim` block".to_string()))
        .collect::<Result<_, _>>()?;
    Ok(fs.par_iter().zip(&settings).map(|(&f, t)| run_trim(&spec.case(f).problem(), f, t)).collect())
}

/// The JSON of one trim: `alpha_deg`, `controls` (name → deg), `thrust`, the residuals and the
/// deformed state.
pub fn to_json(o: &TrimOutput) -> serde_json::Value {
    let controls: serde_json::Map<String, serde_json::Value> =
        o.controls.iter().map(|(n, d)| (n.clone(), json!(d))).collect();
    json!({
        "formulation": o.formulation.as_str(),
        "converged": o.converged,
        "error": o.error,
        "airspeed": o.airspeed,
        "alpha_deg": o.alpha_deg,
        "elevator_deg": o.elevator_deg,
        "controls": controls,
        "thrust": o.thrust,
        "residuals": {
            "force_forward": o.residuals.force_forward,
            "force_up": o.residuals.force_up,
            "pitch_moment": o.residuals.pitch_moment,
        },
        "lift": o.lift,
        "drag": o.drag,
        "profile_drag": o.profile_drag,
        "tip": o.tip,
        "iterations": o.iterations,
        "static_solves": o.static_solves,
        "wall_s": o.wall_s,
        "state": { "q": o.q },
    })
}

/// The report fragment each trimmed case leaves in its folder.
pub const SECTION_FILE: &str = "trim_section.html";

/// Write `<dir>/trim_<formulation>.json` for each output, and the report fragment
/// `<dir>/trim_section.html` of case `name`.
pub fn write(dir: &Path, name: &str, outs: &[TrimOutput]) -> Result<(), Error> {
    for o in outs {
        let text = serde_json::to_string_pretty(&to_json(o)).map_err(|e| Error::Io(e.to_string()))?;
        crate::atomic::write(&dir.join(format!("trim_{}.json", o.formulation.as_str())), text.as_bytes())?;
    }
    crate::atomic::write(&dir.join(SECTION_FILE), section_html(name, outs).as_bytes())
}

/// One case's trim table: per formulation α, elevator, thrust, the net load left, the work.
pub fn section_html(name: &str, outs: &[TrimOutput]) -> String {
    use std::fmt::Write as _;
    let mut h = format!(
        "<h3>{}</h3>\n<table><tr><th>formulation</th><th>airspeed (m/s)</th><th>α (deg)</th><th>elevator (deg)</th>\
         <th>thrust (N)</th><th>net forward / up force (N)</th><th>net pitching moment (N m)</th><th>lift (N)</th>\
         <th>drag (N)</th><th>iterations / static solves</th><th>wall (s)</th></tr>\n",
        esc(name)
    );
    for o in outs {
        let r = &o.residuals;
        let _ = match &o.error {
            None => writeln!(
                h,
                "<tr><td>{}</td><td>{:.2}</td><td>{:.4}</td><td>{:+.4}</td><td>{:.4}</td><td>{:.1e} / {:.1e}</td>\
                 <td>{:.1e}</td><td>{:.1}</td><td>{:.3}</td><td>{} / {}</td><td>{:.2}</td></tr>",
                o.formulation.label(),
                o.airspeed,
                o.alpha_deg,
                o.elevator_deg,
                o.thrust,
                r.force_forward,
                r.force_up,
                r.pitch_moment,
                o.lift,
                o.drag,
                o.iterations,
                o.static_solves,
                o.wall_s
            ),
            Some(e) => {
                writeln!(h, "<tr><td>{}</td><td colspan=\"10\">failed: {}</td></tr>", o.formulation.label(), esc(e))
            }
        };
    }
    h.push_str("</table>\n");
    h
}

/// The trim sections of every case trimmed under `out` (`<out>/<case>/trim_section.html`), in
/// name order; empty when there are none.
pub fn sections_html(out: &Path) -> String {
    crate::report::fragments(out, SECTION_FILE)
}

/// One line per formulation, kept in `lines`; true when a trim failed.
pub fn report(name: &str, outs: &[TrimOutput], lines: &mut crate::console::Lines) -> bool {
    let mut failed = false;
    for o in outs {
        let controls: Vec<String> = o.controls.iter().map(|(n, d)| format!("{n} {d:+.4} deg")).collect();
        match &o.error {
            None => lines.out(format!(
                "trim {name} {}: alpha {:.4} deg, elevator {:+.4} deg ({}), thrust {:.4} N at {:.2} m/s; net load \
                 {:.2e} N forward, {:.2e} N up, {:.2e} N m pitch; {} iterations, {} static solves, {:.2} s",
                o.formulation,
                o.alpha_deg,
                o.elevator_deg,
                controls.join(", "),
                o.thrust,
                o.airspeed,
                o.residuals.force_forward,
                o.residuals.force_up,
                o.residuals.pitch_moment,
                o.iterations,
                o.static_solves,
                o.wall_s
            )),
            Some(e) => {
                failed = true;
                lines.err(format!("trim {name} {}: FAILED: {e}", o.formulation));
            }
        }
    }
    failed
}
