//! Hinge springs and dampers (docs/ancf.md §11): the moment `−k(θ − θ₀) − c θ̇` about a hinge's
//! axis on the child, the opposite on the parent (or ground).
//!
//! The angle is a smooth function of the section slopes. With the unnormalised section frames
//! `F = [r_y × r_z, r_y, r_z]` (parent's end section and child's start section, or the fixed
//! ground) and the fixed unit vectors `n1 ⟂ axis`, `n2 = axis × n1` of
//! [`rotation_basis`](crate::frame::rotation_basis),
//!
//! $$ C = u_1 \cdot w,\quad S = u_2 \cdot w,\qquad u_k = F_P\, n_k,\quad w = F_C\, F_{0}^{T} n_1,
//!    \qquad \theta = \theta_{last} + \operatorname{wrap}\big(\operatorname{atan2}(S, C) - \theta_{last}\big) $$
//!
//! (ground hinge: `u_k = n_k` global, `F_0` the body's reference frame; flared hinge: the axis
//! `−a` and `F_0ᵀ = rel0ᵀ` in the parent's section coordinates, as
//! [`fold_angle`](crate::frame::fold_angle)). For orthonormal slopes this is exactly the fold
//! angle (flared hinge) or the rotation about the fixed axis (ground hinge). `atan2` does not
//! care about the length of `(S, C)`, so the slopes' small stretch does not enter except through
//! their direction. `C` and `S` are polynomials of degree ≤ 4 in the 12 (flared) or 6 (ground)
//! slope coordinates, so `θ_q` and `θ_qq` follow in closed form:
//!
//! $$ \theta_q = \frac{C S_q - S C_q}{\rho},\quad \rho = S^2 + C^2, $$
//!
//! $$ \theta_{qq} = \frac{C S_{qq} - S C_{qq}}{\rho} +
//!    \frac{(S^2 - C^2)(S_q C_q^T + C_q S_q^T) + 2CS(C_q C_q^T - S_q S_q^T)}{\rho^2} . $$
//!
//! `θ_last` is the angle of the last accepted step ([`HingeSpring::accept`], called from the
//! model's `post_step`): inside a step the angle changes by much less than π, so θ is smooth
//! and continuous through ±180° and through any number of turns.

use crate::frame::rotation_basis;
use crate::joint::Joint;
use crate::model::Body;
use crate::shape::NODE_DOF;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use std::f64::consts::{PI, TAU};

/// Largest number of coordinates an angle depends on (two sections' `r_y`, `r_z`).
pub(crate) const MAX_VARS: usize = 12;

/// Gradient of θ over the coordinates it depends on.
pub(crate) type Gradient = SVector<f64, MAX_VARS>;
/// Hessian of θ over the coordinates it depends on.
pub(crate) type Hessian = SMatrix<f64, MAX_VARS, MAX_VARS>;

/// What the child's section is measured against.
#[derive(Debug, Clone, PartialEq)]
enum Base {
    /// Ground hinge: the fixed global unit vectors `n1 ⟂ n`, `n2 = n × n1`.
    Ground { u1: Vector3<f64>, u2: Vector3<f64> },
    /// Flared hinge: the parent's end-section slopes `r_y`, `r_z` at full coordinates
    /// `first..first + 6`, `u_k = F_P n_k` with `n_k` in the parent's section coordinates.
    Section { first: usize, n1: Vector3<f64>, n2: Vector3<f64> },
}

/// A rotational spring and damper across a ground or free flared hinge.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct HingeSpring {
    /// The joint, for sensors.
    pub joint: usize,
    /// k, N·m/rad.
    pub stiffness: f64,
    /// c, N·m·s/rad.
    pub damping: f64,
    /// θ₀, rad.
    pub rest: f64,
    /// The child's start-section slopes `r_y`, `r_z` at full coordinates `child..child + 6`.
    child: usize,
    /// `w = F_C gamma`.
    gamma: Vector3<f64>,
    base: Base,
    /// θ of the last accepted step, rad (0 in the reference configuration).
    theta_last: f64,
}

