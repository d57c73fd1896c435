//! The animated 3-D view of `reports/index.html`: an [`Observer`] that keeps a decimated copy of
//! a run's geometry (beams with their section frames, the wing's leading and trailing edges, the
//! wake) and writes it as `<out>/<case>/view_<formulation>.json`, and the self-contained viewer
//! (`harness/assets/view3d.js`, canvas 2-D with an orbiting camera) that the report inlines with
//! the data.
//!
//! Decimated in time (at most [`MAX_FRAMES`] frames per run) and in space (at most
//! [`MAX_BEAM_POINTS`] nodes per body, [`MAX_WAKE_ROWS`] × [`MAX_WAKE_COLUMNS`] wake nodes), with
//! coordinates stored as integers in units of 10⁻⁴ of the span, so that the report of
//! `harness all` carries every view in a few megabytes (docs/outputs.md §8).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::case::{Case, Formulation, RunSpec};
use crate::run::{Observer, Snapshot};

/// Most frames kept per run.
pub const MAX_FRAMES: usize = 150;
/// Most nodes kept per body.
pub const MAX_BEAM_POINTS: usize = 17;
/// Most spanwise stations of the wing's edges kept.
pub const MAX_EDGE_COLUMNS: usize = 33;
/// Most wake node rows kept (the trailing edge included).
pub const MAX_WAKE_ROWS: usize = 16;
/// Most wake node columns kept.
pub const MAX_WAKE_COLUMNS: usize = 9;
/// Coordinate quantum as a fraction of the span.
const QUANTUM: f64 = 1e-4;

/// One kept output step. Coordinates are integers in units of `ViewData::scale`.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Frame {
    /// Time, s.
    pub t: f64,
    /// Per body: node positions, x y z flattened.
    pub beams: Vec<Vec<i64>>,
    /// Per body: the section's y axis (chord direction) at each kept node, in hundredths.
    pub e2: Vec<Vec<i64>>,
    /// The lattice's first lifting surface and its wake (empty without aerodynamics).
    #[serde(flatten)]
    pub surface: SurfaceFrame,
    /// The lattice's further lifting surfaces, each drawn as the first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub more_surfaces: Vec<SurfaceFrame>,
}

/// One lifting surface of a frame: its edges, control surfaces and wake.
#[derive(Debug, Clone, Default, Serialize)]
pub struct SurfaceFrame {
    /// Leading-edge points of the lattice, x y z flattened.
    pub le: Vec<i64>,
    /// Trailing-edge points of the lattice.
    pub te: Vec<i64>,
    /// Per run of neighbouring grid columns carrying a control surface: its hinge-line points,
    /// then as many trailing-edge points (the deflected flap's edges), x y z flattened.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub flaps: Vec<Vec<i64>>,
    /// Wake nodes, row by row (row 0 the trailing edge), x y z flattened.
    pub wake: Vec<i64>,
    /// Number of wake node rows in `wake`.
    pub wake_rows: usize,
    /// Number of wake node columns in `wake`.
    pub wake_cols: usize,
}

/// What one run's view file holds.
#[derive(Debug, Clone, Serialize)]
pub struct ViewData {
    /// Formulation.
    pub formulation: Formulation,
    /// Metres per coordinate unit.
    pub scale: f64,
    /// Span of the case (sum of body lengths), m.
    pub span: f64,
    /// Kept frames in time order.
    pub frames: Vec<Frame>,
}

/// Records a decimated copy of every `stride`-th snapshot and writes it to `path` as JSON when
/// dropped (the run's end, successful or not).
#[derive(Debug)]
pub struct ViewRecorder {
    path: PathBuf,
    stride: usize,
    data: ViewData,
}

/// Output rows a run of formulation `f` of `case` records (as the time loops count them).
pub fn output_rows(case: &Case, f: Formulation) -> usize {
    let s = crate::scene::settings(case, f);
    let dt = s.params.dt;
    let n_steps = (s.t_end / dt).round().max(1.0) as usize;
    let every = s.output_dt.map_or(1, |o| ((o / dt).round() as usize).max(1));
    n_steps / every + 1
}

