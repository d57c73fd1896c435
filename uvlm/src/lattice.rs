//! The structured vortex-ring lattice of one lifting surface.
//!
//! Grid nodes `G(i, j)`, `i = 0..=M` chordwise (0 = leading edge), `j = 0..=N` spanwise, are
//! generated from the span stations (one station per grid column). The vortex rings are the
//! grid panels shifted a quarter panel downstream *along the grid lines*:
//! `X(i, j) = G(i, j) + ¼ (G(i+1, j) − G(i, j))` for `i < M` and
//! `X(M, j) = G(M, j) + ¼ (G(M, j) − G(M−1, j))` (the trailing-edge ring reaches a quarter panel
//! past the trailing edge, where the wake starts). Ring `(i, j)` has corners
//! `A = X(i, j)`, `B = X(i, j+1)`, `C = X(i+1, j+1)`, `D = X(i+1, j)`, traversed A→B→C→D, unit
//! normal `n = (C − A) × (B − D) / |…|` (along the stations' `z_s`), area `½|(C − A) × (B − D)|`,
//! collocation point at the ring centroid (the ¾-chord point of a uniform geometric panel).
//! A positive circulation gives lift along `n` when the flow comes from the leading edge.
//!
//! A flared hinge is an interior grid column: the rings on both sides reference the same node
//! entries, so the hinge edge is one filament carrying the net circulation.
//!
//! A station's control surface puts a grid row of its column on the hinge and rotates the rows
//! behind it about the hinge line ([`crate::ColumnFlap`], docs/uvlm.md §15).

use crate::error::{Result, UvlmError};
use crate::flap::{ColumnFlap, flap_eta, hinge_row, rotate_about};
use crate::station::{SpanStation, StationVelocity};
use serde::{Deserialize, Serialize};

/// Chordwise distribution of the grid rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChordwiseSpacing {
    /// Equal panels.
    #[default]
    Uniform,
    /// Cosine clustering at both edges: `η_i = (1 − cos(π i/M))/2`.
    Cosine,
}

impl ChordwiseSpacing {
    /// Chordwise fraction of grid row `i` of `m` panels.
    pub fn eta(&self, i: usize, m: usize) -> f64 {
        let t = i as f64 / m as f64;
        match self {
            ChordwiseSpacing::Uniform => t,
            ChordwiseSpacing::Cosine => 0.5 * (1.0 - (std::f64::consts::PI * t).cos()),
        }
    }
}

/// Largest flare angle of a hinge column, degrees (exclusive): beyond it the slanted column's
/// panels degenerate (their spanwise edges approach the chordwise lines).
pub const MAX_HINGE_FLARE_DEG: f64 = 80.0;

/// A flared hinge placed on an interior grid column.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HingeColumn {
    /// Grid column of the hinge (1..N−1).
    pub column: usize,
    /// Flare angle β, rad: the column follows `a = sinβ·x_s + cosβ·y_s` of that station's frame.
    pub flare: f64,
}

/// How to mesh the stations.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatticeSpec {
    /// Number of chordwise panels M (≥ 1).
    pub n_chordwise: usize,
    /// Chordwise distribution.
    #[serde(default)]
    pub spacing: ChordwiseSpacing,
    /// Optional flared hinge column (overrides that station's `slant` with the flare angle).
    #[serde(default)]
    pub hinge: Option<HingeColumn>,
    /// Smallest admissible panel corner angle, degrees (default 2°): smaller means over-skewed.
    #[serde(default = "default_min_corner_angle")]
    pub min_corner_angle_deg: f64,
}

fn default_min_corner_angle() -> f64 {
    2.0
}

impl LatticeSpec {
    /// `n_chordwise` uniform panels, no hinge.
    pub fn new(n_chordwise: usize) -> Self {
        Self { n_chordwise, spacing: ChordwiseSpacing::Uniform, hinge: None, min_corner_angle_deg: 2.0 }
    }
}

/// Largest turn between consecutive spanwise grid steps (or between adjacent panel normals)
/// before the grid counts as folded over, as its cosine (150°): folds up to ±150° are admissible
/// (wind-tunnel wingtips coast past ±125° in sideslip; the tip then still lies clear of the
/// inner wing).
const MAX_TURN_COS: f64 = -0.866_025_403_784_438_6;

