//! Thrust, a follower force (docs/ancf.md §14): `F = T(t) v/|v|` at the axis point at
//! arclength `s` of a body, with
//!
//! $$ v = \alpha_0\, (r_y \times r_z) + \alpha_1\, r_y + \alpha_2\, r_z ,\qquad
//!    r_y = (1-\xi)\, r_y^{(1)} + \xi\, r_y^{(2)},\quad r_z = (1-\xi)\, r_z^{(1)} + \xi\, r_z^{(2)} $$
//!
//! the section slopes interpolated at `s` (as the point moments of [`crate::loads`] use them) and
//! the constant coefficients `α = [r_y × r_z, r_y, r_z]⁻¹_ref R_ref(s) d` that reproduce the
//! case's direction `d` (section frame at `s`) in the reference configuration. A rigid motion
//! rotates `r_y`, `r_z` and `r_y × r_z` alike, so it rotates `F` exactly; normalising `v` keeps
//! `|F| = T` whatever the section's small stretch. The generalised force is `Q = S(s)ᵀ F` and
//! its tangent, exact and unsymmetric,
//!
//! $$ \frac{\partial Q}{\partial q} = S(s)^T\, \frac{T}{|v|}\,(I - u u^T)\, \frac{\partial v}{\partial (r_y, r_z)}\,
//!    \frac{\partial (r_y, r_z)}{\partial q},\qquad u = v/|v| . $$
//!
//! Its power is `F · ṙ(s) = Qᵀ q̇`.

use crate::hinge_spring::frame_vector;
use crate::loads::{Station, add_point_force, locate, slopes};
use crate::model::Body;
use crate::shape::point_weights;
use nalgebra::{Matrix3, SMatrix, Vector3};
use scene::Schedule;

/// A thrust on one element of a body.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Thrust {
    /// The element and ξ of the point of application.
    st: Station,
    /// Coefficients of `v` on `(r_y × r_z, r_y, r_z)`.
    alpha: Vector3<f64>,
    /// T(t), N.
    magnitude: Schedule,
}

/// `F / T = u = v/|v|` and `∂u/∂(r_y, r_z)` (3×6).
type Direction = (Vector3<f64>, SMatrix<f64, 3, 6>);

impl Thrust {
    /// The thrust at arclength `at` of body `b` with the unit direction `direction` in the
    /// body's reference section frame at `at`; `q_ref` the full reference coordinates.
    pub(crate) fn new(b: &Body, at: f64, direction: &Vector3<f64>, magnitude: Schedule, q_ref: &[f64]) -> Self {
        let st = locate(b, at);
        let (ry, rz) = slopes(st, q_ref);
        let basis = Matrix3::from_columns(&[ry.cross(&rz), ry, rz]);
        let target = b.spec.section_frame(at) * direction;
        // The reference slopes span space (the section is not degenerate: validated inertias).
        let alpha = basis.try_inverse().map_or(target, |inv| inv * target);
        Self { st, alpha, magnitude }
    }

    /// T(t), N.
    pub(crate) fn magnitude(&self, t: f64) -> f64 {
        self.magnitude.at(t)
    }

    fn direction(&self, q: &[f64]) -> Direction {
        let (ry, rz) = slopes(self.st, q);
        let (v, jv) = frame_vector(&ry, &rz, &self.alpha);
        let n = v.norm();
        let u = v / n;
        (u, (Matrix3::identity() - u * u.transpose()) * jv / n)
    }

    /// The force (global, N) with magnitude `p` at full coordinates `q`.
    pub(crate) fn force(&self, p: f64, q: &[f64]) -> Vector3<f64> {
        self.direction(q).0 * p
    }

    /// `r −= S(s)ᵀ F` with magnitude `p`.
    pub(crate) fn add_residual(&self, p: f64, q: &[f64], r: &mut [f64]) {
        add_point_force(self.st, 0.0, 0.0, &(-self.force(p, q)), r);
    }

    /// Calls `add(row, col, block)` with the 3×3 blocks of `−c ∂Q/∂q` (full coordinates) for
    /// magnitude `p`: rows on the position weights of `S(s)`, columns on the slopes `r_y`, `r_z`
    /// of both nodes.
    pub(crate) fn tangent(&self, p: f64, q: &[f64], c: f64, mut add: impl FnMut(usize, usize, &Matrix3<f64>)) {
        if p == 0.0 || c == 0.0 {
            return;
        }
        let (_, du) = self.direction(q);
        let st = self.st;
        let w = point_weights(st.xi, st.l, 0.0, 0.0);
        let nodes = [(0usize, 1.0 - st.xi), (4usize, st.xi)];
        let (dy, dz): (Matrix3<f64>, Matrix3<f64>) =
            (du.fixed_view::<3, 3>(0, 0).into(), du.fixed_view::<3, 3>(0, 3).into());
        for (a, &wa) in w.iter().enumerate().filter(|(_, wa)| **wa != 0.0) {
            for &(nb, wb) in &nodes {
                let s = -c * p * wa * wb;
                add(st.first + 3 * a, st.first + 3 * (nb + 2), &(dy * s));
                add(st.first + 3 * a, st.first + 3 * (nb + 3), &(dz * s));
            }
        }
    }

    /// The power `F · ṙ(s)` of magnitude `p` at full coordinates `q` and velocities `v`, W.
    pub(crate) fn power(&self, p: f64, q: &[f64], v: &[f64]) -> f64 {
        let mut q_f = [0.0; crate::shape::ELEMENT_DOF];
        add_point_force(Station { first: 0, ..self.st }, 0.0, 0.0, &self.force(p, q), &mut q_f);
        q_f.iter().enumerate().map(|(i, x)| x * v[self.st.first + i]).sum()
    }
}
