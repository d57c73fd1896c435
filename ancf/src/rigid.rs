//! States of rigidly moved bodies: the nodal coordinates and velocities of bodies that keep
//! their reference shape and move as rigid bodies (for tests, cross-formulation checks and
//! initial conditions).
//!
//! A pose moves body `b` rigidly from its reference configuration (start `X₀`, section frame
//! `F₀`): the material point `X` goes to `r = t + R (X − X₀)` and moves with
//! `ṙ = v + ω × (r − t)`. For the nodes of the two-node element (docs/ancf.md §1) this is
//!
//! $$ r_k = t + R F_0 e_x s_k,\quad [r_x, r_y, r_z]_k = R F_0,\qquad
//!    \dot r_k = v + \omega \times (r_k - t),\quad \dot r_{b,k} = \omega \times r_{b,k} .$$
//!
//! The cubic Hermite centreline and the linear section slopes reproduce this motion exactly,
//! so the kinetic energy is the rigid-body value (for sections with `ρI_xx = ρI_yy + ρI_zz`,
//! see [`Section::slope_inertias`](crate::Section::slope_inertias)) and the strains vanish.

use crate::model::Model;
use crate::shape::NODE_DOF;
use crate::{Error, SolvePath};
use genalpha::State;
use nalgebra::{Matrix3, Vector3};

/// A rigid motion of one body relative to its reference configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidPose {
    /// Rotation from the reference configuration (global components): the section frame
    /// becomes `rotation · frame`.
    pub rotation: Matrix3<f64>,
    /// Current position of the body's start point (global, m).
    pub translation: Vector3<f64>,
    /// Angular velocity (global components, rad/s).
    pub angular_velocity: Vector3<f64>,
    /// Velocity of the body's start point (global, m/s).
    pub velocity: Vector3<f64>,
}

impl RigidPose {
    /// The body at rest in its reference configuration whose start point is `start`.
    pub fn at_rest(start: Vector3<f64>) -> Self {
        Self {
            rotation: Matrix3::identity(),
            translation: start,
            angular_velocity: Vector3::zeros(),
            velocity: Vector3::zeros(),
        }
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
        let deviation = (self.rotation.transpose() * self.rotation - Matrix3::identity()).amax();
        let det = self.rotation.determinant();
        if deviation > 1e-9 || det <= 0.0 {
            return Err(Error::BadFrame { field: format!("poses[{i}].rotation"), deviation, det });
        }
        Ok(())
    }
}

impl Model {
    /// Full nodal coordinates and velocities (DAE layout) of the bodies moved rigidly by
    /// `poses` (one per body, in body order). The joints are not enforced: poses that violate
    /// them give coordinates that violate them (see [`Model::constraint_residual`]).
    pub fn rigid_full_state(&self, poses: &[RigidPose]) -> Result<(Vec<f64>, Vec<f64>), Error> {
        if poses.len() != self.bodies.len() {
            return Err(Error::PoseCount { got: poses.len(), expected: self.bodies.len() });
        }
        for (i, p) in poses.iter().enumerate() {
            p.validate(i)?;
        }
        let n = self.n_full_coords();
        let (mut q, mut v) = (vec![0.0; n], vec![0.0; n]);
        for (b, p) in self.bodies.iter().zip(poses) {
            let f = p.rotation * b.spec.frame;
            for node in 0..b.n_nodes {
                let i = b.offset + NODE_DOF * node;
                let f_node = if b.twisted.is_empty() { f } else { p.rotation * b.node_frame(node) };
                let arm = f.column(0) * (node as f64 * b.element.l);
                let r = p.translation + arm;
                let rd = p.velocity + p.angular_velocity.cross(&arm);
                q[i..i + 3].copy_from_slice(r.as_slice());
                v[i..i + 3].copy_from_slice(rd.as_slice());
                for k in 0..3 {
                    let slope: Vector3<f64> = f_node.column(k).into();
                    let j = i + 3 * (k + 1);
                    q[j..j + 3].copy_from_slice(slope.as_slice());
                    v[j..j + 3].copy_from_slice(p.angular_velocity.cross(&slope).as_slice());
                }
            }
        }
        Ok((q, v))
    }

