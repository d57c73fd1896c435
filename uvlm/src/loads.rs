//! Aerodynamic loads on the lattice nodes.
//!
//! Steady part — Joukowski per lattice segment (Simpson, Palacios & Murua 2013), at the segment
//! midpoint with the local relative velocity:
//!
//! $$ f_s = \rho\,\Gamma_s\,\big(V_{ext}(x_s, t) + u_{ind}(x_s) - \dot x_s\big)\times(x_B - x_A),$$
//!
//! `V_ext = V∞ + u_dist` the external flow at the midpoint (see [`crate::flow`]), `Γ_s` the
//! segment's net circulation, split ½–½ to its end nodes. The trailing-edge segment
//! (net strength Γ_w0 − Γ_TE, the circulation shed during the step) is skipped by default, as in
//! SHARPy's time-marching UVLM, or included, as in Ptera Software and SHARPy's linear UVLM
//! (`te_segment_force`). Unsteady part (eq. 16 of
//! Otsuka, Cheng & Palacios 2024; Katz & Plotkin §13.12):
//!
//! $$ f_r = \rho\,A_r\,n_r\,\frac{d\Gamma_r}{dt}, $$
//!
//! split ¼ to each ring corner. The nodal forces therefore sum exactly to the panel loads, and a
//! structure can lump them to its stations as force + moment about the station origin.

use crate::aic::BoundSystem;
use crate::lattice::Lattice;
use crate::params::UvlmParams;

/// Loads of the last solve, on the vortex-ring nodes of the lattice.
#[derive(Debug, Clone, Default)]
pub struct Loads {
    /// Force on every ring node (index `i·(N+1) + j`, as [`Lattice::ring_nodes`]), N.
    pub nodal: Vec<[f64; 3]>,
    /// Force on every spanwise strip (panel column `j`), N: its spanwise edges, half of its two
    /// chordwise edges and the unsteady terms of its rings.
    pub strip: Vec<[f64; 3]>,
    /// Sum of the Joukowski (steady) segment forces, N.
    pub total_steady: [f64; 3],
    /// Sum of the unsteady ρ·A·n·dΓ/dt terms, N.
    pub total_unsteady: [f64; 3],
    /// Application points of `nodal` (copy of the ring nodes), m.
    pub positions: Vec<[f64; 3]>,
}

impl Loads {
    /// Total force, N.
    pub fn total_force(&self) -> [f64; 3] {
        let (a, b) = (self.total_steady, self.total_unsteady);
        [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
    }

    /// Total moment about `p`, N·m.
    pub fn moment_about(&self, p: [f64; 3]) -> [f64; 3] {
        let mut m = [0.0; 3];
        for (x, f) in self.positions.iter().zip(&self.nodal) {
            let r = [x[0] - p[0], x[1] - p[1], x[2] - p[2]];
            m[0] += r[1] * f[2] - r[2] * f[1];
            m[1] += r[2] * f[0] - r[0] * f[2];
            m[2] += r[0] * f[1] - r[1] * f[0];
        }
        m
    }

    /// Lift and drag, N: drag along the free stream, lift along `v̂ × ŝ` where `ŝ` is
    /// `span_dir` made perpendicular to the free stream. Pass the free stream `V∞` (a direction;
    /// a disturbance does not turn the lift/drag axes).
    pub fn lift_drag(&self, v_inf: [f64; 3], span_dir: [f64; 3]) -> (f64, f64) {
        let f = self.total_force();
        let (l, d) = lift_drag_of(f, v_inf, span_dir);
        (l, d)
    }

    /// Lump the nodal forces of every grid column `j` to the point `origins[j]`: force and moment
    /// about that point (the rigid-arm, virtual-work consistent transfer). Does not allocate.
    ///
    /// # Panics
    /// If the slices do not have one entry per grid column.
    pub fn column_loads_inplace(&self, origins: &[[f64; 3]], force: &mut [[f64; 3]], moment: &mut [[f64; 3]]) {
        lump_columns(&self.positions, &self.nodal, origins, force, moment);
    }
}

/// The loads of several surfaces as one [`Loads`]: nodal forces, positions and strips
/// concatenated in surface order (the global node and strip numbering), totals summed. Does not
/// allocate once `out` has its size.
pub(crate) fn concatenate_loads<'a>(out: &mut Loads, parts: impl Iterator<Item = &'a Loads>) {
    out.nodal.clear();
    out.strip.clear();
    out.positions.clear();
    let (mut ts, mut tu) = ([0.0; 3], [0.0; 3]);
    for l in parts {
        out.nodal.extend_from_slice(&l.nodal);
        out.strip.extend_from_slice(&l.strip);
        out.positions.extend_from_slice(&l.positions);
        for q in 0..3 {
            ts[q] += l.total_steady[q];
            tu[q] += l.total_unsteady[q];
        }
    }
    out.total_steady = ts;
    out.total_unsteady = tu;
}

