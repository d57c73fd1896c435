//! Flared hinge (SHARPy's `hinge_node_FoR`, paper eqs. 11–15): the frame of a child body is
//! attached to the end node `n` of its parent and may rotate relative to that node's section
//! frame B_n only about the axis `a_B = (sin β, cos β, 0)` (B_n components).
//!
//! Velocity-level rows (5), with `C_pc = C^{ApAc} = C^{ApG} C^{GAc}` and `C_n = C^{BnAp}(psi_n)`:
//!
//! * equal velocity of the attachment point, in the child's A components:
//!   `v_Ac − C_pcᵀ (v_Ap + R_dot_n + omega_Ap × R_n) = 0`;
//! * no relative rotation about the two fixed directions `n_1 = z`, `n_2 = a_B × z` of B_n
//!   that are perpendicular to the axis (a rank-2 projection valid for every β, unlike
//!   SHARPy's row picking): `N_Bᵀ (C_n C_pc omega_Ac − T(psi_n) psi_dot_n − C_n omega_Ap) = 0`.
//!
//! A *locked* hinge adds the third angular row along `a_B` itself (no relative rotation at all):
//! the child is welded to the parent's end section.
//!
//! `B` depends on `R_n`, `psi_n` and both quaternions; `∂(B v)/∂q` and `∂(Bᵀ mu)/∂q` are
//! assembled exactly (quaternion directions along `C^{GA} ← C^{GA} exp(δθ̃)`).

use crate::body::Body;
use crate::crv::{M3, Tangent, V3, rotation_matrix, skew};
use crate::ground_hinge::angle_between;
use crate::quaternion::Quaternion;
use genalpha::MatView;

/// Internal flared hinge.
#[derive(Debug, Clone)]
pub(crate) struct FlaredHinge {
    pub parent: usize,
    pub child: usize,
    /// Hinge axis in B_n.
    pub a_b: V3,
    /// Fixed orthonormal directions of the angular rows in B_n: (z, a_B × z) ⟂ a_B, then a_B
    /// itself when the hinge is locked; the first `n_ang` are used.
    pub n: [V3; 3],
    /// Number of angular rows: 2 (free hinge) or 3 (locked).
    pub n_ang: usize,
    /// Hinge axis in the child's A frame.
    pub a_c: V3,
    /// Reference relative rotation C^{BnAc}_0.
    pub rel0: M3,
    /// Relative rotation C^{BnAc} a locked hinge is welded at: `R_rel rel0`, `R_rel` the turn by
    /// the lock's fold about `−a_B` (`rel0` when locked at the reference fold).
    pub rel_lock: M3,
}

/// Kinematic quantities of the joint at a configuration.
struct Kin {
    /// End node index of the parent.
    node: usize,
    r_n: V3,
    tg: Tangent,
    /// C^{BnAp}.
    cn: M3,
    /// C^{GAp}.
    cp: M3,
    /// C^{GAc}.
    cc: M3,
    /// C^{ApAc}.
    cpc: M3,
}

/// Add a 3×3 block into a view at (i, j).
fn add_m3(j: &mut MatView<'_>, i0: usize, j0: usize, m: &M3) {
    j.add_block::<3, 3>(i0, j0, m);
}

/// Add the angular rows `N_Bᵀ m` of a 3×3 block `m` at (i0, j0).
fn add_rows2(j: &mut MatView<'_>, n: &[V3], i0: usize, j0: usize, m: &M3) {
    for (r, nr) in n.iter().enumerate() {
        let row = nr.transpose() * m;
        for c in 0..3 {
            j.add(i0 + r, j0 + c, row[c]);
        }
    }
}