/// The lattice: grid, ring nodes, collocation points, normals, areas and node velocities.
#[derive(Debug, Clone)]
pub struct Lattice {
    spec: LatticeSpec,
    m: usize,
    n: usize,
    eta: Vec<f64>,
    grid: Vec<[f64; 3]>,
    grid_vel: Vec<[f64; 3]>,
    scratch: Vec<[f64; 3]>,
    ring: Vec<[f64; 3]>,
    ring_vel: Vec<[f64; 3]>,
    colloc: Vec<[f64; 3]>,
    colloc_vel: Vec<[f64; 3]>,
    normal: Vec<[f64; 3]>,
    area: Vec<f64>,
    flaps: Vec<Option<ColumnFlap>>,
    flaps_scratch: Vec<Option<ColumnFlap>>,
    version: u64,
}

#[inline]
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
#[inline]
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
#[inline]
fn lerp(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])]
}

impl Lattice {
    /// Mesh the stations (at rest). One grid column per station, `stations.len() − 1` spanwise
    /// panels.
    pub fn from_stations(spec: LatticeSpec, stations: &[SpanStation]) -> Result<Self> {
        if stations.len() < 2 {
            return Err(UvlmError::TooFewStations { n_stations: stations.len() });
        }
        if spec.n_chordwise == 0 {
            return Err(UvlmError::TooFewChordwise { n_chordwise: 0 });
        }
        if !(spec.min_corner_angle_deg.is_finite() && (0.0..90.0).contains(&spec.min_corner_angle_deg)) {
            return Err(UvlmError::InvalidParameter {
                field: "min_corner_angle_deg",
                value: spec.min_corner_angle_deg,
            });
        }
        let m = spec.n_chordwise;
        let n = stations.len() - 1;
        if let Some(h) = spec.hinge {
            if h.column == 0 || h.column >= n {
                return Err(UvlmError::HingeNotInterior { column: h.column, n_columns_minus_one: n });
            }
            if !(h.flare.is_finite() && h.flare.abs() < MAX_HINGE_FLARE_DEG.to_radians()) {
                return Err(UvlmError::InvalidParameter { field: "hinge.flare", value: h.flare });
            }
        }
        let nn = (m + 1) * (n + 1);
        let mut lat = Self {
            spec,
            m,
            n,
            eta: (0..=m).map(|i| spec.spacing.eta(i, m)).collect(),
            grid: vec![[0.0; 3]; nn],
            grid_vel: vec![[0.0; 3]; nn],
            scratch: vec![[0.0; 3]; nn],
            ring: vec![[0.0; 3]; nn],
            ring_vel: vec![[0.0; 3]; nn],
            colloc: vec![[0.0; 3]; m * n],
            colloc_vel: vec![[0.0; 3]; m * n],
            normal: vec![[0.0; 3]; m * n],
            area: vec![0.0; m * n],
            flaps: vec![None; n + 1],
            flaps_scratch: vec![None; n + 1],
            version: 0,
        };
        lat.update_stations(stations, None)?;
        Ok(lat)
    }