/// θ and its derivatives at a configuration. Local coordinates: the child's `r_y`, `r_z`
/// (0..6), then the parent's (6..12) for a flared hinge.
#[derive(Debug, Clone)]
pub(crate) struct Kinematics {
    /// Number of coordinates (6 or 12).
    pub n: usize,
    /// Their full indices.
    pub idx: [usize; MAX_VARS],
    /// θ, rad (unwrapped).
    pub theta: f64,
    /// θ_q (first `n` entries).
    pub grad: Gradient,
    /// θ_qq (leading `n × n` block), when asked for.
    pub hess: Hessian,
}

/// `v = α₀ (r_y × r_z) + α₁ r_y + α₂ r_z` and `∂v/∂(r_y, r_z)` (3×6).
pub(crate) fn frame_vector(
    ry: &Vector3<f64>,
    rz: &Vector3<f64>,
    alpha: &Vector3<f64>,
) -> (Vector3<f64>, SMatrix<f64, 3, 6>) {
    let v = ry.cross(rz) * alpha[0] + ry * alpha[1] + rz * alpha[2];
    let mut j = SMatrix::<f64, 3, 6>::zeros();
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&(Matrix3::identity() * alpha[1] - rz.cross_matrix() * alpha[0]));
    j.fixed_view_mut::<3, 3>(0, 3).copy_from(&(Matrix3::identity() * alpha[2] + ry.cross_matrix() * alpha[0]));
    (v, j)
}

/// `h += c · ∂²(g·v)/∂(r_y, r_z)²` at local offset `o` for `v` of [`frame_vector`]: only the
/// cross product is quadratic, `∂²/∂r_y∂r_z = −α₀ [g]×`.
fn add_frame_hessian(h: &mut Hessian, o: usize, g: &Vector3<f64>, alpha0: f64, c: f64) {
    if alpha0 == 0.0 {
        return;
    }
    let b = g.cross_matrix() * (-alpha0 * c);
    let mut upper = h.fixed_view_mut::<3, 3>(o, o + 3);
    upper += b;
    let mut lower = h.fixed_view_mut::<3, 3>(o + 3, o);
    lower += b.transpose();
}

fn slopes(q: &[f64], first: usize) -> (Vector3<f64>, Vector3<f64>) {
    (Vector3::new(q[first], q[first + 1], q[first + 2]), Vector3::new(q[first + 3], q[first + 4], q[first + 5]))
}

/// `x` wrapped into [−π, π).
fn wrap(x: f64) -> f64 {
    x - TAU * ((x + PI) / TAU).floor()
}

impl HingeSpring {
    /// The spring across `joint` (a ground or free flared hinge).
    ///
    /// # Panics
    /// On a clamp or a locked hinge (the scene's validation rejects those).
    pub(crate) fn new(joint: usize, jt: &Joint, bodies: &[Body], stiffness: f64, damping: f64, rest: f64) -> Self {
        let slope_index = |body: usize, node: usize| bodies[body].offset + NODE_DOF * node + 6;
        let (child, gamma, base) = match jt {
            Joint::Ground { body, axis, .. } => {
                let (n1, n2) = rotation_basis(axis);
                let f0 = bodies[*body].node_frame(0);
                (slope_index(*body, 0), f0.transpose() * n1, Base::Ground { u1: n1, u2: n2 })
            }
            Joint::Flared { parent, child, alpha_p, rel0, lock: None, .. } => {
                let (n1, n2) = rotation_basis(&-alpha_p.normalize());
                let first = slope_index(*parent, bodies[*parent].n_nodes - 1);
                (slope_index(*child, 0), rel0.transpose() * n1, Base::Section { first, n1, n2 })
            }
            _ => panic!("joint {joint}: a hinge spring needs a ground or free flared hinge"),
        };
        Self { joint, stiffness, damping, rest, child, gamma, base, theta_last: 0.0 }
    }

    /// Whether the spring couples two bodies (a flared hinge).
    pub(crate) fn couples_bodies(&self) -> bool {
        matches!(self.base, Base::Section { .. })
    }

