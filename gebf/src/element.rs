//! The three-node quadratic element: shape functions, Gauss rules, the gathered nodal state,
//! and the element-local numbering of unknowns.
//!
//! Local unknowns (24): node k = 0, 1, 2 at `6k` as `(R, psi)`, then the body frame's
//! `v_A` at 18 and `omega_A` at 21. Positions and CRVs are interpolated with the same
//! quadratic Lagrange functions of `ξ ∈ [−1, 1]` (nodes at −1, 0, 1), `s = (1 + ξ) L_e / 2`.

use crate::body::Body;
use crate::crv::{BranchMap, M3, V3};
use crate::inertia::MatrixCoefficients;
use nalgebra::{SMatrix, SVector};

/// Element-local vector.
pub(crate) type Vec24 = SVector<f64, 24>;
/// Element-local matrix.
pub(crate) type Mat24 = SMatrix<f64, 24, 24>;

/// Offset of the frame velocity `v_A` in the local numbering.
pub(crate) const V_OFF: usize = 18;
/// Offset of the frame angular velocity `omega_A` in the local numbering.
pub(crate) const W_OFF: usize = 21;

/// A Gauss rule on [−1, 1]: (abscissa, weight).
pub(crate) fn gauss_rule(n: usize) -> &'static [(f64, f64)] {
    const G1: [(f64, f64); 1] = [(0.0, 2.0)];
    // 1/√3 and √(3/5) written out (not const-evaluable).
    const G2: [(f64, f64); 2] = [(-0.577_350_269_189_625_8, 1.0), (0.577_350_269_189_625_8, 1.0)];
    const G3: [(f64, f64); 3] =
        [(-0.774_596_669_241_483_4, 5.0 / 9.0), (0.0, 8.0 / 9.0), (0.774_596_669_241_483_4, 5.0 / 9.0)];
    match n {
        1 => &G1,
        2 => &G2,
        _ => &G3,
    }
}

/// Shape functions and their derivatives with respect to `s` at `ξ` for element length `le`.
#[inline]
pub(crate) fn shape(xi: f64, le: f64) -> ([f64; 3], [f64; 3]) {
    let n = [0.5 * xi * (xi - 1.0), 1.0 - xi * xi, 0.5 * xi * (xi + 1.0)];
    let j = 2.0 / le;
    let dn = [(xi - 0.5) * j, -2.0 * xi * j, (xi + 0.5) * j];
    (n, dn)
}

/// Interpolate a nodal field.
#[inline]
pub(crate) fn interp(n: &[f64; 3], x: &[V3; 3]) -> V3 {
    x[0] * n[0] + x[1] * n[1] + x[2] * n[2]
}

/// The state of one element gathered from the global vectors.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ElementState {
    /// Nodal positions R in A, m.
    pub r: [V3; 3],
    /// Nodal CRVs psi (B relative to A).
    pub psi: [V3; 3],
    /// Nodal velocities R_dot.
    pub rd: [V3; 3],
    /// Nodal CRV rates psi_dot.
    pub psid: [V3; 3],
    /// Nodal accelerations R_ddot.
    pub rdd: [V3; 3],
    /// Nodal CRV second rates psi_ddot.
    pub psidd: [V3; 3],
    /// Frame velocity v_A (A components).
    pub v: V3,
    /// Frame angular velocity omega_A (A components).
    pub w: V3,
    /// Frame acceleration v_A_dot.
    pub vd: V3,
    /// Frame angular acceleration omega_A_dot.
    pub wd: V3,
    /// Branch maps of end nodes whose stored CRV lies on another branch than the middle
    /// node's; for those nodes `psi`, `psid`, `psidd` above hold the mapped values.
    pub branch: [Option<BranchMap>; 3],
    /// Stored (unmapped) CRV rates of mapped nodes.
    pub psid_stored: [V3; 3],
    /// Stored (unmapped) CRV second rates of mapped nodes.
    pub psidd_stored: [V3; 3],
}

impl ElementState {
    /// Gather element `e` of `body`. `v`, `v_dot` may be `None` (treated as zero).
    pub fn gather(body: &Body, e: usize, q: &[f64], v: Option<&[f64]>, v_dot: Option<&[f64]>) -> Self {
        let mut s = Self::default();
        s.gather_into(body, e, q, v, v_dot);
        s
    }

    /// [`gather`](Self::gather) into `self` (the hot loops reuse one state: no copy of the
    /// returned struct).
    pub fn gather_into(&mut self, body: &Body, e: usize, q: &[f64], v: Option<&[f64]>, v_dot: Option<&[f64]>) {
        // Each pair straight from its slice (node 0 of a body is clamped to the frame: zero).
        let pair = |x: &[f64], at: Option<usize>, a: &mut V3, b: &mut V3| match at {
            Some(k) => {
                *a = V3::new(x[k], x[k + 1], x[k + 2]);
                *b = V3::new(x[k + 3], x[k + 4], x[k + 5]);
            }
            None => {
                *a = V3::zeros();
                *b = V3::zeros();
            }
        };
        for k in 0..3 {
            let i = 2 * e + k;
            pair(q, body.node_coord(i), &mut self.r[k], &mut self.psi[k]);
            let dof = body.node_dof(i);
            pair(v.unwrap_or(&[]), v.and(dof), &mut self.rd[k], &mut self.psid[k]);
            pair(v_dot.unwrap_or(&[]), v_dot.and(dof), &mut self.rdd[k], &mut self.psidd[k]);
            self.branch[k] = None;
        }
        let f = Some(body.frame_dof());
        pair(v.unwrap_or(&[]), v.and(f), &mut self.v, &mut self.w);
        pair(v_dot.unwrap_or(&[]), v_dot.and(f), &mut self.vd, &mut self.wd);
        let s = self;
        // Bring the end nodes onto the middle node's branch (stored CRVs are rescaled to
        // |psi| ≤ π node by node): psi' = u(psi), psi_dot' = J psi_dot,
        // psi_ddot' = J psi_ddot + dJ[psi_dot] psi_dot.
        for k in [0, 2] {
            if let Some(m) = BranchMap::toward(&s.psi[k], &s.psi[1]) {
                let j = m.jac();
                s.psid_stored[k] = s.psid[k];
                s.psidd_stored[k] = s.psidd[k];
                s.psi[k] = m.apply();
                s.psid[k] = j * s.psid_stored[k];
                s.psidd[k] = j * s.psidd_stored[k] + m.djac(&s.psid_stored[k]) * s.psid_stored[k];
                s.branch[k] = Some(m);
            }
        }
    }

