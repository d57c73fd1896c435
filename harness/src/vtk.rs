//! ParaView output: an [`Observer`] that writes XML VTK PolyData files (`.vtp`) of the beams
//! (with their section frames), the wing's chord ribbon, the bound vortex lattice (circulation and
//! pressure jump) and the wake, with a `.pvd` time collection per family; and
//! [`write_beam_series`], which writes any set of beam geometries (a run's frames, a mode shape's
//! phases) as such a time series.
//!
//! Hand-written ASCII XML rather than the `vtkio` crate: PolyData is a few lines of XML per file,
//! and `vtkio` would be a large dependency for that.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::case::{Case, Formulation, RunSpec};
use crate::run::{BeamGeometry, Observer, Placement, Snapshot};
use aeroelastic::planform::Taper;

pub use casefile::VtkOutput;

/// The file families, in the order they are written.
const FAMILIES: [&str; 4] = ["beams", "ribbon", "lattice", "wake"];

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
    /// Chord and leading-edge offset of the sections, m, when the case has a lattice.
    chord: Option<(Taper, Taper)>,
    /// Per family: (time, file name) of each written step.
    steps: [Vec<(f64, String)>; 4],
}

impl VtkWriter {
    /// A writer into `dir` (created at the first write) of every `stride`-th snapshot (0 is
    /// taken as 1).
    pub fn new(dir: impl Into<PathBuf>, stride: usize) -> Self {
        Self { dir: dir.into(), stride: stride.max(1), created: false, chord: None, steps: Default::default() }
    }

    /// Also write each section's chord as a ribbon (`ribbon_<k>.vtp`): `chord` long, its leading
    /// edge `le_offset` ahead of the beam axis along the section's y axis (as the lattice is
    /// built, docs/uvlm.md); each a number or `[root, tip]` per body, as `aero.chord`.
    pub fn with_chord(mut self, chord: impl Into<Taper>, le_offset: impl Into<Taper>) -> Self {
        self.chord = Some((chord.into(), le_offset.into()));
        self
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
        // A run in moving axes (a flight from its trim) is written in the earth frame.
        let placed: Vec<BeamGeometry>;
        let beams = match &s.placement {
            Some(pl) => {
                placed = s
                    .beams
                    .iter()
                    .map(|b| BeamGeometry {
                        arc: b.arc.clone(),
                        positions: b.positions.iter().map(|p| pl.point(p)).collect(),
                        frames: b.frames.iter().map(|r| pl.frame(r)).collect(),
                    })
                    .collect();
                &placed[..]
            }
            None => s.beams,
        };
        self.write_family(0, s.index, s.t, &beams_vtp(beams))?;
        if let Some((chord, le)) = &self.chord {
            let text = ribbon_vtp(beams, chord, le);
            self.write_family(1, s.index, s.t, &text)?;
        }
        if let Some(uv) = s.aero {
            self.write_family(2, s.index, s.t, &lattice_vtp(uv, s.placement.as_ref()))?;
            self.write_family(3, s.index, s.t, &wake_vtp(uv, s.placement.as_ref()))?;
        }
        self.finish()
    }
}

/// The default stride of formulation `f` of `case`: about 100 frames over the run,
/// max(1, output rows / 100).
pub fn default_stride(case: &Case, f: Formulation) -> usize {
    (crate::view3d::output_rows(case, f) / 100).max(1)
}

/// The VTK writer of formulation `f` of run `spec` under `out`, when `--vtk` asks for one
/// (`cli = Some(stride)`, the stride given or not) or the case's `vtk` block does; the stride is
/// `--vtk-stride`, else the case's `vtk.stride`, else [`default_stride`]. With a lattice, the
/// writer also writes the chord ribbon.
pub fn writer_for(out: &Path, spec: &RunSpec, f: Formulation, cli: Option<Option<usize>>) -> Option<VtkWriter> {
    let case = spec.case(f);
    if cli.is_none() && case.vtk.is_none() {
        return None;
    }
    let stride = cli.flatten().or(case.vtk.and_then(|v| v.stride)).unwrap_or_else(|| default_stride(case, f));
    let w = VtkWriter::for_run(out, &spec.name, f, stride);
    let Some(a) = &case.aero else { return Some(w) };
    if let (Some(c), Some(le)) = (&a.chord, &a.le_offset) {
        return Some(w.with_chord(c.clone(), le.clone()));
    }
    // Several surfaces: each body's planform; a body on no surface has a ribbon of zero chord.
    let per_body = a.body_planforms(&case.problem()).unwrap_or_default();
    let ends = |i: usize| -> Taper { Taper::PerBody(per_body.iter().map(|p| p.map_or([0.0; 2], |x| x[i])).collect()) };
    Some(w.with_chord(ends(0), ends(1)))
}

