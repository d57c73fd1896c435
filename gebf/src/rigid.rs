//! States of rigidly moved bodies, and where a state's unknowns live (for tests,
//! cross-formulation checks and initial conditions).
//!
//! A pose moves body `b` rigidly from its reference configuration (start `X₀`, section frame
//! `F₀ = C^{GA}_0`): the material point `X` goes to `r = t + R (X − X₀)` and moves with
//! `ṙ = v + ω × (r − t)`. In the floating-frame description only the frame moves:
//!
//! $$ r_A = t,\quad C^{GA} = R\,C^{GA}_0,\quad v_A = C^{AG} v,\quad \omega_A = C^{AG}\omega ,$$
//!
//! with every node in its reference place (`R_i = (s_i, 0, 0)`, `psi_i = 0`) and at rest in A.

use crate::Error;
use crate::crv::{M3, V3};
use crate::model::Model;
use crate::quaternion::Quaternion;
use genalpha::State;

/// A rigid motion of one body relative to its reference configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidPose {
    /// Rotation from the reference configuration (global components): the section frame
    /// becomes `rotation · frame`.
    pub rotation: M3,
    /// Current position of the body's start point (global, m).
    pub translation: V3,
    /// Angular velocity (global components, rad/s).
    pub angular_velocity: V3,
    /// Velocity of the body's start point (global, m/s).
    pub velocity: V3,
}

impl RigidPose {
    /// The body at rest in its reference configuration whose start point is `start`.
    pub fn at_rest(start: V3) -> Self {
        Self { rotation: M3::identity(), translation: start, angular_velocity: V3::zeros(), velocity: V3::zeros() }
    }

    fn validate(&self, i: usize) -> Result<(), Error> {
        let vectors = [("translation", &self.translation), ("angular_velocity", &self.angular_velocity)];
        for (name, x) in vectors.into_iter().chain([("velocity", &self.velocity)]) {
            for (k, v) in x.iter().enumerate() {
                if !v.is_finite() {
                    return Err(Error::NonFinite { field: format!("poses[{i}].{name}[{k}]"), value: *v });
                }
            }
        }
        for (k, v) in self.rotation.iter().enumerate() {
            if !v.is_finite() {
                return Err(Error::NonFinite {
                    field: format!("poses[{i}].rotation[{}][{}]", k % 3, k / 3),
                    value: *v,
                });
            }
        }
        let deviation = (self.rotation.transpose() * self.rotation - M3::identity()).amax();
        let det = self.rotation.determinant();
        if deviation > 1e-9 || det <= 0.0 {
            return Err(Error::NotOrthonormal { field: format!("poses[{i}].rotation"), deviation, det });
        }
        Ok(())
    }
}

impl Model {
    /// The state (t = 0, zero accelerations and multipliers) of the bodies moved rigidly by
    /// `poses`, one per body in body order. The joints are not enforced: poses that violate
    /// them give a state that violates them (see [`Model::constraint_residual`] and the
    /// velocity rows `psi_inplace`).
    pub fn rigid_state(&self, poses: &[RigidPose]) -> Result<State, Error> {
        if poses.len() != self.bodies.len() {
            return Err(Error::WrongLength { what: "poses", got: poses.len(), expected: self.bodies.len() });
        }
        for (i, p) in poses.iter().enumerate() {
            p.validate(i)?;
        }
        let mut s = self.initial_state();
        for (b, p) in self.bodies.iter().zip(poses) {
            let chi = Quaternion::from_rotation_matrix(&(p.rotation * b.frame));
            let c_ag = chi.to_rotation_matrix().transpose();
            let (fc, fd) = (b.frame_coord(), b.frame_dof());
            s.q[fc..fc + 3].copy_from_slice(p.translation.as_slice());
            chi.write_to(&mut s.q[fc + 3..fc + 7]);
            s.v[fd..fd + 3].copy_from_slice((c_ag * p.velocity).as_slice());
            s.v[fd + 3..fd + 6].copy_from_slice((c_ag * p.angular_velocity).as_slice());
        }
        Ok(s)
    }

    fn check_body_index(&self, body: usize) -> Result<&crate::body::Body, Error> {
        self.bodies.get(body).ok_or(Error::NoSuchBody { field: "body".into(), body, n_bodies: self.bodies.len() })
    }

    /// Storage index (into `q`) of node `node`'s `(R, psi)` (6 numbers: position in A, m, and
    /// CRV of the section relative to A); `None` for node 0, which is clamped to the frame.
    pub fn node_coordinate_index(&self, body: usize, node: usize) -> Result<Option<usize>, Error> {
        let b = self.check_body_index(body)?;
        if node >= b.n_nodes() {
            return Err(Error::NoSuchNode { body, node, n_nodes: b.n_nodes() });
        }
        Ok(b.node_coord(node))
    }

