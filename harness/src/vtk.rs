//! ParaView output: an [`Observer`] that writes XML VTK PolyData files (`.vtp`) of the beams, the
//! bound vortex lattice and the wake, with a `.pvd` time collection per family.
//!
//! Hand-written ASCII XML rather than the `vtkio` crate: PolyData is a few lines of XML per file,
//! and `vtkio` would be a large dependency for that.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::case::{Case, Formulation};
use crate::run::{Observer, Snapshot};
use crate::scene::settings;

/// The three file families, in the order they are written.
const FAMILIES: [&str; 3] = ["beams", "lattice", "wake"];

/// Writes every `stride`-th snapshot of one run as `beams_<k>.vtp` (and, with aerodynamics,
/// `lattice_<k>.vtp` and `wake_<k>.vtp`) into `dir`, `k` the output row index, and keeps
/// `beams.pvd` (`lattice.pvd`, `wake.pvd`) listing every written step with its time.
///
/// The collections are rewritten after each written step, so they stay valid when the run stops
/// early; [`VtkWriter::finish`] (also called on drop) writes them once more.
#[derive(Debug)]
pub struct VtkWriter {
    dir: PathBuf,
    stride: usize,
    created: bool,
    /// Per family: (time, file name) of each written step.
    steps: [Vec<(f64, String)>; 3],
}

impl VtkWriter {
    /// A writer into `dir` (created at the first write) of every `stride`-th snapshot (0 is
    /// taken as 1).
    pub fn new(dir: impl Into<PathBuf>, stride: usize) -> Self {
        Self { dir: dir.into(), stride: stride.max(1), created: false, steps: Default::default() }
    }

    /// The writer of formulation `f` of a case under `out`: `<out>/<case>/vtk/<formulation>/`.
    pub fn for_run(out: &Path, case_name: &str, f: Formulation, stride: usize) -> Self {
        Self::new(out.join(case_name).join("vtk").join(f.to_string()), stride)
    }

    /// The folder written into.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Number of steps written so far.
    pub fn n_written(&self) -> usize {
        self.steps[0].len()
    }

    /// Write the `.pvd` collections of every family written so far.
    pub fn finish(&mut self) -> Result<(), String> {
        for (family, steps) in FAMILIES.iter().zip(&self.steps) {
            if !steps.is_empty() {
                write(&self.dir.join(format!("{family}.pvd")), &pvd(steps))?;
            }
        }
        Ok(())
    }

    fn write_family(&mut self, family: usize, k: usize, t: f64, text: &str) -> Result<(), String> {
        let name = format!("{}_{k:06}.vtp", FAMILIES[family]);
        write(&self.dir.join(&name), text)?;
        self.steps[family].push((t, name));
        Ok(())
    }
}

impl Drop for VtkWriter {
    fn drop(&mut self) {
        // Errors were reported by `observe`; nothing to report them to here.
        let _ = self.finish();
    }
}

impl Observer for VtkWriter {
    fn observe(&mut self, s: &Snapshot<'_>) -> Result<(), String> {
        if !s.index.is_multiple_of(self.stride) {
            return Ok(());
        }
        if !self.created {
            std::fs::create_dir_all(&self.dir).map_err(|e| format!("{}: {e}", self.dir.display()))?;
            self.created = true;
        }
        self.write_family(0, s.index, s.t, &beams_vtp(s))?;
        if let Some(uv) = s.aero {
            self.write_family(1, s.index, s.t, &lattice_vtp(uv))?;
            self.write_family(2, s.index, s.t, &wake_vtp(uv))?;
        }
        self.finish()
    }
}

