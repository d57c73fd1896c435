//! Joints: the input description and the dispatch over the velocity-level joint kinds.

use crate::body::Body;
use crate::clamp::Clamp;
use crate::crv::V3;
use crate::flared_hinge::FlaredHinge;
use crate::ground_hinge::GroundHinge;
use crate::quaternion::Quaternion;
use genalpha::MatView;

pub use scene::JointSpec;

/// Internal joint.
#[derive(Debug, Clone)]
pub(crate) enum Joint {
    Ground(GroundHinge),
    Flared(FlaredHinge),
    Clamp(Clamp),
    /// A free root: no rows.
    Free,
}

impl Joint {
    pub fn n_rows(&self) -> usize {
        match self {
            Joint::Ground(_) => GroundHinge::N_ROWS,
            Joint::Flared(j) => j.n_rows(),
            Joint::Clamp(_) => Clamp::N_ROWS,
            Joint::Free => 0,
        }
    }

    /// `B v` (the joints are scleronomic: `b = 0`).
    pub fn psi(&self, bodies: &[Body], q: &[f64], v: &[f64], out: &mut [f64]) {
        match self {
            Joint::Ground(j) => j.psi(&bodies[j.body], v, out),
            Joint::Flared(j) => j.psi(bodies, q, v, out),
            Joint::Clamp(j) => j.psi(&bodies[j.body], v, out),
            Joint::Free => {}
        }
    }

    pub fn add_b(&self, bodies: &[Body], q: &[f64], m: &mut MatView<'_>, row0: usize) {
        match self {
            Joint::Ground(j) => j.add_b(&bodies[j.body], m, row0),
            Joint::Flared(j) => j.add_b(bodies, q, m, row0),
            Joint::Clamp(j) => j.add_b(&bodies[j.body], m, row0),
            Joint::Free => {}
        }
    }

    pub fn add_psi_q(&self, bodies: &[Body], q: &[f64], v: &[f64], m: &mut MatView<'_>, row0: usize) {
        if let Joint::Flared(j) = self {
            j.add_psi_q(bodies, q, v, m, row0);
        }
    }

    pub fn add_force_tangent(&self, bodies: &[Body], q: &[f64], mu: &[f64], c_k: f64, m: &mut MatView<'_>) {
        if let Joint::Flared(j) = self {
            j.add_force_tangent(bodies, q, mu, c_k, m);
        }
    }

    /// (position gap, m; axis misalignment or rotation angle, rad).
    pub fn violation(&self, bodies: &[Body], q: &[f64]) -> (f64, f64) {
        match self {
            Joint::Ground(j) => j.violation(&bodies[j.body], q),
            Joint::Flared(j) => j.violation(bodies, q),
            Joint::Clamp(j) => j.violation(&bodies[j.body], q),
            Joint::Free => (0.0, 0.0),
        }
    }

    /// Position-level projection (stabilisation); keeps global frame velocities.
    pub fn project(&self, bodies: &[Body], q: &mut [f64], rates: [&mut [f64]; 3]) {
        match self {
            Joint::Flared(j) => j.project(bodies, q, rates),
            Joint::Ground(j) => {
                let b = &bodies[j.body];
                let (_, chi) = b.frame_state(q);
                let fc = b.frame_coord();
                q[fc..fc + 3].copy_from_slice(b.start.as_slice());
                let a = chi.rotate(&j.axis_a);
                realign(b, q, rates, &chi, &a, &j.axis);
            }
            Joint::Clamp(j) => {
                let b = &bodies[j.body];
                let fc = b.frame_coord();
                q[fc..fc + 3].copy_from_slice(b.start.as_slice());
                b.quat0.write_to(&mut q[fc + 3..fc + 7]);
            }
            Joint::Free => {}
        }
    }
}

/// Rotate frame `b` minimally so that its axis `a` (global) becomes `target`, keeping the global
/// velocities of the frame.
fn realign(b: &Body, q: &mut [f64], rates: [&mut [f64]; 3], chi: &Quaternion, a: &V3, target: &V3) {
    let axis = a.cross(target);
    let s = axis.norm();
    if s == 0.0 {
        return;
    }
    let angle = s.atan2(a.dot(target));
    let new = Quaternion::from_rotation_vector(&(axis * (angle / s))).mul(chi).normalized();
    let fc = b.frame_coord();
    new.write_to(&mut q[fc + 3..fc + 7]);
    let qa = new.to_rotation_matrix().transpose() * chi.to_rotation_matrix();
    let fd = b.frame_dof();
    for x in rates {
        for off in [fd, fd + 3] {
            let y = qa * V3::new(x[off], x[off + 1], x[off + 2]);
            x[off..off + 3].copy_from_slice(y.as_slice());
        }
    }
}