/// Several observers fed the same snapshots, in order (the first error stops the run).
pub struct Fanout(pub Vec<Box<dyn Observer>>);

impl Observer for Fanout {
    fn wants_snapshots(&self) -> bool {
        self.0.iter().any(|o| o.wants_snapshots())
    }
    fn observe(&mut self, s: &Snapshot<'_>) -> Result<(), String> {
        self.0.iter_mut().filter(|o| o.wants_snapshots()).try_for_each(|o| o.observe(s))
    }
}

/// Write a set of beam geometries as a time series into `dir`: `<name>_<k>.vtp` for each entry
/// `k` of `frames` ((time or phase, one geometry per body)) and `<name>.pvd` listing them, in
/// the format of the `beams` family (polylines with the section frames). For a run's frames, a
/// mode shape animated over its phase, or any other sequence of configurations.
pub fn write_beam_series(dir: &Path, name: &str, frames: &[(f64, Vec<BeamGeometry>)]) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut steps = Vec::with_capacity(frames.len());
    for (k, (t, beams)) in frames.iter().enumerate() {
        let file = format!("{name}_{k:06}.vtp");
        write(&dir.join(&file), &beams_vtp(beams))?;
        steps.push((*t, file));
    }
    write(&dir.join(format!("{name}.pvd")), &pvd(&steps))
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
fn beams_vtp(beams: &[BeamGeometry]) -> String {
    let n: usize = beams.iter().map(|b| b.positions.len()).sum();
    let mut x = String::new();
    header(&mut x, n, beams.len(), 0);
    x.push_str("<PointData Vectors=\"e1\" Scalars=\"s\">\n");
    for (c, name) in ["e1", "e2", "e3"].iter().enumerate() {
        let v = beams.iter().flat_map(|b| &b.frames).flat_map(|r| (0..3).map(move |i| r[(i, c)]));
        array_f64(&mut x, Some(name), 3, v);
    }
    array_f64(&mut x, Some("s"), 1, beams.iter().flat_map(|b| b.arc.iter().copied()));
    array_i64(&mut x, "body", beams.iter().enumerate().flat_map(|(k, b)| std::iter::repeat_n(k, b.positions.len())));
    x.push_str("</PointData>\n<Points>\n");
    array_f64(&mut x, None, 3, beams.iter().flat_map(|b| &b.positions).flat_map(|p| p.iter().copied()));
    x.push_str("</Points>\n");
    let mut start = 0;
    let lines: Vec<Vec<usize>> = beams
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

/// Each body's sections as a ribbon: at every node a leading-edge point `le` ahead of the axis
/// along the section's y axis and a trailing-edge point `chord − le` behind it (points 2i and
/// 2i + 1 of a body's strip), one quad between neighbouring nodes; point data `s` and `body`.
fn ribbon_vtp(beams: &[BeamGeometry], chord: &Taper, le: &Taper) -> String {
    let n: usize = beams.iter().map(|b| b.positions.len()).sum();
    let mut points = Vec::with_capacity(2 * n);
    let mut quads = Vec::new();
    for (k, b) in beams.iter().enumerate() {
        let base = points.len();
        let length = b.arc.last().copied().unwrap_or(0.0);
        for ((p, r), &s) in b.positions.iter().zip(&b.frames).zip(&b.arc) {
            let frac = if length > 0.0 { s / length } else { 0.0 };
            let (chord, le) = (chord.at(k, frac), le.at(k, frac));
            let y = r.column(1);
            points.push(p + y * le);
            points.push(p + y * (le - chord));
        }
        for i in 1..b.positions.len() {
            let (a, c) = (base + 2 * (i - 1), base + 2 * i);
            quads.push(vec![a, c, c + 1, a + 1]);
        }
    }
    let mut x = String::new();
    header(&mut x, points.len(), 0, quads.len());
    x.push_str("<PointData Scalars=\"s\">\n");
    array_f64(&mut x, Some("s"), 1, beams.iter().flat_map(|b| b.arc.iter().flat_map(|&s| [s, s])));
    array_i64(
        &mut x,
        "body",
        beams.iter().enumerate().flat_map(|(k, b)| std::iter::repeat_n(k, 2 * b.positions.len())),
    );
    x.push_str("</PointData>\n<Points>\n");
    array_f64(&mut x, None, 3, points.iter().flat_map(|p| p.iter().copied()));
    x.push_str("</Points>\n");
    cells(&mut x, "Polys", &quads);
    x.push_str(FOOTER);
    x
}

/// Quads with cell data `gamma` (and `delta_p` when given).
fn quads_vtp(points: &[[f64; 3]], quads: &[Vec<usize>], gamma: &[f64], delta_p: Option<&[f64]>) -> String {
    let mut x = String::new();
    header(&mut x, points.len(), 0, quads.len());
    x.push_str("<CellData Scalars=\"gamma\">\n");
    array_f64(&mut x, Some("gamma"), 1, gamma.iter().copied());
    if let Some(dp) = delta_p {
        array_f64(&mut x, Some("delta_p"), 1, dp.iter().copied());
    }
    x.push_str("</CellData>\n<Points>\n");
    array_f64(&mut x, None, 3, points.iter().flatten().copied());
    x.push_str("</Points>\n");
    cells(&mut x, "Polys", quads);
    x.push_str(FOOTER);
    x
}

/// The bound vortex rings of every lifting surface (corners: the ring nodes), circulation
/// `gamma` and pressure jump `delta_p`, surface after surface in one polydata.
fn lattice_vtp(uv: &uvlm::Uvlm, place: Option<&Placement>) -> String {
    let (mut points, mut quads, mut gamma, mut dp) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for su in uv.surfaces() {
        let l = su.lattice();
        let g = &uv.gamma()[su.rings()];
        let o = points.len();
        for i in 0..l.n_chordwise() {
            for j in 0..l.n_spanwise() {
                quads.push(l.ring_corners(i, j).iter().map(|c| c + o).collect());
                gamma.push(g[l.ring_index(i, j)]);
            }
        }
        points.extend_from_slice(l.ring_nodes());
        dp.extend(surface_pressure_jump(l, su.loads()));
    }
    placed(&mut points, place);
    quads_vtp(&points, &quads, &gamma, Some(&dp))
}

/// Pressure jump across each bound ring of every lifting surface, Pa, surface after surface
/// (positive: the ring's normal side is pushed): the ring's share of the nodal loads of the last
/// solve on its corners, along its normal, over its area; a smoothed panel pressure, not a
/// separate solve. Zero before the first solve.
pub fn pressure_jump(uv: &uvlm::Uvlm) -> Vec<f64> {
    uv.surfaces().iter().flat_map(|su| surface_pressure_jump(su.lattice(), su.loads())).collect()
}

/// Pressure jump across each bound ring of lattice `l`, Pa (positive: the ring's normal side is
/// pushed): `Δp = F · n / A`, with the ring's force `F` taken as an equal share of the loads
/// `loads` on its four corner nodes among the rings meeting there (the nodal loads of the last
/// solve, steady and unsteady parts). The shares sum to the nodal loads, so `Σ Δp A n` is the
/// total normal force; it is a smoothed panel pressure, not a separate solve. Zero before the
/// first solve.
fn surface_pressure_jump(l: &uvlm::Lattice, loads: &uvlm::Loads) -> Vec<f64> {
    let (m, n) = (l.n_chordwise(), l.n_spanwise());
    let nodal = &loads.nodal;
    let mut dp = vec![0.0; m * n];
    if nodal.len() != l.n_nodes() {
        return dp;
    }
    let mut sharing = vec![0usize; l.n_nodes()];
    for i in 0..m {
        for j in 0..n {
            for c in l.ring_corners(i, j) {
                sharing[c] += 1;
            }
        }
    }
    for i in 0..m {
        for j in 0..n {
            let r = l.ring_index(i, j);
            let mut f = [0.0; 3];
            for c in l.ring_corners(i, j) {
                for (k, fk) in f.iter_mut().enumerate() {
                    *fk += nodal[c][k] / sharing[c] as f64;
                }
            }
            let nr = l.normals()[r];
            let a = l.areas()[r];
            dp[i * n + j] = if a > 0.0 { (f[0] * nr[0] + f[1] * nr[1] + f[2] * nr[2]) / a } else { 0.0 };
        }
    }
    dp
}

/// The wake rings of every lifting surface, surface after surface: per surface, node row 0 is
/// the lattice's trailing-edge ring row, node row r + 1 the wake's detached row r; circulation
/// `gamma`.
fn wake_vtp(uv: &uvlm::Uvlm, place: Option<&Placement>) -> String {
    let (mut points, mut quads, mut gamma) = (Vec::new(), Vec::new(), Vec::new());
    for su in uv.surfaces() {
        let (l, w) = (su.lattice(), su.wake());
        let (n, rows) = (w.n_spanwise(), w.n_rows());
        let nc = n + 1;
        let te = l.n_chordwise();
        let o = points.len();
        points.extend((0..nc).map(|j| l.ring_nodes()[l.node_index(te, j)]));
        for r in 0..rows {
            points.extend((0..nc).map(|j| w.node(r, j)));
        }
        for r in 0..rows {
            for j in 0..n {
                quads.push(vec![o + r * nc + j, o + r * nc + j + 1, o + (r + 1) * nc + j + 1, o + (r + 1) * nc + j]);
                gamma.push(w.gamma(r, j));
            }
        }
    }
    placed(&mut points, place);
    quads_vtp(&points, &quads, &gamma, None)
}

/// The points in the earth frame of `place` (unchanged without one).
fn placed(points: &mut [[f64; 3]], place: Option<&Placement>) {
    if let Some(pl) = place {
        for p in points {
            *p = pl.point(&nalgebra::Vector3::from(*p)).into();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector3};

    #[test]
    fn beam_series_lists_every_frame_with_its_time() {
        let dir = std::env::temp_dir().join(format!("harness-vtk-series-{}", std::process::id()));
        let body = |phase: f64| {
            let mut g = BeamGeometry::default();
            for i in 0..3 {
                let s = 0.5 * i as f64;
                g.push(s, Vector3::new(s, 0.0, 0.1 * phase.sin() * s), Matrix3::identity());
            }
            g
        };
        let frames: Vec<(f64, Vec<BeamGeometry>)> =
            (0..4).map(|k| (k as f64 * 0.25, vec![body(k as f64), body(k as f64 + 1.0)])).collect();
        write_beam_series(&dir, "mode1", &frames).unwrap();
        let pvd = std::fs::read_to_string(dir.join("mode1.pvd")).unwrap();
        assert_eq!(pvd.matches("<DataSet ").count(), 4);
        assert!(pvd.contains("timestep=\"7.5e-1\"") && pvd.contains("file=\"mode1_000003.vtp\""));
        let x = std::fs::read_to_string(dir.join("mode1_000002.vtp")).unwrap();
        assert!(x.contains("NumberOfPoints=\"6\"") && x.contains("NumberOfLines=\"2\""));
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn case_field_and_flag_choose_the_writer() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../cases/wing_aoa5.json")).unwrap();
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let out = Path::new("/nonexistent");
        let spec = |v: &serde_json::Value| {
            let dir = std::env::temp_dir().join(format!("harness-vtk-field-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            let p = dir.join("w.json");
            std::fs::write(&p, serde_json::to_string(v).unwrap()).unwrap();
            let s = crate::case::CaseFile::read(&p).and_then(|c| c.expand(&[])).map(|mut r| r.remove(0));
            std::fs::remove_dir_all(dir).ok();
            s
        };
        let s = spec(&v).unwrap();
        assert!(writer_for(out, &s, Formulation::Gebf, None).is_none());
        let w = writer_for(out, &s, Formulation::Gebf, Some(None)).unwrap();
        // 20 s at output_dt 0.01: 2001 rows, about 100 frames.
        assert_eq!(w.stride, 20);
        assert!(w.chord == Some((Taper::Uniform(1.0), Taper::Uniform(0.5))));
        v["vtk"] = serde_json::json!({ "stride": 7 });
        let s = spec(&v).unwrap();
        assert_eq!(writer_for(out, &s, Formulation::Ancf, None).unwrap().stride, 7);
        assert_eq!(writer_for(out, &s, Formulation::Ancf, Some(Some(3))).unwrap().stride, 3);
        v["vtk"] = serde_json::json!({ "stride": 0 });
        let e = spec(&v).unwrap_err().to_string();
        assert!(e.contains("vtk.stride"), "{e}");
        v["vtk"] = serde_json::json!({ "every": 2 });
        assert!(spec(&v).is_err());
    }
}