    /// The state (in the form of [`Options::path`](crate::Options::path), zero accelerations
    /// and multipliers, t = 0) of the bodies moved rigidly by `poses`, one per body.
    ///
    /// On the DAE path the state holds the coordinates of [`Model::rigid_full_state`]. On the
    /// ODE path it holds their independent part `z`; `B z + q_p` reproduces the poses exactly
    /// only when they satisfy the joints (otherwise the dependent coordinates follow the joints).
    pub fn rigid_state(&self, poses: &[RigidPose]) -> Result<State, Error> {
        let (q, v) = self.rigid_full_state(poses)?;
        let mut s = match self.options().path {
            SolvePath::Dae => State::at_rest(self, 0.0, q),
            SolvePath::Ode => State::at_rest(self, 0.0, self.reduction.restrict(&q)),
        };
        s.v = match self.options().path {
            SolvePath::Dae => v,
            SolvePath::Ode => self.reduction.restrict(&v),
        };
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Options, samples};
    use approx::assert_relative_eq;
    use nalgebra::Rotation3;

    #[test]
    fn identity_poses_give_the_reference_configuration() {
        let (b, j, g) = samples::double_pendulum(1.0, 30.0, 3);
        for path in [SolvePath::Dae, SolvePath::Ode] {
            let m = Model::new(&b, &j, g, Options { path, ..Default::default() }).unwrap();
            let poses: Vec<_> = b.iter().map(|x| RigidPose::at_rest(x.start)).collect();
            let s = m.rigid_state(&poses).unwrap();
            assert_eq!(s, m.initial_state());
        }
    }

    #[test]
    fn a_rotated_body_has_its_rotated_frame_and_rigid_velocities() {
        let (b, j, g) = samples::double_pendulum(1.0, 30.0, 2);
        let m = Model::new(&b, &j, g, Options::default()).unwrap();
        let rot = Rotation3::from_scaled_axis(Vector3::new(0.3, -0.2, 0.9)).into_inner();
        let w = Vector3::new(0.5, 1.0, -2.0);
        let pose = RigidPose {
            rotation: rot,
            translation: Vector3::new(1.0, 2.0, 3.0),
            angular_velocity: w,
            velocity: Vector3::x(),
        };
        let (q, v) = m.rigid_full_state(&[pose, RigidPose::at_rest(b[1].start)]).unwrap();
        let (r, f) = m.section_frame(&q, 0, 0.5).unwrap();
        assert_relative_eq!(f, rot, epsilon = 1e-14);
        assert_relative_eq!(r, Vector3::new(1.0, 2.0, 3.0) + rot * Vector3::new(0.5, 0.0, 0.0), epsilon = 1e-14);
        let vel = m.material_velocity(&v, 0, 0.3, 0.01, -0.02).unwrap();
        let p = m.material_point(&q, 0, 0.3, 0.01, -0.02).unwrap();
        assert_relative_eq!(vel, Vector3::x() + w.cross(&(p - Vector3::new(1.0, 2.0, 3.0))), epsilon = 1e-13);
    }

    #[test]
    fn bad_poses_are_errors_naming_the_field() {
        let (b, j, g) = samples::double_pendulum(1.0, 30.0, 2);
        let m = Model::new(&b, &j, g, Options::default()).unwrap();
        let ok = RigidPose::at_rest(Vector3::zeros());
        assert_eq!(m.rigid_state(&[ok]).unwrap_err(), Error::PoseCount { got: 1, expected: 2 });
        let mut bad = ok;
        bad.velocity.y = f64::NAN;
        assert!(
            matches!(m.rigid_state(&[ok, bad]), Err(Error::NonFinite { field, .. }) if field == "poses[1].velocity[1]")
        );
        bad = ok;
        bad.rotation[(0, 0)] = 2.0;
        assert!(
            matches!(m.rigid_state(&[bad, ok]), Err(Error::BadFrame { field, .. }) if field == "poses[0].rotation")
        );
    }
}
