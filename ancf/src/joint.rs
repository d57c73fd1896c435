//! Joints as linear equations in the nodal coordinates (paper eq. 5, docs/ancf.md §5).
//!
//! * Ground hinge about the fixed unit axis `n`: `r = r₀` and `Σ_b α_b r_b = n` at the body's
//!   start node, with `α = F₀ᵀ n` the axis in the body's reference section frame and
//!   `r_b ∈ {r_x, r_y, r_z}`.
//! * Flared hinge: `r^P = r^C` and `a^P = a^C` with `a^P = sin β r^P_x + cos β r^P_y` at the
//!   parent's end and `a^C = Σ_b α^C_b r^C_b`, `α^C = F₀_Cᵀ F₀_P (sin β, cos β, 0)` at the child's
//!   start (for collinear bodies with equal frames simply `sin β r^C_x + cos β r^C_y`). Full
//!   rank for every β in [−90°, 90°]; the sixth equation also equalises the axis stretch.
//! * Locked hinge: `r^P = r^C`, `r^P_y = Σ_b γ^y_b r^C_b`, `r^P_z = Σ_b γ^z_b r^C_b` with
//!   `γ = F₀_Cᵀ F₀_P e`: the two sections are welded like a clamp (the centreline slopes stay
//!   free); the fold angle is still measured about the flared axis.
//! * Clamp: `r = r₀`, `r_y = y₀`, `r_z = z₀` at the start node: the section's position and
//!   orientation are fixed, the centreline slope `r_x` stays free (axial and shear strain at
//!   the root are not suppressed).
//!
//! All equations are `Σ c_j q_j = rhs` with constant coefficients: `Φ_q` is built once.

use crate::frame::{angle_between, rotation_angle, section_frame};
use crate::model::Body;
use crate::{JointSpec, shape::NODE_DOF};
use nalgebra::{Matrix3, Vector3};

/// One linear constraint equation `Σ c_j q_j − rhs = 0`.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintRow {
    /// `(full coordinate index, coefficient)`.
    pub entries: Vec<(usize, f64)>,
    /// Right-hand side.
    pub rhs: f64,
    /// Index of the joint this row belongs to.
    pub joint: usize,
}

impl ConstraintRow {
    /// Φ of this row at `q`.
    #[inline]
    pub fn value(&self, q: &[f64]) -> f64 {
        self.entries.iter().map(|&(j, c)| c * q[j]).sum::<f64>() - self.rhs
    }
}

/// A joint with its precomputed data.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Joint {
    Ground {
        body: usize,
        axis: Vector3<f64>,
        alpha: Vector3<f64>,
        r0: Vector3<f64>,
    },
    Flared {
        parent: usize,
        child: usize,
        alpha_p: Vector3<f64>,
        alpha_c: Vector3<f64>,
        rel0: Matrix3<f64>,
        /// Locked hinge: the child's coefficients of the parent's `r_y` and `r_z`
        /// (`F₀_Cᵀ F₀_P y`, `F₀_Cᵀ F₀_P z`).
        lock: Option<[Vector3<f64>; 2]>,
    },
    Clamp {
        body: usize,
        r0: Vector3<f64>,
        frame0: Matrix3<f64>,
    },
    /// A free root: no rows.
    Free,
}

/// 3-vector block `b` (0 r, 1 r_x, 2 r_y, 3 r_z) of node `node` of `body`.
pub(crate) fn node_vector(body: &Body, q: &[f64], node: usize, block: usize) -> Vector3<f64> {
    let i = body.offset + NODE_DOF * node + 3 * block;
    Vector3::new(q[i], q[i + 1], q[i + 2])
}

fn axis_vector(body: &Body, q: &[f64], node: usize, alpha: &Vector3<f64>) -> Vector3<f64> {
    (1..4).map(|b| node_vector(body, q, node, b) * alpha[b - 1]).sum()
}

