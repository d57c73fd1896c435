//! Ground hinge (SHARPy's `hinge_FoR`): a body's frame origin is fixed and the frame rotates
//! only about a fixed axis.
//!
//! Velocity-level rows (5): `v_A = 0` (3) and `n_kᵀ omega_A = 0` (k = 1, 2), where `n_1, n_2`
//! are a fixed orthonormal pair perpendicular to the hinge axis *in A components*. Because a
//! frame spinning about an axis fixed in A keeps that axis fixed in G, the rows are exactly the
//! hinge kinematics; `B` is constant, so `∂(B v)/∂q = 0` and `∂(Bᵀ mu)/∂q = 0`, and with
//! the Lie update of the quaternion the axis stays aligned to round-off.

use crate::body::Body;
use crate::crv::V3;
use genalpha::MatView;

/// Internal ground hinge.
#[derive(Debug, Clone)]
pub(crate) struct GroundHinge {
    pub body: usize,
    /// Unit axis in G.
    pub axis: V3,
    /// Unit axis in A.
    pub axis_a: V3,
    /// Orthonormal pair ⟂ axis, in A.
    pub n: [V3; 2],
}

/// A fixed orthonormal pair perpendicular to the unit vector `a`.
pub(crate) fn perpendicular_pair(a: &V3) -> [V3; 2] {
    // Start from the coordinate axis least aligned with a.
    let k = a.iamin();
    let e = V3::ith(k, 1.0);
    let n1 = (e - a * a.dot(&e)).normalize();
    [n1, a.cross(&n1)]
}

impl GroundHinge {
    pub fn new(body: usize, axis_g: &V3, b: &Body) -> Self {
        let axis = axis_g.normalize();
        let axis_a = b.frame.transpose() * axis;
        Self { body, axis, axis_a, n: perpendicular_pair(&axis_a) }
    }

    pub const N_ROWS: usize = 5;

    pub fn psi(&self, b: &Body, v: &[f64], out: &mut [f64]) {
        let (va, wa) = b.frame_rates(v);
        out[0] = va.x;
        out[1] = va.y;
        out[2] = va.z;
        out[3] = self.n[0].dot(&wa);
        out[4] = self.n[1].dot(&wa);
    }

    pub fn add_b(&self, b: &Body, j: &mut MatView<'_>, row0: usize) {
        let f = b.frame_dof();
        for k in 0..3 {
            j.add(row0 + k, f + k, 1.0);
            j.add(row0 + 3, f + 3 + k, self.n[0][k]);
            j.add(row0 + 4, f + 3 + k, self.n[1][k]);
        }
    }

    /// (gap of the start point from its reference position, m; angle between the body's hinge
    /// axis and the fixed axis, rad).
    pub fn violation(&self, b: &Body, q: &[f64]) -> (f64, f64) {
        let (r, chi) = b.frame_state(q);
        let gap = (r - b.start).norm();
        let a = chi.rotate(&self.axis_a);
        (gap, angle_between(&a, &self.axis))
    }
}

/// Angle between two unit vectors (accurate at small angles), rad.
pub(crate) fn angle_between(a: &V3, b: &V3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}