/// The default stride of formulation `f` of `case`: about 100 frames over the run,
/// max(1, output rows / 100).
pub fn default_stride(case: &Case, f: Formulation) -> usize {
    let s = settings(case, f);
    let dt = s.params.dt;
    // As the time loops count their steps.
    let n_steps = (s.t_end / dt).round().max(1.0) as usize;
    let every = s.output_dt.map_or(1, |o| ((o / dt).round() as usize).max(1));
    let rows = n_steps / every + 1;
    (rows / 100).max(1)
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// A `.pvd` collection of `(time, file)` steps.
fn pvd(steps: &[(f64, String)]) -> String {
    let mut x = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for (t, f) in steps {
        let _ = writeln!(x, "<DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{f}\"/>");
    }
    x.push_str("</Collection>\n</VTKFile>\n");
    x
}

/// A data array: `values` written with `{:e}` (exact round trip).
fn array_f64(x: &mut String, name: Option<&str>, components: usize, values: impl Iterator<Item = f64>) {
    let name = name.map(|n| format!(" Name=\"{n}\"")).unwrap_or_default();
    let _ = writeln!(x, "<DataArray type=\"Float64\"{name} NumberOfComponents=\"{components}\" format=\"ascii\">");
    for v in values {
        let _ = write!(x, "{v:e} ");
    }
    x.push_str("\n</DataArray>\n");
}

fn array_i64(x: &mut String, name: &str, values: impl Iterator<Item = usize>) {
    let _ = writeln!(x, "<DataArray type=\"Int64\" Name=\"{name}\" format=\"ascii\">");
    for v in values {
        let _ = write!(x, "{v} ");
    }
    x.push_str("\n</DataArray>\n");
}

/// The opening of a PolyData piece.
fn header(x: &mut String, n_points: usize, n_lines: usize, n_polys: usize) {
    let _ = write!(
        x,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n\
         <Piece NumberOfPoints=\"{n_points}\" NumberOfVerts=\"0\" NumberOfLines=\"{n_lines}\" \
         NumberOfStrips=\"0\" NumberOfPolys=\"{n_polys}\">\n"
    );
}

const FOOTER: &str = "</Piece>\n</PolyData>\n</VTKFile>\n";

/// Connectivity and offsets of cells given as lists of point indices.
fn cells(x: &mut String, tag: &str, cells: &[Vec<usize>]) {
    let _ = writeln!(x, "<{tag}>");
    array_i64(x, "connectivity", cells.iter().flatten().copied());
    array_i64(
        x,
        "offsets",
        cells.iter().scan(0, |o, c| {
            *o += c.len();
            Some(*o)
        }),
    );
    let _ = writeln!(x, "</{tag}>");
}

/// Every body as a polyline through its nodes; point data: frame axes `e1`, `e2`, `e3`,
/// arclength `s`, `body`.
fn beams_vtp(s: &Snapshot<'_>) -> String {
    let n: usize = s.beams.iter().map(|b| b.positions.len()).sum();
    let mut x = String::new();
    header(&mut x, n, s.beams.len(), 0);
    x.push_str("<PointData Vectors=\"e1\" Scalars=\"s\">\n");
    for (c, name) in ["e1", "e2", "e3"].iter().enumerate() {
        let v = s.beams.iter().flat_map(|b| &b.frames).flat_map(|r| (0..3).map(move |i| r[(i, c)]));
        array_f64(&mut x, Some(name), 3, v);
    }
    array_f64(&mut x, Some("s"), 1, s.beams.iter().flat_map(|b| b.arc.iter().copied()));
    array_i64(&mut x, "body", s.beams.iter().enumerate().flat_map(|(k, b)| std::iter::repeat_n(k, b.positions.len())));
    x.push_str("</PointData>\n<Points>\n");
    array_f64(&mut x, None, 3, s.beams.iter().flat_map(|b| &b.positions).flat_map(|p| p.iter().copied()));
    x.push_str("</Points>\n");
    let mut start = 0;
    let lines: Vec<Vec<usize>> = s
        .beams
        .iter()
        .map(|b| {
            let l = (start..start + b.positions.len()).collect();
            start += b.positions.len();
            l
        })
        .collect();
    cells(&mut x, "Lines", &lines);
    x.push_str(FOOTER);
    x
}

/// Quads with cell data `gamma`.
fn quads_vtp(points: &[[f64; 3]], quads: &[Vec<usize>], gamma: &[f64]) -> String {
    let mut x = String::new();
    header(&mut x, points.len(), 0, quads.len());
    x.push_str("<CellData Scalars=\"gamma\">\n");
    array_f64(&mut x, Some("gamma"), 1, gamma.iter().copied());
    x.push_str("</CellData>\n<Points>\n");
    array_f64(&mut x, None, 3, points.iter().flatten().copied());
    x.push_str("</Points>\n");
    cells(&mut x, "Polys", quads);
    x.push_str(FOOTER);
    x
}

/// The bound vortex rings (corners: the ring nodes), circulation `gamma`.
fn lattice_vtp(uv: &uvlm::Uvlm) -> String {
    let l = uv.lattice();
    let (m, n) = (l.n_chordwise(), l.n_spanwise());
    let mut quads = Vec::with_capacity(m * n);
    let mut gamma = Vec::with_capacity(m * n);
    for i in 0..m {
        for j in 0..n {
            quads.push(l.ring_corners(i, j).to_vec());
            gamma.push(uv.gamma()[l.ring_index(i, j)]);
        }
    }
    quads_vtp(l.ring_nodes(), &quads, &gamma)
}

/// The wake rings: node row 0 is the lattice's trailing-edge ring row, node row r + 1 the wake's
/// detached row r; circulation `gamma`.
fn wake_vtp(uv: &uvlm::Uvlm) -> String {
    let l = uv.lattice();
    let w = uv.wake();
    let (n, rows) = (w.n_spanwise(), w.n_rows());
    let nc = n + 1;
    let te = l.n_chordwise();
    let mut points: Vec<[f64; 3]> = (0..nc).map(|j| l.ring_nodes()[l.node_index(te, j)]).collect();
    for r in 0..rows {
        points.extend((0..nc).map(|j| w.node(r, j)));
    }
    let mut quads = Vec::with_capacity(rows * n);
    let mut gamma = Vec::with_capacity(rows * n);
    for r in 0..rows {
        for j in 0..n {
            quads.push(vec![r * nc + j, r * nc + j + 1, (r + 1) * nc + j + 1, (r + 1) * nc + j]);
            gamma.push(w.gamma(r, j));
        }
    }
    quads_vtp(&points, &quads, &gamma)
}