impl Joint {
    pub(crate) fn new(spec: &JointSpec, bodies: &[Body]) -> Self {
        match *spec {
            JointSpec::GroundHinge { body, axis } => {
                let b = &bodies[body];
                let axis = axis.normalize();
                Joint::Ground { body, axis, alpha: b.node_frame(0).transpose() * axis, r0: b.spec.start }
            }
            JointSpec::FlaredHinge { parent, child, beta } | JointSpec::LockedHinge { parent, child, beta, .. } => {
                // the parent's end and the child's start section frames (twisted, docs/ancf.md §5)
                let (bp, bc) = (&bodies[parent], &bodies[child]);
                let (fp, fc) = (bp.node_frame(bp.n_nodes - 1), bc.node_frame(0));
                let alpha_p = Vector3::new(beta.sin(), beta.cos(), 0.0);
                let alpha_c = fc.transpose() * (fp * alpha_p);
                // Locked at fold θ: the relative pose F_Pᵀ F_C = R_rel rel0 with R_rel the turn
                // by θ about −a (parent's end-section components), so the parent's y and z
                // are, in the child's section, (R_rel rel0)ᵀ y and (R_rel rel0)ᵀ z.
                let lock = match *spec {
                    JointSpec::LockedHinge { fold, .. } => {
                        let turn = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(-alpha_p), fold);
                        let rel = turn.matrix() * (fp.transpose() * fc);
                        Some([rel.transpose() * Vector3::y(), rel.transpose() * Vector3::z()])
                    }
                    _ => None,
                };
                Joint::Flared { parent, child, alpha_p, alpha_c, rel0: fp.transpose() * fc, lock }
            }
            JointSpec::Clamp { body } => {
                let b = &bodies[body];
                Joint::Clamp { body, r0: b.spec.start, frame0: b.node_frame(0) }
            }
            JointSpec::Free { .. } => Joint::Free,
        }
    }

    /// The constraint equations of this joint (index `j`).
    pub(crate) fn rows(&self, j: usize, bodies: &[Body]) -> Vec<ConstraintRow> {
        let dof =
            |body: usize, node: usize, block: usize, i: usize| bodies[body].offset + NODE_DOF * node + 3 * block + i;
        let mut rows = Vec::new();
        match self {
            Joint::Ground { body, axis, alpha, r0 } => {
                for i in 0..3 {
                    rows.push(ConstraintRow { entries: vec![(dof(*body, 0, 0, i), 1.0)], rhs: r0[i], joint: j });
                }
                for i in 0..3 {
                    let entries =
                        (1..4).filter(|&b| alpha[b - 1] != 0.0).map(|b| (dof(*body, 0, b, i), alpha[b - 1])).collect();
                    rows.push(ConstraintRow { entries, rhs: axis[i], joint: j });
                }
            }
            Joint::Flared { parent, child, alpha_p, alpha_c, lock, .. } => {
                let pe = bodies[*parent].n_nodes - 1;
                for i in 0..3 {
                    rows.push(ConstraintRow {
                        entries: vec![(dof(*parent, pe, 0, i), 1.0), (dof(*child, 0, 0, i), -1.0)],
                        rhs: 0.0,
                        joint: j,
                    });
                }
                // Free: the hinge axis. Locked: the section's r_y and r_z instead (a weld of the
                // two sections, as the clamp welds a section to ground).
                let (y, z) = (Vector3::y(), Vector3::z());
                let pairs: Vec<(&Vector3<f64>, &Vector3<f64>)> = match lock {
                    None => vec![(alpha_p, alpha_c)],
                    Some([gy, gz]) => vec![(&y, gy), (&z, gz)],
                };
                for (alpha_p, alpha_c) in pairs {
                    for i in 0..3 {
                        let mut entries: Vec<(usize, f64)> = (1..4)
                            .filter(|&b| alpha_p[b - 1] != 0.0)
                            .map(|b| (dof(*parent, pe, b, i), alpha_p[b - 1]))
                            .collect();
                        entries.extend(
                            (1..4).filter(|&b| alpha_c[b - 1] != 0.0).map(|b| (dof(*child, 0, b, i), -alpha_c[b - 1])),
                        );
                        rows.push(ConstraintRow { entries, rhs: 0.0, joint: j });
                    }
                }
            }
            Joint::Clamp { body, r0, frame0 } => {
                for (block, target) in [(0, *r0), (2, frame0.column(1).into()), (3, frame0.column(2).into())] {
                    let target: Vector3<f64> = target;
                    for i in 0..3 {
                        rows.push(ConstraintRow {
                            entries: vec![(dof(*body, 0, block, i), 1.0)],
                            rhs: target[i],
                            joint: j,
                        });
                    }
                }
            }
            Joint::Free => {}
        }
        rows
    }

    /// (position gap in m, axis misalignment angle in rad) — for clamps the full rotation angle.
    pub(crate) fn violation(&self, bodies: &[Body], q: &[f64]) -> (f64, f64) {
        match self {
            Joint::Ground { body, axis, alpha, r0 } => {
                let b = &bodies[*body];
                ((node_vector(b, q, 0, 0) - r0).norm(), angle_between(&axis_vector(b, q, 0, alpha), axis))
            }
            Joint::Flared { parent, child, alpha_p, alpha_c, lock, .. } => {
                let (p, c) = (&bodies[*parent], &bodies[*child]);
                let pe = p.n_nodes - 1;
                let gap = (node_vector(p, q, pe, 0) - node_vector(c, q, 0, 0)).norm();
                let axis = angle_between(&axis_vector(p, q, pe, alpha_p), &axis_vector(c, q, 0, alpha_c));
                let locked = lock.map_or(0.0, |[gy, gz]| {
                    let ay = angle_between(&axis_vector(p, q, pe, &Vector3::y()), &axis_vector(c, q, 0, &gy));
                    ay.max(angle_between(&axis_vector(p, q, pe, &Vector3::z()), &axis_vector(c, q, 0, &gz)))
                });
                (gap, axis.max(locked))
            }
            Joint::Clamp { body, r0, frame0 } => {
                let b = &bodies[*body];
                let f = section_frame(&node_vector(b, q, 0, 2), &node_vector(b, q, 0, 3));
                ((node_vector(b, q, 0, 0) - r0).norm(), rotation_angle(&(f * frame0.transpose())))
            }
            Joint::Free => (0.0, 0.0),
        }
    }
}