    /// Move the lattice to new station frames (and velocities; `None` = at rest). Does not
    /// allocate. On error the lattice keeps its previous geometry.
    pub fn update_stations(&mut self, stations: &[SpanStation], velocities: Option<&[StationVelocity]>) -> Result<()> {
        let nc = self.n + 1;
        if stations.len() != nc {
            return Err(UvlmError::LengthMismatch { what: "stations", expected: nc, got: stations.len() });
        }
        if let Some(v) = velocities
            && v.len() != nc
        {
            return Err(UvlmError::LengthMismatch { what: "station velocities", expected: nc, got: v.len() });
        }
        for (j, st) in stations.iter().enumerate() {
            st.validate(j)?;
            if st.flap.is_some() && self.m < 2 {
                return Err(UvlmError::FlapTooFewChordwise { station: j, n_chordwise: self.m });
            }
            if let Some(v) = velocities
                && !(v[j].linear.iter().chain(v[j].angular.iter()).all(|x| x.is_finite()))
            {
                return Err(UvlmError::InvalidStation { station: j, field: "velocity", value: f64::NAN });
            }
        }
        for (j, st) in stations.iter().enumerate() {
            let st = column_station(&self.spec, st, j);
            let flap = st.flap.map(|f| (f.chord_fraction, hinge_row(self.m, f.chord_fraction)));
            for i in 0..=self.m {
                let eta = match flap {
                    Some((e, row)) => flap_eta(self.spec.spacing, i, self.m, row, e),
                    None => self.eta[i],
                };
                let p = st.origin + st.arm(eta);
                self.scratch[i * nc + j] = [p.x, p.y, p.z];
            }
        }
        self.deflect_flaps(stations);
        self.validate_grid(&self.scratch)?;
        std::mem::swap(&mut self.grid, &mut self.scratch);
        std::mem::swap(&mut self.flaps, &mut self.flaps_scratch);
        for (j, st) in stations.iter().enumerate() {
            for i in 0..=self.m {
                let k = i * nc + j;
                self.grid_vel[k] = match velocities {
                    Some(v) => {
                        let g = self.grid[k];
                        let arm = nalgebra::Vector3::new(g[0], g[1], g[2]) - st.origin;
                        let mut u: [f64; 3] = v[j].at(&arm).into();
                        if let Some(f) = self.flaps[j]
                            && i > f.hinge_row
                        {
                            // The flap's rotation relative to the section: δ̇ t × (x − h).
                            let w = crate::flap::cross(f.hinge_axis, sub(g, f.hinge_point));
                            for q in 0..3 {
                                u[q] += f.rate * w[q];
                            }
                        }
                        u
                    }
                    None => [0.0; 3],
                };
            }
        }
        self.derive();
        Ok(())
    }

    /// Set the grid nodes directly (row-major, `(M+1)·(N+1)` entries, index `i·(N+1) + j`) with
    /// their velocities, for motions not described by station frames. Does not allocate.
    pub fn set_grid(&mut self, positions: &[[f64; 3]], velocities: &[[f64; 3]]) -> Result<()> {
        let nn = self.grid.len();
        if positions.len() != nn {
            return Err(UvlmError::LengthMismatch { what: "grid positions", expected: nn, got: positions.len() });
        }
        if velocities.len() != nn {
            return Err(UvlmError::LengthMismatch { what: "grid velocities", expected: nn, got: velocities.len() });
        }
        if let Some(k) = velocities.iter().position(|v| !v.iter().all(|x| x.is_finite())) {
            return Err(UvlmError::NonFiniteNode { row: k / (self.n + 1), column: k % (self.n + 1) });
        }
        self.validate_grid(positions)?;
        self.flaps.fill(None);
        self.grid.copy_from_slice(positions);
        self.grid_vel.copy_from_slice(velocities);
        self.derive();
        Ok(())
    }

    /// Rotate the nodes behind the hinge of every flapped column of `self.scratch` (the
    /// undeflected grid of `stations`) and record the columns' flaps in `self.flaps_scratch`.
    /// The hinge line of column `j` runs through its hinge node along the undeflected hinge points
    /// (same chord fraction) of stations `j − 1` and `j + 1` (one-sided at the ends).
    fn deflect_flaps(&mut self, stations: &[SpanStation]) {
        let (m, n) = (self.m, self.n);
        let nc = n + 1;
        for j in 0..nc {
            self.flaps_scratch[j] = None;
            let Some(f) = stations[j].flap else { continue };
            let e = f.chord_fraction;
            let row = hinge_row(m, e);
            let h = self.scratch[row * nc + j];
            let hinge_of = |jj: usize| {
                let st = column_station(&self.spec, &stations[jj], jj);
                let p = st.origin + st.arm(1.0 - e);
                [p.x, p.y, p.z]
            };
            let a = if j > 0 { hinge_of(j - 1) } else { h };
            let b = if j < n { hinge_of(j + 1) } else { h };
            let d = sub(b, a);
            let len = norm(d);
            let t = [d[0] / len, d[1] / len, d[2] / len];
            for i in row + 1..=m {
                let k = i * nc + j;
                self.scratch[k] = rotate_about(self.scratch[k], h, t, f.deflection);
            }
            self.flaps_scratch[j] = Some(ColumnFlap {
                hinge_row: row,
                hinge_point: h,
                hinge_axis: t,
                chord_fraction: e,
                deflection: f.deflection,
                rate: f.rate,
            });
        }
    }