/// Lump nodal forces `nodal[k]` at `positions[k]` (grid node `k`, column `k mod origins.len()`)
/// to the point `origins[j]` of every grid column `j`: force and moment about that point (the
/// rigid-arm, virtual-work consistent transfer). Does not allocate. [`Loads::column_loads_inplace`]
/// applies it to a solution's loads; the linearised analysis to its unit-response forces.
///
/// # Panics
/// If the slices do not have one entry per grid column, or the nodes do not fill whole rows.
pub fn lump_columns(
    positions: &[[f64; 3]],
    nodal: &[[f64; 3]],
    origins: &[[f64; 3]],
    force: &mut [[f64; 3]],
    moment: &mut [[f64; 3]],
) {
    let nc = origins.len();
    assert!(force.len() == nc && moment.len() == nc, "lump_columns: length mismatch");
    assert!(
        nodal.len() == positions.len() && nodal.len().is_multiple_of(nc),
        "lump_columns: origins do not match the lattice"
    );
    force.fill([0.0; 3]);
    moment.fill([0.0; 3]);
    for (k, (x, f)) in positions.iter().zip(nodal).enumerate() {
        let j = k % nc;
        let o = origins[j];
        let r = [x[0] - o[0], x[1] - o[1], x[2] - o[2]];
        for q in 0..3 {
            force[j][q] += f[q];
        }
        moment[j][0] += r[1] * f[2] - r[2] * f[1];
        moment[j][1] += r[2] * f[0] - r[0] * f[2];
        moment[j][2] += r[0] * f[1] - r[1] * f[0];
    }
}

/// Lift (⊥ free stream, along v̂ × ŝ) and drag (along v̂) components of a force.
pub fn lift_drag_of(f: [f64; 3], v_inf: [f64; 3], span_dir: [f64; 3]) -> (f64, f64) {
    let vn = (v_inf[0].powi(2) + v_inf[1].powi(2) + v_inf[2].powi(2)).sqrt();
    let v = [v_inf[0] / vn, v_inf[1] / vn, v_inf[2] / vn];
    let sd = span_dir[0] * v[0] + span_dir[1] * v[1] + span_dir[2] * v[2];
    let s = [span_dir[0] - sd * v[0], span_dir[1] - sd * v[1], span_dir[2] - sd * v[2]];
    let l = [v[1] * s[2] - v[2] * s[1], v[2] * s[0] - v[0] * s[2], v[0] * s[1] - v[1] * s[0]];
    let ln = (l[0].powi(2) + l[1].powi(2) + l[2].powi(2)).sqrt();
    let lift = (f[0] * l[0] + f[1] * l[1] + f[2] * l[2]) / ln;
    let drag = f[0] * v[0] + f[1] * v[1] + f[2] * v[2];
    (lift, drag)
}