    /// The full coordinates θ depends on, in local order.
    pub(crate) fn coordinates(&self) -> ([usize; MAX_VARS], usize) {
        let mut idx = [0; MAX_VARS];
        for (a, i) in idx[..6].iter_mut().enumerate() {
            *i = self.child + a;
        }
        match self.base {
            Base::Ground { .. } => (idx, 6),
            Base::Section { first, .. } => {
                for (a, i) in idx[6..].iter_mut().enumerate() {
                    *i = first + a;
                }
                (idx, 12)
            }
        }
    }

    /// `(S, C)` at the full coordinates `q`.
    fn sine_cosine(&self, q: &[f64]) -> (f64, f64) {
        let (cy, cz) = slopes(q, self.child);
        let w = cy.cross(&cz) * self.gamma[0] + cy * self.gamma[1] + cz * self.gamma[2];
        let (u1, u2) = match self.base {
            Base::Ground { u1, u2 } => (u1, u2),
            Base::Section { first, n1, n2 } => {
                let (py, pz) = slopes(q, first);
                let n = py.cross(&pz);
                (n * n1[0] + py * n1[1] + pz * n1[2], n * n2[0] + py * n2[1] + pz * n2[2])
            }
        };
        (u2.dot(&w), u1.dot(&w))
    }

    fn unwrap(&self, raw: f64) -> f64 {
        self.theta_last + wrap(raw - self.theta_last)
    }

    /// θ at the full coordinates `q`, rad (unwrapped against the last accepted step).
    pub(crate) fn angle(&self, q: &[f64]) -> f64 {
        let (s, c) = self.sine_cosine(q);
        self.unwrap(s.atan2(c))
    }

    /// Take the angle at `q` as the unwrapping reference (after an accepted step).
    pub(crate) fn accept(&mut self, q: &[f64]) {
        self.theta_last = self.angle(q);
    }

    /// Drop the unwrapping reference: the next [`accept`](Self::accept) takes the principal
    /// angle.
    pub(crate) fn forget(&mut self) {
        self.theta_last = 0.0;
    }

    /// Spring energy ½k(θ − θ₀)², J.
    pub(crate) fn energy(&self, q: &[f64]) -> f64 {
        let d = self.angle(q) - self.rest;
        0.5 * self.stiffness * d * d
    }

    /// θ, θ_q and (when `hessian`) θ_qq at the full coordinates `q`.
    pub(crate) fn kinematics(&self, q: &[f64], hessian: bool) -> Kinematics {
        let (idx, n) = self.coordinates();
        let (cy, cz) = slopes(q, self.child);
        let (w, jw) = frame_vector(&cy, &cz, &self.gamma);
        // gradients and Hessians of C = u1·w and S = u2·w
        let (mut gc, mut gs) = (Gradient::zeros(), Gradient::zeros());
        let (mut hc, mut hs) = (Hessian::zeros(), Hessian::zeros());
        let (u1, u2) = match self.base {
            Base::Ground { u1, u2 } => (u1, u2),
            Base::Section { first, n1, n2 } => {
                let (py, pz) = slopes(q, first);
                let (u1, j1) = frame_vector(&py, &pz, &n1);
                let (u2, j2) = frame_vector(&py, &pz, &n2);
                gc.fixed_rows_mut::<6>(6).copy_from(&(j1.transpose() * w));
                gs.fixed_rows_mut::<6>(6).copy_from(&(j2.transpose() * w));
                if hessian {
                    add_frame_hessian(&mut hc, 6, &w, n1[0], 1.0);
                    add_frame_hessian(&mut hs, 6, &w, n2[0], 1.0);
                    let (x1, x2) = (jw.transpose() * j1, jw.transpose() * j2);
                    hc.fixed_view_mut::<6, 6>(0, 6).copy_from(&x1);
                    hc.fixed_view_mut::<6, 6>(6, 0).copy_from(&x1.transpose());
                    hs.fixed_view_mut::<6, 6>(0, 6).copy_from(&x2);
                    hs.fixed_view_mut::<6, 6>(6, 0).copy_from(&x2.transpose());
                }
                (u1, u2)
            }
        };
        gc.fixed_rows_mut::<6>(0).copy_from(&(jw.transpose() * u1));
        gs.fixed_rows_mut::<6>(0).copy_from(&(jw.transpose() * u2));
        let (c, s) = (u1.dot(&w), u2.dot(&w));
        let rho = s * s + c * c;
        let theta = self.unwrap(s.atan2(c));
        let grad = (gs * c - gc * s) / rho;
        let mut hess = Hessian::zeros();
        if hessian {
            add_frame_hessian(&mut hc, 0, &u1, self.gamma[0], 1.0);
            add_frame_hessian(&mut hs, 0, &u2, self.gamma[0], 1.0);
            let mixed = gs * gc.transpose();
            hess = (hs * c - hc * s) / rho
                + ((mixed + mixed.transpose()) * (s * s - c * c)
                    + (gc * gc.transpose() - gs * gs.transpose()) * (2.0 * c * s))
                    / (rho * rho);
        }
        Kinematics { n, idx, theta, grad, hess }
    }