/// The view file of formulation `f` of run `case_name` under `out`.
pub fn view_path(out: &Path, case_name: &str, f: Formulation) -> PathBuf {
    out.join(case_name).join(format!("view_{f}.json"))
}

impl ViewRecorder {
    /// A recorder for formulation `f` of `case`, run under the name `case_name`, writing into
    /// `out` ([`view_path`]).
    pub fn new(out: &Path, case_name: &str, case: &Case, f: Formulation) -> Self {
        let stride = output_rows(case, f).div_ceil(MAX_FRAMES).max(1);
        let span = case.span().max(f64::MIN_POSITIVE);
        Self {
            path: view_path(out, case_name, f),
            stride,
            data: ViewData { formulation: f, scale: span * QUANTUM, span, frames: Vec::new() },
        }
    }

    /// The frames recorded so far.
    pub fn data(&self) -> &ViewData {
        &self.data
    }

    /// Write the view file now.
    pub fn write(&self) -> Result<(), String> {
        if let Some(d) = self.path.parent() {
            std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
        }
        let json = serde_json::to_string(&self.data).map_err(|e| e.to_string())?;
        std::fs::write(&self.path, json).map_err(|e| format!("{}: {e}", self.path.display()))
    }
}

impl Drop for ViewRecorder {
    fn drop(&mut self) {
        if let Err(e) = self.write() {
            eprintln!("3-D view not written: {e}");
        }
    }
}

/// `k` indices spread evenly over `0..n`, both ends included.
fn spread(n: usize, k: usize) -> Vec<usize> {
    if n <= k || k < 2 {
        return (0..n).collect();
    }
    let mut v: Vec<usize> = (0..k).map(|i| (i * (n - 1) + (k - 1) / 2) / (k - 1)).collect();
    v.dedup();
    v
}

impl Observer for ViewRecorder {
    fn observe(&mut self, s: &Snapshot<'_>) -> Result<(), String> {
        if !s.index.is_multiple_of(self.stride) {
            return Ok(());
        }
        let q = 1.0 / self.data.scale;
        let quant = |p: [f64; 3], out: &mut Vec<i64>| out.extend(p.iter().map(|v| (v * q).round() as i64));
        let mut f = Frame { t: s.t, ..Frame::default() };
        for b in s.beams {
            let (mut pos, mut e2) = (Vec::new(), Vec::new());
            for i in spread(b.positions.len(), MAX_BEAM_POINTS) {
                let p = b.positions[i];
                quant([p.x, p.y, p.z], &mut pos);
                e2.extend((0..3).map(|r| (100.0 * b.frames[i][(r, 1)]).round() as i64));
            }
            f.beams.push(pos);
            f.e2.push(e2);
        }
        if let Some(uv) = s.aero {
            for (k, su) in uv.surfaces().iter().enumerate() {
                let sf = surface_frame(su.lattice(), su.wake(), &quant);
                if k == 0 {
                    f.surface = sf;
                } else {
                    f.more_surfaces.push(sf);
                }
            }
        }
        self.data.frames.push(f);
        Ok(())
    }
}

/// The frame of one lifting surface: lattice `l` and its wake `w`, quantised by `quant`.
fn surface_frame(l: &uvlm::Lattice, w: &uvlm::Wake, quant: &impl Fn([f64; 3], &mut Vec<i64>)) -> SurfaceFrame {
    let mut f = SurfaceFrame::default();
    let (m, n) = (l.n_chordwise(), l.n_spanwise());
    let mut cols = spread(n + 1, MAX_EDGE_COLUMNS);
    if let Some(h) = l.hinge_column() {
        cols.push(h);
        cols.sort_unstable();
        cols.dedup();
    }
    for &j in &cols {
        quant(l.grid_nodes()[l.node_index(0, j)], &mut f.le);
        quant(l.grid_nodes()[l.node_index(m, j)], &mut f.te);
    }
    f.flaps = flap_runs(l, quant);
    let rows = spread(w.n_rows() + 1, MAX_WAKE_ROWS);
    let wcols = spread(w.n_spanwise() + 1, MAX_WAKE_COLUMNS);
    for &r in &rows {
        for &j in &wcols {
            let p = if r == 0 { l.ring_nodes()[l.node_index(m, j)] } else { w.node(r - 1, j) };
            quant(p, &mut f.wake);
        }
    }
    f.wake_rows = rows.len();
    f.wake_cols = wcols.len();
    f
}