    /// Reject non-finite, non-monotone, folded, degenerate or over-skewed grids.
    fn validate_grid(&self, g: &[[f64; 3]]) -> Result<()> {
        let (m, n) = (self.m, self.n);
        let nc = n + 1;
        if let Some(k) = g.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
            return Err(UvlmError::NonFiniteNode { row: k / nc, column: k % nc });
        }
        let limit = self.spec.min_corner_angle_deg.to_radians();
        let wider = CornerTest::new(limit);
        let mut prev_normal = vec_none();
        for i in 0..m {
            for j in 0..n {
                let a = g[i * nc + j];
                let b = g[i * nc + j + 1];
                let c = g[(i + 1) * nc + j + 1];
                let d = g[(i + 1) * nc + j];
                let nrm = cross(sub(c, a), sub(b, d));
                let area = 0.5 * norm(nrm);
                let scale = norm(sub(c, a)) * norm(sub(b, d));
                if !(area > 1e-10 * scale && area > 0.0) {
                    return Err(UvlmError::DegeneratePanel { row: i, column: j, area });
                }
                let nh = [nrm[0] / (2.0 * area), nrm[1] / (2.0 * area), nrm[2] / (2.0 * area)];
                let corners = [a, b, c, d];
                let corner = |k: usize| {
                    let p = corners[k];
                    let q = sub(corners[(k + 3) % 4], p);
                    let r = sub(corners[(k + 1) % 4], p);
                    (dot(cross(q, r), nh), dot(q, r), norm(q) * norm(r) > 0.0)
                };
                // The corner angles (atan2) only where a corner is not clearly wider than the limit.
                let clear = (0..4).all(|k| {
                    let (s, co, sized) = corner(k);
                    sized && wider.clearly(s, co)
                });
                let min_angle = if clear {
                    limit
                } else {
                    (0..4)
                        .map(|k| {
                            let (s, co, sized) = corner(k);
                            if sized { s.atan2(co) } else { 0.0 }
                        })
                        .fold(f64::INFINITY, f64::min)
                };
                if min_angle < limit {
                    return Err(UvlmError::SkewedPanel {
                        row: i,
                        column: j,
                        min_angle_deg: min_angle.to_degrees(),
                        limit_deg: self.spec.min_corner_angle_deg,
                    });
                }
                if j > 0 {
                    let cos = dot(nh, prev_normal);
                    if cos <= MAX_TURN_COS {
                        return Err(UvlmError::FoldedPanels { row: i, column: j, cos });
                    }
                }
                prev_normal = nh;
            }
        }
        for i in 0..=m {
            for j in 1..n {
                let d1 = sub(g[i * nc + j], g[i * nc + j - 1]);
                let d2 = sub(g[i * nc + j + 1], g[i * nc + j]);
                let cos = dot(d1, d2) / (norm(d1) * norm(d2));
                if cos.is_nan() || cos <= MAX_TURN_COS {
                    return Err(UvlmError::NonMonotoneColumns { row: i, column: j, cos_turn: cos });
                }
            }
        }
        for j in 0..=n {
            for i in 1..m {
                let d1 = sub(g[i * nc + j], g[(i - 1) * nc + j]);
                let d2 = sub(g[(i + 1) * nc + j], g[i * nc + j]);
                let cos = dot(d1, d2) / (norm(d1) * norm(d2));
                if cos.is_nan() || cos <= 0.0 {
                    return Err(UvlmError::NonMonotoneRows { row: i, column: j, cos_turn: cos });
                }
            }
        }
        Ok(())
    }

    /// Ring nodes, collocation points, normals, areas from the grid.
    fn derive(&mut self) {
        let (m, n) = (self.m, self.n);
        let nc = n + 1;
        for j in 0..nc {
            for i in 0..=m {
                let k = i * nc + j;
                let (p, v) = if i < m {
                    (lerp(self.grid[k], self.grid[k + nc], 0.25), lerp(self.grid_vel[k], self.grid_vel[k + nc], 0.25))
                } else {
                    (lerp(self.grid[k], self.grid[k - nc], -0.25), lerp(self.grid_vel[k], self.grid_vel[k - nc], -0.25))
                };
                self.ring[k] = p;
                self.ring_vel[k] = v;
            }
        }
        for i in 0..m {
            for j in 0..n {
                let r = i * n + j;
                let ids = [i * nc + j, i * nc + j + 1, (i + 1) * nc + j + 1, (i + 1) * nc + j];
                let [a, b, c, d] = ids.map(|k| self.ring[k]);
                let nrm = cross(sub(c, a), sub(b, d));
                let len = norm(nrm);
                self.area[r] = 0.5 * len;
                self.normal[r] = [nrm[0] / len, nrm[1] / len, nrm[2] / len];
                let mut cp = [0.0; 3];
                let mut cv = [0.0; 3];
                for &k in &ids {
                    for q in 0..3 {
                        cp[q] += 0.25 * self.ring[k][q];
                        cv[q] += 0.25 * self.ring_vel[k][q];
                    }
                }
                self.colloc[r] = cp;
                self.colloc_vel[r] = cv;
            }
        }
        self.version += 1;
    }

    /// Number of chordwise panels M.
    pub fn n_chordwise(&self) -> usize {
        self.m
    }
    /// Number of spanwise panels N.
    pub fn n_spanwise(&self) -> usize {
        self.n
    }
    /// Number of rings M·N.
    pub fn n_rings(&self) -> usize {
        self.m * self.n
    }
    /// Number of nodes (M+1)·(N+1).
    pub fn n_nodes(&self) -> usize {
        (self.m + 1) * (self.n + 1)
    }
    /// Index of node `(i, j)`.
    #[inline]
    pub fn node_index(&self, i: usize, j: usize) -> usize {
        i * (self.n + 1) + j
    }
    /// Index of ring `(i, j)`.
    #[inline]
    pub fn ring_index(&self, i: usize, j: usize) -> usize {
        i * self.n + j
    }
    /// Corner node indices `[A, B, C, D]` of ring `(i, j)`.
    pub fn ring_corners(&self, i: usize, j: usize) -> [usize; 4] {
        let nc = self.n + 1;
        [i * nc + j, i * nc + j + 1, (i + 1) * nc + j + 1, (i + 1) * nc + j]
    }
    /// The meshing specification.
    pub fn spec(&self) -> &LatticeSpec {
        &self.spec
    }
    /// Hinge column, if any.
    pub fn hinge_column(&self) -> Option<usize> {
        self.spec.hinge.map(|h| h.column)
    }
    /// The control surface of every grid column as placed by the last
    /// [`update_stations`](Self::update_stations) (`None`: no flap; all `None` after
    /// [`set_grid`](Self::set_grid), which knows no stations).
    pub fn column_flaps(&self) -> &[Option<ColumnFlap>] {
        &self.flaps
    }
    /// Geometric grid nodes, m.
    pub fn grid_nodes(&self) -> &[[f64; 3]] {
        &self.grid
    }
    /// Geometric grid node velocities, m/s.
    pub fn grid_velocities(&self) -> &[[f64; 3]] {
        &self.grid_vel
    }
    /// Vortex-ring nodes (the quarter-panel shifted grid), m. Nodal loads act here.
    pub fn ring_nodes(&self) -> &[[f64; 3]] {
        &self.ring
    }
    /// The trailing-edge row of the vortex-ring nodes (node row `M`, `N + 1` nodes), m: where
    /// the wake is shed.
    pub fn trailing_edge_nodes(&self) -> &[[f64; 3]] {
        &self.ring[self.m * (self.n + 1)..]
    }
    /// Vortex-ring node velocities, m/s.
    pub fn ring_velocities(&self) -> &[[f64; 3]] {
        &self.ring_vel
    }
    /// Collocation points (ring centroids), m.
    pub fn collocation(&self) -> &[[f64; 3]] {
        &self.colloc
    }
    /// Collocation-point velocities, m/s.
    pub fn collocation_velocities(&self) -> &[[f64; 3]] {
        &self.colloc_vel
    }
    /// Unit normals of the rings.
    pub fn normals(&self) -> &[[f64; 3]] {
        &self.normal
    }
    /// Ring areas, m².
    pub fn areas(&self) -> &[f64] {
        &self.area
    }
    /// Counter incremented by every geometry update (lets solvers reuse factorisations).
    pub fn version(&self) -> u64 {
        self.version
    }
}