    /// Whether a node was mapped to another branch.
    pub fn is_mapped(&self) -> bool {
        self.branch.iter().any(Option::is_some)
    }

    /// Residual rows of the stored CRVs: `r_psi = Jᵀ r'_psi` (virtual work `δpsi' = J δpsi`).
    pub fn map_residual(&self, res: &mut Vec24) {
        for (k, m) in self.branch.iter().enumerate() {
            if let Some(m) = m {
                let o = 6 * k + 3;
                let r = m.jac().transpose() * V3::new(res[o], res[o + 1], res[o + 2]);
                res.fixed_rows_mut::<3>(o).copy_from(&r);
            }
        }
    }

    /// The iteration matrix in the stored unknowns from the separate (unscaled) mass,
    /// gyroscopic and stiffness matrices `m`, `g`, `k` and the residual `res` (all in the
    /// mapped unknowns), by the chain rule through `psi' = u(psi)` and its rates.
    pub fn map_matrix(&self, res: &Vec24, m: &Mat24, g: &Mat24, k: &Mat24, c: MatrixCoefficients) -> Mat24 {
        let mut a = m * c.c_m + g * c.c_c + k * c.c_k;
        // Columns of mapped CRVs.
        for (l, map) in self.branch.iter().enumerate() {
            if let Some(map) = map {
                let o = 6 * l + 3;
                let j = map.jac();
                let djd = map.djac(&self.psid_stored[l]);
                let d2 = map.djac(&self.psidd_stored[l]) + map.hess(&self.psid_stored[l], &self.psid_stored[l]);
                let (ml, gl, kl) = (m.fixed_columns::<3>(o), g.fixed_columns::<3>(o), k.fixed_columns::<3>(o));
                let col = (ml * j) * c.c_m + (gl * j + ml * djd * 2.0) * c.c_c + (kl * j + gl * djd + ml * d2) * c.c_k;
                a.fixed_columns_mut::<3>(o).copy_from(&col);
            }
        }
        // Rows of mapped CRVs.
        for (kk, map) in self.branch.iter().enumerate() {
            if let Some(map) = map {
                let o = 6 * kk + 3;
                let jt = map.jac().transpose();
                let rows = jt * a.fixed_rows::<3>(o);
                a.fixed_rows_mut::<3>(o).copy_from(&rows);
                let r = V3::new(res[o], res[o + 1], res[o + 2]);
                let extra: M3 = map.djac(&r) * c.c_k;
                let mut blk = a.fixed_view_mut::<3, 3>(o, o);
                blk += extra;
            }
        }
        a
    }
}

/// Add a 3-vector into a local vector at `off`.
#[inline]
pub(crate) fn add3(v: &mut Vec24, off: usize, x: &V3) {
    v[off] += x.x;
    v[off + 1] += x.y;
    v[off + 2] += x.z;
}

/// Add a 3×3 block into a local matrix at (i, j).
#[inline]
pub(crate) fn add33(m: &mut Mat24, i: usize, j: usize, x: &crate::crv::M3) {
    let mut b = m.fixed_view_mut::<3, 3>(i, j);
    b += x;
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn shape_functions_partition_unity_and_interpolate_lines() {
        let le = 0.7;
        for xi in [-1.0, -0.3, 0.0, 0.45, 1.0] {
            let (n, dn) = shape(xi, le);
            assert_relative_eq!(n.iter().sum::<f64>(), 1.0, epsilon = 1e-15);
            assert_relative_eq!(dn.iter().sum::<f64>(), 0.0, epsilon = 1e-14);
            // s at the nodes: 0, le/2, le  → interpolation of s is exact, ds/ds = 1.
            let s_nodes = [0.0, 0.5 * le, le];
            let s: f64 = n.iter().zip(&s_nodes).map(|(a, b)| a * b).sum();
            let ds: f64 = dn.iter().zip(&s_nodes).map(|(a, b)| a * b).sum();
            assert_relative_eq!(s, 0.5 * (1.0 + xi) * le, epsilon = 1e-15);
            assert_relative_eq!(ds, 1.0, epsilon = 1e-14);
        }
    }

    #[test]
    fn gauss_rules_integrate_polynomials() {
        for (n, deg) in [(1usize, 1u32), (2, 3), (3, 5)] {
            let rule = gauss_rule(n);
            for p in 0..=deg {
                let num: f64 = rule.iter().map(|(x, w)| w * x.powi(p as i32)).sum();
                let exact = if p % 2 == 1 { 0.0 } else { 2.0 / (p as f64 + 1.0) };
                assert_relative_eq!(num, exact, epsilon = 1e-15);
            }
        }
    }
}