/// Fill `loads` of surface `k` (lattice `lat`) from the solved bound system. `v_mid[s]` and
/// `u_mid[s]` are the external flow and the induced velocity at the midpoint of the surface's
/// lattice segment `s` (local numbering); `gamma_dot` the surface's ring circulation rates (None:
/// steady); `te_shed[j]` the circulation Γ_w0 of the newest wake ring of column `j`, which the
/// trailing-edge segment carries besides the bound −Γ_TE (used with `te_segment_force`; None: no
/// shed row).
#[allow(clippy::too_many_arguments)]
pub(crate) fn compute_loads(
    loads: &mut Loads,
    lat: &Lattice,
    bs: &BoundSystem,
    k: usize,
    v_mid: &[[f64; 3]],
    u_mid: &[[f64; 3]],
    gamma_dot: Option<&[f64]>,
    te_shed: Option<&[f64]>,
    params: &UvlmParams,
) {
    let (rho, te_segment_force) = (params.rho, params.te_segment_force);
    let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
    let nc = n + 1;
    let nodes = lat.ring_nodes();
    let vel = lat.ring_velocities();
    let range = bs.surface(k);
    loads.nodal.clear();
    loads.nodal.resize(nodes.len(), [0.0; 3]);
    loads.strip.clear();
    loads.strip.resize(n, [0.0; 3]);
    loads.positions.clear();
    loads.positions.extend_from_slice(nodes);
    let mut tot = [0.0; 3];
    for s in 0..range.n_lattice_seg {
        let te_row = s >= m * n + m * nc;
        if te_row && !te_segment_force {
            continue;
        }
        let mut g = bs.lattice_segment_gamma(range.seg0 + s);
        if let (true, Some(w)) = (te_row, te_shed) {
            // Net strength of the trailing-edge segment: the shed row's +Γ_w0 with the bound −Γ_TE.
            g += w[(s - (m * n + m * nc)) % n];
        }
        if g == 0.0 {
            continue;
        }
        let (a, b) = bs.fil.segment_nodes(range.seg0 + s);
        let (a, b) = (a as usize - range.node0, b as usize - range.node0);
        let dl = [nodes[b][0] - nodes[a][0], nodes[b][1] - nodes[a][1], nodes[b][2] - nodes[a][2]];
        let mut v = [0.0; 3];
        for q in 0..3 {
            v[q] = v_mid[s][q] + u_mid[s][q] - 0.5 * (vel[a][q] + vel[b][q]);
        }
        let f = [
            rho * g * (v[1] * dl[2] - v[2] * dl[1]),
            rho * g * (v[2] * dl[0] - v[0] * dl[2]),
            rho * g * (v[0] * dl[1] - v[1] * dl[0]),
        ];
        for q in 0..3 {
            loads.nodal[a][q] += 0.5 * f[q];
            loads.nodal[b][q] += 0.5 * f[q];
            tot[q] += f[q];
        }
        if s < m * n || te_row {
            let j = (s - if te_row { m * n + m * nc } else { 0 }) % n;
            for q in 0..3 {
                loads.strip[j][q] += f[q];
            }
        } else {
            let j = (s - m * n) % nc;
            let share = if j == 0 || j == n { 1.0 } else { 0.5 };
            for jj in [j.wrapping_sub(1), j] {
                if jj < n {
                    for q in 0..3 {
                        loads.strip[jj][q] += share * f[q];
                    }
                }
            }
        }
    }
    loads.total_steady = tot;
    let mut tu = [0.0; 3];
    if let Some(gd) = gamma_dot {
        // Without `unsteady_te_corners` the last row's two trailing-edge corners get nothing (as
        // SHARPy's time-marching UVLM): that row applies half its load, at its leading corners.
        let te_nodes = m * nc;
        for i in 0..m {
            for j in 0..n {
                let r = lat.ring_index(i, j);
                let c = rho * lat.areas()[r] * gd[r];
                let nr = lat.normals()[r];
                let f = [c * nr[0], c * nr[1], c * nr[2]];
                let mut applied = 0.0;
                for k in lat.ring_corners(i, j) {
                    if k >= te_nodes && !params.unsteady_te_corners {
                        continue;
                    }
                    applied += 0.25;
                    for q in 0..3 {
                        loads.nodal[k][q] += 0.25 * f[q];
                    }
                }
                for q in 0..3 {
                    loads.strip[j][q] += applied * f[q];
                    tu[q] += applied * f[q];
                }
            }
        }
    }
    loads.total_unsteady = tu;
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn lift_drag_decomposition() {
        // Free stream along +x tilted 10° up, span along +y: lift ⊥ stream in the x-z plane.
        let a = 10f64.to_radians();
        let v = [a.cos(), 0.0, a.sin()];
        let f = [0.3, 0.7, 2.0];
        let (l, d) = lift_drag_of(f, v, [0.0, 1.0, 0.0]);
        assert_relative_eq!(d, 0.3 * a.cos() + 2.0 * a.sin(), max_relative = 1e-14);
        assert_relative_eq!(l, -0.3 * a.sin() + 2.0 * a.cos(), max_relative = 1e-14);
        // Paper frame: flow along −Y, span along +X → lift along +Z.
        let (l, d) = lift_drag_of([0.0, 0.1, 5.0], [0.0, -25.0, 0.0], [1.0, 0.0, 0.0]);
        assert_relative_eq!(l, 5.0, max_relative = 1e-14);
        assert_relative_eq!(d, -0.1, max_relative = 1e-14);
    }

    #[test]
    fn column_loads_and_moment() {
        let loads = Loads {
            nodal: vec![[0.0, 0.0, 1.0], [0.0, 0.0, 2.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
            positions: vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            total_steady: [1.0, 0.0, 2.0],
            ..Default::default()
        };
        let m = loads.moment_about([0.0; 3]);
        // r × f: (0,1,0)×(0,0,2) = (2,0,0); (1,0,0)×(1,0,0) = 0; (1,1,0)×(0,0,−1) = (−1, 1, 0).
        assert_eq!(m, [1.0, 1.0, 0.0]);
        let (mut f, mut mc) = ([[0.0; 3]; 2], [[0.0; 3]; 2]);
        loads.column_loads_inplace(&[[0.0; 3], [0.0, 1.0, 0.0]], &mut f, &mut mc);
        assert_eq!(f, [[1.0, 0.0, 1.0], [0.0, 0.0, 1.0]]);
        // Column 1 about (0,1,0): (1,0,0)×(0,0,−1) = (0,1,0).
        assert_eq!(mc[1], [0.0, 1.0, 0.0]);
    }
}