/// The control surfaces of lattice `l`: per run of neighbouring flapped grid columns, the hinge
/// points then the trailing-edge points, quantised by `quant`.
fn flap_runs(l: &uvlm::Lattice, quant: &impl Fn([f64; 3], &mut Vec<i64>)) -> Vec<Vec<i64>> {
    let m = l.n_chordwise();
    let mut runs: Vec<Vec<usize>> = Vec::new();
    for (j, f) in l.column_flaps().iter().enumerate() {
        match (f, runs.last_mut()) {
            (Some(_), Some(run)) if run.last() == Some(&(j - 1)) => run.push(j),
            (Some(_), _) => runs.push(vec![j]),
            (None, _) => {}
        }
    }
    runs.into_iter()
        .filter(|run| run.len() > 1)
        .map(|run| {
            let mut out = Vec::with_capacity(6 * run.len());
            for &j in &run {
                let hinge = l.column_flaps()[j].map_or([0.0; 3], |f| f.hinge_point);
                quant(hinge, &mut out);
            }
            for &j in &run {
                quant(l.grid_nodes()[l.node_index(m, j)], &mut out);
            }
            out
        })
        .collect()
}

/// The observer of a run of `harness all`: its [`ViewRecorder`], plus the case's ParaView
/// writer when the case asks for one (its `vtk` block, [`crate::vtk::writer_for`]).
pub fn report_observer(out: &Path, spec: &RunSpec, f: Formulation) -> Box<dyn Observer> {
    let view = Box::new(ViewRecorder::new(out, &spec.name, spec.case(f), f));
    match crate::vtk::writer_for(out, spec, f, None) {
        Some(w) => Box::new(crate::vtk::Fanout(vec![view, Box::new(w)])),
        None => view,
    }
}

/// The viewer's script (inlined once into `index.html`).
pub const VIEWER_JS: &str = include_str!("../assets/view3d.js");

/// The HTML of one case's 3-D view: a canvas with its controls and the data of both formulations
/// read from `<out>/<case>/view_<f>.json`; None when no view file exists.
pub fn view_html(out: &Path, case_name: &str, id: &str) -> Option<String> {
    let mut parts = Vec::new();
    for f in Formulation::ALL {
        if let Ok(s) = std::fs::read_to_string(view_path(out, case_name, f)) {
            parts.push(format!("\"{f}\":{s}"));
        }
    }
    if parts.is_empty() {
        return None;
    }
    // JSON inside a <script> element: only "</" could end it early.
    let data = format!("{{{}}}", parts.join(",")).replace("</", "<\\/");
    Some(format!(
        "<div class=\"view3d\" id=\"{id}-view\" data-view=\"{id}\">\
         <canvas width=\"880\" height=\"440\" aria-label=\"3-D view of {id}\"></canvas>\
         <div class=\"controls\"><button type=\"button\" class=\"play\">Play</button> \
         <input type=\"range\" class=\"time\" min=\"0\" max=\"1000\" value=\"0\" aria-label=\"time\"> \
         <span class=\"tlabel\">t = 0 s</span> \
         <label><input type=\"checkbox\" class=\"show-ancf\" checked> ANCF</label> \
         <label><input type=\"checkbox\" class=\"show-gebf\" checked> GEBF</label> \
         <button type=\"button\" class=\"reset\">Reset view</button></div>\
         <script type=\"application/json\" class=\"view-data\">{data}</script></div>\n"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_keeps_both_ends_and_at_most_k() {
        assert_eq!(spread(5, 17), vec![0, 1, 2, 3, 4]);
        let v = spread(101, 16);
        assert_eq!((v[0], *v.last().unwrap(), v.len()), (0, 100, 16));
        assert!(v.windows(2).all(|w| w[0] < w[1]));
    }
}