/// Station `j` as meshed: a flared hinge column takes the hinge's flare as its slant.
fn column_station(spec: &LatticeSpec, st: &SpanStation, j: usize) -> SpanStation {
    match spec.hinge {
        Some(h) if h.column == j => SpanStation { slant: h.flare, ..*st },
        _ => *st,
    }
}

fn vec_none() -> [f64; 3] {
    [0.0; 3]
}

/// Whether a corner angle `atan2(s, co)` is wider than `limit` (0 < limit ≤ π/2) by more than
/// rounding, without the arctangent: the angle lies in (0, π) when `s > 0`, where it exceeds
/// `limit` when `co ≤ 0` or `co sin(limit) < s cos(limit)`. A margin of 1e-9 leaves the
/// borderline corners (and `s ≤ 0`) to the arctangent, so the test never decides otherwise
/// than it would. The limit's sine (with the margin) and cosine, once per lattice check; `None`
/// for a limit outside (0, π/2], which every corner leaves to the arctangent.
struct CornerTest(Option<(f64, f64)>);

impl CornerTest {
    fn new(limit: f64) -> Self {
        Self((limit > 0.0 && limit <= std::f64::consts::FRAC_PI_2).then(|| (limit.sin() * (1.0 + 1e-9), limit.cos())))
    }