    /// θ̇ = θ_q · v for full velocities `v`.
    pub(crate) fn rate(kin: &Kinematics, v: &[f64]) -> f64 {
        (0..kin.n).map(|a| kin.grad[a] * v[kin.idx[a]]).sum()
    }

    /// The generalised moment magnitude `k(θ − θ₀) + c θ̇` (the residual adds it times θ_q).
    pub(crate) fn moment(&self, kin: &Kinematics, rate: f64) -> f64 {
        self.stiffness * (kin.theta - self.rest) + self.damping * rate
    }

    /// `c_k ∂r/∂q + c_c ∂r/∂v` of the spring's residual `(k(θ−θ₀) + c θ̇) θ_q` over its local
    /// coordinates: `c_k [k θ_q θ_qᵀ + (k(θ−θ₀) + cθ̇) θ_qq + c θ_q (θ_qq v)ᵀ] + c_c c θ_q θ_qᵀ`
    /// (`v` the full velocities, `None` for zero). With `newton` (Newton's matrix of a time step)
    /// the damper's `c θ_q (θ_qq v)ᵀ`, the only unsymmetric term, is left out, so that the matrix
    /// stays symmetric (docs/ancf.md §11); the residual, and so every converged step, is unchanged.
    pub(crate) fn tangent(&self, kin: &Kinematics, v: Option<&[f64]>, c_c: f64, c_k: f64, newton: bool) -> Hessian {
        let (k, c) = (self.stiffness, self.damping);
        let g = &kin.grad;
        let rate = v.map_or(0.0, |v| Self::rate(kin, v));
        let mut t = g * g.transpose() * (c_k * k + c_c * c) + kin.hess * (c_k * self.moment(kin, rate));
        if let Some(v) = v
            && c != 0.0
            && !newton
        {
            let mut hv = Gradient::zeros();
            for a in 0..kin.n {
                hv[a] = (0..kin.n).map(|b| kin.hess[(a, b)] * v[kin.idx[b]]).sum();
            }
            t += g * hv.transpose() * (c_k * c);
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Model, Options, RigidPose, samples};
    use nalgebra::{Rotation3, Unit};

    fn springs(model: &Model) -> Vec<HingeSpring> {
        (0..2).map(|j| HingeSpring::new(j, &model.joints[j], &model.bodies, 1.0, 0.0, 0.0)).collect()
    }

    /// A flexed, sheared and twisted state: rigid rotations of both bodies plus noise on every
    /// coordinate.
    fn state(model: &Model, seed: usize) -> Vec<f64> {
        let r0 = Rotation3::from_scaled_axis(Vector3::new(0.2, 0.9, -0.3)).into_inner();
        let r1 = Rotation3::from_scaled_axis(Vector3::new(-0.7, 1.9, 0.4)).into_inner();
        let b = &model.bodies;
        let poses = [
            RigidPose { rotation: r0, ..RigidPose::at_rest(b[0].spec.start) },
            RigidPose { rotation: r1, ..RigidPose::at_rest(b[1].spec.start) },
        ];
        let (q, _) = model.rigid_full_state(&poses).unwrap();
        q.iter().enumerate().map(|(i, x)| x + 0.03 * (((i + seed) * 37 % 101) as f64 / 101.0 - 0.5)).collect()
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let (b, j, g) = samples::double_pendulum(1.0, 35.0, 2);
        let model = Model::new(&b, &j, g, Options::default()).unwrap();
        for spring in springs(&model) {
            for seed in 0..3 {
                let q = state(&model, seed);
                let kin = spring.kinematics(&q, true);
                let h = 1e-6;
                for a in 0..kin.n {
                    let (mut qp, mut qm) = (q.clone(), q.clone());
                    qp[kin.idx[a]] += h;
                    qm[kin.idx[a]] -= h;
                    let fd = (spring.angle(&qp) - spring.angle(&qm)) / (2.0 * h);
                    approx::assert_relative_eq!(kin.grad[a], fd, epsilon = 1e-8);
                    let (gp, gm) = (spring.kinematics(&qp, false).grad, spring.kinematics(&qm, false).grad);
                    for c in 0..kin.n {
                        approx::assert_relative_eq!(kin.hess[(c, a)], (gp[c] - gm[c]) / (2.0 * h), epsilon = 1e-7);
                    }
                }
                assert!((kin.hess - kin.hess.transpose()).amax() < 1e-12);
            }
        }
    }

    #[test]
    fn rigid_rotations_give_the_fold_angle_and_the_ground_rotation() {
        let (b, j, g) = samples::double_pendulum(1.0, 35.0, 2);
        let model = Model::new(&b, &j, g, Options::default()).unwrap();
        let s = springs(&model);
        let beta = 35f64.to_radians();
        let a = Vector3::new(beta.sin(), beta.cos(), 0.0);
        let r0 = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::y()), 0.4).into_inner();
        for theta in [-2.5, -0.3, 0.0, 0.8, 3.0] {
            // body 1 turned by θ about −a relative to body 0, which is turned by 0.4 about y
            let rel = Rotation3::from_axis_angle(&Unit::new_normalize(-(r0 * a)), theta).into_inner();
            let poses = [
                RigidPose { rotation: r0, ..RigidPose::at_rest(b[0].start) },
                RigidPose { rotation: rel * r0, translation: r0 * b[1].start, ..RigidPose::at_rest(b[1].start) },
            ];
            let (q, _) = model.rigid_full_state(&poses).unwrap();
            approx::assert_relative_eq!(s[0].angle(&q), 0.4, epsilon = 1e-13);
            approx::assert_relative_eq!(s[1].angle(&q), theta, epsilon = 1e-13);
            approx::assert_relative_eq!(model.fold_angle(&q, 1).unwrap(), theta, epsilon = 1e-13);
        }
    }

    #[test]
    fn the_angle_unwraps_past_half_a_turn() {
        let (b, j, g) = samples::double_pendulum(1.0, 0.0, 2);
        let model = Model::new(&b, &j, g, Options::default()).unwrap();
        let mut s = springs(&model).remove(0);
        let mut last = 0.0;
        for k in 1..=40 {
            let phi = 0.2 * k as f64; // up to 8 rad, past ±π and 2π
            let r = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::y()), phi).into_inner();
            let poses = [RigidPose { rotation: r, ..RigidPose::at_rest(b[0].start) }, RigidPose::at_rest(b[1].start)];
            let (q, _) = model.rigid_full_state(&poses).unwrap();
            let theta = s.angle(&q);
            assert!((theta - phi).abs() < 1e-12 && theta > last, "{theta} at {phi}");
            s.accept(&q);
            last = theta;
        }
    }

    #[test]
    fn wrap_maps_into_half_open_interval() {
        for (x, y) in [(0.0, 0.0), (3.0, 3.0), (PI + 0.1, -PI + 0.1), (-PI - 0.1, PI - 0.1), (7.0, 7.0 - TAU)] {
            approx::assert_relative_eq!(wrap(x), y, epsilon = 1e-14);
        }
    }
}