impl FlaredHinge {
    /// A flared hinge of flare `beta` (rad), free, or locked at fold `locked` (rad).
    pub fn new(parent: usize, child: usize, beta: f64, locked: Option<f64>, bp: &Body, bc: &Body) -> Self {
        let a_b = V3::new(beta.sin(), beta.cos(), 0.0);
        let z = V3::z();
        let n = [z, a_b.cross(&z), a_b];
        // Reference: C^{GBn}_0 = C^{GAp}_0 C^{ApBn}(psi_n0), C^{GAp}_0 itself untwisted (psi_n0 = 0).
        let rel0 = bp.section_frame0(bp.n_nodes() - 1).transpose() * bc.frame;
        let turn = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(-a_b), locked.unwrap_or(0.0));
        let rel_lock = turn.matrix() * rel0;
        let n_ang = if locked.is_some() { 3 } else { 2 };
        Self { parent, child, a_b, n, n_ang, a_c: rel0.transpose() * a_b, rel0, rel_lock }
    }

    /// Number of velocity rows: 5, or 6 when locked.
    pub fn n_rows(&self) -> usize {
        3 + self.n_ang
    }

    /// The angular-row directions in use.
    fn dirs(&self) -> &[V3] {
        &self.n[..self.n_ang]
    }

    fn kin(&self, bodies: &[Body], q: &[f64]) -> Kin {
        let (bp, bc) = (&bodies[self.parent], &bodies[self.child]);
        let node = bp.n_nodes() - 1;
        let (r_n, psi_n) = bp.node_state(q, node);
        let (_, chi_p) = bp.frame_state(q);
        let (_, chi_c) = bc.frame_state(q);
        let cp = chi_p.to_rotation_matrix();
        let cc = chi_c.to_rotation_matrix();
        Kin {
            node,
            r_n,
            tg: Tangent::new(&psi_n),
            cn: rotation_matrix(&psi_n).transpose(),
            cp,
            cc,
            cpc: cp.transpose() * cc,
        }
    }

    pub fn psi(&self, bodies: &[Body], q: &[f64], v: &[f64], out: &mut [f64]) {
        let (bp, bc) = (&bodies[self.parent], &bodies[self.child]);
        let k = self.kin(bodies, q);
        let (rd_n, psid_n) = bp.node_rates(v, k.node);
        let (vp, wp) = bp.frame_rates(v);
        let (vc, wc) = bc.frame_rates(v);
        let w = vp + rd_n + wp.cross(&k.r_n);
        let lin = vc - k.cpc.transpose() * w;
        let rel = k.cn * (k.cpc * wc) - k.tg.t * psid_n - k.cn * wp;
        out[0] = lin.x;
        out[1] = lin.y;
        out[2] = lin.z;
        for (o, d) in out[3..].iter_mut().zip(self.dirs()) {
            *o = d.dot(&rel);
        }
    }

    pub fn add_b(&self, bodies: &[Body], q: &[f64], j: &mut MatView<'_>, row0: usize) {
        let (bp, bc) = (&bodies[self.parent], &bodies[self.child]);
        let k = self.kin(bodies, q);
        let nd = bp.node_dof(k.node).expect("end node is never the clamped node 0");
        let (fp, fc) = (bp.frame_dof(), bc.frame_dof());
        let cpc_t = k.cpc.transpose();
        add_m3(j, row0, fc, &M3::identity());
        add_m3(j, row0, nd, &(-cpc_t));
        add_m3(j, row0, fp, &(-cpc_t));
        add_m3(j, row0, fp + 3, &(cpc_t * skew(&k.r_n)));
        add_rows2(j, self.dirs(), row0 + 3, fc + 3, &(k.cn * k.cpc));
        add_rows2(j, self.dirs(), row0 + 3, nd + 3, &(-k.tg.t));
        add_rows2(j, self.dirs(), row0 + 3, fp + 3, &(-k.cn));
    }

    /// `∂(B v)/∂q` at fixed `v`.
    pub fn add_psi_q(&self, bodies: &[Body], q: &[f64], v: &[f64], j: &mut MatView<'_>, row0: usize) {
        let (bp, bc) = (&bodies[self.parent], &bodies[self.child]);
        let k = self.kin(bodies, q);
        let nd = bp.node_dof(k.node).expect("end node is never the clamped node 0");
        let (fp, fc) = (bp.frame_dof(), bc.frame_dof());
        let (rd_n, psid_n) = bp.node_rates(v, k.node);
        let (vp, wp) = bp.frame_rates(v);
        let (_, wc) = bc.frame_rates(v);
        let cpc_t = k.cpc.transpose();
        let w = vp + rd_n + wp.cross(&k.r_n);
        let x = cpc_t * w;
        add_m3(j, row0, nd, &(-cpc_t * skew(&wp)));
        add_m3(j, row0, fp + 3, &(cpc_t * skew(&w)));
        add_m3(j, row0, fc + 3, &(-skew(&x)));
        let t = k.tg.t;
        let y = k.cpc * wc;
        let d_psi = skew(&(k.cn * y)) * t - k.tg.jac(&psid_n) - skew(&(k.cn * wp)) * t;
        add_rows2(j, self.dirs(), row0 + 3, nd + 3, &d_psi);
        add_rows2(j, self.dirs(), row0 + 3, fp + 3, &(k.cn * skew(&y)));
        add_rows2(j, self.dirs(), row0 + 3, fc + 3, &(-(k.cn * k.cpc * skew(&wc))));
    }

    /// `c_k ∂(Bᵀ mu)/∂q` at fixed `mu` (this joint's 5 multipliers).
    pub fn add_force_tangent(&self, bodies: &[Body], q: &[f64], mu: &[f64], c_k: f64, j: &mut MatView<'_>) {
        let (bp, bc) = (&bodies[self.parent], &bodies[self.child]);
        let k = self.kin(bodies, q);
        let nd = bp.node_dof(k.node).expect("end node is never the clamped node 0");
        let (fp, fc) = (bp.frame_dof(), bc.frame_dof());
        let mu_l = V3::new(mu[0], mu[1], mu[2]);
        let m: V3 = self.dirs().iter().zip(&mu[3..]).map(|(d, x)| d * *x).sum();
        let t = k.tg.t;
        let z = k.cpc * mu_l;
        let zt = skew(&z);
        let dz_c = k.cpc * skew(&mu_l); // −∂z/∂θ_c
        let rt = skew(&k.r_n);
        let mut j = j.scaled(c_k);
        // R_dot_n and v_Ap rows carry −z.
        for row in [nd, fp] {
            add_m3(&mut j, row, fp + 3, &(-zt));
            add_m3(&mut j, row, fc + 3, &dz_c);
        }
        // omega_Ap row, translational part −R_n × z.
        add_m3(&mut j, fp + 3, nd, &zt);
        add_m3(&mut j, fp + 3, fp + 3, &(-(rt * zt)));
        add_m3(&mut j, fp + 3, fc + 3, &(rt * dz_c));
        // omega_Ac row: C_pcᵀ C_nᵀ m.
        let u = k.cn.transpose() * m;
        let mt = skew(&m);
        add_m3(&mut j, fc + 3, nd + 3, &(-(k.cpc.transpose() * k.cn.transpose() * mt * t)));
        add_m3(&mut j, fc + 3, fp + 3, &(-(k.cpc.transpose() * skew(&u))));
        add_m3(&mut j, fc + 3, fc + 3, &skew(&(k.cpc.transpose() * u)));
        // psi_dot_n row: −T_nᵀ m.
        add_m3(&mut j, nd + 3, nd + 3, &(-k.tg.jac_t(&m)));
        // omega_Ap row, rotational part −C_nᵀ m.
        add_m3(&mut j, fp + 3, nd + 3, &(k.cn.transpose() * mt * t));
    }

    /// (gap between the child's frame origin and the parent's end node, m; angle between the
    /// hinge axis of the parent's end section and that of the child frame, rad).
    pub fn violation(&self, bodies: &[Body], q: &[f64]) -> (f64, f64) {
        let (bp, bc) = (&bodies[self.parent], &bodies[self.child]);
        let k = self.kin(bodies, q);
        let (r_p, _) = bp.frame_state(q);
        let (r_c, _) = bc.frame_state(q);
        let gap = (r_c - (r_p + k.cp * k.r_n)).norm();
        let a_parent = k.cp * (k.cn.transpose() * self.a_b);
        let a_child = k.cc * self.a_c;
        (gap, angle_between(&a_parent, &a_child))
    }

    /// Fold angle θ (rad): the rotation of the child relative to the parent's end section about
    /// `−a`, zero in the reference configuration.
    pub fn fold_angle(&self, bodies: &[Body], q: &[f64]) -> f64 {
        let k = self.kin(bodies, q);
        // R_rel = C^{BnG} C^{GAc}, divided by its reference value (in B_n components).
        let r = k.cn * k.cpc * self.rel0.transpose();
        let a = -self.a_b;
        let n1 = V3::z(); // ⟂ a_B for every β
        let n2 = a.cross(&n1);
        let rn1 = r * n1;
        n2.dot(&rn1).atan2(n1.dot(&rn1))
    }

    /// Position-level projection of the child frame: re-anchor its origin at the parent's end
    /// node and rotate it minimally so that the hinge axes coincide. The child frame's global
    /// velocities (and accelerations) are kept, so the velocity rows stay satisfied.
    pub fn project(&self, bodies: &[Body], q: &mut [f64], rates: [&mut [f64]; 3]) {
        let (bp, bc) = (&bodies[self.parent], &bodies[self.child]);
        let k = self.kin(bodies, q);
        let (r_p, _) = bp.frame_state(q);
        let (_, chi_c) = bc.frame_state(q);
        let target = r_p + k.cp * k.r_n;
        let a_parent = k.cp * (k.cn.transpose() * self.a_b);
        let a_child = k.cc * self.a_c;
        let axis = a_child.cross(&a_parent);
        let s = axis.norm();
        let fc = bc.frame_coord();
        q[fc..fc + 3].copy_from_slice(target.as_slice());
        let new = if self.n_ang == 3 {
            // Locked: the child frame is exactly its welded pose relative to B_n.
            Some(Quaternion::from_rotation_matrix(&(k.cp * k.cn.transpose() * self.rel_lock)))
        } else if s > 0.0 {
            let angle = s.atan2(a_child.dot(&a_parent));
            Some(Quaternion::from_rotation_vector(&(axis * (angle / s))).mul(&chi_c).normalized())
        } else {
            None
        };
        if let Some(new) = new {
            new.write_to(&mut q[fc + 3..fc + 7]);
            // Keep global velocities: x_A ← C_newᵀ C_old x_A.
            let c_new = new.to_rotation_matrix();
            let qa = c_new.transpose() * k.cc;
            let fd = bc.frame_dof();
            for x in rates {
                for off in [fd, fd + 3] {
                    let y = qa * V3::new(x[off], x[off + 1], x[off + 2]);
                    x[off..off + 3].copy_from_slice(y.as_slice());
                }
            }
        }
    }
}