    fn clearly(&self, s: f64, co: f64) -> bool {
        match self.0 {
            Some((sin, cos)) if s > 0.0 => co <= 0.0 || co * sin < s * cos,
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Matrix3, Vector3};

    /// The corner test without the arctangent never passes a corner the arctangent puts below
    /// the limit, and passes the clear ones: corners all round the circle, limits 0.5° to 89.9°,
    /// including angles within 1e-7 rad of the limit.
    #[test]
    fn the_corner_test_agrees_with_the_arctangent() {
        let mut passed = 0;
        for li in 0..60 {
            let limit = (0.5 + 89.4 * li as f64 / 59.0).to_radians();
            let wider = CornerTest::new(limit);
            for k in 0..2000 {
                let theta = -std::f64::consts::PI + 2.0 * std::f64::consts::PI * (k as f64 + 0.37) / 2000.0;
                for (t, mag) in [(theta, 1.0), (limit + 1e-7, 3.0), (limit - 1e-7, 0.2), (limit, 7.0)] {
                    let (s, co) = (mag * t.sin(), mag * t.cos());
                    if wider.clearly(s, co) {
                        assert!(s.atan2(co) >= limit, "limit {limit}, angle {}", s.atan2(co));
                        passed += 1;
                    }
                }
            }
        }
        assert!(passed > 60 * 1000, "{passed} clear corners");
    }

    /// Stations of a flat rectangular wing along +Y with the flow along +X (x_s = Y, y_s = −X).
    fn rect(n: usize, span: f64, chord: f64) -> Vec<SpanStation> {
        let frame = Matrix3::from_columns(&[Vector3::y(), -Vector3::x(), Vector3::z()]);
        (0..=n)
            .map(|j| SpanStation::new(Vector3::new(0.0, span * j as f64 / n as f64, 0.0), frame, chord, 0.0))
            .collect()
    }

    #[test]
    fn ring_shift_collocation_normal_area() {
        let lat = Lattice::from_stations(LatticeSpec::new(4), &rect(3, 3.0, 1.0)).unwrap();
        // Leading-edge ring node a quarter panel aft of the LE: x = 0.0625; TE ring node at 1.0625.
        assert_relative_eq!(lat.ring_nodes()[0][0], 0.0625, epsilon = 1e-15);
        assert_relative_eq!(lat.ring_nodes()[lat.node_index(4, 0)][0], 1.0625, epsilon = 1e-15);
        // Collocation at 3/4 of the geometric panel: x = 0.1875 for the first row.
        assert_relative_eq!(lat.collocation()[0][0], 0.1875, epsilon = 1e-15);
        assert_relative_eq!(lat.collocation()[0][1], 0.5, epsilon = 1e-15);
        assert_relative_eq!(lat.normals()[0][2], 1.0, epsilon = 1e-15);
        let total: f64 = lat.areas().iter().sum();
        assert_relative_eq!(total, 3.0, max_relative = 1e-14);
    }

    #[test]
    fn rejects_bad_grids() {
        // Crossed stations: column 2 behind column 1.
        let mut st = rect(3, 3.0, 1.0);
        st.swap(1, 2);
        assert!(matches!(
            Lattice::from_stations(LatticeSpec::new(2), &st),
            Err(UvlmError::FoldedPanels { .. } | UvlmError::NonMonotoneColumns { .. } | UvlmError::SkewedPanel { .. })
        ));
        // Coincident stations: zero-area panel.
        let mut st = rect(3, 3.0, 1.0);
        st[2].origin = st[1].origin;
        assert!(matches!(
            Lattice::from_stations(LatticeSpec::new(2), &st),
            Err(UvlmError::DegeneratePanel { column: 1, .. } | UvlmError::SkewedPanel { .. })
        ));
        // NaN.
        let mut st = rect(3, 3.0, 1.0);
        st[1].origin.z = f64::NAN;
        assert!(matches!(Lattice::from_stations(LatticeSpec::new(2), &st), Err(UvlmError::InvalidStation { .. })));
        // Over-skewed: a station shifted by 20 chords along the flow.
        let mut st = rect(3, 3.0, 1.0);
        st[2].origin.x = 60.0;
        assert!(matches!(Lattice::from_stations(LatticeSpec::new(2), &st), Err(UvlmError::SkewedPanel { .. })));
        // Hinge must be interior.
        let spec = LatticeSpec { hinge: Some(HingeColumn { column: 3, flare: 0.1 }), ..LatticeSpec::new(2) };
        assert!(matches!(Lattice::from_stations(spec, &rect(3, 3.0, 1.0)), Err(UvlmError::HingeNotInterior { .. })));
        // Wrong length on update, geometry kept.
        let mut lat = Lattice::from_stations(LatticeSpec::new(2), &rect(3, 3.0, 1.0)).unwrap();
        let v0 = lat.version();
        assert!(matches!(lat.update_stations(&rect(4, 3.0, 1.0), None), Err(UvlmError::LengthMismatch { .. })));
        let mut bad = rect(3, 3.0, 1.0);
        bad[1].origin.y = 2.5;
        bad[2].origin.y = 1.5;
        assert!(lat.update_stations(&bad, None).is_err());
        assert_eq!(lat.version(), v0);
        assert_relative_eq!(lat.grid_nodes()[1][1], 1.0, epsilon = 1e-15);
    }

    #[test]
    fn rigid_rotation_velocities() {
        let mut lat = Lattice::from_stations(LatticeSpec::new(2), &rect(2, 2.0, 1.0)).unwrap();
        let st = rect(2, 2.0, 1.0);
        let w = Vector3::new(0.0, 0.3, 0.0);
        let vel: Vec<StationVelocity> =
            st.iter().map(|_| StationVelocity { linear: Vector3::zeros(), angular: w }).collect();
        lat.update_stations(&st, Some(&vel)).unwrap();
        for (p, v) in lat.ring_nodes().iter().zip(lat.ring_velocities()) {
            let origin_y = p[1];
            let arm = Vector3::new(p[0], p[1] - origin_y, p[2]);
            let ex = w.cross(&arm);
            for q in 0..3 {
                assert_relative_eq!(v[q], ex[q], epsilon = 1e-14);
            }
        }
    }
}