    /// Tangent index (into `v`, `v_dot`, residual rows) of node `node`'s `(R_dot, psi_dot)`;
    /// `None` for node 0.
    pub fn node_dof_index(&self, body: usize, node: usize) -> Result<Option<usize>, Error> {
        let b = self.check_body_index(body)?;
        if node >= b.n_nodes() {
            return Err(Error::NoSuchNode { body, node, n_nodes: b.n_nodes() });
        }
        Ok(b.node_dof(node))
    }

    /// Storage index of the frame's `r_A` (3, global, m), followed by the quaternion `χ`
    /// (4, `[w, x, y, z]`, `C^{GA}`).
    pub fn frame_coordinate_index(&self, body: usize) -> Result<usize, Error> {
        Ok(self.check_body_index(body)?.frame_coord())
    }

    /// Tangent index of the frame's `v_A` (3), followed by `omega_A` (3), both in A components.
    pub fn frame_dof_index(&self, body: usize) -> Result<usize, Error> {
        Ok(self.check_body_index(body)?.frame_dof())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Options, samples};
    use approx::assert_relative_eq;
    use genalpha::ConstrainedSystem;
    use nalgebra::Rotation3;

    #[test]
    fn identity_poses_give_the_reference_configuration() {
        let (b, j, g) = samples::double_pendulum(1.0, 30.0, 3);
        let m = Model::new(&b, &j, g, Options::default()).unwrap();
        let poses: Vec<_> = b.iter().map(|x| RigidPose::at_rest(x.start)).collect();
        let s = m.rigid_state(&poses).unwrap();
        let s0 = m.initial_state();
        for (x, y) in s.q.iter().zip(&s0.q) {
            assert_relative_eq!(*x, *y, epsilon = 1e-15);
        }
        assert_eq!(s.v, s0.v);
    }

    #[test]
    fn a_rotated_body_has_its_rotated_frame_and_rigid_velocities() {
        let (b, j, g) = samples::double_pendulum(1.0, 30.0, 2);
        let m = Model::new(&b, &j, g, Options::default()).unwrap();
        let rot = Rotation3::from_scaled_axis(V3::new(0.3, -0.2, 0.9)).into_inner();
        let (t, w) = (V3::new(1.0, 2.0, 3.0), V3::new(0.5, 1.0, -2.0));
        let pose = RigidPose { rotation: rot, translation: t, angular_velocity: w, velocity: V3::x() };
        let s = m.rigid_state(&[pose, RigidPose::at_rest(b[1].start)]).unwrap();
        let last = m.n_nodes(0) - 1;
        let p = m.node_position(&s.q, 0, last).unwrap();
        assert_relative_eq!(p, t + rot * V3::new(0.5, 0.0, 0.0), epsilon = 1e-14);
        assert_relative_eq!(m.node_frame(&s.q, 0, last).unwrap(), rot, epsilon = 1e-14);
        assert_relative_eq!(
            m.node_velocity(&s.q, &s.v, 0, last).unwrap(),
            V3::x() + w.cross(&(p - t)),
            epsilon = 1e-13
        );
        assert_relative_eq!(m.node_angular_velocity(&s.q, &s.v, 0, last).unwrap(), w, epsilon = 1e-14);
        assert_eq!(s.q.len(), m.n_coords());
    }

    #[test]
    fn layout_indices_and_bad_poses() {
        let (b, j, g) = samples::double_pendulum(1.0, 30.0, 2);
        let m = Model::new(&b, &j, g, Options::default()).unwrap();
        assert_eq!(m.node_coordinate_index(0, 0).unwrap(), None);
        assert_eq!(m.node_coordinate_index(1, 1).unwrap(), Some(12 * 2 + 7));
        assert_eq!(m.frame_coordinate_index(1).unwrap(), 2 * (12 * 2 + 7) - 7);
        assert_eq!(m.frame_dof_index(0).unwrap(), 24);
        assert_eq!(m.node_dof_index(1, 4).unwrap(), Some(30 + 18));
        assert!(matches!(m.node_dof_index(1, 5), Err(Error::NoSuchNode { .. })));
        assert!(matches!(m.frame_dof_index(2), Err(Error::NoSuchBody { .. })));
        let ok = RigidPose::at_rest(V3::zeros());
        assert!(matches!(m.rigid_state(&[ok]), Err(Error::WrongLength { got: 1, expected: 2, .. })));
        let mut bad = ok;
        bad.rotation[(1, 0)] = 0.5;
        let err = m.rigid_state(&[ok, bad]).unwrap_err();
        assert!(matches!(err, Error::NotOrthonormal { ref field, .. } if field == "poses[1].rotation"), "{err}");
    }
}
